//! Tests of the membrane under imposed projected area (`langevin_fem::fem::plate_area`):
//! the exact per-block compliances of the Bogner–Fox–Schmit mesh against the dense
//! generalized eigenproblem, their convergence to the continuum, the total stored area,
//! the exact tension against its limits and the mean field, quadrature self-convergence,
//! the work bound of the CLI range, and `theory area` itself.
//!
//! Deterministic (no sampling).

use langevin_fem::fem::plate_area::{
    AREA_BENDING_RANGE, AreaCutoff, AreaParams, AreaTheory, MAX_AREA_ELEMENTS,
    continuum_compliances, dense_compliances, discrete_compliances, max_area_strain_ratio,
};
use langevin_fem::spectral::membrane::MembraneBoundary;
use langevin_fem::theory::{MIN_STRAIN_RATIO, QuadratureOptions, STRETCH_BEND_RATIO_RANGE};
use std::process::Command;

const BOUNDARIES: [MembraneBoundary; 2] = [
    MembraneBoundary::SimplySupported,
    MembraneBoundary::Periodic,
];

/// Non-unit, non-square parameters, so that a wrong power of a side cannot cancel.
fn params(boundary: MembraneBoundary) -> AreaParams {
    AreaParams {
        bending_rigidity: 7.0,
        area_modulus: 3e5,
        kt: 1.3,
        width: 1.3,
        height: 0.9,
        boundary,
    }
}

/// What: the block form's compliances (every μ of the pencil `G y = μ K_b y`, one block of
/// ≤ 4×4 per pair of waves) against the dense generalized eigenproblem of the assembled
/// `K_b` and `G` of `PlateModel` (independent: the banded Kronecker assembly, one dense
/// Cholesky and eigensolver); counts (`4·nx·ny`, less the periodic zero mode).
/// Set-up: both boundaries, meshes 2×2, 3×2, 4×3, 4×4 (≤ 64 DOFs).
/// Tolerance: 10⁻¹⁰ relative per eigenvalue (observed ≤ 6·10⁻¹⁵).
#[test]
fn block_compliances_match_dense_eigenproblem() {
    for boundary in BOUNDARIES {
        let p = params(boundary);
        for (nx, ny) in [(2, 2), (3, 2), (4, 3), (4, 4)] {
            let blocks = discrete_compliances(&p, nx, ny).unwrap();
            let dense = dense_compliances(&p, nx, ny).unwrap();
            let n = 4 * nx * ny - usize::from(boundary == MembraneBoundary::Periodic);
            assert_eq!(blocks.len(), n, "{boundary:?} {nx}x{ny}");
            assert_eq!(dense.len(), n, "{boundary:?} {nx}x{ny}");
            for (b, d) in blocks.iter().zip(&dense) {
                assert!(
                    (b.mu / d - 1.0).abs() <= 1e-10,
                    "{boundary:?} {nx}x{ny}: {} vs {d}",
                    b.mu
                );
            }
        }
    }
}

/// What: per acoustic mode, the discrete weight converges to the continuum's at O(h⁴)
/// from below, and the acoustic modes are exactly the continuum's at the mesh's cutoff.
/// Reference: `μ = 1/(κq²)` (continuum, `continuum_compliances` at the lattice cutoff of
/// the mesh).
/// Set-up: both boundaries, N × N meshes N = 8, 16, 32, 64; modes (1, 1), (2, 1), (1, 2)
/// simply supported, (1, 0), (0, 1), (1, 1) periodic.
/// Tolerance: observed order log₂(e_N/e_2N) within 0.15 of 4 for N ≥ 16 (the relative
/// error e_N = 1 − μ_h/μ is ≥ 4·10⁻¹⁰ there, far above rounding); e_N > 0; the labels
/// (m, n) of the acoustic modes are the continuum's, count for count.
#[test]
fn acoustic_weights_converge_at_fourth_order() {
    for boundary in BOUNDARIES {
        let p = params(boundary);
        let modes: &[(usize, usize)] = match boundary {
            MembraneBoundary::SimplySupported => &[(1, 1), (2, 1), (1, 2)],
            MembraneBoundary::Periodic => &[(1, 0), (0, 1), (1, 1)],
        };
        let mut prev: Vec<Option<f64>> = vec![None; modes.len()];
        for n in [8usize, 16, 32, 64] {
            let disc = discrete_compliances(&p, n, n).unwrap();
            let cont = continuum_compliances(&p, AreaCutoff::Lattice { nx: n, ny: n }).unwrap();
            let mut labels_d: Vec<(usize, usize)> = disc
                .iter()
                .filter(|c| c.acoustic)
                .map(|c| (c.m, c.n))
                .collect();
            let mut labels_c: Vec<(usize, usize)> = cont.iter().map(|c| (c.m, c.n)).collect();
            labels_d.sort();
            labels_c.sort();
            assert_eq!(labels_d, labels_c, "{boundary:?} N = {n}");
            for (i, &(m, k)) in modes.iter().enumerate() {
                let mu_h = disc
                    .iter()
                    .find(|c| c.acoustic && (c.m, c.n) == (m, k))
                    .unwrap()
                    .mu;
                let mu = cont.iter().find(|c| (c.m, c.n) == (m, k)).unwrap().mu;
                let e = 1.0 - mu_h / mu;
                assert!(e > 0.0, "{boundary:?} N = {n} ({m}, {k}): {e:e}");
                if let Some(pe) = prev[i] {
                    let order = (pe / e).log2();
                    println!("{boundary:?} ({m}, {k}) N = {n}: error {e:.3e}, order {order:.3}");
                    if n >= 32 {
                        assert!(
                            (order - 4.0).abs() < 0.15,
                            "{boundary:?} ({m}, {k}) N = {n}: order {order}"
                        );
                    }
                }
                prev[i] = Some(e);
            }
        }
    }
}

/// What: the total ⟨ΔA⟩₀/A₀ of the mesh against the continuum at the mesh's cutoff. Both
/// grow as ln N (Helfrich–Servuss); the mesh exceeds the continuum by a bounded amount:
/// its acoustic weights lie slightly below the continuum's, and its `3N²` optical modes
/// (μ = O(h²/κ) each) add `O(A₀/κ)` in μ, i.e. `O(kT/κ)` in ⟨ΔA⟩₀/A₀, independent of N.
/// Reference: `continuum_compliances` at `AreaCutoff::Lattice { nx: N, ny: N }`.
/// Set-up: both boundaries, N × N meshes, N = 8 … 128.
/// Tolerance (the stated bound): `0 < (⟨s⟩_h − ⟨s⟩_c)·κ/kT ≤ 0.15` for every N (observed
/// 0.046 → 0.042 simply supported); the difference converges (successive changes shrink
/// by at least 1.5×, first order in h), while the continuum's own κ⟨s⟩/kT grows by more
/// than 0.05 per doubling of N (`Σ 1/(2A₀q²) ≈ ln Q/(4π)`: ln 2/(4π) ≈ 0.055 per
/// doubling; the difference is not the bulk).
#[test]
fn total_stored_area_of_mesh_vs_continuum_at_cutoff() {
    for boundary in BOUNDARIES {
        let p = params(boundary);
        let scale = p.bending_rigidity / p.kt;
        let mut diffs = Vec::new();
        let mut conts = Vec::new();
        for n in [8usize, 16, 32, 64, 128] {
            let disc = AreaTheory::discrete(&p, n, n).unwrap();
            let cont = AreaTheory::continuum(&p, AreaCutoff::Lattice { nx: n, ny: n }).unwrap();
            let (sd, sc) = (disc.free_excess_area_ratio(), cont.free_excess_area_ratio());
            let diff = (sd - sc) * scale;
            println!("{boundary:?} N = {n}: <s>_h {sd:.6e}, <s>_c {sc:.6e}, diff·κ/kT {diff:.5}");
            assert!(diff > 0.0 && diff <= 0.15, "{boundary:?} N = {n}: {diff}");
            diffs.push(diff);
            conts.push(sc * scale);
        }
        for w in diffs.windows(3) {
            assert!(
                (w[1] - w[2]).abs() * 1.5 <= (w[0] - w[1]).abs(),
                "{boundary:?}: {diffs:?}"
            );
        }
        for w in conts.windows(2) {
            assert!(w[1] - w[0] > 0.05, "{boundary:?}: {conts:?}");
        }
    }
}

/// What: the exact tension against its limits and the Gaussian mean field.
/// Reference: (i) `ε = 0`: `⟨σ⟩ = K_A(⟨s⟩_0 − 0) − (fluctuation shift) > 0` and the mean
/// field `σ_mf` solves `ψ'(−σ_mf A₀/kT) = ε + σ_mf/K_A` (tension from the thermal excess
/// area); (ii) large tension `ε ≪ 0`: `⟨σ⟩ → −K_Aε + K_A⟨s⟩_ε` with `0 ≤ ⟨s⟩_ε ≤ ⟨s⟩₀`,
/// and the exact → mean field; (iii) far beyond buckling `⟨σ⟩ → −σ_c`, `σ_c = 1/μ_max`
/// (the softest mode's buckling tension: σ_c0 for the continuum, above it for the mesh).
/// If the softest weight has multiplicity g (its modes sum to a χ²_g), then as for the
/// filament `−⟨σ⟩ − σ_c ≈ (1 − g/2)(kT/A₀)/(ε − r̄)`: beyond the buckling tension for the
/// simply supported square (g = 1, the 2D filament's behaviour), short of it for the
/// periodic square (g = 4: cos and sin of (1, 0) and (0, 1)); the mean field stays short of
/// it (it never passes the buckling tension).
/// Set-up: default κ = 20 kT, S = 10⁶, both boundaries, mesh 16 × 16 and continuum at its
/// cutoff; ε/ε_c0 = −10⁴, 0, 10³.
/// Tolerance: (ii) `|⟨σ⟩ − σ_mf| ≤ 10⁻⁶σ_c0` and the bracket; (iii) `|−⟨σ⟩/σ_c − 1| ≤ 0.01`
/// with the sign of `1 − g/2` (g counted to 10⁻¹² relative), `0 < 1 + σ_mf/σ_c ≤ 0.01`.
#[test]
fn tension_limits_and_mean_field() {
    for boundary in BOUNDARIES {
        let p = AreaParams {
            boundary,
            ..AreaParams::default()
        };
        let sc0 = p.reference_tension();
        let ec0 = p.reference_strain();
        for th in [
            AreaTheory::discrete(&p, 16, 16).unwrap(),
            AreaTheory::continuum(&p, AreaCutoff::Lattice { nx: 16, ny: 16 }).unwrap(),
        ] {
            let s0 = th.free_excess_area_ratio();
            // (i)
            let t0 = th.mean_tension(0.0).unwrap();
            assert!(
                t0 > 0.0 && t0 <= p.area_modulus * s0,
                "{t0} vs {}",
                p.area_modulus * s0
            );
            // (ii)
            let eps = -1e4 * ec0;
            let t = th.mean_tension(eps).unwrap();
            let t_mf = th.mean_field_tension(eps).unwrap();
            assert!((t - t_mf).abs() <= 1e-6 * sc0, "{t} vs {t_mf}");
            let hooke = -p.area_modulus * eps;
            assert!(
                t >= hooke && t <= hooke + p.area_modulus * s0,
                "{t} vs {hooke}"
            );
            // (iii)
            let sigma_c = p.kt / (2.0 * p.area() * th.theory().law().weights[0]);
            assert!(sigma_c >= sc0 * (1.0 - 1e-12));
            let eps = 1e3 * ec0;
            let t = th.mean_tension(eps).unwrap();
            let t_mf = th.mean_field_tension(eps).unwrap();
            let w = &th.theory().law().weights;
            let g = w.iter().filter(|&&c| c >= w[0] * (1.0 - 1e-12)).count() as f64;
            let beyond = -t / sigma_c - 1.0;
            assert!(
                beyond.abs() <= 0.01 && beyond * (1.0 - g / 2.0) > 0.0,
                "{boundary:?} g = {g}: {t} vs {sigma_c}"
            );
            assert!(
                1.0 + t_mf / sigma_c > 0.0 && 1.0 + t_mf / sigma_c <= 0.01,
                "{t_mf} vs {sigma_c}"
            );
        }
    }
}

/// What: quadrature self-convergence of a membrane law: halving the trapezoid step.
/// Reference: the default quadrature (the trapezoid rule on an analytic integrand
/// converges exponentially, so any change is rounding).
/// Set-up: both boundaries, mesh 8 × 8 and the continuum at cutoff 32; ε/ε_c0 = −10⁴, −10,
/// 0, 3, 100 and the largest allowed strain ratio (2500); mean and variance.
/// Tolerance: 10⁻¹⁰ relative (relative to max(|⟨σ⟩|, σ_c0) for the mean); for the variance
/// 10⁻¹⁰ relative plus the rounding floor `10⁻¹⁴K_A·kT/A₀` of its formula
/// `K_A·kT/A₀ − (kT/A₀)²(M₂ − M₁²)`, which cancels in tension (observed 1.7·10⁻¹⁰ relative
/// at ε/ε_c0 = −10⁴, where Var σ ≈ 2·10⁻⁶ K_A·kT/A₀).
#[test]
fn membrane_quadrature_is_converged() {
    for boundary in BOUNDARIES {
        let p = AreaParams {
            boundary,
            ..AreaParams::default()
        };
        let sc0 = p.reference_tension();
        let rmax = max_area_strain_ratio(&p);
        for th in [
            AreaTheory::discrete(&p, 8, 8).unwrap(),
            AreaTheory::continuum(&p, AreaCutoff::Lattice { nx: 32, ny: 32 }).unwrap(),
        ] {
            let fine = th
                .clone()
                .with_options(QuadratureOptions {
                    step_scale: 0.5,
                    ..QuadratureOptions::default()
                })
                .unwrap();
            for r in [-1e4, -10.0, 0.0, 3.0, 100.0, rmax] {
                let eps = r * p.reference_strain();
                let (a, b) = (
                    th.mean_tension(eps).unwrap(),
                    fine.mean_tension(eps).unwrap(),
                );
                assert!(
                    (a - b).abs() <= 1e-10 * a.abs().max(sc0),
                    "{boundary:?} r {r}: {a} vs {b}"
                );
                let (va, vb) = (
                    th.tension_variance(eps).unwrap(),
                    fine.tension_variance(eps).unwrap(),
                );
                assert!(
                    (va - vb).abs() <= 1e-10 * va + 1e-14 * p.area_modulus * p.kt / p.area(),
                    "{boundary:?} r {r}: variance {va} vs {vb}"
                );
            }
        }
    }
}

/// What: the documented CLI range of `theory area` keeps the work bounded: at the largest
/// and the smallest strain ratio, across κ/kT ∈ [10⁻³, 10⁶] and S/κ² ∈ [10⁻², 10¹²].
/// Reference: the work measure `CompressionTheory::quadrature_work` (≈ 10⁸ per second).
/// Set-up: simply supported and periodic squares, the largest mesh (128 × 128 is too slow
/// for a test grid: 16 × 16, whose quadrature work is the larger, since fewer modes widen
/// the tilted law) and the continuum at cutoff 16; κ/kT at both ends, S/κ² = 10⁻², 10⁵,
/// 10¹²; ε/ε_c0 = `max_area_strain_ratio` and `MIN_STRAIN_RATIO`.
/// Tolerance: work ≤ 3·10⁸ mode evaluations (≈ 3 s; observed ≤ 1.3·10⁸, at S/κ² = 10⁵:
/// few modes widen the tilted law); the evaluation succeeds.
#[test]
fn cli_range_keeps_the_work_bounded() {
    let (k_lo, k_hi) = AREA_BENDING_RANGE;
    let (l_lo, l_hi) = STRETCH_BEND_RATIO_RANGE;
    let mut worst = 0.0_f64;
    for boundary in BOUNDARIES {
        for kappa in [k_lo, k_hi] {
            for lambda in [l_lo, 1e5, l_hi] {
                let p = AreaParams {
                    bending_rigidity: kappa,
                    area_modulus: lambda * kappa * kappa,
                    kt: 1.0,
                    width: 1.0,
                    height: 1.0,
                    boundary,
                };
                for th in [
                    AreaTheory::discrete(&p, 16, 16).unwrap(),
                    AreaTheory::continuum(&p, AreaCutoff::Lattice { nx: 16, ny: 16 }).unwrap(),
                ] {
                    for r in [max_area_strain_ratio(&p), MIN_STRAIN_RATIO] {
                        let eps = r * p.reference_strain();
                        let work = th.theory().quadrature_work(eps).unwrap();
                        worst = worst.max(work);
                        assert!(
                            work <= 3e8,
                            "{boundary:?} κ {kappa:e} S/κ² {lambda:e} r {r:e}: {work:e}"
                        );
                        assert!(th.tension_ratio(r).unwrap().is_finite());
                    }
                }
            }
        }
    }
    println!("largest work {worst:.3e}");
}

fn run_cli(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_langevin-fem"))
        .arg("theory")
        .arg("area")
        .args(args)
        .output()
        .expect("binary runs")
}

/// What: `theory area` prints the documented JSON, equal to the library's numbers, accepts
/// the ends of its documented ranges and refuses values just outside with exit 2 and a
/// message naming the flag and the range.
/// Reference: the library (units kT = 1: K_A = S/A₀).
/// Set-up: default κ = 20, S = 10⁶, a unit square; a 12 × 8 mesh and a periodic continuum
/// at cutoff 10; the range ends.
/// Tolerance: ratios equal to the library's to 10⁻¹² (JSON round-trips f64); exact exit
/// codes and substrings.
#[test]
fn cli_json_ranges_and_exit_codes() {
    let out = run_cli(&["--strain-ratio", "-10,0,3", "--elements", "12,8"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let p = AreaParams::default();
    let th = AreaTheory::discrete(&p, 12, 8).unwrap();
    assert_eq!(v["elements"], serde_json::json!([12, 8]));
    assert_eq!(v["modes"], serde_json::json!(4 * 12 * 8));
    let close = |a: &serde_json::Value, b: f64| (a.as_f64().unwrap() - b).abs() <= 1e-12 * b.abs();
    assert!(close(&v["reference_tension"], p.reference_tension()));
    assert!(close(&v["reference_strain"], p.reference_strain()));
    assert!(close(
        &v["free_excess_area_ratio"],
        th.free_excess_area_ratio()
    ));
    for (pt, r) in v["points"]
        .as_array()
        .unwrap()
        .iter()
        .zip([-10.0, 0.0, 3.0])
    {
        let eps = r * p.reference_strain();
        assert!(close(&pt["tension_ratio"], th.tension_ratio(r).unwrap()));
        assert!(close(
            &pt["mean_field_tension_ratio"],
            th.mean_field_tension(eps).unwrap() / p.reference_tension()
        ));
        assert!(close(
            &pt["std_dev_ratio"],
            th.tension_variance(eps).unwrap().sqrt() / p.reference_tension()
        ));
    }
    let out = run_cli(&[
        "--strain-ratio",
        "1",
        "--cutoff",
        "10",
        "--boundary",
        "periodic",
    ]);
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    // periodic half-lattice 2|m| < 10, 2|n| < 10 without q = 0: (9·9 − 1)/2 wavevectors, ×2
    assert_eq!(v["modes"], serde_json::json!(80));
    let max = MAX_AREA_ELEMENTS.to_string();
    let ok: [&[&str]; 7] = [
        &["--strain-ratio", "-1e8,2500", "--elements", "1"],
        &["--strain-ratio", "0", "--elements", &max],
        &["--strain-ratio", "0", "--cutoff", "256,2"],
        &[
            "--strain-ratio",
            "0",
            "--elements",
            "2",
            "--bending-rigidity",
            "1e-3",
            "--stretch-ratio",
            "1e-8",
        ],
        &[
            "--strain-ratio",
            "0",
            "--elements",
            "2",
            "--bending-rigidity",
            "1e6",
            "--stretch-ratio",
            "1e24",
        ],
        &["--strain-ratio", "0", "--elements", "2", "--height", "10"],
        &["--strain-ratio", "0", "--elements", "2", "--height", "0.1"],
    ];
    for args in ok {
        let out = run_cli(args);
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let bad: [(&[&str], &str, &str); 16] = [
        (
            &["--strain-ratio", "-1.0000001e8", "--elements", "2"],
            "--strain-ratio",
            "[-1e8, 0]",
        ),
        (
            &["--strain-ratio", "2500.001", "--elements", "2"],
            "--strain-ratio",
            "[0, 2.5e3]",
        ),
        (
            &["--strain-ratio", "nan", "--elements", "2"],
            "--strain-ratio",
            "comma-separated",
        ),
        (
            &["--strain-ratio", "", "--elements", "2"],
            "--strain-ratio",
            "non-empty",
        ),
        (
            &["--strain-ratio", "0"],
            "--elements/--cutoff",
            "exactly one of",
        ),
        (
            &["--strain-ratio", "0", "--elements", "129"],
            "--elements",
            "[1, 128]",
        ),
        (
            &["--strain-ratio", "0", "--elements", "0"],
            "--elements",
            "[1, 128]",
        ),
        (
            &[
                "--strain-ratio",
                "0",
                "--elements",
                "1",
                "--boundary",
                "periodic",
            ],
            "--elements",
            "[2, 128]",
        ),
        (
            &["--strain-ratio", "0", "--cutoff", "4,4,4"],
            "--cutoff",
            "N or N,NY",
        ),
        (
            &["--strain-ratio", "0", "--cutoff", "257"],
            "--cutoff",
            "[2, 256]",
        ),
        (
            &["--strain-ratio", "0", "--cutoff", "1"],
            "--cutoff",
            "[2, 256]",
        ),
        (
            &[
                "--strain-ratio",
                "0",
                "--cutoff",
                "2",
                "--boundary",
                "periodic",
            ],
            "--cutoff",
            "[3, 256]",
        ),
        (
            &[
                "--strain-ratio",
                "0",
                "--elements",
                "2",
                "--bending-rigidity",
                "9.99e-4",
            ],
            "--bending-rigidity",
            "[1e-3, 1e6]",
        ),
        (
            &[
                "--strain-ratio",
                "0",
                "--elements",
                "2",
                "--stretch-ratio",
                "3.99",
            ],
            "--stretch-ratio",
            "[4e0, 4e14]",
        ),
        (
            &[
                "--strain-ratio",
                "0",
                "--elements",
                "2",
                "--height",
                "10.01",
            ],
            "--height",
            "b/a in [0.1, 10]",
        ),
        (
            &["--strain-ratio", "0", "--elements", "2", "--width", "-1"],
            "--width",
            "got -1",
        ),
    ];
    for (args, flag, range) in bad {
        let out = run_cli(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains(flag) && err.contains(range),
            "{args:?}: {err:?}"
        );
        assert!(out.stdout.is_empty());
    }
}

/// What: the mesh's acoustic modes within a fixed lattice cutoff are the continuum's modes
/// of that cutoff one for one (same count and labels, μ within 5 %), and the tension of
/// that fixed mode set converges to the continuum's at the element's fourth order, while
/// the whole mesh's free excess area keeps growing by about `kT ln 2/(4πκ)` per doubling
/// (the Helfrich–Servuss logarithm: physics, not error).
/// Set-up: both boundaries, meshes 4, 8, 16 (fixed cutoff: the 4-element lattice), strain
/// ratios −2, 0.5 and 3.
/// Tolerance: observed orders in [3.5, 4.5]; the excess-area increment of 8 → 16 within
/// 25 % of the continuum's `kT ln 2/(4πκ)` (the mesh's top modes carry O(1) eigenvalue
/// errors at every N, so only the asymptotic increment is the continuum's).
#[test]
fn fixed_cutoff_converges_at_fourth_order_while_the_whole_mesh_drifts() {
    use langevin_fem::fem::plate_area::{mesh_convergence, within_lattice};
    for boundary in BOUNDARIES {
        let p = params(boundary);
        let all = discrete_compliances(&p, 8, 8).unwrap();
        let mut fixed = within_lattice(&p, &all, 4, 4);
        let mut cont = continuum_compliances(&p, AreaCutoff::Lattice { nx: 4, ny: 4 }).unwrap();
        assert_eq!(fixed.len(), cont.len(), "{boundary:?}");
        let key = |c: &langevin_fem::fem::plate_area::AreaCompliance| (c.m, c.n);
        fixed.sort_by(|a, b| key(a).cmp(&key(b)).then(a.mu.total_cmp(&b.mu)));
        cont.sort_by(|a, b| key(a).cmp(&key(b)).then(a.mu.total_cmp(&b.mu)));
        for (d, c) in fixed.iter().zip(&cont) {
            assert_eq!(key(d), key(c), "{boundary:?}");
            assert!(
                (d.mu / c.mu - 1.0).abs() < 0.05,
                "{boundary:?}: {d:?} vs {c:?}"
            );
        }
        let ratios = [-2.0, 0.5, 3.0];
        let (_, rows) = mesh_convergence(&p, &[4, 8, 16], &ratios).unwrap();
        for row in &rows[1..] {
            for (j, order) in row.fixed_order.iter().enumerate() {
                let order = order.unwrap();
                eprintln!(
                    "{boundary:?} N {} ratio {}: error {:.3e} order {order:.2}",
                    row.elements, ratios[j], row.fixed_error[j]
                );
                assert!(
                    (3.5..=4.5).contains(&order),
                    "{boundary:?} N {}: {order}",
                    row.elements
                );
            }
        }
        let step = rows[2].free_excess_area_ratio - rows[1].free_excess_area_ratio;
        let continuum = p.kt * 2f64.ln() / (4.0 * std::f64::consts::PI * p.bending_rigidity);
        eprintln!("{boundary:?}: excess-area increment {step:.4e} vs {continuum:.4e}");
        assert!(
            (step / continuum - 1.0).abs() < 0.25,
            "{boundary:?}: {step} vs {continuum}"
        );
    }
}

/// What: `theory area --mesh-convergence` prints per mesh the whole mesh's curve, the
/// continuum at its cutoff, the fixed-cutoff error and order, and the note naming the
/// drift as physics; a descending, out-of-range or malformed list, or one given with
/// `--elements`, exits 2 naming the flag.
#[test]
fn cli_mesh_convergence() {
    let out = run_cli(&[
        "--boundary",
        "periodic",
        "--strain-ratio",
        "0,10",
        "--mesh-convergence",
        "4,8",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["note"].as_str().unwrap().contains("Helfrich-Servuss"));
    assert_eq!(v["fixed_cutoff"], serde_json::json!([4, 4]));
    let meshes = v["meshes"].as_array().unwrap();
    assert_eq!(meshes.len(), 2);
    assert!(meshes[0]["fixed_cutoff_order"][0].is_null());
    let order = meshes[1]["fixed_cutoff_order"][0].as_f64().unwrap();
    assert!((3.5..4.5).contains(&order), "{order}");
    for key in [
        "tension_ratio",
        "continuum_at_mesh_cutoff",
        "fixed_cutoff_error",
    ] {
        assert_eq!(meshes[1][key].as_array().unwrap().len(), 2, "{key}");
    }
    for bad in ["8,4", "4,65", "2,4", "4,x"] {
        let out = run_cli(&[
            "--boundary",
            "periodic",
            "--strain-ratio",
            "0",
            "--mesh-convergence",
            bad,
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{bad}: {err}");
        assert!(err.contains("--mesh-convergence"), "{bad}: {err}");
    }
    let out = run_cli(&[
        "--strain-ratio",
        "0",
        "--elements",
        "4",
        "--mesh-convergence",
        "4,8",
    ]);
    assert_eq!(out.status.code(), Some(2));
}

/// What: the membrane's exact-theory domain, as `theory area` bounds its flags: the
/// test membrane (κ = 7, K_A = 3·10⁵, kT = 1.3, 1.3 × 0.9) inside at strains up to its
/// bound `max_area_strain_ratio`, and κ, K_A and a strain each found outside.
/// Reference: `AREA_BENDING_RANGE`, `STRETCH_BEND_RATIO_RANGE` (S/(κ/kT)²).
/// Tolerance: exact.
#[test]
fn domain_violation_names_the_input_outside() {
    use langevin_fem::theory::DomainInput;
    let p = params(MembraneBoundary::SimplySupported);
    let max = langevin_fem::fem::plate_area::max_area_strain_ratio(&p);
    assert_eq!(p.domain_violation(&[0.0, 4.0, max]), None);
    let input = |q: AreaParams, r: &[f64]| q.domain_violation(r).map(|(i, _)| i);
    assert_eq!(
        input(p, &[0.0, max * 1.01]),
        Some(DomainInput::StrainRatio(1))
    );
    let soft = AreaParams {
        area_modulus: 1e-30,
        ..p
    };
    assert_eq!(input(soft, &[0.0]), Some(DomainInput::StretchRigidity));
    let floppy = AreaParams {
        bending_rigidity: 1e-4,
        ..p
    };
    assert_eq!(input(floppy, &[0.0]), Some(DomainInput::BendingRigidity));
}
