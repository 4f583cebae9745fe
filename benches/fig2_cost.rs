//! Cost of one step of the Fig. 2 filament (EI = 100, EA = 1e6 in units L = kT = ξ = 1, at
//! ε = 3 ε_c0), per trajectory-step, 2D and 3D, at 10, 100 and 1000 elements:
//!
//! - the Metropolis-adjusted Crank–Nicolson chain in the paired modal form
//!   ([`ModalMetropolis`], what the scenes run on their uniform meshes), at Δt = 0.32 τ1;
//! - the same chain in banded nodal form ([`NonlinearIntegrator`], the general-mesh
//!   fallback), at Δt = 0.02 τ1;
//! - the paper's explicit Euler–Maruyama (with the axial solve of step i) at half its
//!   stability limit (10 elements only);
//! - the random numbers alone: the step's standard normals and one uniform, from the same
//!   generator.
//!
//! Every figure is the median of 7 timed runs (after a warm-up of a quarter of the run).
//! Run: `cargo bench --bench fig2_cost`; `-- quick` for 10 elements only.

use langevin_fem::dynamics::{Driver, IntegratorKind, ModalMetropolis, NonlinearState, Observer};
use langevin_fem::fem::beam::BeamModel;
use langevin_fem::fem::mesh::Mesh;
use langevin_fem::fem::noise::NoiseModel;
use langevin_fem::fem::paired::PairedModes;
use langevin_fem::rng::trajectory_rng;
use langevin_fem::{dynamics::nonlinear::NonlinearIntegrator, fem::vonkarman::CompressedFilament};
use rand::RngExt;
use rand_distr::StandardNormal;
use std::hint::black_box;
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

/// The Fig. 2 filament with `elements` elements at ε = 3 ε_c0.
fn fig2_model(dims: usize, elements: usize) -> CompressedFilament {
    let p = langevin_fem::FilamentParams {
        bending_rigidity: 100.0,
        stretch_rigidity: 1e6,
        ..langevin_fem::FilamentParams::default()
    };
    let beam = BeamModel::new(p, Mesh::uniform(p.length, elements).expect("mesh")).expect("beam");
    CompressedFilament::new(beam, dims, 3.0 * p.euler_strain()).expect("model")
}

/// ns per step of the modal chain at step `dt`.
fn modal_ns_per_step(model: &CompressedFilament, modes: &PairedModes, dt: f64, steps: u64) -> f64 {
    let mut rng = trajectory_rng(1, 0);
    let mut chain = ModalMetropolis::new(model, modes, dt, &mut rng).expect("chain");
    let mut timer = Timer {
        warm_up: steps / 4,
        start: None,
        elapsed: Duration::ZERO,
    };
    Driver::new(dt, steps / 4, steps, steps)
        .run(0, &mut chain, &mut rng, &mut timer, |_| {
            "diverged".to_string()
        })
        .expect("finite trajectory");
    timer.elapsed.as_nanos() as f64 / steps as f64
}

/// ns per step of the random numbers alone: `n` standard normals and one uniform.
fn normals_ns_per_step(n: usize, steps: u64) -> f64 {
    let mut rng = trajectory_rng(1, 0);
    let mut buf = vec![0.0; n];
    let start = Instant::now();
    for _ in 0..steps {
        for z in &mut buf {
            *z = rng.sample(StandardNormal);
        }
        let u: f64 = rng.random();
        black_box((&buf, u));
    }
    start.elapsed().as_nanos() as f64 / steps as f64
}

/// Median of 7 runs of `f`.
fn median7(mut f: impl FnMut() -> f64) -> f64 {
    let mut t: Vec<f64> = (0..7).map(|_| f()).collect();
    t.sort_by(f64::total_cmp);
    t[3]
}

fn main() {
    let quick = std::env::args().any(|a| a == "quick");
    let sizes: &[usize] = if quick { &[10] } else { &[10, 100, 1000] };
    println!(
        "| dims | elements | unknowns | modal Metropolis ns/step (0.32 tau1) | normals + uniform alone ns | modal / normals | banded Metropolis ns/step (0.02 tau1) | explicit EM ns/step |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|");
    for dims in [2, 3] {
        for &ne in sizes {
            let model = fig2_model(dims, ne);
            let tau1 = model.beam().params().tau1();
            let modes = PairedModes::new(model.beam()).expect("uniform mesh");
            let unknowns = model.components() * model.beam().n_dofs();
            let steps = (2_000_000 / unknowns as u64).max(2000);
            let modal = median7(|| modal_ns_per_step(&model, &modes, 0.32 * tau1, steps));
            let normals = median7(|| normals_ns_per_step(unknowns, steps));
            let banded = median7(|| {
                ns_per_step(
                    &model,
                    IntegratorKind::MetropolisCrankNicolson,
                    0.02 * tau1,
                    steps / 2,
                )
            });
            let explicit = if ne == 10 {
                let limit = 2.0 / model.beam().max_rate().expect("max rate");
                format!(
                    "{:.0}",
                    median7(|| ns_per_step(
                        &model,
                        IntegratorKind::EulerMaruyama,
                        0.5 * limit,
                        steps
                    ))
                )
            } else {
                "-".to_string()
            };
            println!(
                "| {dims} | {ne} | {unknowns} | {modal:.0} | {normals:.0} | {:.2} | {banded:.0} | {explicit} |",
                modal / normals
            );
        }
    }
}
