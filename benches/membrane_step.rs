//! Cost of one Crank–Nicolson step of the membrane (Bogner–Fox–Schmit plate, simply
//! supported, κ = ξ = kT = a = b = 1, σ = 0) on 16², 32² and 64² elements, against the cost
//! of drawing the step's standard normals alone (issue #27, deliverable 5).
//!
//! ```sh
//! cargo bench --bench membrane_step            # 16², 32², 64² elements
//! cargo bench --bench membrane_step -- quick   # 16² and 32² only
//! ```
//!
//! Two ways of taking the same step (the same law: [`langevin_fem::dynamics::DiscreteLaw`]):
//!
//! - **separable** ([`ModalStep`] on the rates of [`PlateModes`]): on a uniform simply
//!   supported mesh the plate's matrices are block diagonal per wavevector, its generalized
//!   modes are known without a dense transform, and a consistent-noise step is one normal
//!   and two flops per mode;
//! - **banded** ([`ThetaScheme`] on the assembled `SymBanded` K and C): the general path
//!   (any mesh, any noise), one banded product and one banded solve per step, cost
//!   O(n·bw) with half-bandwidth bw = 3·2N + 3.
//!
//! The "normals alone" baseline fills a buffer of n standard normals (one per free DOF)
//! from the same generator (`Pcg64` from `trajectory_rng`, `rand_distr::StandardNormal`).
//! Every figure is the median over [`REPS`] timed loops of ≥ [`TARGET`], the cases of one
//! size measured round-robin so that background load affects them alike. Δt = 10⁻³ τ₁,
//! τ₁ = 1/λ₁₁.

use langevin_fem::dynamics::{Integrator, IntegratorKind, ModalStep, ThetaScheme};
use langevin_fem::fem::NoiseModel;
use langevin_fem::fem::plate::PlateModel;
use langevin_fem::fem::plate_modes::PlateModes;
use langevin_fem::rng::{TrajectoryRng, trajectory_rng};
use langevin_fem::spectral::membrane::{Membrane, MembraneParams};
use rand::RngExt;
use rand_distr::StandardNormal;
use std::hint::black_box;
use std::time::{Duration, Instant};

/// Minimum duration of one timed loop.
const TARGET: Duration = Duration::from_millis(50);
/// Timed loops per figure; the median is reported.
const REPS: usize = 9;
/// Master seed of the benchmark's random streams.
const SEED: u64 = 20_261_203;

/// Something to time.
enum Work {
    /// One step of an integrator on its state.
    Step {
        integrator: Box<dyn Integrator>,
        state: Vec<f64>,
        rng: TrajectoryRng,
    },
    /// One step's worth of standard normals.
    Normals { buf: Vec<f64>, rng: TrajectoryRng },
}

impl Work {
    fn run(&mut self, iters: u64) -> Duration {
        let t = Instant::now();
        match self {
            Work::Step {
                integrator,
                state,
                rng,
            } => {
                for _ in 0..iters {
                    integrator.step(black_box(state.as_mut_slice()), rng);
                }
            }
            Work::Normals { buf, rng } => {
                for _ in 0..iters {
                    for v in buf.iter_mut() {
                        *v = rng.sample::<f64, _>(StandardNormal);
                    }
                    black_box(buf.as_mut_slice());
                }
            }
        }
        t.elapsed()
    }

    fn calibrate(&mut self) -> u64 {
        self.run(1);
        let mut iters: u64 = 1;
        loop {
            let el = self.run(iters);
            if el >= TARGET {
                return iters;
            }
            let grow = (TARGET.as_secs_f64() * 1.2 / el.as_secs_f64().max(1e-9)).min(100.0);
            iters = ((iters as f64 * grow).ceil() as u64).max(iters + 1);
        }
    }

    fn is_finite(&self) -> bool {
        match self {
            Work::Step { state, .. } => state.iter().all(|v| v.is_finite()),
            Work::Normals { .. } => true,
        }
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Median ns per call of every work item, the repetitions interleaved round-robin.
fn measure_round_robin(works: &mut [Work]) -> Vec<f64> {
    let iters: Vec<u64> = works.iter_mut().map(Work::calibrate).collect();
    let mut samples = vec![Vec::with_capacity(REPS); works.len()];
    for _ in 0..REPS {
        for ((w, &it), s) in works.iter_mut().zip(&iters).zip(&mut samples) {
            let t = w.run(it);
            s.push(t.as_secs_f64() * 1e9 / it as f64);
        }
    }
    samples.into_iter().map(median).collect()
}

fn main() {
    let quick = std::env::args().any(|a| a == "quick");
    let sizes: &[usize] = if quick { &[16, 32] } else { &[16, 32, 64] };
    let params = MembraneParams::default();
    let membrane = Membrane::new(params).expect("membrane");
    let slowest = membrane.modes(1).expect("modes")[0];
    let dt = 1e-3 / membrane.mode_rate(slowest);
    println!(
        "| elements | unknowns n | half-bandwidth | separable CN ns/step | banded CN ns/step | normals alone ns | separable/normals | banded/normals |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|");
    let mut previous: Option<(usize, f64, f64)> = None;
    for &ne in sizes {
        let plate = PlateModel::new(params, ne, ne).expect("plate");
        let n = plate.n_dofs();
        let bw = plate.stiffness().bandwidth();
        let modes = PlateModes::new(&plate).expect("plate modes");
        let separable =
            ModalStep::new(IntegratorKind::CrankNicolson, &modes.rates(), dt, params.kt)
                .expect("separable step");
        let banded =
            ThetaScheme::new(&plate, NoiseModel::Consistent, 0.5, dt).expect("banded step");
        let mut works = vec![
            Work::Step {
                integrator: Box::new(separable),
                state: vec![0.0; n],
                rng: trajectory_rng(SEED, ne as u64),
            },
            Work::Step {
                integrator: Box::new(banded),
                state: vec![0.0; n],
                rng: trajectory_rng(SEED, 1000 + ne as u64),
            },
            Work::Normals {
                buf: vec![0.0; n],
                rng: trajectory_rng(SEED ^ 0x5EED, ne as u64),
            },
        ];
        let ns = measure_round_robin(&mut works);
        assert!(
            works.iter().all(Work::is_finite),
            "non-finite state at {ne}²"
        );
        println!(
            "| {ne}² | {n} | {bw} | {:.0} | {:.0} | {:.0} | {:.2} | {:.2} |",
            ns[0],
            ns[1],
            ns[2],
            ns[0] / ns[2],
            ns[1] / ns[2]
        );
        if let Some((n0, s0, b0)) = previous {
            let growth = |a: f64, b: f64| (b / a).ln() / (n as f64 / n0 as f64).ln();
            eprintln!(
                "growth exponent from {n0} to {n} unknowns: separable {:.2}, banded {:.2} (1 = O(n))",
                growth(s0, ns[0]),
                growth(b0, ns[1])
            );
        }
        previous = Some((n, ns[0], ns[1]));
    }
}
