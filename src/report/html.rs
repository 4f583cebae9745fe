//! The HTML index of a verification run (`index.html`).
//!
//! A single static, self-contained page: inline CSS, no scripts, no external resources.
//! Figures are referenced by their relative paths (they live next to `index.html`), so
//! the output directory can be moved or archived as a whole. All text from the summary
//! is HTML-escaped. The run id (also in `summary.json`), the wall times and the
//! provenance box's start time, command line and thread count are the only content that
//! differs between two runs with the same seeds.
//!
//! [`write_report`] finishes a verification's [`ReportRun`]: `summary.json` and
//! `index.html` are written last, after every other file of the run (see
//! [`crate::output::manifest`]).

use std::fmt::Write as _;
use std::path::Path;

use crate::error::Result;
use crate::output::ProvenanceRef;
use crate::output::io::json_text;
use crate::output::{ReportRun, write_atomic};
use crate::verify::runner::ENTRY_POINTS;
use crate::verify::summary::{CheckResult, SceneSummary, Summary};

pub(crate) const CSS: &str = "\
body{font-family:system-ui,-apple-system,'Segoe UI',Roboto,Helvetica,Arial,sans-serif;\
margin:2em auto;max-width:1200px;padding:0 1em;color:#1f2328;line-height:1.45}
h1{margin-bottom:.2em}
h2{margin-top:2em;border-bottom:1px solid #d0d7de;padding-bottom:.2em}
table{border-collapse:collapse;margin:.8em 0;font-size:.92em}
th,td{border:1px solid #d0d7de;padding:.3em .55em;vertical-align:top}
th{background:#f6f8fa;text-align:left}
td.num{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}
td.detail{max-width:28em}
.badge{display:inline-block;padding:.05em .5em;border-radius:.3em;font-weight:bold;\
font-size:.85em;vertical-align:middle}
.badge.pass,td.pass{background:#dafbe1;color:#116329}
.badge.fail,td.fail{background:#ffebe9;color:#a40e26}
td.pass,td.fail{font-weight:bold;text-align:center}
tr.fail{background:#fff5f4}
.verdict{font-size:1.6em;margin:.3em 0}
.meta{color:#57606a}
.figures{display:flex;flex-wrap:wrap;gap:1em}
figure{margin:0;border:1px solid #d0d7de;padding:.4em;background:#fff}
figure img{display:block;width:100%;max-width:800px;height:auto}
figcaption{font-size:.85em;color:#57606a;text-align:center;font-family:monospace}
code{font-size:.95em}
.provenance{border:1px solid #d0d7de;border-radius:.4em;padding:.2em 1em;margin:1em 0;\
background:#f6f8fa}
.provenance table{background:#fff}
.provenance code{word-break:break-all}
";

/// Renders the HTML index page for `summary`.
///
/// Content: the overall verdict, the run id (every file of the report belongs to this
/// run; `summary.json` lists them), the provenance box (version, commit, start time,
/// command line, threads, per scene its seed, source and SHA-256; the full record is in
/// the journal it names), the budget and the family-wise significance level α
/// (Holm-corrected within each scene), a table of scenes, and per scene its notes, its
/// figures embedded as `<img>` with the file name as caption, links to its CSV tables and
/// the table of its checks (estimate, reference, standard error, raw and Holm-adjusted
/// p-values to 4 significant digits, `—` where a value does not apply).
pub fn render_index(summary: &Summary) -> String {
    let mut h = String::with_capacity(16 * 1024);
    let verdict = pass_fail(summary.passed);
    let n_scenes = summary.scenes.len();
    let n_failed_scenes = summary.scenes.iter().filter(|s| !s.passed).count();
    let n_checks: usize = summary.scenes.iter().map(|s| s.checks.len()).sum();
    let n_failed_checks: usize = summary
        .scenes
        .iter()
        .map(|s| s.checks.iter().filter(|c| !c.passed).count())
        .sum();
    let total_wall: f64 = summary.scenes.iter().map(|s| s.wall_seconds).sum();

    h.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
    h.push_str("<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n");
    let _ = writeln!(
        h,
        "<title>langevin-fem verification: {verdict} ({})</title>",
        esc(&summary.budget)
    );
    let _ = writeln!(h, "<style>\n{CSS}</style>\n</head>\n<body>");
    h.push_str("<h1>langevin-fem verification report</h1>\n");
    let _ = writeln!(
        h,
        "<p class=\"verdict\">Overall result: <span class=\"badge {}\">{verdict}</span></p>",
        verdict.to_ascii_lowercase()
    );
    let _ = writeln!(
        h,
        "<p>{} of {n_scenes} scene{} passed; {} of {n_checks} check{} failed. \
         Total wall time {}.</p>",
        n_scenes - n_failed_scenes,
        plural(n_scenes),
        n_failed_checks,
        plural(n_checks),
        fmt_seconds(total_wall)
    );
    if !summary.run_id.is_empty() {
        let _ = writeln!(
            h,
            "<p class=\"meta\">Run <code id=\"run-id\">{}</code>: every file of this \
             report was written by this run; <a href=\"summary.json\">summary.json</a> \
             lists them ({} files).</p>",
            esc(&summary.run_id),
            summary.files.len()
        );
    }
    if let Some(p) = &summary.provenance {
        provenance_box(&mut h, p);
    }
    let _ = writeln!(
        h,
        "<p>Budget: <b>{}</b>. Family-wise significance level α = {} per scene: the \
         p-values of the checks of a scene form one family and are Holm-corrected \
         (Holm–Bonferroni step-down), so that the probability of any false failure in a \
         scene whose simulation is correct is at most α. The tables show raw and \
         Holm-adjusted p-values. Reference kind <code>discrete</code>: exact for the \
         discretized system and time integrator; <code>continuum</code>: exact for the \
         continuum model.</p>",
        esc(&summary.budget),
        fmt_alpha(summary.alpha)
    );

    scenes_table(&mut h, summary);
    for (i, scene) in summary.scenes.iter().enumerate() {
        scene_section(&mut h, i, scene);
    }
    h.push_str("</body>\n</html>\n");
    h
}

/// Writes [`render_index`] of `summary` to `out_dir/index.html`, atomically.
///
/// # Errors
/// [`crate::Error::Io`] naming the file if it cannot be written.
/// If `out_dir/convergence/index.html` exists (the reduced stability map of
/// `make verify`, or `make converge`), a section linking it is added before `</body>`.
pub fn write_index(out_dir: &Path, summary: &Summary) -> Result<()> {
    write_atomic(
        &out_dir.join("index.html"),
        index_html(out_dir, summary).as_bytes(),
    )
}

/// Finishes the verification's report run `run`: removes the files of earlier runs it did
/// not rewrite, completes its journal, then writes `summary.json` and `index.html` (as
/// [`write_index`]), in that order, atomically.
///
/// # Errors
/// [`crate::Error::Io`] naming a file that cannot be removed or written.
pub fn write_report(run: ReportRun, summary: &Summary) -> Result<()> {
    let [summary_name, index_name] = ENTRY_POINTS;
    let json = json_text(&run.dir().join(summary_name), summary)?;
    let html = index_html(run.dir(), summary);
    run.finish(&[
        (summary_name, json.as_bytes()),
        (index_name, html.as_bytes()),
    ])
}

/// [`render_index`] of `summary`, with the link to `out_dir/convergence/index.html` if
/// that exists.
fn index_html(out_dir: &Path, summary: &Summary) -> String {
    let mut html = render_index(summary);
    if out_dir.join("convergence").join("index.html").exists()
        && let Some(i) = html.rfind("</body>")
    {
        html.insert_str(
            i,
            "<h2>Convergence and stability</h2>\n<p>Stability map, per-mode stationary bias against each integrator's exact formula (and, after <code>make converge</code>, the convergence studies, work–precision and extreme scenes): <a href=\"convergence/index.html\">convergence/index.html</a>.</p>\n",
        );
    }
    html
}

/// The provenance box: what produced the report.
pub(crate) fn provenance_box(h: &mut String, p: &ProvenanceRef) {
    let dirty = match p.dirty {
        Some(true) => " <b>(dirty: built with uncommitted changes to tracked files)</b>",
        Some(false) => "",
        None => " (unknown whether the work tree had changes)",
    };
    let _ = writeln!(
        h,
        "<div class=\"provenance\" id=\"provenance\">\n<h2>Provenance</h2>\n<table>\n\
         <tr><th>Version</th><td>langevin-fem {}</td></tr>\n\
         <tr><th>Commit</th><td><code id=\"commit\">{}</code>{dirty}</td></tr>\n\
         <tr><th>Started</th><td>{} (UTC)</td></tr>\n\
         <tr><th>Command line</th><td><code>{}</code></td></tr>\n\
         <tr><th>Threads</th><td class=\"num\">{}</td></tr>\n</table>",
        esc(&p.version),
        esc(&p.commit),
        esc(&p.started),
        esc(&shell_words(&p.command_line)),
        p.threads
    );
    h.push_str(
        "<table>\n<thead><tr><th>Scene</th><th>Seed</th><th>Source</th><th>SHA-256 of the scene text</th>\
         <th>Overrides</th></tr></thead>\n<tbody>\n",
    );
    for s in &p.scenes {
        let overrides = if s.overrides.is_empty() {
            "none (ran as written)".to_string()
        } else {
            s.overrides.join("; ")
        };
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td class=\"num\">{}</td><td><code>{}</code></td>\
             <td><code>{}</code></td><td>{}</td></tr>",
            esc(&s.name),
            s.seed,
            esc(&s.source),
            esc(&s.sha256),
            esc(&overrides)
        );
    }
    let _ = writeln!(
        h,
        "</tbody>\n</table>\n<p class=\"meta\">The full record — every scene's text as run, \
         its physical parameters with units and dimensionless groups, the wall time, and the \
         unit of every column of every CSV table — is in <a href=\"{0}\">{0}</a>.</p>\n</div>",
        esc(&url_path(&p.manifest))
    );
}

/// A command line as one string: arguments with characters other than
/// `[A-Za-z0-9_./=:,+-]` in single quotes.
fn shell_words(args: &[String]) -> String {
    args.iter()
        .map(|a| {
            let plain = !a.is_empty()
                && a.chars()
                    .all(|c| c.is_ascii_alphanumeric() || "_./=:,+-".contains(c));
            if plain {
                a.clone()
            } else {
                format!("'{}'", a.replace('\'', "'\\''"))
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

fn scenes_table(h: &mut String, summary: &Summary) {
    h.push_str(
        "<h2>Scenes</h2>\n<table>\n<thead><tr><th>Scene</th><th>Result</th>\
                <th>Wall time</th><th>Checks</th><th>Failed checks</th></tr></thead>\n<tbody>\n",
    );
    for (i, s) in summary.scenes.iter().enumerate() {
        let failed = s.checks.iter().filter(|c| !c.passed).count();
        let verdict = pass_fail(s.passed);
        let _ = writeln!(
            h,
            "<tr><td><a href=\"#scene-{i}\">{}</a></td><td class=\"{}\">{verdict}</td>\
             <td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{failed}</td></tr>",
            esc(&s.name),
            verdict.to_ascii_lowercase(),
            fmt_seconds(s.wall_seconds),
            s.checks.len(),
        );
    }
    h.push_str("</tbody>\n</table>\n");
}

fn scene_section(h: &mut String, i: usize, s: &SceneSummary) {
    let verdict = pass_fail(s.passed);
    let failed = s.checks.iter().filter(|c| !c.passed).count();
    let _ = writeln!(
        h,
        "<section id=\"scene-{i}\">\n<h2>{} <span class=\"badge {}\">{verdict}</span></h2>",
        esc(&s.name),
        verdict.to_ascii_lowercase()
    );
    let _ = writeln!(
        h,
        "<p class=\"meta\">Wall time {}; {} check{}, {failed} failed.</p>",
        fmt_seconds(s.wall_seconds),
        s.checks.len(),
        plural(s.checks.len())
    );

    if !s.warnings.is_empty() {
        h.push_str("<ul class=\"warnings\">\n");
        for w in &s.warnings {
            let _ = writeln!(h, "<li><strong>Warning:</strong> {}</li>", esc(w));
        }
        h.push_str("</ul>\n");
    }

    if !s.notes.is_empty() {
        h.push_str("<ul class=\"notes\">\n");
        for note in &s.notes {
            let _ = writeln!(h, "<li>{}</li>", esc(note));
        }
        h.push_str("</ul>\n");
    }

    if !s.figures.is_empty() {
        h.push_str("<div class=\"figures\">\n");
        for fig in &s.figures {
            let href = esc(&url_path(fig));
            let name = esc(file_name(fig));
            let _ = writeln!(
                h,
                "<figure><a href=\"{href}\"><img src=\"{href}\" alt=\"{name}\"></a>\
                 <figcaption>{name}</figcaption></figure>"
            );
        }
        h.push_str("</div>\n");
    }

    if !s.tables.is_empty() {
        h.push_str("<p>Tables (CSV): ");
        for (k, table) in s.tables.iter().enumerate() {
            if k > 0 {
                h.push_str(", ");
            }
            let _ = write!(
                h,
                "<a href=\"{}\">{}</a>",
                esc(&url_path(table)),
                esc(file_name(table))
            );
        }
        h.push_str("</p>\n");
    }

    if s.checks.is_empty() {
        h.push_str("<p class=\"meta\">No checks.</p>\n");
    } else {
        checks_table(h, &s.checks);
    }
    h.push_str("</section>\n");
}

fn checks_table(h: &mut String, checks: &[CheckResult]) {
    h.push_str(
        "<table class=\"checks\">\n<thead><tr><th>Check</th><th>Kind</th><th>Reference kind</th>\
         <th>Estimate</th><th>Reference</th><th>Continuum</th><th>Std. error</th><th>p</th>\
         <th>Holm-adjusted p</th><th>Result</th><th>Detail</th></tr></thead>\n<tbody>\n",
    );
    for c in checks {
        let verdict = pass_fail(c.passed);
        let class = verdict.to_ascii_lowercase();
        let _ = writeln!(
            h,
            "<tr class=\"{class}\"><td>{}</td><td>{}</td><td>{}</td>\
             <td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>\
             <td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>\
             <td class=\"{class}\">{verdict}</td>\
             <td class=\"detail\">{}</td></tr>",
            esc(&c.name),
            esc(&c.kind),
            esc(&c.reference_kind),
            fmt4(c.estimate),
            fmt4(c.reference),
            fmt4(c.continuum),
            fmt4(c.std_error),
            fmt4(c.p_value),
            fmt4(c.p_adjusted),
            esc(&c.detail),
        );
    }
    h.push_str("</tbody>\n</table>\n");
}

fn pass_fail(passed: bool) -> &'static str {
    if passed { "PASS" } else { "FAIL" }
}

fn plural(n: usize) -> &'static str {
    if n == 1 { "" } else { "s" }
}

/// Escapes text for HTML element content and double- or single-quoted attributes.
pub(crate) fn esc(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(c),
        }
    }
    out
}

/// A relative file path as a URL path: `\` becomes `/`, bytes other than unreserved
/// characters and `/` are percent-encoded (plain paths are unchanged).
pub(crate) fn url_path(path: &str) -> String {
    let mut out = String::with_capacity(path.len());
    for &b in path.replace('\\', "/").as_bytes() {
        if b.is_ascii_alphanumeric() || matches!(b, b'-' | b'.' | b'_' | b'~' | b'/') {
            out.push(char::from(b));
        } else {
            let _ = write!(out, "%{b:02X}");
        }
    }
    out
}

/// The last component of a `/`- or `\`-separated relative path.
fn file_name(path: &str) -> &str {
    path.rsplit(['/', '\\']).next().unwrap_or(path)
}

/// A number to 4 significant digits: fixed-point for magnitudes in `[1e-3, 1e5)`,
/// scientific otherwise; `—` for `None`.
pub(crate) fn fmt4(value: Option<f64>) -> String {
    let Some(v) = value else {
        return "—".to_string();
    };
    if v.is_nan() {
        return "NaN".to_string();
    }
    if v.is_infinite() {
        return if v > 0.0 { "∞" } else { "−∞" }.to_string();
    }
    if v == 0.0 {
        return "0".to_string();
    }
    // The exponent after rounding to 4 significant digits (9.9996 → 1.000e1).
    let sci = format!("{v:.3e}");
    let exp: i32 = sci
        .rsplit('e')
        .next()
        .and_then(|e| e.parse().ok())
        .unwrap_or(0);
    if (-3..5).contains(&exp) {
        let decimals = usize::try_from(3 - exp).unwrap_or(0);
        format!("{v:.decimals$}")
    } else {
        sci
    }
}

fn fmt_alpha(alpha: f64) -> String {
    // α is a configuration value such as 0.01: print it as given.
    if alpha.is_finite() && alpha > 0.0 {
        format!("{alpha}")
    } else {
        fmt4(Some(alpha))
    }
}

pub(crate) fn fmt_seconds(seconds: f64) -> String {
    if !seconds.is_finite() {
        "—".to_string()
    } else if seconds < 10.0 {
        format!("{seconds:.2} s")
    } else if seconds < 600.0 {
        format!("{seconds:.1} s")
    } else {
        format!("{:.1} min", seconds / 60.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn four_significant_digits() {
        assert_eq!(fmt4(None), "—");
        assert_eq!(fmt4(Some(0.5)), "0.5000");
        assert_eq!(fmt4(Some(9.99996)), "10.00");
        assert_eq!(fmt4(Some(123.456)), "123.5");
        assert_eq!(fmt4(Some(1.23456e-7)), "1.235e-7");
        assert_eq!(fmt4(Some(-0.00123456)), "-0.001235");
        assert_eq!(fmt4(Some(123_456.0)), "1.235e5");
    }

    #[test]
    fn command_lines_are_quoted_where_needed() {
        let args = ["langevin-fem", "verify", "--out", "a b", "it's"].map(String::from);
        assert_eq!(
            shell_words(&args),
            "langevin-fem verify --out 'a b' 'it'\\''s'"
        );
    }

    #[test]
    fn paths() {
        assert_eq!(url_path("a b/c&d.svg"), "a%20b/c%26d.svg");
        assert_eq!(url_path("scene/fig-1.svg"), "scene/fig-1.svg");
        assert_eq!(file_name("scene/fig-1.svg"), "fig-1.svg");
    }
}
