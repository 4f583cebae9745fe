//! Golden snapshots of the numerics.
//!
//! What: for every scene in `verification/` and every run in it, the exact references
//! (per-mode discrete variance, one-step multiplier and rate, profile and two-time
//! references; for compression scenes the exact ⟨F⟩/F_c0 at every strain) and a short
//! fixed-seed trace from rest (modal amplitudes and deflections every 25 steps for 200
//! steps; for compression scenes F/F_c0 after burn-in at the first and last strain),
//! printed to 10 significant digits.
//! Why: any change of the numerics — element matrices, noise draws, integrator algebra,
//! reference formulas, random streams — shows up as a diff in `golden/`. Review with
//! `git diff golden/` after `make golden`; CI (`CI=true`) fails on any mismatch.
//! Tolerance: none beyond the printed precision; 10 significant digits are far above
//! round-off differences between correct builds of the same code on x86-64.

mod common;

use common::manifest_dir;
use common::seeds::GOLDEN_SEED;
use langevin_fem::rng::{derive_seed, trajectory_rng};
use langevin_fem::scene::Scene;
use langevin_fem::scene::compression::{CompressionRun, CompressionTheoryTable};
use langevin_fem::scene::linear::LinearRun;
use std::fmt::Write;

fn g(v: f64) -> String {
    format!("{v:.9e}")
}

/// Compression scenes: the exact theory at every strain, and per run a short trace of
/// F/F_c0 (burn-in, then 10 samples) at the first and last strain.
fn compression_snapshot(scene: &Scene, s: &mut String) {
    let comp = scene.compression.as_ref().expect("compression table");
    let theory = CompressionTheoryTable::new(scene, comp).expect("theory");
    writeln!(s, "strain_ratio  theory_discrete  theory_continuum").unwrap();
    for i in 0..theory.strain_ratios.len() {
        writeln!(
            s,
            "{}  {}  {}",
            g(theory.strain_ratios[i]),
            g(theory.discrete[i]),
            g(theory.continuum[i])
        )
        .unwrap();
    }
    for spec in &scene.runs {
        let run = CompressionRun::prepare(scene, comp, spec).expect("run prepares");
        writeln!(
            s,
            "\nrun {}: integrator {}, dt {}",
            spec.name,
            spec.integrator,
            g(run.dt)
        )
        .unwrap();
        for point in [0, run.points() - 1] {
            let mut rng = trajectory_rng(derive_seed(GOLDEN_SEED, &spec.name), point as u64);
            let rec = run
                .simulate(point, &mut rng, 10 * run.sample_every)
                .expect("trajectory runs");
            let vals: Vec<String> = rec.force_ratio.iter().map(|v| g(*v)).collect();
            writeln!(
                s,
                "strain {}: accepted {}/{}: {}",
                g(theory.strain_ratios[point]),
                rec.accepted,
                rec.proposed,
                vals.join(" ")
            )
            .unwrap();
        }
    }
}

fn snapshot_of(scene: &Scene) -> String {
    let mut s = String::new();
    writeln!(
        s,
        "scene {} (model {:?}, dims {})",
        scene.name, scene.model, scene.dims
    )
    .unwrap();
    if scene.compression.is_some() {
        compression_snapshot(scene, &mut s);
        return s;
    }
    for spec in &scene.runs {
        let run = LinearRun::prepare(scene, spec).expect("scene prepares");
        let r = &run.reference;
        writeln!(
            s,
            "\nrun {}: integrator {}, noise {}, dt {}, lambda_max {}",
            spec.name,
            spec.integrator,
            spec.noise.name(),
            g(r.dt),
            g(r.max_rate)
        )
        .unwrap();
        if scene.compression.is_some() {
            compression_snapshot(scene, &mut s);
            return s;
        }
        writeln!(
            s,
            "mode  variance_discrete  variance_continuum  multiplier  rate_discrete"
        )
        .unwrap();
        for m in &r.modes {
            writeln!(
                s,
                "{}  {}  {}  {}  {}",
                m.n,
                g(m.variance_discrete),
                g(m.variance_continuum),
                g(m.multiplier),
                m.rate_discrete.map_or("none".to_string(), g)
            )
            .unwrap();
        }
        for (j, x) in r.profile_x.iter().enumerate() {
            writeln!(
                s,
                "profile x={}: discrete {} continuum {}",
                g(*x),
                g(r.profile_discrete[j]),
                g(r.profile_continuum[j])
            )
            .unwrap();
        }
        for q in &r.two_time {
            writeln!(
                s,
                "two-time x={} y={} t={} eta={}: discrete {} continuum {}",
                g(q.x),
                g(q.y),
                g(q.t),
                g(q.eta),
                g(q.discrete),
                g(q.continuum)
            )
            .unwrap();
        }
        // The tangent-angle cosines of Gittes et al. (issue #29), where checked.
        for t in &r.tangent {
            writeln!(
                s,
                "tangent-angle n={}: discrete {} continuum {}",
                t.n,
                g(t.variance_discrete),
                g(t.variance_continuum)
            )
            .unwrap();
        }
        let mut rng = trajectory_rng(derive_seed(GOLDEN_SEED, &spec.name), 0);
        let trace = run.trace(&mut rng, 200, 25).expect("trace runs");
        for (k, row) in trace.iter().enumerate() {
            let vals: Vec<String> = row.iter().map(|v| g(*v)).collect();
            writeln!(s, "step {}: {}", (k + 1) * 25, vals.join(" ")).unwrap();
        }
    }
    s
}

/// What: the snapshot of every scene in `verification/` (see the file header) equals
/// its reviewed copy `golden/<scene>.snap`.
/// Reference: the snapshots themselves (a regression check, not a correctness check).
/// Set-up: traces from [`GOLDEN_SEED`].
/// Tolerance: exact text at 10 significant digits (see the file header).
#[test]
fn golden_scenes() {
    let dir = manifest_dir();
    let scenes = Scene::discover(&dir.join("verification")).expect("scene directory");
    assert!(!scenes.is_empty(), "no scenes found");
    let mut settings = insta::Settings::clone_current();
    settings.set_snapshot_path(dir.join("golden"));
    settings.set_prepend_module_to_snapshot(false);
    settings.bind(|| {
        for path in scenes {
            let scene = Scene::load(&path).expect("scene loads");
            insta::assert_snapshot!(scene.name.clone(), snapshot_of(&scene));
        }
    });
}
