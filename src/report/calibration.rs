//! The HTML index of a calibration run (`index.html` beside `calibration.json`): the
//! verdict, the seeds, per scene its false-alarm rate with its exact interval and the
//! seeds that failed, per check kind the uniformity of its p-values, and the p-value
//! histograms. Static and self-contained as the verification index ([`super::html`]).
//!
//! [`write_calibration_report`] finishes the calibration's [`ReportRun`]:
//! `calibration.json` and `index.html` are written last, after `p-values.csv` and the
//! figures (see [`crate::output::manifest`]).

use std::fmt::Write as _;

use super::html::{CSS, esc, fmt_seconds, fmt4, provenance_box, url_path};
use crate::error::Result;
use crate::output::ReportRun;
use crate::output::io::json_text;
use crate::verify::calibrate::{
    CalibrationSummary, ENTRY_POINTS, KindUniformity, P_VALUES_CSV, SceneCalibration,
    UNIFORMITY_LEVEL,
};

/// Renders the calibration index page for `summary`.
pub fn render_calibration_index(summary: &CalibrationSummary) -> String {
    let mut h = String::with_capacity(16 * 1024);
    let verdict = if summary.passed { "PASS" } else { "FAIL" };
    h.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
    h.push_str("<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n");
    let _ = writeln!(
        h,
        "<title>langevin-fem calibration: {verdict} ({})</title>\n<style>\n{CSS}</style>\n</head>\n<body>",
        esc(&summary.budget)
    );
    h.push_str("<h1>langevin-fem calibration of the verifier</h1>\n");
    let _ = writeln!(
        h,
        "<p class=\"verdict\">Overall result: <span class=\"badge {}\">{verdict}</span></p>",
        verdict.to_ascii_lowercase()
    );
    let seeds = &summary.seeds;
    let _ = writeln!(
        h,
        "<p>Each scene verified at {} seeds ({} … {}), budget <b>{}</b>, family-wise \
         α = {} per scene (Holm). Seeds: {}.</p>",
        seeds.count,
        seeds.seeds.first().copied().unwrap_or(seeds.first),
        seeds.seeds.last().copied().unwrap_or(seeds.first),
        esc(&summary.budget),
        summary.alpha,
        esc(&seeds.rule)
    );
    let _ = writeln!(
        h,
        "<p class=\"meta\">Run <code id=\"run-id\">{}</code>. Every check at every seed: \
         <a href=\"{1}\">{1}</a>; the result: <a href=\"calibration.json\">calibration.json</a>.</p>",
        esc(&summary.run_id),
        P_VALUES_CSV
    );
    if let Some(p) = &summary.provenance {
        provenance_box(&mut h, p);
    }
    let _ = writeln!(
        h,
        "<h2>False alarms per scene</h2>\n<p>Rule: {}.</p>",
        esc(&summary.false_alarm_rule)
    );
    scenes_table(&mut h, &summary.scenes);
    let _ = writeln!(
        h,
        "<h2>Uniformity of the p-values per check kind</h2>\n<p>Rule: {}.</p>",
        esc(&summary.uniformity_rule)
    );
    kinds_table(&mut h, &summary.kinds);
    for k in summary.kinds.iter().filter(|k| k.rejected) {
        let names: Vec<String> = k
            .per_check
            .iter()
            .filter(|c| c.rejected)
            .map(|c| {
                format!(
                    "{}: {} (adjusted KS p = {})",
                    c.scene,
                    c.name,
                    fmt4(c.ks_p_adjusted)
                )
            })
            .collect();
        let _ = writeln!(
            h,
            "<p><b>{}</b>: non-uniform p-values in {}.</p>",
            esc(&k.kind),
            esc(&names.join("; "))
        );
    }
    h.push_str("<h2>p-value histograms</h2>\n<div class=\"figures\">\n");
    for s in &summary.scenes {
        let href = esc(&url_path(&s.figure));
        let _ = writeln!(
            h,
            "<figure><a href=\"{href}\"><img src=\"{href}\" alt=\"{0}\"></a>\
             <figcaption>{0} <code>{1}</code></figcaption></figure>",
            esc(crate::verify::calibrate::P_VALUE_CAPTION),
            esc(&s.figure)
        );
    }
    h.push_str("</div>\n</body>\n</html>\n");
    h
}

fn scenes_table(h: &mut String, scenes: &[SceneCalibration]) {
    h.push_str(
        "<table>\n<thead><tr><th>Scene</th><th>Verdict</th><th>Seeds</th><th>Failed</th>\
         <th>of which run failures</th><th>Rate</th><th>95 % interval</th>\
         <th>Binomial p (rate ≤ α)</th><th>Checks per seed</th><th>Wall time</th>\
         <th>Failed seeds</th></tr></thead>\n<tbody>\n",
    );
    for s in scenes {
        let f = &s.false_alarms;
        let (class, verdict) = if f.consistent {
            ("pass", "consistent")
        } else {
            ("fail", "ABOVE α")
        };
        let failed: Vec<String> = s
            .failed_seeds
            .iter()
            .map(|x| match &x.run_failure {
                Some(msg) => format!("{}: run failed: {msg}", x.seed),
                None => format!("{}: {}", x.seed, x.failed_checks.join(", ")),
            })
            .collect();
        let per_seed: Vec<String> = s.checks_per_seed.iter().map(|n| n.to_string()).collect();
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td class=\"{class}\">{verdict}</td><td class=\"num\">{}</td>\
             <td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>\
             <td class=\"num\">[{}, {}]</td><td class=\"num\">{}</td><td class=\"num\">{}</td>\
             <td class=\"num\">{}</td><td class=\"detail\">{}</td></tr>",
            esc(&s.name),
            f.seeds,
            f.failed,
            f.run_failures,
            fmt4(Some(f.rate)),
            fmt4(Some(f.interval[0])),
            fmt4(Some(f.interval[1])),
            fmt4(Some(f.binomial_p)),
            per_seed.join(", "),
            fmt_seconds(s.wall_seconds),
            esc(&failed.join("; "))
        );
    }
    h.push_str("</tbody>\n</table>\n");
}

fn kinds_table(h: &mut String, kinds: &[KindUniformity]) {
    let _ = writeln!(
        h,
        "<table>\n<thead><tr><th>Kind</th><th>Verdict (adjusted KS p &lt; {UNIFORMITY_LEVEL})</th>\
         <th>Checks</th><th>Tested</th><th>p-values</th><th>Smallest adjusted KS p</th>\
         <th>Fraction p &lt; 0.05 (± s.e.)</th><th>Fraction p &lt; 0.01 (± s.e.)</th></tr></thead>\n<tbody>"
    );
    for k in kinds {
        let (class, verdict) = match (k.tested, k.rejected) {
            (0, _) => ("", "not tested"),
            (_, true) => ("fail", "REJECTED"),
            (_, false) => ("pass", "uniform"),
        };
        let tail = |i: usize| {
            k.tails.get(i).map_or("—".to_string(), |t| {
                format!("{} ± {}", fmt4(Some(t.fraction)), fmt4(Some(t.std_error)))
            })
        };
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td class=\"{class}\">{verdict}</td><td class=\"num\">{}</td>\
             <td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>\
             <td class=\"num\">{}</td><td class=\"num\">{}</td></tr>",
            esc(&k.kind),
            k.checks,
            k.tested,
            k.p_values,
            fmt4(k.smallest_adjusted_p),
            tail(0),
            tail(1)
        );
    }
    h.push_str("</tbody>\n</table>\n");
}

/// Finishes the calibration's report run `run`: removes the files of earlier runs it did
/// not rewrite, completes its journal, then writes `calibration.json` and `index.html`,
/// in that order, atomically.
///
/// # Errors
/// [`crate::Error::Io`] naming a file that cannot be removed or written.
pub fn write_calibration_report(run: ReportRun, summary: &CalibrationSummary) -> Result<()> {
    let [json_name, index_name] = ENTRY_POINTS;
    let json = json_text(&run.dir().join(json_name), summary)?;
    let html = render_calibration_index(summary);
    run.finish(&[(json_name, json.as_bytes()), (index_name, html.as_bytes())])
}
