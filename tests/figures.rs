//! Figures a scientist can read (issue #14): units on every axis, a caption for every
//! figure of `verify`, one colour per quantity, legends clear of the data, and the
//! stability map's status colours.
//!
//! What is checked, and against what:
//! - every SVG that a quick `verify` of `hinged-linear-3d` and `compression-2d` writes
//!   names its axes (the `<desc>` the renderer writes: `horizontal axis: …`,
//!   `vertical axis: …`), each label is drawn as text and carries a unit — a bracketed
//!   unit (`[L²]`, `[1/T]`), a multiple of τ₁, F_c0 or ε_c0, or an explicit
//!   "(dimensionless)"; every figure listed in `summary.json` has a caption, which is
//!   also the SVG's `<title>`; the linear runs have their ⟨w²(x)⟩ and two-time figures;
//!   the files stay small (under 200 kB, at most 1400 px wide);
//! - a quick `verify` of the membrane fixture writes the height spectrum (log–log against
//!   |q|), the m, n, q columns of its mode tables and figures worded for the membrane
//!   ((M5), (M4), c_q/ξ; no filament formula), each with units and a caption;
//! - the stability map draws each cell as a disc in its status colour — stable green
//!   `#1A7F37`, biased amber `#E69100`, unstable red `#CF222E` — counted against the
//!   statuses in `stability-cells.csv` (plus one legend disc per status), and every
//!   cell's disc has a radius of at least 8 px;
//! - a figure with data in every corner puts its legend beside the plot, one with a free
//!   corner puts it there; a pair of series joined in the legend shares one colour, the
//!   reference one in a lighter tint.
//!
//! The verify run takes a few seconds (quick budget of two scenes), the membrane fixture's
//! about one, the stability map a fraction of a second (two meshes, short runs): the
//! statuses it finds do not matter, only that each is drawn in its colour.

mod common;

use common::svg::{element, svg_texts};
use common::{TempDir, assert_no_panic, describe, json, run, strings};
use langevin_fem::output::{Figure, Series};
use std::path::Path;

/// The (horizontal, vertical) axis labels the SVG's `<desc>` names.
fn axis_labels(svg: &str) -> (String, String) {
    let desc = element(svg, "desc").expect("<desc> with the axis labels");
    let mut x = None;
    let mut y = None;
    for line in desc.lines() {
        if let Some(l) = line.strip_prefix("horizontal axis: ") {
            x = Some(l.to_string());
        } else if let Some(l) = line.strip_prefix("vertical axis: ") {
            y = Some(l.to_string());
        }
    }
    (
        x.expect("horizontal axis line"),
        y.expect("vertical axis line"),
    )
}

/// Whether an axis label names its unit.
fn has_unit(label: &str) -> bool {
    let bracketed = label
        .find('[')
        .is_some_and(|i| label[i..].find(']').is_some_and(|j| j > 1));
    bracketed
        || label.contains("/ τ₁")
        || label.contains("F_c0")
        || label.contains("ε_c0")
        || label.contains("(dimensionless)")
}

/// The value of attribute `name` in the tag `tag` (e.g. `fill="#1A7F37"`).
fn attr<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let key = format!(" {name}=\"");
    let start = tag.find(&key)? + key.len();
    let end = tag[start..].find('"')? + start;
    Some(&tag[start..end])
}

/// Every `<tag …>` opening tag of `svg`.
fn tags<'a>(svg: &'a str, tag: &str) -> Vec<&'a str> {
    let open = format!("<{tag} ");
    let mut out = Vec::new();
    let mut rest = svg;
    while let Some(start) = rest.find(&open) {
        let end = rest[start..].find('>').expect("tag closed") + start;
        out.push(&rest[start..=end]);
        rest = &rest[end..];
    }
    out
}

/// The canvas width of an SVG document.
fn svg_width(svg: &str) -> u32 {
    let svg_tag = tags(svg, "svg")[0];
    attr(svg_tag, "width")
        .expect("width")
        .parse()
        .expect("number")
}

/// Every `.svg` file under `dir`, relative.
fn svg_files(dir: &Path) -> Vec<String> {
    common::all_files(dir)
        .into_iter()
        .filter(|f| f.ends_with(".svg"))
        .collect()
}

/// A quick `verify` of a linear and a compression scene: every SVG has labelled axes
/// with units, drawn as text; every figure of the summary has a caption, which is its
/// SVG's title; the ⟨w²(x)⟩ and two-time figures exist; the files stay small.
#[test]
fn verify_figures_have_units_and_captions() {
    let tmp = TempDir::new("figures_verify");
    let out = tmp.join_str("out");
    let args = [
        "verify",
        "--scene",
        "hinged-linear-3d",
        "--scene",
        "compression-2d",
        "--out",
        &out,
    ];
    let o = run(&args);
    assert_no_panic(&args, &o);
    assert_eq!(o.status.code(), Some(0), "{}", describe(&args, &o));
    let out = Path::new(&out);

    let files = svg_files(out);
    for run in ["crank-nicolson", "exact-modal"] {
        for kind in ["profile", "two-time", "modes", "spectrum"] {
            let f = format!("hinged-linear-3d/{run}-{kind}.svg");
            assert!(files.contains(&f), "{f} missing from {files:?}");
        }
    }
    for f in &files {
        let path = out.join(f);
        let svg = std::fs::read_to_string(&path).expect("svg");
        assert!(svg.starts_with("<svg"), "{f}: no SVG");
        let (x, y) = axis_labels(&svg);
        let texts = svg_texts(&svg);
        for label in [&x, &y] {
            assert!(!label.trim().is_empty(), "{f}: empty axis label");
            assert!(has_unit(label), "{f}: axis label without a unit: {label:?}");
            assert!(texts.contains(label), "{f}: axis label {label:?} not drawn");
        }
        assert!(
            !svg.contains("lambda") && !svg.contains("&lt;F&gt;"),
            "{f}: ASCII labels"
        );
        let bytes = std::fs::metadata(&path).expect("metadata").len();
        assert!(bytes < 200_000, "{f}: {bytes} bytes");
        assert!(svg_width(&svg) <= 1400, "{f}: {} px wide", svg_width(&svg));
    }

    let summary = json(&out.join("summary.json"));
    let scenes = summary["scenes"].as_array().expect("scenes");
    let mut listed = 0;
    for scene in scenes {
        let figures = strings(&scene["figures"]);
        let captions = strings(&scene["captions"]);
        assert_eq!(figures.len(), captions.len(), "{}", scene["name"]);
        assert!(!figures.is_empty(), "{}: no figures", scene["name"]);
        for (fig, caption) in figures.iter().zip(&captions) {
            assert!(
                caption.len() > 80 && caption.contains("should"),
                "{fig}: caption does not say what a reader should see: {caption:?}"
            );
            let svg = std::fs::read_to_string(out.join(fig)).expect("listed figure exists");
            assert_eq!(
                element(&svg, "title").as_deref(),
                Some(caption.as_str()),
                "{fig}: <title>"
            );
            listed += 1;
        }
    }
    // Every SVG written is listed with its caption (fig2.svg under the compression
    // scene).
    assert_eq!(listed, files.len(), "{files:?}");
}

/// A quick `verify` of the membrane fixture (issue #27; about a second): its run has the
/// height spectrum `<run>-height-spectrum.svg` — log–log, |q| with its unit, the simulated
/// markers with error bars, the continuum law (M3) and the discrete discs — listed with its
/// caption in `summary.json` and in `index.html`; its mode tables carry `m`, `n` and `q`
/// after `mode` (known to the column dictionary, with the slowest mode (1, 1) at
/// |q| = π√2); its profile, two-time and rates figures are worded for the membrane
/// ((M5), (M4), c_q/ξ) and not for the filament (EI, eq. (4), n⁴). Every figure has axis
/// units and a caption that says what to see, as the filament's.
#[test]
fn membrane_report_has_its_spectrum_mode_labels_and_profile() {
    let tmp = TempDir::new("figures_membrane");
    let out = tmp.join_str("out");
    let scene = common::fixture("tests/scenes/good/membrane-hinged.toml");
    let scene = scene.to_string_lossy();
    let args = ["verify", "--scene", &scene, "--out", &out];
    let o = run(&args);
    assert_no_panic(&args, &o);
    // Exit 1 (a check failed) is a legitimate outcome of a tiny ensemble; the outputs are
    // written either way.
    assert!(
        matches!(o.status.code(), Some(0 | 1)),
        "{}",
        describe(&args, &o)
    );
    let out = Path::new(&out);
    let dir = out.join("membrane-hinged");
    let read = |f: &str| std::fs::read_to_string(dir.join(f)).expect(f);

    // The height spectrum: log–log, |q| with its unit, markers, curve and discs.
    let svg = read("crank-nicolson-height-spectrum.svg");
    let (x, y) = axis_labels(&svg);
    assert!(x.contains("|q|") && has_unit(&x), "{x}");
    assert!(y.contains("⟨a²⟩") && has_unit(&y), "{y}");
    let texts = svg_texts(&svg);
    for legend in [
        "continuum (M3): 4kT/(A c_q)",
        "simulated (±1 s.e.)",
        "exact, discretized",
    ] {
        assert!(
            texts.iter().any(|t| t.starts_with(legend)),
            "{legend} not in {texts:?}"
        );
    }
    // Decade ticks of both log axes (10⁻², 10⁻³ on the variances).
    assert!(texts.iter().any(|t| t.contains("10⁻")), "{texts:?}");

    // The mode tables: m, n, q after mode, every column in the dictionary.
    let manifest = json(&out.join("manifest.json"));
    for (table, rest) in [
        ("crank-nicolson-modes.csv", "predicted_ratio"),
        ("crank-nicolson-mode-statistics.csv", "variance"),
    ] {
        let text = read(table);
        let mut lines = text.lines();
        let header = lines.next().expect("header");
        assert!(
            header.starts_with(&format!("mode,m,n,q,{rest},")),
            "{header}"
        );
        let first: Vec<f64> = lines
            .next()
            .expect("row")
            .split(',')
            .map(|v| v.parse().expect("number"))
            .collect();
        assert_eq!(first[..3], [1.0, 1.0, 1.0], "{table}");
        let q = std::f64::consts::PI * 2f64.sqrt();
        assert!((first[3] / q - 1.0).abs() < 1e-12, "{table}: {first:?}");
        let columns = &manifest["columns"][format!("membrane-hinged/{table}")]["columns"];
        let columns = columns.as_array().expect("columns");
        assert!(columns.iter().all(|c| !c["unit"].is_null()), "{columns:?}");
        assert_eq!(columns[3]["unit"], "1/[L]");
    }

    // Every figure listed with a caption that says what to see; the membrane's words.
    let summary = json(&out.join("summary.json"));
    let scene = &summary["scenes"][0];
    let figures = strings(&scene["figures"]);
    let captions = strings(&scene["captions"]);
    assert_eq!(figures.len(), captions.len());
    assert_eq!(figures.len(), svg_files(out).len(), "{figures:?}");
    let caption = |name: &str| -> &str {
        let k = figures
            .iter()
            .position(|f| f.ends_with(name))
            .unwrap_or_else(|| panic!("{name} not listed in {figures:?}"));
        &captions[k]
    };
    for (fig, caption) in figures.iter().zip(&captions) {
        assert!(caption.contains("should"), "{fig}: {caption}");
        let svg = std::fs::read_to_string(out.join(fig)).expect("listed figure exists");
        let (x, y) = axis_labels(&svg);
        assert!(has_unit(&x) && has_unit(&y), "{fig}: {x} / {y}");
        assert!(!svg.contains("filament") && !svg.contains("EI"), "{fig}");
    }
    let spectrum = caption("crank-nicolson-height-spectrum.svg");
    assert!(
        spectrum.contains("q⁻⁴") && spectrum.contains("(1, 1)"),
        "{spectrum}"
    );
    let profile = caption("crank-nicolson-profile.svg");
    assert!(
        profile.contains("membrane") && profile.contains("(M5)") && profile.contains("b/2"),
        "{profile}"
    );
    let two_time = caption("crank-nicolson-two-time.svg");
    assert!(
        two_time.contains("(M4)") && !two_time.contains("eq. (4)"),
        "{two_time}"
    );
    let rates = read("crank-nicolson-rates.svg");
    assert!(!rates.contains("n⁴") && rates.contains("c_q/ξ"));

    // The index shows the height spectrum with its caption.
    let index = std::fs::read_to_string(out.join("index.html")).expect("index");
    assert!(index.contains("membrane-hinged/crank-nicolson-height-spectrum.svg"));
    assert!(index.contains("Height fluctuation spectrum"));
}

/// The stability map: every cell a disc in its status colour, the count of each colour
/// the count of cells with that status in `stability-cells.csv` plus one legend disc.
#[test]
fn stability_map_colours_are_red_amber_green() {
    let tmp = TempDir::new("figures_stability");
    let out = tmp.join_str("out");
    let args = [
        "stability",
        "--elements",
        "5,10",
        "--steps",
        "2000",
        "--burn-in",
        "500",
        "--out",
        &out,
    ];
    let o = run(&args);
    assert_no_panic(&args, &o);
    assert!(
        matches!(o.status.code(), Some(0 | 1)),
        "{}",
        describe(&args, &o)
    );
    let out = Path::new(&out);
    let cells = std::fs::read_to_string(out.join("stability-cells.csv")).expect("cells");
    let colours = [
        ("stable", "#1A7F37"),
        ("biased", "#E69100"),
        ("unstable", "#CF222E"),
    ];
    for integrator in [
        "euler-maruyama",
        "backward-euler",
        "crank-nicolson",
        "exact-modal",
    ] {
        let svg = std::fs::read_to_string(out.join(format!("stability-map-{integrator}.svg")))
            .expect("map");
        let discs = tags(&svg, "circle");
        for (status, colour) in colours {
            let cells_with = cells
                .lines()
                .filter(|l| {
                    let f: Vec<&str> = l.split(',').collect();
                    f[0] == integrator && f[5] == status
                })
                .count();
            let drawn = discs
                .iter()
                .filter(|t| attr(t, "fill") == Some(colour))
                .count();
            assert_eq!(
                drawn,
                cells_with + 1,
                "{integrator}: {status} cells in {colour} (one more in the legend)"
            );
        }
        assert!(
            discs
                .iter()
                .all(|t| colours.iter().any(|(_, c)| attr(t, "fill") == Some(*c))),
            "{integrator}: a disc in another colour"
        );
        // Cell discs are large (radius 8 px or more); only the legend's are smaller.
        let large = discs
            .iter()
            .filter(|t| attr(t, "r").and_then(|r| r.parse::<u32>().ok()) >= Some(8))
            .count();
        let cells_of = cells
            .lines()
            .filter(|l| l.starts_with(&format!("{integrator},")))
            .count();
        assert_eq!(large, cells_of, "{integrator}: markers too small");
        let (x, y) = axis_labels(&svg);
        assert!(
            x.contains("Δt·λ_max") && y.contains("elements"),
            "{x} / {y}"
        );
    }
}

/// The legend box (the rectangle with the legend's grey border) of a rendered figure:
/// (x0, y0, x1, y1) in pixels.
fn legend_box(svg: &str) -> (i32, i32, i32, i32) {
    let rect = tags(svg, "rect")
        .into_iter()
        .find(|t| attr(t, "stroke") == Some("#969696"))
        .expect("legend box");
    let n = |k: &str| attr(rect, k).expect(k).parse::<i32>().expect("integer");
    (n("x"), n("y"), n("x") + n("width"), n("y") + n("height"))
}

/// A free upper-right corner takes the legend; data in every corner push it beside the
/// plot (a wider canvas), never over a data point.
#[test]
fn legends_avoid_the_data() {
    let rising: Vec<(f64, f64)> = (0..=20).map(|k| (f64::from(k), f64::from(k))).collect();
    let fig = Figure::new("rising", "x [L]", "y [L]")
        .series(Series::markers("data", rising.clone()))
        .series(Series::line("reference", rising));
    let svg = fig.render_svg().expect("renders");
    assert_eq!(svg_width(&svg), 800);
    let (x0, y0, _, _) = legend_box(&svg);
    // Upper left (the diagonal fills the upper-right and lower-left corners).
    assert!(x0 < 400 && y0 < 260, "legend at ({x0}, {y0})");

    let corners = vec![(0.0, 0.0), (0.0, 1.0), (1.0, 0.0), (1.0, 1.0), (0.5, 0.5)];
    let fig = Figure::new("corners", "x [L]", "y [L]")
        .series(Series::markers("points in every corner", corners));
    let svg = fig.render_svg().expect("renders");
    assert!(svg_width(&svg) > 800, "legend not moved beside the plot");
    let (x0, y0, x1, y1) = legend_box(&svg);
    for c in tags(&svg, "circle") {
        let (cx, cy): (i32, i32) = (
            attr(c, "cx").unwrap().parse().unwrap(),
            attr(c, "cy").unwrap().parse().unwrap(),
        );
        let inside = cx >= x0 && cx <= x1 && cy >= y0 && cy <= y1;
        // Only the legend's own glyph lies in its box.
        assert!(
            !inside || cx < x0 + 40,
            "data point ({cx}, {cy}) under the legend"
        );
    }
}

/// A simulated series joined in the legend with its exact curve: one legend entry, the
/// curve in a lighter tint of the same colour; the caption becomes the SVG's title and
/// the axis labels its description.
#[test]
fn joined_series_share_a_colour_and_the_caption_is_the_title() {
    let pts: Vec<(f64, f64)> = (1..=5)
        .map(|k| (f64::from(k), 1.0 / f64::from(k)))
        .collect();
    let fig = Figure::new("one mode", "f [1/T]", "S(f) [L²·T]")
        .series(
            Series::markers("mode 1: simulated / exact", pts.clone())
                .palette(0)
                .joined_with_next(),
        )
        .series(Series::line("", pts).palette(0).light())
        .caption("A caption & a <title>");
    let svg = fig.render_svg().expect("renders");
    assert_eq!(
        svg_texts(&svg)
            .iter()
            .filter(|t| t.starts_with("mode 1"))
            .count(),
        1
    );
    // Markers in palette colour 0, the line in its tint.
    assert!(svg.contains("fill=\"#1F77B4\""), "markers");
    assert!(svg.contains("stroke=\"#9AC2DD\""), "light line");
    assert_eq!(
        element(&svg, "title").as_deref(),
        Some("A caption & a <title>")
    );
    assert!(svg.contains("<title>A caption &amp; a &lt;title&gt;</title>"));
    assert_eq!(
        axis_labels(&svg),
        ("f [1/T]".to_string(), "S(f) [L²·T]".to_string())
    );
}
