//! Line and scatter figures rendered to SVG with `plotters`.
//!
//! A [`Figure`] is plain data (title, axis labels, log flags, [`Series`], horizontal
//! reference lines) and renders deterministically: the same figure always produces the
//! same SVG bytes. Text is emitted as SVG `<text>` elements and laid out by the viewer, so
//! no font files are needed (plotters only estimates text extents, from the character
//! count, to place the legend box).
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

use plotters::chart::SeriesAnno;
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
const MARKER_RADIUS: i32 = 3;
/// Legend font size (plotters units; the SVG font size is this / 1.24).
const LEGEND_FONT: f64 = 15.0;
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
}

impl Series {
    /// A series drawn as a solid line.
    pub fn line(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Series {
            label: label.into(),
            points,
            y_err: None,
            style: SeriesStyle::Line,
        }
    }

    /// A series drawn as markers.
    pub fn markers(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Series {
            label: label.into(),
            points,
            y_err: None,
            style: SeriesStyle::Markers,
        }
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
}

/// A 2-D figure: series, optional error bars, horizontal reference lines, linear or
/// logarithmic axes.
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
    /// The data series, drawn in order (later series on top).
    pub series: Vec<Series>,
    /// Horizontal reference lines `(y, legend label)`, drawn dashed across the plot.
    pub hlines: Vec<(f64, String)>,
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
            series: Vec::new(),
            hlines: Vec::new(),
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

    /// Renders the figure as an SVG document (800 × 520 pixels).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if a series has error bars whose count differs from its
    /// number of points; [`Error::Numerical`] if plotters fails to draw (not expected for
    /// the SVG backend).
    pub fn render_svg(&self) -> Result<String> {
        let prepared = self.prepare()?;
        let mut buf = String::new();
        {
            let root = SVGBackend::with_string(&mut buf, (WIDTH, HEIGHT)).into_drawing_area();
            self.draw(&root, &prepared)
                .map_err(|e| self.render_error(e))?;
            root.present().map_err(|e| self.render_error(e))?;
        }
        Ok(buf)
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

    /// Maps a data coordinate to plot space (`log10` on a log axis); `None` if the value
    /// cannot be drawn on that axis.
    fn tx(&self, x: f64) -> Option<f64> {
        to_axis(x, self.x_log)
    }

    fn ty(&self, y: f64) -> Option<f64> {
        to_axis(y, self.y_log)
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

        Ok(Prepared {
            series,
            hlines,
            skipped,
            skipped_hlines,
            has_data,
            x: Axis::new(xs, self.x_log),
            y: Axis::new(ys, self.y_log),
        })
    }

    fn draw(&self, root: &Root<'_>, prep: &Prepared) -> DrawResult<()> {
        root.fill(&WHITE)?;
        let mut chart = self.chart_with_mesh(root, prep)?;
        // Reference lines first, so that data are drawn over them.
        draw_hlines(&mut chart, prep)?;
        for (i, (s, p)) in self.series.iter().zip(&prep.series).enumerate() {
            draw_data_series(&mut chart, prep, s, p, series_color(i))?;
        }
        let n_legend = self.legend_entries(&mut chart, prep)?;
        if !prep.has_data {
            draw_no_data_note(root, &chart)?;
        }
        if n_legend > 0 {
            self.draw_legend(&mut chart, prep)?;
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
            builder.caption(&self.title, (FONT, 24));
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

    /// Legend entries: empty series that only carry a label and a glyph, for every
    /// labelled series and then every labelled reference line; returns their number.
    fn legend_entries<'a, 'b: 'a>(
        &self,
        chart: &mut Chart<'a, 'b>,
        prep: &Prepared,
    ) -> DrawResult<usize> {
        let mut n_legend = 0usize;
        for (i, s) in self.series.iter().enumerate() {
            if s.label.is_empty() {
                continue;
            }
            n_legend += 1;
            let anno = chart.draw_series(std::iter::empty::<PathElement<(f64, f64)>>())?;
            Glyph::new(series_color(i), s.style, s.y_err.is_some()).attach(anno, &s.label);
        }
        for (k, _, label) in &prep.hlines {
            if label.is_empty() {
                continue;
            }
            n_legend += 1;
            let anno = chart.draw_series(std::iter::empty::<PathElement<(f64, f64)>>())?;
            Glyph::new(
                HLINE_COLORS[k % HLINE_COLORS.len()],
                SeriesStyle::Dashed,
                false,
            )
            .attach(anno, label);
        }
        Ok(n_legend)
    }

    /// The legend box, in the corner chosen by [`legend_position`].
    fn draw_legend<'a, 'b: 'a>(
        &self,
        chart: &mut Chart<'a, 'b>,
        prep: &Prepared,
    ) -> DrawResult<()> {
        let labels: Vec<&str> = self
            .series
            .iter()
            .map(|s| s.label.as_str())
            .chain(prep.hlines.iter().map(|(_, _, l)| l.as_str()))
            .filter(|l| !l.is_empty())
            .collect();
        let position = legend_position(chart, prep, &labels);
        chart
            .configure_series_labels()
            .position(position)
            .label_font((FONT, LEGEND_FONT))
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(150, 150, 150))
            .draw()?;
        Ok(())
    }
}

/// The drawing area of a figure.
type Root<'b> = DrawingArea<SVGBackend<'b>, plotters::coord::Shift>;
/// The result of a plotters drawing call on the SVG backend.
type DrawResult<T> = std::result::Result<T, DrawingAreaErrorKind<std::io::Error>>;

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
            .map(|&pt| Circle::new(pt, MARKER_RADIUS, color.filled())),
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

/// The legend glyph of a series: up to three line pieces (solid or dashed), an error bar
/// with caps and a marker, in pixel offsets from the legend entry's anchor. Parts that a
/// style does not use are transparent, which the SVG backend skips, so that every glyph
/// has the same element type.
#[derive(Clone)]
struct Glyph {
    paths: [(Vec<(i32, i32)>, ShapeStyle); 6],
    marker: ShapeStyle,
}

impl Glyph {
    fn new(color: RGBColor, style: SeriesStyle, with_bar: bool) -> Self {
        let line = color.stroke_width(2);
        let none = TRANSPARENT.stroke_width(1);
        let thin = if with_bar {
            color.stroke_width(1)
        } else {
            none
        };
        let solid = matches!(style, SeriesStyle::Line | SeriesStyle::LineMarkers);
        let dashed = style == SeriesStyle::Dashed;
        let markers = matches!(style, SeriesStyle::Markers | SeriesStyle::LineMarkers);
        let (first, second, third) = if dashed {
            (
                (vec![(0, 0), (7, 0)], line),
                (vec![(10, 0), (14, 0)], line),
                (vec![(17, 0), (24, 0)], line),
            )
        } else {
            (
                (vec![(0, 0), (24, 0)], if solid { line } else { none }),
                (vec![], none),
                (vec![], none),
            )
        };
        Glyph {
            paths: [
                (vec![(12, -6), (12, 6)], thin),
                (vec![(12 - CAP, -6), (12 + CAP, -6)], thin),
                (vec![(12 - CAP, 6), (12 + CAP, 6)], thin),
                first,
                second,
                third,
            ],
            marker: if markers {
                color.filled()
            } else {
                TRANSPARENT.filled()
            },
        }
    }

    /// Attaches `label` and this glyph to a (data-less) series annotation.
    fn attach<'a, DB: DrawingBackend + 'a>(self, anno: &mut SeriesAnno<'a, DB>, label: &str) {
        anno.label(label).legend(move |origin| {
            let [a, b, c, d, e, f] = self.paths.clone();
            EmptyElement::at(origin)
                + PathElement::new(a.0, a.1)
                + PathElement::new(b.0, b.1)
                + PathElement::new(c.0, c.1)
                + PathElement::new(d.0, d.1)
                + PathElement::new(e.0, e.1)
                + PathElement::new(f.0, f.1)
                + Circle::new((12, 0), MARKER_RADIUS, self.marker)
        });
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

/// Picks the plot corner where the legend box covers the fewest drawn points (sampled
/// along lines and error bars); ties prefer upper right, upper left, lower right, lower
/// left, in that order.
fn legend_position(chart: &Chart<'_, '_>, prep: &Prepared, labels: &[&str]) -> SeriesLabelPosition {
    // Mirrors plotters' legend layout without font metrics:
    // character width 0.7 em, line height 1.25 of the font height, 30 px glyph area,
    // 10 px margins, 5 px from the plot border.
    let em = LEGEND_FONT / 1.24 / 1.24;
    let max_chars = labels.iter().map(|l| l.len()).max().unwrap_or(0) as f64;
    let w = (em * 0.7 * max_chars + 30.0 + 20.0).round() as i32 + 4;
    let h = (labels.len() as f64 * em * 1.24 * 1.25 + 20.0).round() as i32 + 4;

    let (xr, yr) = chart.plotting_area().get_pixel_range();
    let left = xr.start + 5;
    let right = xr.end - 5 - w;
    let top = yr.start + 5;
    let bottom = yr.end - 5 - h;

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
            if let [single] = run.as_slice() {
                let c = chart.backend_coord(single);
                add_segment(c, c);
            }
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

    let candidates = [
        (SeriesLabelPosition::UpperRight, right, top),
        (SeriesLabelPosition::UpperLeft, left, top),
        (SeriesLabelPosition::LowerRight, right, bottom),
        (SeriesLabelPosition::LowerLeft, left, bottom),
    ];
    let mut best = SeriesLabelPosition::UpperRight;
    let mut best_count = usize::MAX;
    for (pos, x0, y0) in candidates {
        let count = samples
            .iter()
            .filter(|&&(x, y)| x >= x0 && x <= x0 + w && y >= y0 && y <= y0 + h)
            .count();
        if count < best_count {
            best_count = count;
            best = pos;
        }
    }
    best
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
