//! The index page of the convergence reports (`reports/convergence/index.html`): the
//! convergence studies, the work–precision study, the stability map and the extreme
//! scenes, rebuilt from the JSON summaries present in the directory each time one of
//! `converge`, `work-precision` or `stability` writes there.

use super::html::{CSS, esc, url_path};
use crate::error::{Error, Result};
use crate::output::write_atomic;
use serde_json::Value;
use std::fmt::Write as _;
use std::path::Path;

fn num(v: &Value) -> String {
    match v.as_f64() {
        Some(x) if x != 0.0 && (x.abs() < 1e-3 || x.abs() >= 1e4) => format!("{x:.3e}"),
        Some(x) => format!("{x:.4}"),
        None => "–".to_string(),
    }
}

fn fit(v: &Value) -> String {
    if v.is_null() {
        return "–".to_string();
    }
    match (v["order"].as_f64(), v["ci"].as_array()) {
        (Some(p), Some(ci)) if ci.len() == 2 => format!(
            "{p:.2} [{:.2}, {:.2}] ({} pts)",
            ci[0].as_f64().unwrap_or(f64::NAN),
            ci[1].as_f64().unwrap_or(f64::NAN),
            v["points"]
        ),
        (Some(p), _) => format!("{p:.2} (2 pts, no CI)"),
        _ => "–".to_string(),
    }
}

fn figure(h: &mut String, file: &str) {
    let _ = writeln!(
        h,
        "<figure><a href=\"{0}\"><img src=\"{0}\" alt=\"{1}\"></a><figcaption>{1}</figcaption></figure>",
        url_path(file),
        esc(file)
    );
}

fn files(h: &mut String, v: &Value) {
    let list: Vec<&str> = v["files"]
        .as_array()
        .map(|a| a.iter().filter_map(Value::as_str).collect())
        .unwrap_or_default();
    h.push_str("<div class=\"figures\">\n");
    for f in list.iter().filter(|f| f.ends_with(".svg")) {
        figure(h, f);
    }
    h.push_str("</div>\n<p class=\"meta\">Data: ");
    for f in list.iter().filter(|f| !f.ends_with(".svg")) {
        let _ = write!(h, "<a href=\"{}\">{}</a> ", url_path(f), esc(f));
    }
    h.push_str("</p>\n");
}

fn convergence_section(h: &mut String, v: &Value) {
    let _ = writeln!(
        h,
        "<h3>{} / {} ({} noise, {}) over {}</h3>\n<p class=\"meta\">h = {}; {}; errors against the {}; budget {}: {} trajectories x {} tau1 per value; {:.1} s.</p>",
        esc(v["scene"].as_str().unwrap_or("")),
        esc(v["run"].as_str().unwrap_or("")),
        esc(v["noise"].as_str().unwrap_or("")),
        esc(v["integrator"].as_str().unwrap_or("")),
        esc(v["over"].as_str().unwrap_or("")),
        esc(v["h"].as_str().unwrap_or("")),
        esc(v["fixed"].as_str().unwrap_or("")),
        esc(v["limit_reference"].as_str().unwrap_or("")),
        esc(v["budget"].as_str().unwrap_or("")),
        v["trajectories"],
        v["duration_tau1"],
        v["wall_seconds"].as_f64().unwrap_or(0.0)
    );
    h.push_str("<table><tr><th>observable</th><th>expected order</th><th>observed order (95 % CI)</th><th>agrees</th><th>exact-error order</th><th>sampling floor at</th><th>why / note</th></tr>\n");
    for o in v["observables"].as_array().into_iter().flatten() {
        let e = &o["expected"];
        let expected = match (e["order"].as_f64(), e["exact"].as_bool()) {
            (Some(p), _) => format!("{p}"),
            (None, Some(true)) => "exact (zero error)".to_string(),
            _ => "no single order".to_string(),
        };
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td class=\"num\">{}</td>{}<td class=\"num\">{}</td><td>{}</td><td class=\"detail\">{} {}</td></tr>",
            esc(o["observable"].as_str().unwrap_or("")),
            esc(&expected),
            esc(&fit(&o["observed"])),
            match o["agrees"].as_bool() {
                Some(true) => "<td class=\"pass\">yes</td>",
                Some(false) => "<td class=\"warn\">no (see note)</td>",
                None => "<td>–</td>",
            },
            esc(&fit(&o["exact"])),
            esc(&o["floor_values"].to_string()),
            esc(e["why"].as_str().unwrap_or("")),
            esc(o["note"].as_str().unwrap_or(""))
        );
    }
    h.push_str("</table>\n");
    let c = &v["discrete_consistency"];
    if !c.is_null() {
        let p = c["p_value"].as_f64().unwrap_or(f64::NAN);
        let _ = writeln!(
            h,
            "<p class=\"meta\">Simulation against the exact discrete reference of each value: largest |z| = {} ({}) over {} rows, <span class=\"{}\">Bonferroni p = {}</span> (below 0.01: the simulation disagrees with its own discretization); Σz² = {}.</p>",
            num(&c["max_abs_z"]),
            esc(c["worst"].as_str().unwrap_or("")),
            c["rows"],
            if p < 0.01 { "fail" } else { "pass" },
            num(&c["p_value"]),
            num(&c["chi2"])
        );
    }
    let list = |h: &mut String, key: &str, class: &str, label: &str| {
        for n in v[key].as_array().into_iter().flatten() {
            let text = match n {
                Value::String(t) => t.clone(),
                other => format!(
                    "{} at {} = {}: {}",
                    other["kind"].as_str().unwrap_or(""),
                    v["over"].as_str().unwrap_or(""),
                    other["value"],
                    other["error"].as_str().unwrap_or("")
                ),
            };
            let _ = writeln!(h, "<p class=\"{class}\">{label}{}</p>", esc(&text));
        }
    };
    list(h, "failed", "fail", "no rows: ");
    list(h, "warnings", "warn", "warning: ");
    list(h, "notes", "meta", "");
    files(h, v);
}

fn work_precision_section(h: &mut String, v: &Value) {
    let _ = writeln!(
        h,
        "<h2>Work–precision ({})</h2>\n<p class=\"meta\">Error in &lt;w²(L/2)&gt; against the continuum, {} elements, {} trajectories x {} tau1 per point (euler-maruyama {} tau1), {} threads; sampling floor (median relative s.e.) {}. Projected wall time to reach a relative error of {} with 95 % confidence (bias + 2 s.e.), from the measured cost and standard error (s.e. ∝ T<sup>-1/2</sup>); {} points disagree with their exact discrete value by more than 3 s.e.</p>",
        esc(v["scene"].as_str().unwrap_or("")),
        v["elements"],
        v["trajectories"],
        v["duration_tau1"],
        v["em_duration_tau1"],
        v["threads"],
        num(&v["sampling_floor"]),
        num(&v["tolerance"]),
        v["inconsistent_points"]
    );
    h.push_str("<table><tr><th>integrator</th><th>noise</th><th>projected time (s)</th><th>best dt/tau1</th><th>cost vs fastest</th><th>smallest exact bias</th><th>note</th></tr>\n");
    for m in v["methods"].as_array().into_iter().flatten() {
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"detail\">{}</td></tr>",
            esc(m["integrator"].as_str().unwrap_or("")),
            esc(m["noise"].as_str().unwrap_or("")),
            num(&m["seconds_to_tolerance"]),
            num(&m["best_dt_tau1"]),
            num(&m["relative_cost"]),
            num(&m["min_rel_bias"]),
            esc(m["note"].as_str().unwrap_or(""))
        );
    }
    h.push_str("</table>\n");
    files(h, v);
}

fn stability_section(h: &mut String, v: &Value) {
    let _ = writeln!(
        h,
        "<h2>Stability map ({})</h2>\n<p class=\"meta\">Consistent noise, {} trajectories x {} steps after {} burn-in steps per cell. <b>unstable</b>: |m| ≥ 1, refused before running and, forced, overflowing; <b>biased</b>: the stationary variance of a checked mode differs from kT/λ beyond its error (Holm over the map, α = {}); <b>stable</b>: no bias resolved. Exact per-mode formulas: {} of {} comparisons rejected; stability predictions {}.</p>",
        esc(v["scene"].as_str().unwrap_or("")),
        v["trajectories"],
        v["sampled_steps"],
        v["burn_in_steps"],
        v["alpha"],
        v["formula_rejections"],
        v["formula_tests"],
        if v["stability_as_predicted"].as_bool() == Some(true) {
            "all held"
        } else {
            "did NOT all hold"
        }
    );
    let cells: Vec<&Value> = v["cells"].as_array().into_iter().flatten().collect();
    let mut integrators: Vec<&str> = Vec::new();
    let mut steps: Vec<f64> = Vec::new();
    let mut elements: Vec<u64> = Vec::new();
    for c in &cells {
        let i = c["integrator"].as_str().unwrap_or("");
        if !integrators.contains(&i) {
            integrators.push(i);
        }
        let a = c["dt_lambda_max"].as_f64().unwrap_or(f64::NAN);
        if !steps.contains(&a) {
            steps.push(a);
        }
        let e = c["elements"].as_u64().unwrap_or(0);
        if !elements.contains(&e) {
            elements.push(e);
        }
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
                let c = cells.iter().find(|c| {
                    c["integrator"].as_str() == Some(i)
                        && c["elements"].as_u64() == Some(*e)
                        && c["dt_lambda_max"].as_f64() == Some(*a)
                });
                match c {
                    Some(c) => {
                        let s = c["status"].as_str().unwrap_or("");
                        let class = match s {
                            "stable" => "pass",
                            "unstable" => "fail",
                            _ => "warn",
                        };
                        let _ = write!(
                            h,
                            "<td class=\"{class}\" title=\"{}\">{}</td>",
                            esc(c["detail"].as_str().unwrap_or("")),
                            esc(s)
                        );
                    }
                    None => h.push_str("<td></td>"),
                }
            }
            h.push_str("</tr>\n");
        }
    }
    h.push_str("</table>\n<p class=\"meta\">Hover a cell for its detail (measured variance ratio, z, unresolved modes); all of it is in stability-cells.csv and stationary-bias.csv.</p>\n");
    files(h, v);
}

/// Rebuilds `index.html` in `dir` from the JSON summaries there (convergence studies
/// `*-elements.json` / `*-dt.json`, `work-precision.json`, `stability.json`) and links
/// the extreme-scene report `extreme/index.html` if present.
///
/// # Errors
/// I/O failures naming the path.
pub fn write_convergence_index(dir: &Path) -> Result<()> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map_err(|e| Error::io(dir, e))?
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".json"))
        .collect();
    names.sort();
    let read = |n: &str| -> Option<Value> {
        let text = std::fs::read_to_string(dir.join(n)).ok()?;
        serde_json::from_str(&text).ok()
    };
    let mut h = String::new();
    let _ = writeln!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>langevin-fem convergence</title><style>{CSS}td.warn{{background:#fff8c5;color:#7d4e00;font-weight:bold;text-align:center}}p.fail,span.fail{{color:#a40e26;font-weight:bold}}p.warn{{color:#7d4e00}}</style></head><body>\n<h1>langevin-fem: convergence, work–precision, stability</h1>"
    );
    if dir.join("extreme").join("index.html").exists() {
        h.push_str("<h2>Extreme scenes</h2>\n<p>Very stiff, floppy (small-slope warning), 1000-element and huge-EA scenes: <a href=\"extreme/index.html\">extreme/index.html</a>.</p>\n");
    }
    if let Some(v) = read("stability.json") {
        stability_section(&mut h, &v);
    }
    if let Some(v) = read("work-precision.json") {
        work_precision_section(&mut h, &v);
    }
    let studies: Vec<Value> = names
        .iter()
        .filter(|n| n.ends_with("-elements.json") || n.ends_with("-dt.json"))
        .filter_map(|n| read(n))
        .filter(|v| v.get("over").is_some())
        .collect();
    if !studies.is_empty() {
        h.push_str("<h2>Convergence over element count and time step</h2>\n");
        for v in &studies {
            convergence_section(&mut h, v);
        }
    }
    h.push_str("</body></html>\n");
    write_atomic(&dir.join("index.html"), h.as_bytes())
}
