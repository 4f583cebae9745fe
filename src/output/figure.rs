//! Line and scatter figures rendered to SVG with `plotters`.
//!
//! A [`Figure`] is plain data (title, axis labels with units, log or category axes,
//! [`Series`], horizontal reference lines, a caption) and renders deterministically: the
//! same figure always produces the same SVG bytes. Text is emitted as SVG `<text>`
//! elements and laid out by the viewer, so no font files are needed and Unicode labels
//! (`⟨F⟩`, `λᵢ`, `τ₁`) render as they are; text extents are estimated from the character
//! count to place the legend box.
//!
//! Reading aids:
//! - colours: a series takes the palette colour of its index unless it names one
//!   ([`Series::palette`], [`Series::rgb`]); the series of one quantity share a colour,
//!   the reference curve in a [light](Series::light) tint beneath the data, and a legend
//!   entry can [join](Series::joined_with_next) the two ("mode 1: simulated / exact");
//! - the legend goes in a corner of the plot that no point, line, marker or error bar
//!   touches, else beside the plot (the canvas widens): it never hides data;
//! - the SVG carries the caption as its `<title>` and the axis labels as its `<desc>`
//!   (`horizontal axis: …` and `vertical axis: …`, one a line), for screen readers and
//!   tests; [`AxisUnits`] spells the units of the column dictionary in the labels.
//!
//! Robustness rules, so that a figure never hides a failed run behind a rendering error:
//! - points with a non-finite coordinate are skipped, and so are points with a
//!   non-positive coordinate on a logarithmic axis; a line is broken at a skipped point
//!   rather than drawn across it, and the figure carries a footnote with the number of
//!   points not shown;
//! - the axis ranges cover all drawn points, error bars and reference lines, plus a 5 %
//!   margin (on a log axis in decades); a degenerate range is widened;
//! - a figure without any drawable point still renders, with a note in the plot area.

use std::path::Path;

use std::ops::Range;

use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::error::{Error, Result};

use super::io::write_atomic;

/// Width of a rendered figure in pixels.
const WIDTH: u32 = 800;
/// Height of a rendered figure in pixels.
const HEIGHT: u32 = 520;
const FONT: &str = "sans-serif";
/// Half width of an error-bar cap in pixels.
const CAP: i32 = 4;
/// Default marker radius in pixels.
const MARKER_RADIUS: u32 = 4;
/// Legend font size (plotters units; the SVG font size is this / 1.24, 12.5 px).
const LEGEND_FONT: f64 = 15.5;
/// Estimated width of a legend character in pixels (about 0.53 em of the 12.5-px font,
/// a little above the average of DejaVu Sans and Liberation Sans text).
const LEGEND_CHAR_WIDTH: f64 = 6.6;
/// Height of a legend line in pixels.
const LEGEND_LINE: i32 = 19;
/// Inner margin of the legend box in pixels.
const LEGEND_PAD: i32 = 8;
/// Width of a legend glyph in pixels.
const GLYPH_WIDTH: i32 = 24;
/// Left edge of a legend placed beside the plot (just right of the plot area).
const OUTSIDE_X: i32 = WIDTH as i32 - 10;
/// Lowest top edge of a legend placed beside the plot.
const OUTSIDE_TOP: i32 = 40;
/// Relative margin added on each side of the data range.
const MARGIN: f64 = 0.05;

/// Series colours (the "Tableau 10" palette, distinguishable on white and in print);
/// further series get colours spread around the hue circle.
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// Colours of horizontal reference lines (drawn dashed).
const HLINE_COLORS: [RGBColor; 3] = [
    RGBColor(0, 0, 0),
    RGBColor(90, 90, 90),
    RGBColor(150, 60, 0),
];

/// Units for axis labels: the column dictionary's base dimensions made readable
/// (`[L]`, `[L²]`, `[1/T]`, `[L²·T]`; see [`super::columns`]), or the concrete units of a
/// scene given in physical units (`[µm]`, `[µm²]`, `[1/s]`, `[µm²·s]`; see
/// [`super::provenance::SceneProvenance::units`]). Multiples of τ₁, F_c0 and ε_c0 are
/// written as ratios in the labels themselves (`t / τ₁`, `⟨F⟩ / F_c0`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AxisUnits {
    /// The length unit (`L` or `µm`).
    pub length: &'static str,
    /// The time unit (`T` or `s`).
    pub time: &'static str,
}

impl AxisUnits {
    /// The units of a scene in its own consistent units (`physical` false: `[L]`, `[T]`)
    /// or given in physical units (`physical` true: µm, s).
    pub fn new(physical: bool) -> Self {
        if physical {
            AxisUnits {
                length: "µm",
                time: "s",
            }
        } else {
            AxisUnits {
                length: "L",
                time: "T",
            }
        }
    }

    /// A length, e.g. `[L]`.
    pub fn length(&self) -> String {
        format!("[{}]", self.length)
    }

    /// A squared length, e.g. `[L²]`.
    pub fn area(&self) -> String {
        format!("[{}²]", self.length)
    }

    /// A frequency, e.g. `[1/T]`.
    pub fn frequency(&self) -> String {
        format!("[1/{}]", self.time)
    }

    /// A power spectral density of a length, e.g. `[L²·T]`.
    pub fn psd(&self) -> String {
        format!("[{}²·{}]", self.length, self.time)
    }
}

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SeriesStyle {
    /// A solid line through the points.
    Line,
    /// A dashed line through the points (e.g. an exact reference curve).
    Dashed,
    /// Filled circular markers, no line (e.g. estimates).
    Markers,
    /// A solid line with markers at the points.
    LineMarkers,
}

/// The colour of a series.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SeriesColor {
    /// Entry `i` of the figure palette (the "Tableau 10" colours, then hues spread around
    /// the colour circle).
    Palette(usize),
    /// An explicit colour (red, green, blue), e.g. for a status with a conventional
    /// colour.
    Rgb(u8, u8, u8),
}

/// One data series of a [`Figure`].
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend label (an empty label gives no legend entry).
    pub label: String,
    /// The points `(x, y)`, in the order in which lines connect them.
    pub points: Vec<(f64, f64)>,
    /// Optional symmetric vertical error bars, one half-width per point
    /// (non-finite or negative entries draw no bar).
    pub y_err: Option<Vec<f64>>,
    /// How the series is drawn.
    pub style: SeriesStyle,
    /// Its colour; `None`: the palette colour of the series' index in the figure.
    pub color: Option<SeriesColor>,
    /// Drawn in a light tint of its colour, under the other series (e.g. the exact curve
    /// of a mode beneath the simulated markers of the same colour).
    pub light: bool,
    /// Marker radius in pixels.
    pub marker_radius: u32,
    /// The legend entry of this series also shows the glyph of the next series: one entry
    /// for a pair such as "mode 1: simulated / exact" (the next series then needs no
    /// label of its own).
    pub legend_joins_next: bool,
}

impl Series {
    fn with(label: impl Into<String>, points: Vec<(f64, f64)>, style: SeriesStyle) -> Self {
        Series {
            label: label.into(),
            points,
            y_err: None,
            style,
            color: None,
            light: false,
            marker_radius: MARKER_RADIUS,
            legend_joins_next: false,
        }
    }

    /// A series drawn as a solid line.
    pub fn line(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Series::with(label, points, SeriesStyle::Line)
    }

    /// A series drawn as markers.
    pub fn markers(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Series::with(label, points, SeriesStyle::Markers)
    }

    /// Adds vertical error bars (half-widths, one per point, e.g. standard errors).
    #[must_use]
    pub fn with_errors(mut self, errs: Vec<f64>) -> Self {
        self.y_err = Some(errs);
        self
    }

    /// Draws the series as a dashed line.
    #[must_use]
    pub fn dashed(mut self) -> Self {
        self.style = SeriesStyle::Dashed;
        self
    }

    /// Sets the drawing style.
    #[must_use]
    pub fn with_style(mut self, style: SeriesStyle) -> Self {
        self.style = style;
        self
    }

    /// Draws the series in palette colour `i` (series of one quantity share a colour).
    #[must_use]
    pub fn palette(mut self, i: usize) -> Self {
        self.color = Some(SeriesColor::Palette(i));
        self
    }

    /// Draws the series in the colour `(r, g, b)`.
    #[must_use]
    pub fn rgb(mut self, r: u8, g: u8, b: u8) -> Self {
        self.color = Some(SeriesColor::Rgb(r, g, b));
        self
    }

    /// Draws the series in a light tint of its colour, beneath the other series.
    #[must_use]
    pub fn light(mut self) -> Self {
        self.light = true;
        self
    }

    /// Sets the marker radius in pixels (default 4).
    #[must_use]
    pub fn marker_radius(mut self, px: u32) -> Self {
        self.marker_radius = px;
        self
    }

    /// Makes this series' legend entry also show the next series' glyph (see
    /// [`Series::legend_joins_next`]).
    #[must_use]
    pub fn joined_with_next(mut self) -> Self {
        self.legend_joins_next = true;
        self
    }
}

/// A 2-D figure: series, optional error bars, horizontal reference lines, linear,
/// logarithmic or category axes, and a caption.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Title above the plot.
    pub title: String,
    /// Label of the horizontal axis (include units).
    pub x_label: String,
    /// Label of the vertical axis (include units).
    pub y_label: String,
    /// Logarithmic horizontal axis (base 10).
    pub x_log: bool,
    /// Logarithmic vertical axis (base 10).
    pub y_log: bool,
    /// Category labels of the horizontal axis: if not empty, x = k is drawn at the `k`-th
    /// label (k = 0, 1, …) and `x_log` is ignored.
    pub x_categories: Vec<String>,
    /// Category labels of the vertical axis (as [`Figure::x_categories`]).
    pub y_categories: Vec<String>,
    /// The data series, drawn in order (later series on top; light series first).
    pub series: Vec<Series>,
    /// Horizontal reference lines `(y, legend label)`, drawn dashed across the plot.
    pub hlines: Vec<(f64, String)>,
    /// What the figure shows and what a reader should see in it; written into the SVG as
    /// its `<title>` (empty: none).
    pub caption: String,
}

impl Figure {
    /// An empty figure with linear axes.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Figure {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            x_log: false,
            y_log: false,
            x_categories: Vec::new(),
            y_categories: Vec::new(),
            series: Vec::new(),
            hlines: Vec::new(),
            caption: String::new(),
        }
    }

    /// Makes the horizontal axis logarithmic.
    #[must_use]
    pub fn log_x(mut self) -> Self {
        self.x_log = true;
        self
    }

    /// Makes the vertical axis logarithmic.
    #[must_use]
    pub fn log_y(mut self) -> Self {
        self.y_log = true;
        self
    }

    /// Makes the horizontal axis a category axis (see [`Figure::x_categories`]).
    #[must_use]
    pub fn x_categories(mut self, labels: Vec<String>) -> Self {
        self.x_categories = labels;
        self
    }

    /// Makes the vertical axis a category axis (see [`Figure::y_categories`]).
    #[must_use]
    pub fn y_categories(mut self, labels: Vec<String>) -> Self {
        self.y_categories = labels;
        self
    }

    /// Adds a series.
    #[must_use]
    pub fn series(mut self, s: Series) -> Self {
        self.series.push(s);
        self
    }

    /// Adds a horizontal reference line at `y` with a legend label.
    #[must_use]
    pub fn hline(mut self, y: f64, label: impl Into<String>) -> Self {
        self.hlines.push((y, label.into()));
        self
    }

    /// Sets the caption (see [`Figure::caption`]).
    #[must_use]
    pub fn caption(mut self, text: impl Into<String>) -> Self {
        self.caption = text.into();
        self
    }

    /// Renders the figure as an SVG document: 800 × 520 pixels, wider (and taller, for
    /// a long legend) when the legend has to go beside the plot.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if a series has error bars whose count differs from its
    /// number of points; [`Error::Numerical`] if plotters fails to draw (not expected for
    /// the SVG backend).
    pub fn render_svg(&self) -> Result<String> {
        let prepared = self.prepare()?;
        let legend = self.legend_entries(&prepared);
        let size = legend_size(&legend);
        let corner = if legend.is_empty() {
            None
        } else {
            self.free_corner(&prepared, size)
                .map_err(|e| self.render_error(e))?
        };
        let (width, height, place) = match corner {
            _ if legend.is_empty() => (WIDTH, HEIGHT, LegendPlace::None),
            Some(at) => (WIDTH, HEIGHT, LegendPlace::Inside(at)),
            None => (
                (OUTSIDE_X + size.0 + 12) as u32,
                HEIGHT.max((OUTSIDE_TOP + size.1 + 12) as u32),
                LegendPlace::Outside,
            ),
        };
        let mut buf = String::new();
        {
            let root = SVGBackend::with_string(&mut buf, (width, height)).into_drawing_area();
            self.draw(&root, &prepared, &legend, place)
                .map_err(|e| self.render_error(e))?;
            root.present().map_err(|e| self.render_error(e))?;
        }
        Ok(self.with_accessible_text(buf))
    }

    /// Renders the figure (see [`Figure::render_svg`]) and writes it to `path` atomically.
    ///
    /// # Errors
    /// As [`Figure::render_svg`], and [`Error::Io`] naming `path` if writing fails.
    pub fn write_svg(&self, path: &Path) -> Result<()> {
        let svg = self.render_svg()?;
        write_atomic(path, svg.as_bytes())
    }

    fn render_error(&self, e: impl std::fmt::Display) -> Error {
        Error::Numerical {
            routine: "SVG figure rendering".into(),
            detail: format!("figure `{}`: {e}", self.title),
        }
    }

    /// `svg` with the caption as `<title>` and the axis labels as `<desc>` (one a line:
    /// `horizontal axis: …`, `vertical axis: …`) right after the opening `<svg>` tag, for
    /// screen readers, browsers' tooltips and tests.
    fn with_accessible_text(&self, mut svg: String) -> String {
        let Some(end) = svg.find('>') else {
            return svg;
        };
        let mut text = String::new();
        if !self.caption.is_empty() {
            text.push_str(&format!("\n<title>{}</title>", xml_escape(&self.caption)));
        }
        text.push_str(&format!(
            "\n<desc>horizontal axis: {}\nvertical axis: {}</desc>",
            xml_escape(&self.x_label),
            xml_escape(&self.y_label)
        ));
        svg.insert_str(end + 1, &text);
        svg
    }

    /// Maps a data coordinate to plot space (`log10` on a log axis); `None` if the value
    /// cannot be drawn on that axis.
    fn tx(&self, x: f64) -> Option<f64> {
        to_axis(x, self.x_log && self.x_categories.is_empty())
    }

    fn ty(&self, y: f64) -> Option<f64> {
        to_axis(y, self.y_log && self.y_categories.is_empty())
    }

    /// Filters and transforms the data and computes the axes.
    fn prepare(&self) -> Result<Prepared> {
        let mut skipped = 0usize;
        let mut skipped_hlines = 0usize;
        let mut xs = Extent::default();
        let mut ys = Extent::default();
        let mut series = Vec::with_capacity(self.series.len());

        for s in &self.series {
            if let Some(errs) = &s.y_err
                && errs.len() != s.points.len()
            {
                return Err(Error::invalid(
                    format!(
                        "number of error bars of series `{}` in figure `{}`",
                        s.label, self.title
                    ),
                    errs.len(),
                    format!("{} (the number of points)", s.points.len()),
                ));
            }
            let mut p = PreparedSeries::default();
            let mut run: Vec<(f64, f64)> = Vec::new();
            for (i, &(x, y)) in s.points.iter().enumerate() {
                let (Some(px), Some(py)) = (self.tx(x), self.ty(y)) else {
                    skipped += 1;
                    if !run.is_empty() {
                        p.runs.push(std::mem::take(&mut run));
                    }
                    continue;
                };
                xs.add(px);
                ys.add(py);
                run.push((px, py));
                p.points.push((px, py));
                let err = s.y_err.as_ref().map_or(f64::NAN, |e| e[i]);
                if err.is_finite() && err > 0.0 {
                    let hi = self.ty(y + err);
                    let lo = self.ty(y - err);
                    if let Some(hi) = hi {
                        ys.add(hi);
                    }
                    if let Some(lo) = lo {
                        ys.add(lo);
                    }
                    p.bars.push(Bar { x: px, lo, hi });
                }
            }
            if !run.is_empty() {
                p.runs.push(run);
            }
            series.push(p);
        }

        let has_data = series.iter().any(|s| !s.points.is_empty());
        let mut hlines = Vec::with_capacity(self.hlines.len());
        for (k, (y, label)) in self.hlines.iter().enumerate() {
            match self.ty(*y) {
                Some(py) => {
                    ys.add(py);
                    hlines.push((k, py, label.clone()));
                }
                None => skipped_hlines += 1,
            }
        }

        let axis = |extent: Extent, log: bool, categories: &[String]| {
            if categories.is_empty() {
                Axis::new(extent, log)
            } else {
                Axis::categories(extent, categories)
            }
        };
        Ok(Prepared {
            series,
            hlines,
            skipped,
            skipped_hlines,
            has_data,
            x: axis(xs, self.x_log, &self.x_categories),
            y: axis(ys, self.y_log, &self.y_categories),
        })
    }

    fn draw(
        &self,
        root: &Root<'_>,
        prep: &Prepared,
        legend: &[LegendEntry],
        place: LegendPlace,
    ) -> DrawResult<()> {
        root.fill(&WHITE)?;
        let plot_root = root.clone().shrink((0, 0), (WIDTH, HEIGHT));
        let mut chart = self.chart_with_mesh(&plot_root, prep)?;
        // Reference lines first, then light series (references), so that data are drawn
        // over them.
        draw_hlines(&mut chart, prep)?;
        let order = self
            .series
            .iter()
            .enumerate()
            .filter(|(_, s)| s.light)
            .chain(self.series.iter().enumerate().filter(|(_, s)| !s.light));
        for (i, s) in order {
            draw_data_series(&mut chart, prep, s, &prep.series[i], self.color(i))?;
        }
        if !prep.has_data {
            draw_no_data_note(root, &chart)?;
        }
        match place {
            LegendPlace::None => {}
            LegendPlace::Inside(at) => draw_legend(root, legend, at)?,
            LegendPlace::Outside => {
                let (_, yr) = chart.plotting_area().get_pixel_range();
                draw_legend(root, legend, (OUTSIDE_X, yr.start.max(OUTSIDE_TOP)))?;
            }
        }
        if let Some(note) = prep.skipped_note(self.x_log || self.y_log) {
            root.draw(&Text::new(
                note,
                (8, HEIGHT as i32 - 6),
                (FONT, 14)
                    .into_font()
                    .color(&RGBColor(110, 110, 110))
                    .pos(Pos::new(HPos::Left, VPos::Bottom)),
            ))?;
        }
        Ok(())
    }

    /// The colour of series `i`: its own, or the palette colour of its index.
    fn color(&self, i: usize) -> RGBColor {
        let s = &self.series[i];
        let c = match s.color {
            None => series_color(i),
            Some(SeriesColor::Palette(k)) => series_color(k),
            Some(SeriesColor::Rgb(r, g, b)) => RGBColor(r, g, b),
        };
        if s.light { tint(c) } else { c }
    }

    /// The chart (caption, label areas, axes in plot space) with its grid, ticks and axis
    /// labels drawn.
    fn chart_with_mesh<'a, 'b>(
        &self,
        root: &'a Root<'b>,
        prep: &Prepared,
    ) -> DrawResult<Chart<'a, 'b>> {
        let mut builder = ChartBuilder::on(root);
        builder
            .margin(14)
            .margin_right(24)
            .x_label_area_size(52)
            .y_label_area_size(92);
        if !self.title.is_empty() {
            // Smaller type for a long title, so that it fits the width (about 0.55 em a
            // character; the SVG font size is the plotters size / 1.24).
            let chars = self.title.chars().count().max(1) as f64;
            let fit = f64::from(WIDTH - 40) / (0.55 * chars) * 1.24;
            builder.caption(&self.title, (FONT, fit.clamp(14.0, 22.0)));
        }
        let mut chart =
            builder.build_cartesian_2d(TickedRange::new(&prep.x), TickedRange::new(&prep.y))?;

        let x_fmt = |v: &f64| prep.x.format(*v);
        let y_fmt = |v: &f64| prep.y.format(*v);
        chart
            .configure_mesh()
            .x_desc(self.x_label.as_str())
            .y_desc(self.y_label.as_str())
            .x_label_formatter(&x_fmt)
            .y_label_formatter(&y_fmt)
            .label_style((FONT, 16))
            .axis_desc_style((FONT, 18))
            .bold_line_style(RGBColor(205, 205, 205).stroke_width(1))
            .light_line_style(RGBColor(238, 238, 238).stroke_width(1))
            .axis_style(BLACK.stroke_width(1))
            .draw()?;
        Ok(chart)
    }

    /// The legend entries: every labelled series (with the glyph of the next series too
    /// if it [joins](Series::legend_joins_next) it), then every labelled reference line.
    fn legend_entries(&self, prep: &Prepared) -> Vec<LegendEntry> {
        let mut entries = Vec::new();
        for (i, s) in self.series.iter().enumerate() {
            if s.label.is_empty() {
                continue;
            }
            let mut glyph = Glyph::of(s, self.color(i));
            if s.legend_joins_next
                && let Some(next) = self.series.get(i + 1)
            {
                glyph.join(Glyph::of(next, self.color(i + 1)));
            }
            entries.push(LegendEntry {
                label: s.label.clone(),
                glyph,
            });
        }
        for (k, _, label) in &prep.hlines {
            if label.is_empty() {
                continue;
            }
            let color = HLINE_COLORS[k % HLINE_COLORS.len()];
            let line = Series::line("", Vec::new()).dashed();
            entries.push(LegendEntry {
                label: label.clone(),
                glyph: Glyph::of(&line, color),
            });
        }
        entries
    }

    /// The top-left pixel of a legend box of `size` in a corner of the plot that no
    /// drawn point, line, marker or error bar touches (tried in the order upper right,
    /// upper left, lower right, lower left); `None` if every corner has data. Lays the
    /// chart out on a scratch canvas of the final plot size to find where data go.
    fn free_corner(&self, prep: &Prepared, size: (i32, i32)) -> DrawResult<Option<(i32, i32)>> {
        let mut scratch = String::new();
        let root = SVGBackend::with_string(&mut scratch, (WIDTH, HEIGHT)).into_drawing_area();
        let chart = self.chart_with_mesh(&root, prep)?;
        let samples = data_pixels(&chart, prep);
        let pad = self
            .series
            .iter()
            .map(|s| s.marker_radius as i32)
            .max()
            .unwrap_or(0)
            + 3;
        let (w, h) = size;
        let (xr, yr) = chart.plotting_area().get_pixel_range();
        let (left, right) = (xr.start + 6, xr.end - 6 - w);
        let (top, bottom) = (yr.start + 6, yr.end - 6 - h);
        let free = |(x0, y0): (i32, i32)| {
            !samples.iter().any(|&(x, y)| {
                x >= x0 - pad && x <= x0 + w + pad && y >= y0 - pad && y <= y0 + h + pad
            })
        };
        Ok([(right, top), (left, top), (right, bottom), (left, bottom)]
            .into_iter()
            .filter(|&(x0, y0)| x0 >= xr.start && y0 >= yr.start)
            .find(|&c| free(c)))
    }
}

/// The drawing area of a figure.
type Root<'b> = DrawingArea<SVGBackend<'b>, plotters::coord::Shift>;
/// The result of a plotters drawing call on the SVG backend.
type DrawResult<T> = std::result::Result<T, DrawingAreaErrorKind<std::io::Error>>;

/// Where the legend goes.
#[derive(Debug, Clone, Copy)]
enum LegendPlace {
    /// No legend (no labelled series or reference line).
    None,
    /// Inside the plot, with its box's top-left corner at this pixel.
    Inside((i32, i32)),
    /// To the right of the plot (the canvas is widened).
    Outside,
}

/// One legend line: a glyph and its label.
struct LegendEntry {
    label: String,
    glyph: Glyph,
}

/// The legend box size in pixels for `entries` (text width estimated from the number of
/// characters: plotters has no font metrics without fonts).
fn legend_size(entries: &[LegendEntry]) -> (i32, i32) {
    let chars = entries
        .iter()
        .map(|e| e.label.chars().count())
        .max()
        .unwrap_or(0) as f64;
    let w = 2 * LEGEND_PAD + GLYPH_WIDTH + 8 + (LEGEND_CHAR_WIDTH * chars).ceil() as i32;
    let h = 2 * LEGEND_PAD + LEGEND_LINE * entries.len() as i32;
    (w, h)
}

/// Draws the legend box with its top-left corner at `at` (pixels of `root`).
fn draw_legend(root: &Root<'_>, entries: &[LegendEntry], at: (i32, i32)) -> DrawResult<()> {
    let (w, h) = legend_size(entries);
    root.draw(&Rectangle::new(
        [at, (at.0 + w, at.1 + h)],
        WHITE.mix(0.9).filled(),
    ))?;
    root.draw(&Rectangle::new(
        [at, (at.0 + w, at.1 + h)],
        RGBColor(150, 150, 150).stroke_width(1),
    ))?;
    for (k, e) in entries.iter().enumerate() {
        let y = at.1 + LEGEND_PAD + LEGEND_LINE * k as i32 + LEGEND_LINE / 2;
        let x = at.0 + LEGEND_PAD;
        e.glyph.draw(root, (x, y))?;
        root.draw(&Text::new(
            e.label.clone(),
            (x + GLYPH_WIDTH + 8, y),
            (FONT, LEGEND_FONT)
                .into_font()
                .color(&BLACK)
                .pos(Pos::new(HPos::Left, VPos::Center)),
        ))?;
    }
    Ok(())
}

/// The pixels that data cover: lines and error bars sampled every 6 pixels, markers,
/// reference lines.
fn data_pixels(chart: &Chart<'_, '_>, prep: &Prepared) -> Vec<(i32, i32)> {
    let mut samples: Vec<(i32, i32)> = Vec::new();
    let mut add_segment = |a: (i32, i32), b: (i32, i32)| {
        let len = (b.0 - a.0).abs().max((b.1 - a.1).abs());
        let n = (len / 6).max(1);
        for k in 0..=n {
            let t = f64::from(k) / f64::from(n);
            samples.push((
                (f64::from(a.0) + t * f64::from(b.0 - a.0)).round() as i32,
                (f64::from(a.1) + t * f64::from(b.1 - a.1)).round() as i32,
            ));
        }
    };
    for s in &prep.series {
        for run in &s.runs {
            for pair in run.windows(2) {
                add_segment(chart.backend_coord(&pair[0]), chart.backend_coord(&pair[1]));
            }
        }
        for p in &s.points {
            let c = chart.backend_coord(p);
            add_segment(c, c);
        }
        for bar in &s.bars {
            let hi = bar.hi.unwrap_or(prep.y.hi);
            let lo = bar.lo.unwrap_or(prep.y.lo);
            add_segment(
                chart.backend_coord(&(bar.x, lo)),
                chart.backend_coord(&(bar.x, hi)),
            );
        }
    }
    for (_, y, _) in &prep.hlines {
        add_segment(
            chart.backend_coord(&(prep.x.lo, *y)),
            chart.backend_coord(&(prep.x.hi, *y)),
        );
    }
    samples
}

/// Escapes `&`, `<`, `>`, `"` and `'` for XML text.
fn xml_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            _ => out.push(c),
        }
    }
    out
}

/// The inverse of `xml_escape`: decodes `&lt;`, `&gt;`, `&quot;`, `&apos;` and `&amp;`.
pub fn xml_unescape(s: &str) -> String {
    s.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&apos;", "'")
        .replace("&amp;", "&")
}

/// The caption an SVG written by [`Figure`] carries as its `<title>`, decoded; `None`
/// if it has none.
pub fn svg_caption(svg: &str) -> Option<String> {
    let (_, rest) = svg.split_once("<title>")?;
    let (title, _) = rest.split_once("</title>")?;
    Some(xml_unescape(title))
}

/// A light tint of `c` (halfway to white and a bit more), for reference curves drawn
/// beneath data of the same colour.
fn tint(c: RGBColor) -> RGBColor {
    let t = |v: u8| (f64::from(v) + 0.55 * (255.0 - f64::from(v))).round() as u8;
    RGBColor(t(c.0), t(c.1), t(c.2))
}

/// The horizontal reference lines, dashed across the whole x range.
fn draw_hlines<'a, 'b: 'a>(chart: &mut Chart<'a, 'b>, prep: &Prepared) -> DrawResult<()> {
    for (k, y, _) in &prep.hlines {
        let color = HLINE_COLORS[k % HLINE_COLORS.len()];
        chart.draw_series(DashedLineSeries::new(
            vec![(prep.x.lo, *y), (prep.x.hi, *y)],
            9,
            6,
            color.stroke_width(2),
        ))?;
    }
    Ok(())
}

/// One series: its error bars, then its line runs, then its markers (and isolated
/// points of a line, which would be invisible as a line).
fn draw_data_series<'a, 'b: 'a>(
    chart: &mut Chart<'a, 'b>,
    prep: &Prepared,
    s: &Series,
    p: &PreparedSeries,
    color: RGBColor,
) -> DrawResult<()> {
    draw_error_bars(chart, prep, &p.bars, color)?;
    let line_style = color.stroke_width(2);
    let draws_line = matches!(
        s.style,
        SeriesStyle::Line | SeriesStyle::Dashed | SeriesStyle::LineMarkers
    );
    let mut marker_points: Vec<(f64, f64)> = Vec::new();
    if draws_line {
        for run in &p.runs {
            if run.len() == 1 {
                // An isolated point would be invisible as a line.
                marker_points.push(run[0]);
            } else if s.style == SeriesStyle::Dashed {
                chart.draw_series(DashedLineSeries::new(run.iter().copied(), 9, 6, line_style))?;
            } else {
                chart.draw_series(LineSeries::new(run.iter().copied(), line_style))?;
            }
        }
    }
    if matches!(s.style, SeriesStyle::Markers | SeriesStyle::LineMarkers) {
        marker_points.clone_from(&p.points);
    }
    chart.draw_series(
        marker_points
            .iter()
            .map(|&pt| Circle::new(pt, s.marker_radius, color.filled())),
    )?;
    Ok(())
}

/// Vertical error bars with caps at the drawable ends; an end that cannot be drawn
/// extends to the axis border.
fn draw_error_bars<'a, 'b: 'a>(
    chart: &mut Chart<'a, 'b>,
    prep: &Prepared,
    bars: &[Bar],
    color: RGBColor,
) -> DrawResult<()> {
    let bar_style = color.stroke_width(1);
    for bar in bars {
        let hi = bar.hi.unwrap_or(prep.y.hi);
        let lo = bar.lo.unwrap_or(prep.y.lo);
        chart.draw_series(std::iter::once(PathElement::new(
            vec![(bar.x, lo), (bar.x, hi)],
            bar_style,
        )))?;
        let caps = [bar.hi, bar.lo];
        chart.draw_series(caps.iter().flatten().map(|&y| {
            EmptyElement::at((bar.x, y)) + PathElement::new(vec![(-CAP, 0), (CAP, 0)], bar_style)
        }))?;
    }
    Ok(())
}

/// "no finite data to plot", centred in the plot area.
fn draw_no_data_note(root: &Root<'_>, chart: &Chart<'_, '_>) -> DrawResult<()> {
    let (xr, yr) = chart.plotting_area().get_pixel_range();
    let centre = ((xr.start + xr.end) / 2, (yr.start + yr.end) / 2);
    root.draw(&Text::new(
        "no finite data to plot",
        centre,
        (FONT, 20)
            .into_font()
            .color(&RGBColor(120, 120, 120))
            .pos(Pos::new(HPos::Center, VPos::Center)),
    ))?;
    Ok(())
}

fn to_axis(v: f64, log: bool) -> Option<f64> {
    if !v.is_finite() {
        None
    } else if log {
        (v > 0.0).then(|| v.log10())
    } else {
        Some(v)
    }
}

fn series_color(i: usize) -> RGBColor {
    if i < PALETTE.len() {
        PALETTE[i]
    } else {
        // Golden-angle hue steps keep successive extra colours apart.
        let hue = ((i - PALETTE.len()) as f64 * 0.381_966_011_250_105).fract();
        let (r, g, b) = HSLColor(hue, 0.65, 0.42).rgb();
        RGBColor(r, g, b)
    }
}

/// A legend glyph: line pieces (solid or dashed), an error bar with caps and markers, in
/// pixel offsets from the entry's anchor (left end, vertical centre).
#[derive(Clone)]
struct Glyph {
    paths: Vec<(Vec<(i32, i32)>, ShapeStyle)>,
    /// Marker radii and styles, drawn at the glyph's centre over the paths.
    markers: Vec<(u32, ShapeStyle)>,
}

impl Glyph {
    /// The glyph of series `s` drawn in `color`.
    fn of(s: &Series, color: RGBColor) -> Self {
        let line = color.stroke_width(2);
        let mid = GLYPH_WIDTH / 2;
        let mut paths = Vec::new();
        if s.y_err.is_some() {
            let thin = color.stroke_width(1);
            paths.push((vec![(mid, -6), (mid, 6)], thin));
            paths.push((vec![(mid - CAP, -6), (mid + CAP, -6)], thin));
            paths.push((vec![(mid - CAP, 6), (mid + CAP, 6)], thin));
        }
        match s.style {
            SeriesStyle::Dashed => {
                paths.push((vec![(0, 0), (7, 0)], line));
                paths.push((vec![(10, 0), (14, 0)], line));
                paths.push((vec![(17, 0), (GLYPH_WIDTH, 0)], line));
            }
            SeriesStyle::Line | SeriesStyle::LineMarkers => {
                paths.push((vec![(0, 0), (GLYPH_WIDTH, 0)], line));
            }
            SeriesStyle::Markers => {}
        }
        let markers = if matches!(s.style, SeriesStyle::Markers | SeriesStyle::LineMarkers) {
            vec![(s.marker_radius.min(6), color.filled())]
        } else {
            Vec::new()
        };
        Glyph { paths, markers }
    }

    /// Adds `other`'s parts (its paths under this glyph's markers).
    fn join(&mut self, other: Glyph) {
        self.paths.extend(other.paths);
        self.markers.extend(other.markers);
    }

    /// Draws the glyph with its anchor at `(x, y)` (pixels of `root`).
    fn draw(&self, root: &Root<'_>, (x, y): (i32, i32)) -> DrawResult<()> {
        for (points, style) in &self.paths {
            let shifted: Vec<(i32, i32)> = points.iter().map(|&(a, b)| (x + a, y + b)).collect();
            root.draw(&PathElement::new(shifted, *style))?;
        }
        for &(r, style) in &self.markers {
            root.draw(&Circle::new((x + GLYPH_WIDTH / 2, y), r, style))?;
        }
        Ok(())
    }
}

type Chart<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<TickedRange, TickedRange>>;

/// A linear `f64` coordinate with precomputed ticks: labelled ticks (bold grid lines) and
/// minor ticks (light grid lines). (plotters' own `WithKeyPoints` over `f64` cannot be
/// combined with custom tick labels.)
struct TickedRange {
    lo: f64,
    hi: f64,
    bold: Vec<f64>,
    light: Vec<f64>,
}

impl TickedRange {
    fn new(axis: &Axis) -> Self {
        TickedRange {
            lo: axis.lo,
            hi: axis.hi,
            bold: axis.bold.clone(),
            light: axis.light.clone(),
        }
    }
}

impl Ranged for TickedRange {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    /// The same mapping as plotters' `RangedCoordf64`.
    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        let actual = limit.1 - limit.0;
        if actual == 0 || self.hi <= self.lo {
            return limit.0 + actual / 2;
        }
        let t = (v - self.lo) / (self.hi - self.lo);
        if !t.is_finite() {
            return if t > 0.0 { limit.1 } else { limit.0 };
        }
        if actual > 0 {
            limit.0 + (f64::from(actual) * t + 1e-3).floor() as i32
        } else {
            limit.0 + (f64::from(actual) * t - 1e-3).ceil() as i32
        }
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.light.clone()
        } else {
            self.bold.clone()
        }
    }

    fn range(&self) -> Range<f64> {
        self.lo..self.hi
    }
}

/// Data of one series in plot space.
#[derive(Default)]
struct PreparedSeries {
    /// Maximal runs of consecutive drawable points (lines are not drawn across gaps).
    runs: Vec<Vec<(f64, f64)>>,
    /// All drawable points.
    points: Vec<(f64, f64)>,
    bars: Vec<Bar>,
}

/// A vertical error bar in plot space; an end that cannot be drawn (lower end not
/// positive on a log axis) is `None` and extends to the axis border, without a cap.
struct Bar {
    x: f64,
    lo: Option<f64>,
    hi: Option<f64>,
}

struct Prepared {
    series: Vec<PreparedSeries>,
    /// `(index, y in plot space, label)` of the drawable reference lines.
    hlines: Vec<(usize, f64, String)>,
    /// Points that could not be drawn.
    skipped: usize,
    /// Reference lines that could not be drawn.
    skipped_hlines: usize,
    /// Whether any series has a drawable point.
    has_data: bool,
    x: Axis,
    y: Axis,
}

impl Prepared {
    /// The footnote about data left out, e.g. `3 points and 1 reference line not shown
    /// (non-finite or not positive on a log axis)`.
    fn skipped_note(&self, any_log: bool) -> Option<String> {
        let count = |n: usize, what: &str| match n {
            0 => None,
            1 => Some(format!("1 {what}")),
            _ => Some(format!("{n} {what}s")),
        };
        let parts: Vec<String> = [
            count(self.skipped, "point"),
            count(self.skipped_hlines, "reference line"),
        ]
        .into_iter()
        .flatten()
        .collect();
        if parts.is_empty() {
            return None;
        }
        let why = if any_log {
            "non-finite, or not positive on a log axis"
        } else {
            "non-finite"
        };
        Some(format!("{} not shown ({why})", parts.join(" and ")))
    }
}

/// Running minimum and maximum.
#[derive(Default, Clone, Copy)]
struct Extent {
    range: Option<(f64, f64)>,
}

impl Extent {
    fn add(&mut self, v: f64) {
        self.range = Some(match self.range {
            None => (v, v),
            Some((lo, hi)) => (lo.min(v), hi.max(v)),
        });
    }
}

/// How tick labels are printed.
#[derive(Debug, Clone, Copy)]
enum TickFormat {
    /// Fixed-point with this many decimals.
    Fixed(usize),
    /// Scientific with this many mantissa decimals.
    Sci(usize),
    /// Powers of ten (log axes spanning decades), e.g. `10⁻³`.
    Decades,
    /// 1, 2 and 5 times powers of ten (log axes spanning about two decades): plain
    /// numbers such as `0.02` if `plain`, else e.g. `2×10⁻⁵`.
    LogMixed { plain: bool },
    /// The category labels of a category axis (value k: the k-th label).
    Category,
}

/// An axis in plot space (`log10` of the data on a log axis) with its ticks.
struct Axis {
    lo: f64,
    hi: f64,
    log: bool,
    /// Labelled ticks (bold grid lines).
    bold: Vec<f64>,
    /// Minor ticks (light grid lines).
    light: Vec<f64>,
    format: TickFormat,
    /// The labels of a category axis (empty otherwise).
    categories: Vec<String>,
}

impl Axis {
    fn new(extent: Extent, log: bool) -> Axis {
        let (lo, hi) = padded_range(extent, log);
        let mut axis = Axis {
            lo,
            hi,
            log,
            bold: Vec::new(),
            light: Vec::new(),
            format: TickFormat::Fixed(0),
            categories: Vec::new(),
        };
        if log {
            axis.log_ticks();
        } else {
            let (bold, light, format) = linear_ticks(lo, hi);
            axis.bold = bold;
            axis.light = light;
            axis.format = format;
        }
        axis
    }

    /// A category axis: a labelled tick at k = 0, 1, … for every label, from −½ to
    /// n − ½ (widened to data outside that range).
    fn categories(extent: Extent, labels: &[String]) -> Axis {
        let n = labels.len() as f64;
        let (lo, hi) = match extent.range {
            Some((a, b)) => ((a - 0.5).min(-0.5), (b + 0.5).max(n - 0.5)),
            None => (-0.5, n - 0.5),
        };
        Axis {
            lo,
            hi,
            log: false,
            bold: (0..labels.len()).map(|k| k as f64).collect(),
            light: Vec::new(),
            format: TickFormat::Category,
            categories: labels.to_vec(),
        }
    }

    fn log_ticks(&mut self) {
        let (lo, hi) = (self.lo, self.hi);
        let first = lo.ceil() as i32;
        let last = hi.floor() as i32;
        if last - first + 1 >= 2 {
            let count = last - first + 1;
            let step = ((count + 7) / 8).max(1);
            let first_tick = first + (step - first.rem_euclid(step)) % step;
            self.bold = (first_tick..=last)
                .step_by(step as usize)
                .map(f64::from)
                .collect();
            self.format = TickFormat::Decades;
            if step == 1 {
                // With only two labelled decades, label 2× and 5× as well.
                let labelled_between = count <= 2;
                for k in (lo.floor() as i32)..=(hi.ceil() as i32) {
                    for m in 2..=9 {
                        let v = f64::from(k) + f64::from(m).log10();
                        if v > lo && v < hi {
                            if labelled_between && (m == 2 || m == 5) {
                                self.bold.push(v);
                            } else {
                                self.light.push(v);
                            }
                        }
                    }
                }
                if labelled_between {
                    self.bold.sort_by(f64::total_cmp);
                    let (min, max) = (self.bold[0], self.bold[self.bold.len() - 1]);
                    let plain = min >= -2.0 - 1e-9 && max <= 4.0 + 1e-9;
                    self.format = TickFormat::LogMixed { plain };
                }
            } else {
                self.light = (first..=last)
                    .map(f64::from)
                    .filter(|v| !self.bold.contains(v))
                    .collect();
            }
        } else {
            // Less than two decades visible: linear ticks in data space.
            let (bold, light, format) = linear_ticks(10f64.powf(lo), 10f64.powf(hi));
            let to_log = |v: Vec<f64>| -> Vec<f64> {
                v.into_iter()
                    .filter(|&t| t > 0.0)
                    .map(f64::log10)
                    .filter(|&t| t >= lo && t <= hi)
                    .collect()
            };
            self.bold = to_log(bold);
            self.light = to_log(light);
            self.format = format;
        }
    }

    /// The tick label of a plot-space value.
    fn format(&self, v: f64) -> String {
        match self.format {
            TickFormat::Category => {
                let k = v.round();
                if k >= 0.0 && (k as usize) < self.categories.len() {
                    self.categories[k as usize].clone()
                } else {
                    String::new()
                }
            }
            TickFormat::Decades => format!("10{}", superscript(v.round() as i32)),
            TickFormat::LogMixed { plain } => {
                // v = log10(m · 10^k) with m in {1, 2, 5}.
                let k = (v + 1e-9).floor();
                let m = 10f64.powf(v - k).round();
                let k = k as i32;
                if plain {
                    let decimals = usize::try_from(-k).unwrap_or(0);
                    format!("{:.decimals$}", m * 10f64.powi(k))
                } else if m == 1.0 {
                    format!("10{}", superscript(k))
                } else {
                    format!("{m}×10{}", superscript(k))
                }
            }
            TickFormat::Fixed(d) => {
                let v = if self.log { 10f64.powf(v) } else { v };
                let s = format!("{v:.d$}");
                if s.trim_start_matches('-')
                    .chars()
                    .all(|c| c == '0' || c == '.')
                {
                    format!("{:.d$}", 0.0)
                } else {
                    s
                }
            }
            TickFormat::Sci(d) => {
                let v = if self.log { 10f64.powf(v) } else { v };
                if v == 0.0 {
                    "0".to_string()
                } else {
                    format!("{v:.d$e}")
                }
            }
        }
    }
}

/// The axis range in plot space: the data extent plus a margin; a sensible default when
/// there are no data, widened when the extent is a single value.
fn padded_range(extent: Extent, log: bool) -> (f64, f64) {
    let (lo, hi) = match extent.range {
        None => return (0.0, 1.0),
        Some(r) => r,
    };
    let span = hi - lo;
    let (lo, hi) = if span > 0.0 && span > 1e-12 * lo.abs().max(hi.abs()) {
        (lo - MARGIN * span, hi + MARGIN * span)
    } else if log {
        (lo - 0.5, hi + 0.5)
    } else {
        let pad = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
        (lo - pad, hi + pad)
    };
    if lo.is_finite() && hi.is_finite() && hi > lo {
        (lo, hi)
    } else {
        // Extreme magnitudes overflowed: fall back to the unpadded extent if possible.
        match extent.range {
            Some((a, b)) if b > a => (a, b),
            _ => (0.0, 1.0),
        }
    }
}

/// "Nice" ticks (1, 2 or 5 times a power of ten) covering `[lo, hi]`: labelled ticks,
/// minor ticks and the label format.
fn linear_ticks(lo: f64, hi: f64) -> (Vec<f64>, Vec<f64>, TickFormat) {
    let span = hi - lo;
    if !(span.is_finite() && span > 0.0) {
        return (vec![], vec![], TickFormat::Fixed(0));
    }
    let raw = span / 6.0;
    let mut exp = raw.log10().floor() as i32;
    let base = 10f64.powi(exp);
    let f = raw / base;
    let mant = if f <= 1.0 {
        1.0
    } else if f <= 2.0 {
        2.0
    } else if f <= 5.0 {
        5.0
    } else {
        exp += 1;
        1.0
    };
    let bold = multiples(lo, hi, mant, exp);
    // Minor ticks: 1 → 0.2, 2 → 0.5, 5 → 1 (times the same power of ten).
    let (minor_mant, minor_exp) = if mant == 1.0 {
        (2.0, exp - 1)
    } else if mant == 2.0 {
        (5.0, exp - 1)
    } else {
        (1.0, exp)
    };
    let tol = mant * 10f64.powi(exp) * 1e-6;
    let light: Vec<f64> = multiples(lo, hi, minor_mant, minor_exp)
        .into_iter()
        .filter(|v| bold.iter().all(|b| (b - v).abs() > tol))
        .collect();

    let max_abs = lo.abs().max(hi.abs());
    let mag = max_abs.log10().floor() as i32;
    let format = if (-2..5).contains(&mag) {
        TickFormat::Fixed(usize::try_from(-exp).unwrap_or(0))
    } else {
        TickFormat::Sci(usize::try_from(mag - exp).unwrap_or(0).min(6))
    };
    (bold, light, format)
}

/// The multiples of `mant · 10^exp` in `[lo, hi]`, computed as exactly as possible
/// (`k · mant / 10^-exp` for negative `exp`, so that e.g. `3 · 0.2` prints as `0.6`).
fn multiples(lo: f64, hi: f64, mant: f64, exp: i32) -> Vec<f64> {
    let step = mant * 10f64.powi(exp);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    if last < first || last - first > 10_000 {
        return Vec::new();
    }
    (first..=last)
        .map(|k| {
            if exp >= 0 {
                k as f64 * step
            } else {
                k as f64 * mant / 10f64.powi(-exp)
            }
        })
        .collect()
}

/// `n` in Unicode superscript digits, e.g. `-3` → `⁻³`.
fn superscript(n: i32) -> String {
    n.to_string()
        .chars()
        .map(|c| match c {
            '-' => '⁻',
            '0' => '⁰',
            '1' => '¹',
            '2' => '²',
            '3' => '³',
            '4' => '⁴',
            '5' => '⁵',
            '6' => '⁶',
            '7' => '⁷',
            '8' => '⁸',
            _ => '⁹',
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_ticks_are_nice() {
        let (bold, _, format) = linear_ticks(-0.03, 1.07);
        assert_eq!(bold, vec![0.0, 0.2, 0.4, 0.6, 0.8, 1.0]);
        assert!(matches!(format, TickFormat::Fixed(1)));
        let (_, _, format) = linear_ticks(1e-7, 3e-7);
        assert!(matches!(format, TickFormat::Sci(1)));
    }

    #[test]
    fn superscripts() {
        assert_eq!(superscript(-12), "⁻¹²");
        assert_eq!(superscript(0), "⁰");
    }
}
