//! Effective samples per CPU-second: the figure of merit of an integrator for an
//! equilibrium average (issue #11).
//!
//! For an observable `x` sampled every `k` steps of size Δt, with integrated
//! autocorrelation time τ_int (Sokal's ½-convention, [`mean_with_error`]) in samples, a
//! run of n samples holds `n_eff = n/(2τ_int)` independent ones, and
//!
//! ```text
//! n_eff per CPU-second = n_eff / (CPU seconds of the run)
//!                      = 1 / (2 τ_int[time] · CPU seconds per unit simulated time),
//! ```
//!
//! the product the issue names: the correlation time per unit simulated time times the
//! cost per unit simulated time. The standard error of the mean after T CPU-seconds is
//! `σ/sqrt(T · n_eff per CPU-second)`, so the figure ranks integrators directly, provided
//! the average they converge to is the right one (the θ-schemes of the nonlinear filament
//! are biased by O(Δt): the table gives each mean against the exact theory).
//!
//! Two parts:
//!
//! 1. **⟨F⟩ of the 2D compression filament** (the Fig. 2 scene
//!    `verification/compression-2d.toml`: EI = 100, EA = 10⁶, L = kT = ξ = 1, 10 elements,
//!    consistent noise) at ε/ε_c0 = 0, 3 and 10, for every nonlinear integrator. Each
//!    trajectory starts from the exact equilibrium: 5 τ₁ of the Metropolis chain
//!    ([`ModalMetropolis`] at Δt = 0.02 τ₁, exact at any Δt), then 1 τ₁ of the integrator
//!    under test (its own, possibly biased, law), neither timed; then the timed sampling
//!    run records F/F_c0. τ_int is estimated per trajectory; n_eff and the CPU time are
//!    summed over the trajectories. The exact ⟨F⟩ and Var F are those of the same
//!    discretized filament ([`CompressionTheory`] with the discrete stored-length law).
//! 2. **Mode-1 variance of the linear hinged filament** (`verification/hinged-linear-2d.toml`:
//!    EI = L = kT = ξ = 1, consistent noise, 10 and 100 elements): the observable is
//!    `q₁²`, `q₁ = φ₁ᵀC w` the first generalized modal amplitude. Every linear
//!    integrator is an AR(1) recursion `q ← m q + g z` per mode, so `q₁²` has
//!    `ρ(k) = m^{2k}` and `τ_int = (1 + m²)/(2(1 − m²))` samples exactly; the bench times
//!    the step (with the projection), prints the measured τ_int beside the exact one where
//!    the run is long enough (≥ 100 τ_int), and reports the figure of merit from the exact
//!    τ_int.
//!
//! CPU time is the thread's own (`CLOCK_THREAD_CPUTIME_ID` on Linux, wall time elsewhere),
//! so that other jobs on a shared machine inflate it less than wall time. Every trajectory
//! has a fixed seed ([`SEED`]); the figures of merit still vary by the timing noise
//! (±10–20 % on a loaded machine) and by the statistical error of τ_int (≈ ±10 % at 100
//! τ_int per trajectory, more where noted).
//!
//! Run: `cargo bench --bench effective_samples` (≈ 1.5 min); `-- nonlinear` or `-- linear`
//! runs one part.

#[path = "common/cpu.rs"]
mod cpu;

use cpu::cpu_now;
use langevin_fem::FilamentParams;
use langevin_fem::dynamics::{
    Components, Driver, IntegratorKind, ModalMetropolis, NonlinearIntegrator, NonlinearState,
    Observer, Trajectory, build_integrator,
};
use langevin_fem::fem::beam::BeamModel;
use langevin_fem::fem::mesh::Mesh;
use langevin_fem::fem::modal::generalized_modes;
use langevin_fem::fem::noise::NoiseModel;
use langevin_fem::fem::paired::PairedModes;
use langevin_fem::fem::vonkarman::CompressedFilament;
use langevin_fem::rng::{TrajectoryRng, trajectory_rng};
use langevin_fem::scene::Scene;
use langevin_fem::stats::{MeanEstimate, combine_independent, mean_with_error};
use langevin_fem::theory::{CompressionTheory, Dims, StoredLengthLaw};
use rand::RngExt;
use rand_distr::StandardNormal;
use std::path::Path;
use std::time::{Duration, Instant};

/// Master seed of every trajectory of this bench.
const SEED: u64 = 20261201;

/// The strains of part 1, in units of ε_c0.
const STRAIN_RATIOS: [f64; 3] = [0.0, 3.0, 10.0];

/// Pre-equilibration of every nonlinear trajectory with the exact Metropolis chain: time
/// (τ₁) and step (τ₁).
const PRE_EQUILIBRATION_TAU1: f64 = 5.0;
const PRE_EQUILIBRATION_DT_TAU1: f64 = 0.02;

/// Burn-in of the integrator under test after the pre-equilibration (τ₁): its own law,
/// biased for the θ-schemes, relaxes from the exact one within about τ₁.
const OWN_BURN_IN_TAU1: f64 = 1.0;

/// Records `F/F_c0` at every sample of a nonlinear trajectory.
struct ForceRecorder<'m> {
    model: &'m CompressedFilament,
    euler_load: f64,
    samples: Vec<f64>,
}

impl Observer<NonlinearState<NonlinearIntegrator<'_>>> for ForceRecorder<'_> {
    fn on_sample(&mut self, _: usize, _: u64, s: &NonlinearState<NonlinearIntegrator<'_>>) {
        let f = self.model.compressive_force(self.model.stored_length(&s.w));
        self.samples.push(f / self.euler_load);
    }
}

impl Observer<ModalMetropolis<'_>> for ForceRecorder<'_> {
    fn on_sample(&mut self, _: usize, _: u64, chain: &ModalMetropolis<'_>) {
        self.samples.push(chain.force() / self.euler_load);
    }
}

/// A nonlinear integrator of part 1: the banded [`NonlinearIntegrator`] of `kind` or the
/// paired modal Metropolis chain.
#[derive(Debug, Clone, Copy)]
enum Stepper {
    Nodal(IntegratorKind),
    Modal,
}

/// One row group of part 1: an integrator at one step, with its run length.
#[derive(Debug, Clone, Copy)]
struct Case {
    stepper: Stepper,
    /// Time step in τ₁; `None`: half the explicit stability limit.
    dt_tau1: Option<f64>,
    /// Steps between samples.
    every: u64,
    trajectories: usize,
    /// Timed sampling time per trajectory, τ₁.
    duration_tau1: f64,
}

impl Case {
    fn label(&self) -> String {
        match self.stepper {
            Stepper::Nodal(IntegratorKind::MetropolisCrankNicolson) => {
                "metropolis-crank-nicolson (banded)".into()
            }
            Stepper::Nodal(kind) => kind.name().into(),
            Stepper::Modal => "metropolis-crank-nicolson (modal)".into(),
        }
    }
}

/// What one trajectory of part 1 gives: the estimate of ⟨F/F_c0⟩, the samples' sum of
/// squares about zero, the timed steps and CPU time, and the Metropolis counts.
struct TrajectoryResult {
    estimate: MeanEstimate,
    sum_squares: f64,
    steps: u64,
    cpu: Duration,
    proposed: u64,
    accepted: u64,
}

/// Runs trajectory `index` of `case` at `model` (see the module docs).
fn run_trajectory(
    case: &Case,
    model: &CompressedFilament,
    modes: &PairedModes,
    dt: f64,
    tau1: f64,
    rng: &mut TrajectoryRng,
) -> TrajectoryResult {
    let euler_load = model.beam().params().euler_load();
    let pre_dt = PRE_EQUILIBRATION_DT_TAU1 * tau1;
    let mut chain = ModalMetropolis::new(model, modes, pre_dt, rng).expect("chain");
    let pre_steps = (PRE_EQUILIBRATION_TAU1 / PRE_EQUILIBRATION_DT_TAU1).round() as u64;
    Driver::new(pre_dt, pre_steps, 0, 1)
        .run(0, &mut chain, rng, &mut (), |_| "pre-equilibration".into())
        .expect("finite pre-equilibration");
    let burn_in = (OWN_BURN_IN_TAU1 * tau1 / dt).round() as u64;
    let sampled = ((case.duration_tau1 * tau1 / dt).round() as u64).max(case.every * 64);
    let sampled = sampled - sampled % case.every;
    let mut rec = ForceRecorder {
        model,
        euler_load,
        samples: Vec::with_capacity((sampled / case.every) as usize),
    };
    let detail = || format!("{} diverged at dt = {:.3e} tau1", case.label(), dt / tau1);
    let (cpu, proposed, accepted) = match case.stepper {
        Stepper::Modal => {
            chain.set_dt(dt).expect("dt");
            Driver::new(dt, burn_in, 0, 1)
                .run(0, &mut chain, rng, &mut (), |_| detail())
                .expect("finite burn-in");
            let (p0, a0) = (chain.proposed, chain.accepted);
            let start = cpu_now();
            Driver::new(dt, 0, sampled, case.every)
                .run(0, &mut chain, rng, &mut rec, |_| detail())
                .expect("finite trajectory");
            (cpu_now() - start, chain.proposed - p0, chain.accepted - a0)
        }
        Stepper::Nodal(kind) => {
            let integrator = NonlinearIntegrator::new(model, kind, NoiseModel::Consistent, dt)
                .expect("integrator");
            let mut state = NonlinearState {
                integrator,
                w: chain.nodal_state(),
            };
            Driver::new(dt, burn_in, 0, 1)
                .run(0, &mut state, rng, &mut (), |_| detail())
                .expect("finite burn-in");
            let (p0, a0) = (state.integrator.proposed, state.integrator.accepted);
            let start = cpu_now();
            Driver::new(dt, 0, sampled, case.every)
                .run(0, &mut state, rng, &mut rec, |_| detail())
                .expect("finite trajectory");
            (
                cpu_now() - start,
                state.integrator.proposed - p0,
                state.integrator.accepted - a0,
            )
        }
    };
    TrajectoryResult {
        estimate: mean_with_error(&rec.samples).expect("tau_int"),
        sum_squares: rec.samples.iter().map(|x| x * x).sum(),
        steps: sampled,
        cpu,
        proposed,
        accepted,
    }
}

/// Formats `x` with 3 significant digits (plain for 0.01 ≤ |x| < 10⁵, else scientific).
fn sig3(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 || !(1e-2..1e5).contains(&a) {
        format!("{x:.2e}")
    } else {
        let decimals = (2 - a.log10().floor() as i32).max(0) as usize;
        format!("{x:.decimals$}")
    }
}

/// Part 1: ⟨F⟩ of the 2D compression filament.
fn nonlinear(root: &Path) {
    let scene = Scene::load(&root.join("compression-2d.toml")).expect("scene");
    let p = scene.filament;
    let elements = scene.mesh.elements;
    let tau1 = p.tau1();
    let beam = BeamModel::new(p, Mesh::uniform(p.length, elements).expect("mesh")).expect("beam");
    let modes = PairedModes::new(&beam).expect("uniform mesh");
    let half_limit = 0.5 * beam.explicit_euler_dt_limit().expect("limit");
    let law = StoredLengthLaw::discrete(&p, Dims::Two, elements).expect("law");
    let theory = CompressionTheory::new(&p, law).expect("theory");
    let nodal = |kind, dt_tau1, every, trajectories, duration_tau1| Case {
        stepper: Stepper::Nodal(kind),
        dt_tau1,
        every,
        trajectories,
        duration_tau1,
    };
    let modal = |dt_tau1: f64, duration_tau1| Case {
        stepper: Stepper::Modal,
        dt_tau1: Some(dt_tau1),
        every: 1,
        trajectories: 4,
        duration_tau1,
    };
    let cases = [
        // The explicit scheme at 2.6·10⁵ steps per τ₁: 10 τ₁ per trajectory (25–50
        // τ_int at ε = 3 ε_c0), sampled every 64 steps (2.5·10⁻⁴ τ₁).
        nodal(IntegratorKind::EulerMaruyama, None, 64, 4, 10.0),
        nodal(IntegratorKind::CrankNicolson, Some(0.002), 1, 4, 200.0),
        nodal(IntegratorKind::BackwardEuler, Some(0.002), 1, 4, 200.0),
        nodal(
            IntegratorKind::MetropolisCrankNicolson,
            Some(0.02),
            1,
            4,
            400.0,
        ),
        modal(0.02, 400.0),
        modal(0.08, 800.0),
        modal(0.32, 1600.0),
        modal(0.64, 3200.0),
    ];
    println!(
        "| integrator | Δt/τ₁ | ε/ε_c0 | sample every | trajectories × τ₁ | CPU ns/step | acceptance | τ_int/τ₁ | Var(F/F_c0) (exact) | n_eff per τ₁ | **n_eff per CPU-s** | ⟨F⟩/F_c0 − exact (s.e.) |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for case in &cases {
        let dt = case.dt_tau1.map_or(half_limit, |d| d * tau1);
        for (point, &ratio) in STRAIN_RATIOS.iter().enumerate() {
            let model =
                CompressedFilament::new(beam.clone(), 2, ratio * p.euler_strain()).expect("model");
            let results: Vec<TrajectoryResult> = (0..case.trajectories)
                .map(|j| {
                    let mut rng = trajectory_rng(SEED + point as u64, j as u64);
                    run_trajectory(case, &model, &modes, dt, tau1, &mut rng)
                })
                .collect();
            let estimates: Vec<MeanEstimate> = results.iter().map(|r| r.estimate).collect();
            let (mean, se) = combine_independent(&estimates);
            let n: usize = estimates.iter().map(|e| e.n).sum();
            let n_eff: f64 = estimates.iter().map(|e| e.n_eff).sum();
            let variance =
                results.iter().map(|r| r.sum_squares).sum::<f64>() / n as f64 - mean * mean;
            let steps: u64 = results.iter().map(|r| r.steps).sum();
            let cpu: f64 = results.iter().map(|r| r.cpu.as_secs_f64()).sum();
            let simulated_tau1 = steps as f64 * dt / tau1;
            // τ_int in time: n/(2 n_eff) samples of `every` steps each.
            let tau_int_tau1 = n as f64 / (2.0 * n_eff) * case.every as f64 * dt / tau1;
            let proposed: u64 = results.iter().map(|r| r.proposed).sum();
            let accepted: u64 = results.iter().map(|r| r.accepted).sum();
            let acceptance = if proposed > 0 {
                format!("{:.3}", accepted as f64 / proposed as f64)
            } else {
                "–".into()
            };
            let exact = theory.force_ratio(ratio).expect("theory");
            let exact_var = theory
                .force_variance(ratio * p.euler_strain())
                .expect("theory")
                / p.euler_load().powi(2);
            println!(
                "| {} | {} | {ratio} | {} | {} × {} | {:.0} | {acceptance} | {} | {} ({}) | {} | **{}** | {:+.4} ({:.4}) |",
                case.label(),
                sig3(dt / tau1),
                case.every,
                case.trajectories,
                sig3(simulated_tau1 / case.trajectories as f64),
                cpu * 1e9 / steps as f64,
                sig3(tau_int_tau1),
                sig3(variance),
                sig3(exact_var),
                sig3(n_eff / simulated_tau1),
                sig3(n_eff / cpu),
                mean - exact,
                se,
            );
        }
    }
}

/// Records `q₁²` (the first modal amplitude squared) at every sample of a linear
/// trajectory.
struct ModeRecorder<'a> {
    /// Row `φ₁ᵀC` of the modal projector.
    projector: &'a [f64],
    samples: Vec<f64>,
}

impl<I> Observer<Components<I>> for ModeRecorder<'_> {
    fn on_sample(&mut self, _: usize, _: u64, s: &Components<I>) {
        let q: f64 = self
            .projector
            .iter()
            .zip(&s.states[0])
            .map(|(p, w)| p * w)
            .sum();
        self.samples.push(q * q);
    }
}

/// Part 2: the mode-1 variance of the linear hinged filament.
fn linear(root: &Path) {
    let scene = Scene::load(&root.join("hinged-linear-2d.toml")).expect("scene");
    let p: FilamentParams = scene.filament;
    let tau1 = p.tau1();
    println!(
        "| elements | integrator | Δt/τ₁ | CPU ns/step | timed steps | τ_int of q₁² (samples, exact) | measured | Var q₁ / (kT/λ₁) | n_eff per τ₁ | **n_eff per CPU-s** |"
    );
    println!("|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for (elements, steps) in [(10usize, 400_000u64), (100, 60_000)] {
        let beam =
            BeamModel::new(p, Mesh::uniform(p.length, elements).expect("mesh")).expect("beam");
        let max_rate = beam.max_rate().expect("max rate");
        let gm = generalized_modes(&beam).expect("modes");
        let projector = gm.projector(&beam, 1);
        let row: Vec<f64> = projector.row(0).iter().copied().collect();
        let lambda1 = gm.rates[0];
        let cases = [
            (IntegratorKind::EulerMaruyama, None),
            (IntegratorKind::BackwardEuler, Some(1e-3)),
            (IntegratorKind::CrankNicolson, Some(1e-3)),
            (IntegratorKind::CrankNicolson, Some(0.1)),
            (IntegratorKind::CrankNicolson, Some(0.5)),
            (IntegratorKind::ExactModal, Some(1e-3)),
            (IntegratorKind::ExactModal, Some(0.1)),
            (IntegratorKind::ExactModal, Some(0.5)),
        ];
        for (index, (kind, dt_tau1)) in cases.into_iter().enumerate() {
            let dt = dt_tau1.map_or(1.0 / max_rate, |d| d * tau1);
            let integrator =
                build_integrator(kind, &beam, NoiseModel::Consistent, dt, max_rate, Some(&gm))
                    .expect("integrator");
            let mut system = Components::at_rest(integrator, 1, beam.n_dofs());
            // Start from the exact equilibrium w = Σ φ_i sqrt(kT/λ_i) z_i.
            let mut rng = trajectory_rng(SEED + 100 + elements as u64, index as u64);
            for (i, &rate) in gm.rates.iter().enumerate() {
                let a = (p.kt / rate).sqrt() * rng.sample::<f64, _>(StandardNormal);
                for (w, phi) in system.states[0].iter_mut().zip(gm.vectors.column(i).iter()) {
                    *w += a * phi;
                }
            }
            let mut rec = ModeRecorder {
                projector: &row,
                samples: Vec::with_capacity(steps as usize),
            };
            let start = cpu_now();
            Driver::new(dt, 0, steps, 1)
                .run(0, &mut system, &mut rng, &mut rec, |_| "diverged".into())
                .expect("finite trajectory");
            let cpu = (cpu_now() - start).as_secs_f64();
            debug_assert!(system.is_finite());
            let (m, g) = kind.modal_form(lambda1, dt, p.kt);
            let tau_exact = (1.0 + m * m) / (2.0 * (1.0 - m * m));
            let variance_ratio = g * g / (1.0 - m * m) * lambda1 / p.kt;
            let measured = if steps as f64 >= 100.0 * tau_exact {
                format!("{:.3}", mean_with_error(&rec.samples).expect("tau").tau_int)
            } else {
                "– (run < 100 τ_int)".into()
            };
            let per_step = cpu / steps as f64;
            println!(
                "| {elements} | {kind} | {} | {:.0} | {steps} | {} | {measured} | {:.4} | {} | **{}** |",
                sig3(dt / tau1),
                per_step * 1e9,
                sig3(tau_exact),
                variance_ratio,
                sig3(tau1 / (2.0 * tau_exact * dt)),
                sig3(1.0 / (2.0 * tau_exact * per_step)),
            );
        }
    }
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("verification");
    let args: Vec<String> = std::env::args().collect();
    let only = |part: &str| args.iter().any(|a| a == part);
    let both = !only("nonlinear") && !only("linear");
    let wall = Instant::now();
    if both || only("nonlinear") {
        nonlinear(&root);
        println!();
    }
    if both || only("linear") {
        linear(&root);
    }
    eprintln!(
        "effective_samples: {:.1} s wall",
        wall.elapsed().as_secs_f64()
    );
}
