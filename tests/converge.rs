//! Tests of the convergence studies (`langevin-fem converge`, `src/verify/converge.rs`):
//! the order fit on synthetic data, the exact discretization-error orders of the finite
//! elements from the references alone (no simulation), and the command line's bad-input
//! exits. The whole file runs in a few seconds.

use langevin_fem::verify::Scene;
use langevin_fem::verify::converge::{Over, exact_study, fit_order, sampling_floor};
use std::path::Path;
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_langevin-fem");

/// Exact power-law data error = C·h^p (C = 0.7, p = 2.5): the weighted fit returns p and
/// C to round-off, whatever the (positive) standard errors, and its confidence interval
/// collapses onto p.
#[test]
fn fit_recovers_exact_power_law() {
    let h = [0.2, 0.1, 0.05, 0.025, 0.0125];
    let err: Vec<f64> = h.iter().map(|x: &f64| 0.7 * x.powf(2.5)).collect();
    let se: Vec<f64> = err.iter().map(|e| 0.1 * e).collect();
    for f in [
        fit_order(&h, &err, None).unwrap(),
        fit_order(&h, &err, Some(&se)).unwrap(),
    ] {
        assert!((f.order - 2.5).abs() < 1e-10, "order {}", f.order);
        assert!(
            (f.prefactor - 0.7).abs() < 1e-9,
            "prefactor {}",
            f.prefactor
        );
        let (lo, hi) = f.ci.unwrap();
        assert!(lo <= f.order && f.order <= hi && hi - lo < 1e-8);
        assert_eq!(f.points, 5);
    }
    // Two points: an order but no interval; one point: no fit.
    let two = fit_order(&h[..2], &err[..2], None).unwrap();
    assert!((two.order - 2.5).abs() < 1e-10 && two.ci.is_none());
    assert!(fit_order(&h[..1], &err[..1], None).is_none());
}

/// Noisy data with a sampling floor: true error 0.5·h² measured with 5 % relative noise
/// (fixed pseudo-random deviates) down to h = 0.025; below that the true error is under
/// the standard error (1e-4) and the measured error is sampling noise. The floor points
/// (h ≤ 0.025) are flagged (≤ 3 s.e.) and, left out, the weighted fit gives 2 within its
/// 95 % interval (and within 0.2), from the 4 resolved points.
#[test]
fn fit_flags_and_excludes_the_sampling_floor() {
    let h = [0.4, 0.2, 0.1, 0.05, 0.025, 0.0125, 0.00625];
    let z = [0.8, -1.1, 0.3, 1.4, -0.6, 0.9, -0.4];
    let floor_se = 1e-4;
    let mut err = Vec::new();
    let mut se = Vec::new();
    for (x, zi) in h.iter().zip(z) {
        let truth: f64 = 0.5 * x * x;
        let s = (0.05 * truth).max(floor_se);
        se.push(s);
        err.push((truth + zi * s).abs());
    }
    let floor = sampling_floor(&err, &se);
    assert_eq!(floor, [false, false, false, false, true, true, true]);
    let (hr, er, sr): (Vec<f64>, Vec<f64>, Vec<f64>) = (0..h.len())
        .filter(|&i| !floor[i])
        .map(|i| (h[i], err[i], se[i]))
        .fold((vec![], vec![], vec![]), |mut a, (x, e, s)| {
            a.0.push(x);
            a.1.push(e);
            a.2.push(s);
            a
        });
    let f = fit_order(&hr, &er, Some(&sr)).unwrap();
    let (lo, hi) = f.ci.unwrap();
    assert!(lo < 2.0 && 2.0 < hi, "CI [{lo}, {hi}]");
    assert!((f.order - 2.0).abs() < 0.2, "order {}", f.order);
    assert_eq!(f.points, 4);
}

fn scene(name: &str) -> Scene {
    Scene::load(Path::new(&format!("verification/{name}.toml"))).unwrap()
}

fn run_index(s: &Scene, name: &str) -> usize {
    s.runs.iter().position(|r| r.name == name).unwrap()
}

/// Exact discretization error of the mode-1 variance, references only (5, 10, 20, 40
/// elements, no simulation): consistent noise under exact-modal (and Crank–Nicolson)
/// converges as h⁴ (Hermite-cubic eigenvalues); the paper's element-uniform noise under
/// Crank–Nicolson has the h² deficit (i π h/L)²/12. Tolerance 0.1 on the order.
#[test]
fn exact_error_orders_of_mode_variance() {
    let s = scene("hinged-linear-2d");
    let values = [5.0, 10.0, 20.0, 40.0];
    let order = |run: &str, obs: usize| {
        let pts = exact_study(&s, run_index(&s, run), Over::Elements, &values).unwrap();
        let h: Vec<f64> = pts.iter().map(|p| p.h).collect();
        let e: Vec<f64> = pts
            .iter()
            .map(|p| (p.discrete[obs] - p.limit[obs]).abs())
            .collect();
        fit_order(&h, &e, None).unwrap().order
    };
    for run in ["exact-modal", "crank-nicolson"] {
        let p = order(run, 1);
        assert!((p - 4.0).abs() < 0.1, "{run}: mode-1 order {p}");
    }
    let p = order("element-uniform", 1);
    assert!((p - 2.0).abs() < 0.1, "element-uniform: mode-1 order {p}");
    // The element-uniform deficit of mode 1 is about (pi h/L)^2/12 of the variance.
    let pts = exact_study(
        &s,
        run_index(&s, "element-uniform"),
        Over::Elements,
        &[40.0],
    )
    .unwrap();
    let rel = 1.0 - pts[0].discrete[1] / pts[0].limit[1];
    let predicted = (std::f64::consts::PI / 40.0).powi(2) / 12.0;
    assert!(
        (rel / predicted - 1.0).abs() < 0.05,
        "deficit {rel} vs {predicted}"
    );
}

/// Time-step error from the references only (10 elements): backward Euler's mode-1
/// variance error against the Δt → 0 limit is first order; Crank–Nicolson's is zero to
/// round-off.
#[test]
fn exact_error_orders_over_dt() {
    let s = scene("hinged-linear-2d");
    let values = [4e-3, 2e-3, 1e-3, 5e-4];
    let be = exact_study(&s, run_index(&s, "backward-euler"), Over::Dt, &values).unwrap();
    let h: Vec<f64> = be.iter().map(|p| p.h).collect();
    let e: Vec<f64> = be
        .iter()
        .map(|p| (p.discrete[1] - p.limit[1]).abs())
        .collect();
    let p = fit_order(&h, &e, None).unwrap().order;
    assert!((p - 1.0).abs() < 0.05, "backward-euler order {p}");
    let cn = exact_study(&s, run_index(&s, "crank-nicolson"), Over::Dt, &values).unwrap();
    for pt in &cn {
        for k in 0..4 {
            assert!((pt.discrete[k] - pt.limit[k]).abs() <= 1e-10 * pt.limit[k].abs());
        }
    }
}

fn run_cli(args: &[&str]) -> (i32, String) {
    let out = Command::new(BIN).args(args).output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Bad input exits 2 with a message naming the flag and the allowed values: an unknown
/// `--over`, a compression scene, an euler-maruyama Δt above its stability limit (the
/// message gives the limit), and a non-integer element count.
#[test]
fn cli_rejects_bad_input_with_exit_2() {
    let out = std::env::temp_dir().join("langevin-fem-converge-test");
    let out = out.to_str().unwrap();
    let (code, err) = run_cli(&[
        "converge",
        "--scene",
        "hinged-linear-2d",
        "--over",
        "modes",
        "--out",
        out,
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("--over") && err.contains("elements") && err.contains("dt"),
        "{err}"
    );

    let (code, err) = run_cli(&[
        "converge",
        "--scene",
        "compression-2d",
        "--over",
        "dt",
        "--out",
        out,
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("--scene") && err.contains("not supported"),
        "{err}"
    );

    let (code, err) = run_cli(&[
        "converge",
        "--scene",
        "hinged-linear-2d",
        "--run",
        "paper",
        "--over",
        "dt",
        "--values",
        "1e-5,5e-6",
        "--out",
        out,
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("--values") && err.contains("7.7309e-6"),
        "{err}"
    );

    let (code, err) = run_cli(&[
        "converge",
        "--scene",
        "hinged-linear-2d",
        "--run",
        "crank-nicolson",
        "--over",
        "elements",
        "--values",
        "5,7.5",
        "--out",
        out,
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("--values") && err.contains("[2, 200]"),
        "{err}"
    );
}
