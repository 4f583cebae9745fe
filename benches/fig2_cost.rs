//! What the paper's explicit scheme would need for the Fig. 2 accuracy, measured on a
//! short run and extrapolated (labelled as such in the README).
//!
//! For each compression scene, the cost of one step is measured for the paper's explicit
//! Euler–Maruyama (with the axial solve of step i, at half its stability limit) and for the
//! Metropolis-adjusted Crank–Nicolson used by the scene, on the same filament at
//! ε = 3 ε_c0. The simulated time the scene needs at the full budget (all strains,
//! trajectories, burn-in and sampling of its primary run) is then converted into the number
//! of explicit steps and an extrapolated wall time. The extrapolation assumes the explicit
//! scheme needs the same simulated time for the same error bar (its correlation times are
//! the physical ones), which flatters it: it is a lower bound.
//!
//! Run: `cargo bench --bench fig2_cost`; `cargo bench --bench fig2_cost -- metropolis`
//! times only the scenes' Metropolis step (median of 7 runs of 100 000 steps each).

use langevin_fem::dynamics::{Driver, IntegratorKind, NonlinearState, Observer};
use langevin_fem::fem::beam::BeamModel;
use langevin_fem::fem::mesh::Mesh;
use langevin_fem::fem::noise::NoiseModel;
use langevin_fem::rng::trajectory_rng;
use langevin_fem::scene::Budget;
use langevin_fem::scene::Scene;
use langevin_fem::{dynamics::nonlinear::NonlinearIntegrator, fem::vonkarman::CompressedFilament};
use std::hint::black_box;
use std::path::Path;
use std::time::{Duration, Instant};

/// Starts a clock at the end of the warm-up and reads it at the end of the run.
struct Timer {
    warm_up: u64,
    start: Option<Instant>,
    elapsed: Duration,
}

impl<S> Observer<S> for Timer {
    fn on_start(&mut self, _: usize, _: &S) {
        if self.warm_up == 0 {
            self.start = Some(Instant::now());
        }
    }
    fn on_step(&mut self, _: usize, step: u64, _: &S) {
        if step == self.warm_up {
            self.start = Some(Instant::now());
        }
    }
    fn on_finish(&mut self, _: usize, system: &S) {
        black_box(system);
        self.elapsed = self.start.map(|t| t.elapsed()).unwrap_or_default();
    }
}

fn ns_per_step(model: &CompressedFilament, kind: IntegratorKind, dt: f64, steps: u64) -> f64 {
    let integrator =
        NonlinearIntegrator::new(model, kind, NoiseModel::Consistent, dt).expect("integrator");
    let mut state = NonlinearState {
        integrator,
        w: vec![vec![0.0; model.beam().n_dofs()]; model.components()],
    };
    let mut rng = trajectory_rng(1, 0);
    // Warm up into the fluctuating state, then time (the driver's finiteness check
    // included, as in a real trajectory).
    let mut timer = Timer {
        warm_up: steps / 4,
        start: None,
        elapsed: Duration::ZERO,
    };
    Driver::new(dt, steps / 4, steps, steps)
        .run(0, &mut state, &mut rng, &mut timer, |_| {
            format!("{kind} diverged")
        })
        .expect("finite trajectory");
    timer.elapsed.as_nanos() as f64 / steps as f64
}

/// The model of a compression scene at ε = 3 ε_c0, with the scene's primary run.
fn scene_model(root: &Path, name: &str) -> (Scene, CompressedFilament) {
    let scene = Scene::load(&root.join(format!("{name}.toml"))).expect("scene");
    let p = scene.filament;
    let beam = BeamModel::new(
        p,
        Mesh::uniform(p.length, scene.mesh.elements).expect("mesh"),
    )
    .expect("beam");
    let model = CompressedFilament::new(beam, scene.dims, 3.0 * p.euler_strain()).expect("model");
    (scene, model)
}

/// The Metropolis step alone at each scene: median ns/step of 7 runs.
fn metropolis_only(root: &Path) {
    println!("| scene | elements | dt / tau1 | Metropolis ns/step (median of 7) | min | max |");
    println!("|---|---:|---:|---:|---:|---:|");
    for name in ["compression-2d", "compression-3d"] {
        let (scene, model) = scene_model(root, name);
        let run = &scene.runs[0];
        let dt = run.dt_tau1 * scene.filament.tau1();
        let mut t: Vec<f64> = (0..7)
            .map(|_| ns_per_step(&model, run.integrator, dt, 100_000))
            .collect();
        t.sort_by(f64::total_cmp);
        println!(
            "| {name} | {} | {:.2e} | {:.0} | {:.0} | {:.0} |",
            scene.mesh.elements, run.dt_tau1, t[3], t[0], t[6]
        );
    }
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("verification");
    if std::env::args().any(|a| a == "metropolis") {
        metropolis_only(&root);
        return;
    }
    println!(
        "| scene | explicit dt / tau1 | explicit ns/step | scene dt / tau1 | scene ns/step | simulated tau1 (full budget) | scene steps | explicit steps | explicit wall (extrapolated, 1 core) |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for name in ["compression-2d", "compression-3d"] {
        let (scene, model) = scene_model(&root, name);
        let comp = scene.compression.as_ref().expect("compression scene");
        let p = scene.filament;
        let tau1 = p.tau1();
        let limit = 2.0 / model.beam().max_rate().expect("max rate");
        let run = &scene.runs[0];
        let e = run.ensemble(Budget::Full);
        let simulated = comp.strain_ratios.len() as f64
            * e.trajectories as f64
            * (e.duration_tau1 + comp.burn_in_tau1);
        let dt_explicit = 0.5 * limit;
        let explicit = ns_per_step(&model, IntegratorKind::EulerMaruyama, dt_explicit, 400_000);
        let scene_cost = ns_per_step(&model, run.integrator, run.dt_tau1 * tau1, 100_000);
        let scene_steps = simulated / run.dt_tau1;
        let explicit_steps = simulated * tau1 / dt_explicit;
        let wall = explicit_steps * explicit * 1e-9;
        println!(
            "| {name} | {:.2e} | {explicit:.0} | {:.2e} | {scene_cost:.0} | {simulated:.3e} | {scene_steps:.2e} | {explicit_steps:.2e} | {:.1} h |",
            dt_explicit / tau1,
            run.dt_tau1,
            wall / 3600.0
        );
    }
}
