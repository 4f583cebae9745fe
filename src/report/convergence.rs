//! The index page of the convergence reports (`reports/convergence/index.html`): the
//! convergence studies, the work–precision study, the stability map and the extreme
//! scenes, rebuilt each time one of `converge`, `work-precision` or `stability` has
//! written there.
//!
//! The page lists exactly the studies whose journal (`<stem>.manifest.json`, see
//! [`crate::studies::output`]) says complete and whose summary `<stem>.json` carries the
//! journal's run id, each with that run id; a study whose journal is incomplete (killed
//! while writing, or still writing) is named as not listed. Summaries without a journal
//! (written before journals existed) are not listed: nothing attributes them to a run.

use super::html::{CSS, esc, url_path};
use crate::error::{Error, Result};
use crate::output::{Manifest, read_manifest, write_atomic};
use crate::studies::converge::{ConvergeSummary, OrderFit};
use crate::studies::coupled_dt::{self, CoupledDtSummary};
use crate::studies::fig2_schemes::{self, Fig2SchemesSummary};
use crate::studies::output::{INDEX, STUDY_COMMANDS, stem_of_journal, summary_name};
use crate::studies::stability::{Cell, StabilitySummary, Status};
use crate::studies::work_precision::WorkPrecisionSummary;
use serde::Serialize;
use serde::de::DeserializeOwned;
use std::fmt::Write as _;
use std::path::Path;

/// A number as the JSON summary spells it (`200.0`, `1e-5`; `null` if non-finite).
fn json<T: Serialize>(x: &T) -> String {
    serde_json::to_string(x).unwrap_or_default()
}

/// A number for a table: 4 decimals, or 3 significant exponent digits if very small or
/// large; "–" if non-finite (`null` in the summary).
fn num(x: f64) -> String {
    if !x.is_finite() {
        "–".to_string()
    } else if x != 0.0 && (x.abs() < 1e-3 || x.abs() >= 1e4) {
        format!("{x:.3e}")
    } else {
        format!("{x:.4}")
    }
}

/// [`num`] of an optional number ("–" if absent).
fn num_opt(x: Option<f64>) -> String {
    x.map_or_else(|| "–".to_string(), num)
}

/// A fitted order with its interval and number of points, "–" if none (or its order is
/// non-finite).
fn fit(f: Option<&OrderFit>) -> String {
    match f {
        Some(f) if f.order.is_finite() => match f.ci {
            Some((lo, hi)) => format!("{:.2} [{lo:.2}, {hi:.2}] ({} pts)", f.order, f.points),
            None => format!("{:.2} (2 pts, no CI)", f.order),
        },
        _ => "–".to_string(),
    }
}

/// The caption of figure `file` in `dir`: the `<title>` every figure of the project
/// carries ([`crate::output::figure::svg_caption`]), empty if it has none.
fn svg_caption(dir: &Path, file: &str) -> String {
    let text = std::fs::read_to_string(dir.join(file)).unwrap_or_default();
    crate::output::figure::svg_caption(&text).unwrap_or_default()
}

/// A figure with its caption (what is plotted, what to see) and its file name.
fn figure(h: &mut String, dir: &Path, file: &str) {
    let caption = svg_caption(dir, file);
    let alt = if caption.is_empty() { file } else { &caption };
    let _ = writeln!(
        h,
        "<figure><a href=\"{0}\"><img src=\"{0}\" alt=\"{1}\"></a><figcaption>{2} <code>{3}</code></figcaption></figure>",
        url_path(file),
        esc(alt),
        esc(&caption),
        esc(file)
    );
}

/// The figures (SVG) of a summary, then links to its data files.
fn files(h: &mut String, dir: &Path, list: &[String]) {
    h.push_str("<div class=\"figures\">\n");
    for f in list.iter().filter(|f| f.ends_with(".svg")) {
        figure(h, dir, f);
    }
    h.push_str("</div>\n<p class=\"meta\">Data: ");
    for f in list.iter().filter(|f| !f.ends_with(".svg")) {
        let _ = write!(h, "<a href=\"{}\">{}</a> ", url_path(f), esc(f));
    }
    h.push_str("</p>\n");
}

/// The heading, the table of observables and the consistency line of one study.
fn convergence_section(h: &mut String, dir: &Path, journal: &str, v: &ConvergeSummary) {
    let _ = writeln!(
        h,
        "<h3>{} / {} ({} noise, {}) over {}</h3>\n<p class=\"meta\">h = {}; {}; errors against the {}; budget {}: {} trajectories x {} tau1 per value; {:.1} s.</p>",
        esc(&v.scene),
        esc(&v.run),
        esc(&v.noise),
        esc(&v.integrator),
        esc(v.over.name()),
        esc(&v.h),
        esc(&v.fixed),
        esc(&v.limit_reference),
        esc(&v.budget),
        v.trajectories,
        json(&v.duration_tau1),
        v.wall_seconds
    );
    run_line(h, journal, &v.run_id);
    h.push_str("<table><tr><th>observable</th><th>expected order</th><th>observed order (95 % CI)</th><th>agrees</th><th>exact-error order</th><th>sampling floor at</th><th>why / note</th></tr>\n");
    for o in &v.observables {
        let e = &o.expected;
        let expected = match (e.order, e.exact) {
            (Some(p), _) => format!("{p}"),
            (None, true) => "exact (zero error)".to_string(),
            (None, false) => "no single order".to_string(),
        };
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td class=\"num\">{}</td>{}<td class=\"num\">{}</td><td>{}</td><td class=\"detail\">{} {}</td></tr>",
            esc(&o.observable),
            esc(&expected),
            esc(&fit(o.observed.as_ref())),
            match o.agrees {
                Some(true) => "<td class=\"pass\">yes</td>",
                Some(false) => "<td class=\"warn\">no (see note)</td>",
                None => "<td>–</td>",
            },
            esc(&fit(o.exact.as_ref())),
            esc(&json(&o.floor_values)),
            esc(&e.why),
            esc(&o.note)
        );
    }
    h.push_str("</table>\n");
    if let Some(c) = &v.discrete_consistency {
        let _ = writeln!(
            h,
            "<p class=\"meta\">Simulation against the exact discrete reference of each value: largest |z| = {} ({}) over {} rows, <span class=\"{}\">Bonferroni p = {}</span> (below 0.01: the simulation disagrees with its own discretization); Σz² = {}.</p>",
            num(c.max_abs_z),
            esc(&c.worst),
            c.rows,
            if c.p_value < 0.01 { "fail" } else { "pass" },
            num(c.p_value),
            num(c.chi2)
        );
    }
    let list = |h: &mut String, texts: &[String], class: &str, label: &str| {
        for text in texts {
            let _ = writeln!(h, "<p class=\"{class}\">{label}{}</p>", esc(text));
        }
    };
    let failed: Vec<String> = v
        .failed
        .iter()
        .map(|f| {
            format!(
                "{} at {} = {}: {}",
                f.kind,
                v.over.name(),
                json(&f.value),
                f.error
            )
        })
        .collect();
    list(h, &failed, "fail", "no rows: ");
    list(h, &v.warnings, "warn", "warning: ");
    list(h, &v.notes, "meta", "");
    files(h, dir, &v.files);
}

/// The work–precision heading and its table of methods.
fn work_precision_section(h: &mut String, dir: &Path, journal: &str, v: &WorkPrecisionSummary) {
    let _ = writeln!(
        h,
        "<h2>Work–precision ({})</h2>\n<p class=\"meta\">Error in &lt;{}&gt; against the continuum, {} elements, {} trajectories x {} tau1 per point (euler-maruyama {} tau1), {} threads; sampling floor (median relative s.e.) {}. Projected wall time to reach a relative error of {} with 95 % confidence (bias + 2 s.e.), from the measured cost and standard error (s.e. ∝ T<sup>-1/2</sup>); {} points disagree with their exact discrete value by more than 3 s.e.</p>",
        esc(&v.scene),
        match v.observable.as_str() {
            "w2(L/2)" => "w²(L/2)".to_string(),
            "h2(a/2,b/2)" => "h²(a/2, b/2)".to_string(),
            other => esc(other),
        },
        v.elements,
        v.trajectories,
        json(&v.duration_tau1),
        json(&v.em_duration_tau1),
        v.threads,
        num(v.sampling_floor),
        num(v.tolerance),
        v.inconsistent_points
    );
    run_line(h, journal, &v.run_id);
    h.push_str("<table><tr><th>integrator</th><th>noise</th><th>projected time (s)</th><th>best dt/tau1</th><th>cost vs fastest</th><th>smallest exact bias</th><th>note</th></tr>\n");
    for m in &v.methods {
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"detail\">{}</td></tr>",
            esc(&m.integrator),
            esc(&m.noise),
            num_opt(m.seconds_to_tolerance),
            num_opt(m.best_dt_tau1),
            num_opt(m.relative_cost),
            num(m.min_rel_bias),
            esc(&m.note)
        );
    }
    h.push_str("</table>\n");
    files(h, dir, &v.files);
}

/// The schemes of Fig. 2: a table of every method and step (cost, projected CPU time,
/// largest |bias|), the dynamics comparison, the figures.
fn fig2_schemes_section(h: &mut String, dir: &Path, journal: &str, v: &Fig2SchemesSummary) {
    let _ = writeln!(
        h,
        "<h2>Work–precision of Fig. 2 ({}, {}D)</h2>\n<p class=\"meta\">The paper's explicit scheme, Crank–Nicolson with the stretching force explicit and the Metropolis chain at strains eps/eps_c0 = {}, {} elements, {} trajectories x {} tau1 per strain and step, {} threads. Bias: &lt;F&gt;/F_c0 minus the exact discrete theory of the mesh. Projected CPU time to a standard error of {} F_c0 at every strain with the bias below it (a theta-scheme: its 95 % bound |bias| + 2 s.e.; the chain is exact at any step), from the measured CPU time per tau1 (getrusage) and standard errors.</p>",
        esc(&v.scene),
        v.dims,
        v.strain_ratios
            .iter()
            .map(json)
            .collect::<Vec<_>>()
            .join(", "),
        v.elements,
        v.trajectories,
        json(&v.duration_tau1),
        v.threads,
        num(v.tolerance)
    );
    run_line(h, journal, &v.run_id);
    h.push_str("<table><tr><th>integrator</th><th>noise</th><th>dt/tau1</th><th>CPU-s per tau1</th><th>projected CPU-s</th><th>largest |bias| (its s.e.)</th></tr>\n");
    for r in &v.runs {
        let worst = r
            .points
            .iter()
            .max_by(|a, b| a.bias.abs().total_cmp(&b.bias.abs()));
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td></tr>",
            esc(&r.integrator),
            esc(&r.noise),
            num(r.dt_tau1),
            num(r.cpu_per_tau1),
            match (&r.failed, r.cpu_to_tolerance) {
                (Some(why), _) => format!("no estimate: {}", esc(why)),
                (None, t) => num_opt(t),
            },
            worst.map_or("–".to_string(), |p| format!(
                "{} ({}) at eps/eps_c0 = {}",
                num(p.bias.abs()),
                num(p.force_std_error),
                json(&p.strain_ratio)
            ))
        );
    }
    h.push_str("</table>\n");
    let _ = writeln!(
        h,
        "<p class=\"meta\">The dynamics at each scheme's smallest step: the integrated autocorrelation time of F and of the buckled mode's squared amplitude A² (tau1), chi2 of log tau about the weighted mean, Holm at alpha = {}.</p>",
        json(&v.alpha)
    );
    h.push_str("<table><tr><th>eps/eps_c0</th><th>observable</th><th>tau_int ± s.e. per scheme (dt/tau1)</th><th>p</th><th>Holm p</th><th>verdict</th></tr>\n");
    for t in &v.dynamics {
        let _ = writeln!(
            h,
            "<tr><td class=\"num\">{}</td><td>{}</td><td class=\"detail\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"{}\">{}</td></tr>",
            json(&t.strain_ratio),
            esc(&t.observable),
            t.methods
                .iter()
                .map(|(m, dt, tau, se)| format!(
                    "{}: {} ± {} ({})",
                    esc(m),
                    num(*tau),
                    num(*se),
                    num(*dt)
                ))
                .collect::<Vec<_>>()
                .join("; "),
            num(t.p_value),
            num(t.p_holm),
            if t.passed { "pass" } else { "fail" },
            if t.passed { "agree" } else { "differ" }
        );
    }
    h.push_str("</table>\n");
    files(h, dir, &v.files);
}

/// The coupled time-step study of one run: its orders per strain and differences.
fn coupled_dt_section(h: &mut String, dir: &Path, journal: &str, v: &CoupledDtSummary) {
    let _ = writeln!(
        h,
        "<h2>Time-step order of &lt;F&gt; from coupled pairs: {} / {} ({}, {} noise, {}D)</h2>\n<p class=\"meta\">Pairs of trajectories at a step and its half driven by the same Brownian path: {} pairs x {} tau1 per step and strain after {} tau1 of burn-in, {} elements, {:.1} CPU-s. D = &lt;F&gt;_dt − &lt;F&gt;_dt/2 (F_c0); the order is the weighted fit of ln|D| against ln dt with its 95 % interval; expected {} as dt → 0; predicted: the linear-response prediction of the scheme's exact discrete stationary covariance.</p>",
        esc(&v.scene),
        esc(&v.run),
        esc(&v.integrator),
        esc(&v.noise),
        v.dims,
        v.trajectories,
        json(&v.duration_tau1),
        json(&v.burn_in_tau1),
        v.elements,
        v.cpu_seconds,
        json(&coupled_dt::EXPECTED_ORDER)
    );
    run_line(h, journal, &v.run_id);
    h.push_str("<table><tr><th>eps/eps_c0</th><th>D ± s.e. per coarse dt/tau1 (predicted)</th><th>observed order [95 %]</th><th>fit p</th><th>predicted order</th></tr>\n");
    for o in &v.orders {
        let d = v
            .points
            .iter()
            .filter(|p| p.strain_ratio == o.strain_ratio)
            .map(|p| {
                format!(
                    "{}: {} ± {} ({})",
                    num(p.dt_tau1),
                    num(p.difference),
                    num(p.std_error),
                    num(p.predicted)
                )
            })
            .collect::<Vec<_>>()
            .join("; ");
        let observed = match o.ci {
            Some((lo, hi)) => format!("{} [{}, {}]", num(o.order), num(lo), num(hi)),
            None => esc(&o.note),
        };
        let _ = writeln!(
            h,
            "<tr><td class=\"num\">{}</td><td class=\"detail\">{}</td><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td></tr>",
            json(&o.strain_ratio),
            esc(&d),
            observed,
            num(o.fit_p_value),
            num(o.predicted_order)
        );
    }
    h.push_str("</table>\n");
    files(h, dir, &v.files);
}

/// The run id of a listed study, with a link to its journal.
fn run_line(h: &mut String, journal: &str, run_id: &str) {
    let _ = writeln!(
        h,
        "<p class=\"meta\">Run <code class=\"run-id\" data-journal=\"{}\">{}</code> (journal <a href=\"{}\">{}</a>).</p>",
        esc(journal),
        esc(run_id),
        url_path(journal),
        esc(journal)
    );
}

/// Pushes `x` onto `list` unless it is already there (first-seen order).
fn push_new<T: PartialEq>(list: &mut Vec<T>, x: T) {
    if !list.contains(&x) {
        list.push(x);
    }
}

/// One table cell of the stability map: its status, with its detail on hover.
fn stability_cell(h: &mut String, c: Option<&Cell>) {
    let Some(c) = c else {
        h.push_str("<td></td>");
        return;
    };
    let class = match c.status {
        Status::Stable => "pass",
        Status::Unstable => "fail",
        Status::Biased => "warn",
    };
    let _ = write!(
        h,
        "<td class=\"{class}\" title=\"{}\">{}</td>",
        esc(&c.detail),
        esc(c.status.name())
    );
}

/// The stability heading and the map: one row per integrator and element count, one
/// column per dt·λ_max.
fn stability_section(h: &mut String, dir: &Path, journal: &str, v: &StabilitySummary) {
    let _ = writeln!(
        h,
        "<h2>Stability map ({})</h2>\n<p class=\"meta\">Consistent noise, {} trajectories x {} steps after {} burn-in steps per cell. <b>unstable</b>: |m| ≥ 1, refused before running and, forced, overflowing; <b>biased</b>: the stationary variance of a checked mode differs from kT/λ beyond its error (Holm over the map, α = {}); <b>stable</b>: no bias resolved. Exact per-mode formulas: {} of {} comparisons rejected; stability predictions {}.</p>",
        esc(&v.scene),
        v.trajectories,
        v.sampled_steps,
        v.burn_in_steps,
        json(&v.alpha),
        v.formula_rejections,
        v.formula_tests,
        if v.stability_as_predicted {
            "all held"
        } else {
            "did NOT all hold"
        }
    );
    run_line(h, journal, &v.run_id);
    let mut integrators: Vec<&str> = Vec::new();
    let mut steps: Vec<f64> = Vec::new();
    let mut elements: Vec<usize> = Vec::new();
    for c in &v.cells {
        push_new(&mut integrators, c.integrator.as_str());
        push_new(&mut steps, c.dt_lambda_max);
        push_new(&mut elements, c.elements);
    }
    h.push_str("<table><tr><th>integrator</th><th>elements</th>");
    for a in &steps {
        let _ = write!(h, "<th>dt·λ<sub>max</sub> = {a}</th>");
    }
    h.push_str("</tr>\n");
    for i in &integrators {
        for e in &elements {
            let _ = write!(h, "<tr><td>{}</td><td class=\"num\">{e}</td>", esc(i));
            for a in &steps {
                let c = v
                    .cells
                    .iter()
                    .find(|c| c.integrator == *i && c.elements == *e && c.dt_lambda_max == *a);
                stability_cell(h, c);
            }
            h.push_str("</tr>\n");
        }
    }
    h.push_str("</table>\n<p class=\"meta\">Hover a cell for its detail (measured variance ratio, z, unresolved modes); all of it is in stability-cells.csv and stationary-bias.csv.</p>\n");
    files(h, dir, &v.files);
}

/// The summary `name` in `dir`, if it exists and reads as a `T`.
fn read<T: DeserializeOwned>(dir: &Path, name: &str) -> Option<T> {
    let text = std::fs::read_to_string(dir.join(name)).ok()?;
    serde_json::from_str(&text).ok()
}

/// A study's summary, by the command that wrote it.
enum Study {
    Stability(StabilitySummary),
    WorkPrecision(WorkPrecisionSummary),
    Fig2Schemes(Box<Fig2SchemesSummary>),
    Converge(Box<ConvergeSummary>),
    CoupledDt(Box<CoupledDtSummary>),
}

impl Study {
    /// The summary of `journal`'s output set, if it reads as its command's summary and
    /// carries the journal's run id.
    fn read(dir: &Path, stem: &str, journal: &Manifest) -> Option<Study> {
        let name = summary_name(stem);
        let study = match journal.command.as_str() {
            "stability" => Study::Stability(read(dir, &name)?),
            "work-precision" if stem == fig2_schemes::STEM => {
                Study::Fig2Schemes(Box::new(read(dir, &name)?))
            }
            "work-precision" => Study::WorkPrecision(read(dir, &name)?),
            // A coupled study's stem ends so; a convergence study of a run named
            // "coupled" over dt does too, and reads as the convergence summary it is.
            "converge" => match stem
                .ends_with(coupled_dt::STEM_SUFFIX)
                .then(|| read::<CoupledDtSummary>(dir, &name))
                .flatten()
            {
                Some(v) => Study::CoupledDt(Box::new(v)),
                None => Study::Converge(Box::new(read(dir, &name)?)),
            },
            _ => return None,
        };
        let run_id = match &study {
            Study::Stability(v) => &v.run_id,
            Study::WorkPrecision(v) => &v.run_id,
            Study::Fig2Schemes(v) => &v.run_id,
            Study::Converge(v) => &v.run_id,
            Study::CoupledDt(v) => &v.run_id,
        };
        (*run_id == journal.run_id).then_some(study)
    }

    /// The order of the sections: the stability map, work–precision, then the
    /// convergence studies.
    fn rank(&self) -> u8 {
        match self {
            Study::Stability(_) => 0,
            Study::WorkPrecision(_) | Study::Fig2Schemes(_) => 1,
            Study::Converge(_) | Study::CoupledDt(_) => 2,
        }
    }
}

/// The studies of `dir`, from their journals (sorted by journal name): the listed ones
/// (complete, with a summary of the same run) as (journal, summary), and the others as
/// (journal, run id).
type Journals = (Vec<(String, Study)>, Vec<(String, String)>);

/// Reads every study journal in `dir` (see [`Journals`]).
fn journals(dir: &Path) -> Result<Journals> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map_err(|e| Error::io(dir, e))?
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| stem_of_journal(n).is_some())
        .collect();
    names.sort();
    let mut listed = Vec::new();
    let mut other = Vec::new();
    for name in names {
        let Some(journal) = read_manifest(&dir.join(&name)) else {
            continue;
        };
        if !STUDY_COMMANDS.contains(&journal.command.as_str()) {
            continue;
        }
        let stem = stem_of_journal(&name).unwrap_or_default();
        match Study::read(dir, stem, &journal).filter(|_| journal.complete) {
            Some(study) => listed.push((name, study)),
            None => other.push((name, journal.run_id)),
        }
    }
    listed.sort_by_key(|(_, s)| s.rank());
    Ok((listed, other))
}

/// Rebuilds `index.html` in `dir` from the complete study journals there and their
/// summaries (see the [module docs](self)), and links the extreme-scene report
/// `extreme/index.html` if present.
///
/// # Errors
/// I/O failures naming the path.
pub fn write_convergence_index(dir: &Path) -> Result<()> {
    let (listed, other) = journals(dir)?;
    let mut h = String::new();
    let _ = writeln!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>langevin-fem convergence</title><style>{CSS}td.warn{{background:#fff8c5;color:#7d4e00;font-weight:bold;text-align:center}}p.fail,span.fail{{color:#a40e26;font-weight:bold}}p.warn{{color:#7d4e00}}</style></head><body>\n<h1>langevin-fem: convergence, work–precision, stability</h1>\n<p class=\"meta\">Every study below is listed from its complete journal (<code>&lt;study&gt;.manifest.json</code>: its run id and every file it wrote).</p>"
    );
    for (journal, run_id) in &other {
        let _ = writeln!(
            h,
            "<p class=\"warn\">Not listed: the study of <a href=\"{}\">{}</a> (run <code class=\"incomplete-run-id\">{}</code>) did not finish writing (interrupted, or still running); its next run replaces or removes its files.</p>",
            url_path(journal),
            esc(journal),
            esc(run_id)
        );
    }
    if dir.join("extreme").join("index.html").exists() {
        h.push_str("<h2>Extreme scenes</h2>\n<p>Very stiff, floppy (small-slope warning), 1000-element and huge-EA scenes: <a href=\"extreme/index.html\">extreme/index.html</a>.</p>\n");
    }
    let mut converge_heading = false;
    for (journal, study) in &listed {
        match study {
            Study::Stability(v) => stability_section(&mut h, dir, journal, v),
            Study::WorkPrecision(v) => work_precision_section(&mut h, dir, journal, v),
            Study::Fig2Schemes(v) => fig2_schemes_section(&mut h, dir, journal, v),
            Study::CoupledDt(v) => coupled_dt_section(&mut h, dir, journal, v),
            Study::Converge(v) => {
                if !converge_heading {
                    h.push_str("<h2>Convergence over element count and time step</h2>\n");
                    converge_heading = true;
                }
                convergence_section(&mut h, dir, journal, v);
            }
        }
    }
    h.push_str("</body></html>\n");
    write_atomic(&dir.join(INDEX), h.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    /// The schemes of Fig. 2 are listed from their journal beside a linear work–precision
    /// study of the same command (not named as unfinished), with both tables and the four
    /// figures.
    #[test]
    fn the_fig2_schemes_study_is_listed_with_its_tables_and_figures() {
        let dir = std::env::temp_dir().join(format!("lfem-conv-fig2-{}", std::process::id()));
        let opts = crate::studies::fig2_schemes::test_options(
            crate::studies::fig2_schemes::DEFAULT_METHODS.to_vec(),
            &dir,
        );
        crate::studies::fig2_schemes::run_fig2_schemes(&opts).unwrap();
        write_convergence_index(&dir).unwrap();
        let html = std::fs::read_to_string(dir.join(INDEX)).unwrap();
        assert!(
            html.contains("Work–precision of Fig. 2 (fig2-paper-2d, 2D)"),
            "{html}"
        );
        assert!(!html.contains("Not listed"), "{html}");
        assert!(
            html.contains("metropolis-crank-nicolson/consistent: "),
            "{html}"
        );
        for f in [
            "work-precision-fig2.svg",
            "fig2-bias.svg",
            "fig2-tau-int-force.svg",
            "fig2-tau-int-buckled-mode.svg",
        ] {
            assert!(html.contains(f), "{f}");
        }
        std::fs::remove_dir_all(&dir).ok();
    }

    /// Non-finite numbers, written as `null`, read back as NaN (or `None`) and render as
    /// "–"; the summary serializes back to the same JSON.
    #[test]
    fn null_numbers_read_back_and_render() {
        let text = json!({
            "run_id": "r", "scene": "s", "seed": 7, "elements": 10, "observable": "w2(L/2)", "continuum": null,
            "tolerance": 0.01, "trajectories": 2, "duration_tau1": 50.0,
            "em_duration_tau1": 4.0, "threads": 1, "sampling_floor": null, "points": [],
            "methods": [{
                "integrator": "exact-modal", "noise": "consistent", "min_rel_bias": null,
                "seconds_to_tolerance": null, "best_dt_tau1": null, "relative_cost": null,
                "note": "n"
            }],
            "inconsistent_points": 0, "files": ["a.svg", "a.csv"], "wall_seconds": 1.5
        });
        let v: WorkPrecisionSummary = serde_json::from_value(text.clone()).unwrap();
        assert!(v.continuum.is_nan() && v.methods[0].min_rel_bias.is_nan());
        assert_eq!(serde_json::to_value(&v).unwrap(), text);
        let mut h = String::new();
        work_precision_section(&mut h, Path::new("."), "work-precision.manifest.json", &v);
        assert!(h.contains("sampling floor (median relative s.e.) –."));
        assert!(h.contains("<td class=\"num\">–</td><td class=\"detail\">n</td>"));
        let f: OrderFit = serde_json::from_value(
            json!({"order": 2.0, "std_error": null, "ci": [null, 2.5], "prefactor": 1.0, "points": 3}),
        )
        .unwrap();
        assert_eq!(fit(Some(&f)), "2.00 [NaN, 2.50] (3 pts)");
    }
}
