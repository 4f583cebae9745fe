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
use crate::verify::summary::{CheckResult, SceneSummary, Summary, Totals};

pub(crate) const CSS: &str = "\
body{font-family:system-ui,-apple-system,'Segoe UI',Roboto,Helvetica,Arial,sans-serif;\
margin:1.2em auto;max-width:1200px;padding:0 1em;color:#1f2328;line-height:1.45}
h1{margin:.2em 0;font-size:1.5em}
h2{margin-top:1.4em;border-bottom:1px solid #d0d7de;padding-bottom:.2em;font-size:1.25em}
table{border-collapse:collapse;margin:.6em 0;font-size:.92em}
th,td{border:1px solid #d0d7de;padding:.25em .5em;vertical-align:top}
th{background:#f6f8fa;text-align:left}
td.num{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}
td.detail{font-size:.85em;color:#57606a;border-top:none;padding-left:2em}
tr.detail td{border-top:none}
.badge{display:inline-block;padding:.05em .5em;border-radius:.3em;font-weight:bold;\
font-size:.85em;vertical-align:middle}
.badge.pass,td.pass{background:#dafbe1;color:#116329}
.badge.fail,td.fail{background:#ffebe9;color:#a40e26}
td.pass,td.fail{font-weight:bold;text-align:center}
td.skip{background:#fff8c5;color:#7d4e00}
tr.fail{background:#fff5f4}
tr.check td{border-bottom:none}
table.checks{font-size:.82em}
table.checks tr.check td{white-space:nowrap}
.wide{overflow-x:auto}
.verdict{border-radius:.5em;padding:.6em 1em;margin:.6em 0}
.verdict.pass{background:#dafbe1;border:1px solid #4ac26b}
.verdict.fail{background:#ffebe9;border:1px solid #ff8182}
.verdict .word{font-size:1.8em;font-weight:bold;margin-right:.5em}
.verdict.pass .word{color:#116329}.verdict.fail .word{color:#a40e26}
.meta{color:#57606a}
details{margin:.3em 0}
details>summary{cursor:pointer;color:#0969da}
.figures{display:flex;flex-wrap:wrap;gap:1em}
figure{margin:0;border:1px solid #d0d7de;padding:.4em;background:#fff;max-width:560px}
figure img{display:block;width:100%;height:auto}
figcaption{font-size:.85em;color:#1f2328;margin-top:.3em}
figcaption code{color:#57606a}
code{font-size:.95em}
.provenance{border:1px solid #d0d7de;border-radius:.4em;padding:.2em 1em;margin:1em 0;\
background:#f6f8fa}
.provenance table{background:#fff}
.provenance code{word-break:break-all}
";

/// Renders the HTML index page for `summary`.
///
/// Laid out for a reader who wants the verdict first and the details on demand (native
/// `<details>` elements, no scripts): the verdict with the totals (checks passed, failed
/// and skipped; budget, α, wall time, run id); the failed checks of every scene in one
/// table; the scenes table; then per scene a summary of its checks per run and test
/// (passed / failed / skipped), and, collapsed, its notes, figures with captions, skipped
/// checks and the table of all its checks; the convergence link; the provenance box
/// (version, commit, start time, command line, threads, per scene its seed, source and
/// SHA-256) and how to read the tables. Check tables keep one meaning per column: test,
/// statistic, degrees of freedom, raw and Holm-adjusted p-values, estimate ± standard
/// error, exact reference, continuum value and unit, to 4 significant digits (`—` where a
/// value does not apply).
pub fn render_index(summary: &Summary) -> String {
    let mut h = String::with_capacity(64 * 1024);
    let verdict = if summary.passed { "PASSED" } else { "FAILED" };
    let _ = writeln!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>langevin-fem verification: {verdict} ({})</title>\n<style>\n{CSS}</style>\n\
         </head>\n<body>\n<h1>langevin-fem verification report</h1>",
        esc(&summary.budget)
    );
    verdict_box(&mut h, summary);
    failures_section(&mut h, summary);
    scenes_table(&mut h, summary);
    for (i, scene) in summary.scenes.iter().enumerate() {
        scene_section(&mut h, i, scene);
    }
    h.push_str(CONVERGENCE_MARK);
    if let Some(p) = &summary.provenance {
        provenance_box(&mut h, p);
    }
    reading_guide(&mut h, summary);
    h.push_str("</body>\n</html>\n");
    h
}

/// Where [`index_html`] puts the convergence section.
const CONVERGENCE_MARK: &str = "<!-- convergence -->\n";

/// The verdict and the totals, first on the page.
fn verdict_box(h: &mut String, summary: &Summary) {
    let total = Totals::of(&summary.scenes);
    let n = summary.scenes.len();
    let failed_scenes = summary.scenes.iter().filter(|s| !s.passed).count();
    let wall: f64 = summary.scenes.iter().map(|s| s.wall_seconds).sum();
    let (class, word) = if summary.passed {
        ("pass", "PASSED")
    } else {
        ("fail", "FAILED")
    };
    let _ = writeln!(
        h,
        "<div class=\"verdict {class}\" id=\"verdict\"><span class=\"word\">{word}</span>\
         <span id=\"totals\">{} of {n} scene{} passed; checks: {}.</span>\
         <br><span class=\"meta\">Budget <b>{}</b>; family-wise α = {} per scene (Holm); \
         wall time {}.",
        n - failed_scenes,
        plural(n),
        total.text(),
        esc(&summary.budget),
        fmt_alpha(summary.alpha),
        fmt_seconds(wall)
    );
    if !summary.run_id.is_empty() {
        let _ = write!(
            h,
            " Run <code id=\"run-id\">{}</code>; <a href=\"summary.json\">summary.json</a> \
             lists its {} files.",
            esc(&summary.run_id),
            summary.files.len()
        );
    }
    h.push_str("</span></div>\n");
}

/// The failed checks of every scene, in one table, right after the verdict.
fn failures_section(h: &mut String, summary: &Summary) {
    h.push_str("<section id=\"failures\">\n<h2>Failures</h2>\n");
    let failed: Vec<(usize, &SceneSummary, &CheckResult)> = summary
        .scenes
        .iter()
        .enumerate()
        .flat_map(|(i, s)| {
            s.checks
                .iter()
                .filter(|c| !c.passed)
                .map(move |c| (i, s, c))
        })
        .collect();
    if failed.is_empty() {
        h.push_str("<p class=\"ok\">No check failed.</p>\n");
    } else {
        checks_header(h, true);
        for (i, s, c) in failed {
            check_row(h, Some((i, &s.name)), c);
        }
        h.push_str("</tbody>\n</table></div>\n");
    }
    let warnings: Vec<(&str, &String)> = summary
        .scenes
        .iter()
        .flat_map(|s| s.warnings.iter().map(move |w| (s.name.as_str(), w)))
        .collect();
    if !warnings.is_empty() {
        h.push_str("<ul class=\"warnings\">\n");
        for (scene, w) in warnings {
            let _ = writeln!(
                h,
                "<li><strong>Warning ({}):</strong> {}</li>",
                esc(scene),
                esc(w)
            );
        }
        h.push_str("</ul>\n");
    }
    h.push_str("</section>\n");
}

fn scenes_table(h: &mut String, summary: &Summary) {
    h.push_str(
        "<section id=\"scenes\">\n<h2>Scenes</h2>\n<table>\n<thead><tr><th>Scene</th>\
         <th>Result</th><th>Passed</th><th>Failed</th><th>Skipped</th><th>Wall time</th>\
         <th>What it checks</th></tr></thead>\n<tbody>\n",
    );
    for (i, s) in summary.scenes.iter().enumerate() {
        let t = Totals::of([s]);
        let verdict = pass_fail(s.passed);
        let _ = writeln!(
            h,
            "<tr><td><a href=\"#scene-{i}\">{}</a></td><td class=\"{}\">{verdict}</td>\
             <td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>\
             <td class=\"num\">{}</td><td class=\"detail\">{}</td></tr>",
            esc(&s.name),
            verdict.to_ascii_lowercase(),
            t.passed,
            t.failed,
            t.skipped,
            fmt_seconds(s.wall_seconds),
            esc(s.notes.first().map_or("", String::as_str)),
        );
    }
    h.push_str("</tbody>\n</table>\n</section>\n");
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

/// [`render_index`] of `summary`, with its convergence section: the link to
/// `out_dir/convergence/index.html` if that exists, else the commands that write it (no
/// link that leads nowhere).
fn index_html(out_dir: &Path, summary: &Summary) -> String {
    let html = render_index(summary);
    let section = if out_dir.join("convergence").join("index.html").exists() {
        "<section id=\"convergence\"><h2>Convergence and stability</h2>\n<p>Stability map, per-mode stationary bias against each integrator's exact formula (and, after <code>make converge</code>, the convergence studies, work–precision and extreme scenes): <a href=\"convergence/index.html\">convergence/index.html</a>.</p></section>\n"
    } else {
        "<section id=\"convergence\"><h2>Convergence and stability</h2>\n<p class=\"meta\">Not in this output directory: <code>langevin-fem stability</code> and <code>langevin-fem converge</code> with <code>--out &lt;this directory&gt;/convergence</code> (or <code>make verify</code>, <code>make converge</code>) write them, and the next <code>verify</code> links them here.</p></section>\n"
    };
    html.replacen(CONVERGENCE_MARK, section, 1)
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
        "<details class=\"provenance\" id=\"provenance\">\n<summary>Provenance: langevin-fem {0}, \
         commit <code>{1}</code>, started {2} (UTC)</summary>\n<table>\n\
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
         unit of every column of every CSV table — is in <a href=\"{0}\">{0}</a>.</p>\n</details>",
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

/// One scene: its verdict and description, its checks per run and test, and collapsed
/// its notes, figures, tables, skipped checks and the table of all its checks.
fn scene_section(h: &mut String, i: usize, s: &SceneSummary) {
    let verdict = pass_fail(s.passed);
    let t = Totals::of([s]);
    let _ = writeln!(
        h,
        "<section id=\"scene-{i}\" class=\"scene\">\n<h2>{} <span class=\"badge {}\">{verdict}</span></h2>\n\
         <p class=\"meta\">{}; wall time {}.</p>",
        esc(&s.name),
        verdict.to_ascii_lowercase(),
        t.text(),
        fmt_seconds(s.wall_seconds)
    );
    run_kind_table(h, s);
    if s.notes.len() > 1 {
        let _ = writeln!(
            h,
            "<details class=\"notes\"><summary>Notes ({})</summary>\n<ul>",
            s.notes.len() - 1
        );
        for note in &s.notes[1..] {
            let _ = writeln!(h, "<li>{}</li>", esc(note));
        }
        h.push_str("</ul>\n</details>\n");
    }
    if !s.figures.is_empty() {
        let _ = writeln!(
            h,
            "<details class=\"figures\"><summary>Figures ({})</summary>\n<div class=\"figures\">",
            s.figures.len()
        );
        for (k, fig) in s.figures.iter().enumerate() {
            let href = esc(&url_path(fig));
            let name = esc(file_name(fig));
            let caption = s.captions.get(k).map_or("", String::as_str);
            let alt = if caption.is_empty() {
                name.clone()
            } else {
                esc(caption)
            };
            let _ = writeln!(
                h,
                "<figure><a href=\"{href}\"><img src=\"{href}\" alt=\"{alt}\"></a>\
                 <figcaption>{} <code>{name}</code></figcaption></figure>",
                esc(caption)
            );
        }
        h.push_str("</div>\n</details>\n");
    }
    tables_details(h, s);
    if !s.skipped.is_empty() {
        let _ = writeln!(
            h,
            "<details class=\"skipped\"><summary>Skipped checks ({}): not evaluated, neither \
             passed nor failed</summary>\n<ul>",
            s.skipped.len()
        );
        for k in &s.skipped {
            let _ = writeln!(
                h,
                "<li><code>{}</code>: {}</li>",
                esc(&k.name),
                esc(&k.reason)
            );
        }
        h.push_str("</ul>\n</details>\n");
    }
    if s.checks.is_empty() {
        h.push_str("<p class=\"meta\">No checks.</p>\n");
    } else {
        let _ = writeln!(
            h,
            "<details class=\"checks\"><summary>All {} checks ({})</summary>",
            s.checks.len(),
            t.text()
        );
        checks_header(h, false);
        for c in &s.checks {
            check_row(h, None, c);
        }
        h.push_str("</tbody>\n</table></div>\n</details>\n");
    }
    h.push_str("</section>\n");
}

/// A scene's CSV tables, collapsed like its notes and figures: a scene's CSV list wraps
/// over several lines, and the page of a run must stay short before expansion.
fn tables_details(h: &mut String, s: &SceneSummary) {
    if s.tables.is_empty() {
        return;
    }
    let _ = write!(
        h,
        "<details class=\"tables\"><summary>Tables (CSV, {})</summary>\n<p>",
        s.tables.len()
    );
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
    h.push_str("</p>\n</details>\n");
}

/// The checks of a scene counted per run (rows; `scene` for the scene's own checks) and
/// test (columns): `passed`, with the failed and skipped when there are any.
fn run_kind_table(h: &mut String, s: &SceneSummary) {
    let mut kinds: Vec<&str> = Vec::new();
    let mut runs: Vec<&str> = Vec::new();
    for c in &s.checks {
        if !kinds.contains(&c.kind.as_str()) {
            kinds.push(&c.kind);
        }
        if !runs.contains(&c.run.as_str()) {
            runs.push(&c.run);
        }
    }
    let skipped_run = |k: &crate::verify::summary::SkippedCheck| {
        k.name.split('/').next().unwrap_or("").to_string()
    };
    if kinds.is_empty() {
        return;
    }
    h.push_str("<table class=\"summary\"><thead><tr><th>Run</th>");
    for k in &kinds {
        let _ = write!(h, "<th>{}</th>", esc(k));
    }
    h.push_str("<th>Skipped</th></tr></thead>\n<tbody>\n");
    for run in &runs {
        let label = if run.is_empty() { "(scene)" } else { run };
        let _ = write!(h, "<tr><td>{}</td>", esc(label));
        for k in &kinds {
            let of: Vec<&CheckResult> = s
                .checks
                .iter()
                .filter(|c| c.run == *run && c.kind == *k)
                .collect();
            let failed = of.iter().filter(|c| !c.passed).count();
            if of.is_empty() {
                h.push_str("<td class=\"num\"></td>");
            } else if failed == 0 {
                let _ = write!(h, "<td class=\"num\">{} ✓</td>", of.len());
            } else {
                let _ = write!(
                    h,
                    "<td class=\"num fail\">{} ✓ {failed} ✗</td>",
                    of.len() - failed
                );
            }
        }
        let skipped = s
            .skipped
            .iter()
            .filter(|k| !run.is_empty() && skipped_run(k) == *run)
            .count();
        if skipped > 0 {
            let _ = write!(h, "<td class=\"num skip\">{skipped}</td>");
        } else {
            h.push_str("<td class=\"num\"></td>");
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</tbody></table>\n");
}

/// The header of a check table (with a scene column in the failures table).
fn checks_header(h: &mut String, with_scene: bool) {
    h.push_str("<div class=\"wide\"><table class=\"checks\">\n<thead><tr>");
    if with_scene {
        h.push_str("<th>Scene</th>");
    }
    h.push_str(
        "<th>Run</th><th>Check</th><th>Parameter</th><th>Test</th><th>Statistic</th>\
         <th>dof</th><th>p</th><th>Holm p</th><th>Estimate ± s.e.</th><th>Reference</th>\
         <th>Continuum</th><th>Unit</th><th>Result</th></tr></thead>\n<tbody>\n",
    );
}

/// One check's row: every column keeps one meaning (see [`render_index`]).
fn check_row(h: &mut String, scene: Option<(usize, &str)>, c: &CheckResult) {
    let verdict = pass_fail(c.passed);
    let class = verdict.to_ascii_lowercase();
    let _ = write!(h, "<tr class=\"check {class}\">");
    if let Some((i, name)) = scene {
        let _ = write!(h, "<td><a href=\"#scene-{i}\">{}</a></td>", esc(name));
    }
    let (check, parameter) = if c.check.is_empty() {
        (c.name.as_str(), "")
    } else {
        (c.check.as_str(), c.parameter.as_str())
    };
    let estimate = match (c.estimate, c.std_error) {
        (Some(e), Some(se)) => format!("{} ± {}", fmt4(Some(e)), fmt4(Some(se))),
        (e, _) => fmt4(e),
    };
    // A reference that is the continuum's says so in its cell (issue #31).
    let reference = if c.reference_kind == "continuum" && c.reference.is_some() {
        format!(
            "{} <span class=\"kind\" title=\"the continuum's value, not a discretization's\">(continuum)</span>",
            fmt4(c.reference)
        )
    } else {
        fmt4(c.reference)
    };
    let _ = writeln!(
        h,
        "<td>{}</td><td title=\"{}\">{}</td><td>{}</td><td>{}</td><td class=\"num\">{}</td>\
         <td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>\
         <td class=\"num\">{estimate}</td><td class=\"num\">{reference}</td><td class=\"num\">{}</td>\
         <td>{}</td><td class=\"{class}\">{verdict}</td></tr>\n<tr class=\"{class} detail\">\
         <td colspan=\"{}\" class=\"detail\">{}</td></tr>",
        esc(if c.run.is_empty() { "(scene)" } else { &c.run }),
        esc(&c.name),
        esc(check),
        esc(parameter),
        esc(&c.kind),
        fmt4(c.statistic),
        fmt_dof(c.dof),
        fmt4(c.p_value),
        fmt4(c.p_adjusted),
        fmt4(c.continuum),
        esc(&c.unit),
        if scene.is_some() { 14 } else { 13 },
        esc(&c.detail),
    );
}

/// How to read the tables: collapsed, at the end.
fn reading_guide(h: &mut String, summary: &Summary) {
    let _ = writeln!(
        h,
        "<details id=\"guide\"><summary>How to read this report</summary>\n\
         <p>Budget <b>{}</b>. Family-wise significance level α = {} per scene: the p-values \
         of a scene's statistical checks form one family and are Holm-corrected \
         (Holm–Bonferroni step-down), so that the probability of any false failure in a \
         scene whose simulation is correct is at most α. Deterministic checks (tests \
         <code>oracle</code> and <code>residual</code>: no p-value) pass or fail on their \
         own tolerance and are outside the family.</p>\n<ul>\
         <li><b>Test</b>: t-test, z-test, band-t-test and band-z-test (against the nearest \
         point of a tolerance band, p = 1 inside it; band-chi2-sum their sum of squared scores), chi2-variance (χ² test of a variance), quadratic-form \
         (a Gaussian quadratic form — a mode's squared AR(1) amplitudes, the squared field at \
         a profile point, the two-time products — against its null law, scale from the \
         reference), chi2-gof \
         (χ² goodness of fit of a distribution), chi2-sum (sum of squared scores), ks \
         (Kolmogorov–Smirnov), oracle (a discrete reference against closed forms of the \
         continuum within its discretization error), residual (a round-off bound).</li>\
         <li><b>Statistic</b> and <b>dof</b>: the test's statistic (t, z, χ², KS distance) \
         and the degrees of freedom of its null distribution.</li>\
         <li><b>p</b>, <b>Holm p</b>: raw and Holm-adjusted p-values; the check fails when \
         the adjusted p is below α.</li>\
         <li><b>Estimate ± s.e.</b>: the simulated value with its standard error \
         (autocorrelation-aware); <b>Reference</b>: the exact value for the discretized \
         filament and integrator (for an oracle check, the closed form it is held to); \
         <b>Continuum</b>: the exact value of the continuum model (eqs. 2–4); the gap \
         between them is the discretization error. A reference marked <i>(continuum)</i> is \
         the continuum's own value (data whose discretization this tool does not model, whose \
         mesh and time-step errors are then part of what is checked; an oracle's closed \
         form). <b>Unit</b>: the unit of those three, in \
         the scene's units ([L] length, [T] time; F_c0 the Euler load; 1 dimensionless); \
         empty for a test whose result is its statistic.</li>\
         <li><b>Skipped</b>: a check the scene asks for that the data at this budget cannot \
         support (the reason is listed); it counts neither as passed nor as failed.</li>\
         </ul>\n</details>",
        esc(&summary.budget),
        fmt_alpha(summary.alpha)
    );
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

/// Degrees of freedom: a whole number as such (`7`, not `7.000`), else as [`fmt4`].
fn fmt_dof(dof: Option<f64>) -> String {
    match dof {
        Some(d) if d.fract() == 0.0 && d.abs() < 1e15 => format!("{d:.0}"),
        d => fmt4(d),
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
