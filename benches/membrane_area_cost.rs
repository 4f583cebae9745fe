//! Cost of the membrane's tension–strain curve under imposed projected area (issue #28,
//! point 4 "Speed"): the CPU-seconds for ⟨σ⟩ at 24 strains with standard error
//! ≤ 0.01 σ_c0 each, on a 16 × 16 mesh, for both set-ups of the scenes
//! (`verification/membrane-area-soft.toml`: κ = 20 kT, periodic;
//! `verification/membrane-area-stiff.toml`: κ = 200 kT, simply supported; K_A = 10⁶,
//! a = b = kT = ξ = 1), and for each proposal of [`ModalMetropolis`] ([`Proposal`]).
//!
//! A **budget by target precision** as for Fig. 2 (docs/src/reference/performance.md): at
//! each strain and candidate step, one trajectory (the start of the scenes: exact free
//! bending equilibrium, moved onto the buckled branch; burn-in of 5 τ1 at the scenes'
//! 0.02 τ1 with the proposal under test, then [`OWN_BURN_IN`] steps at the candidate step,
//! neither timed) records σ/σ_c0 at every step for a timed run of at least
//! [`MIN_CPU`] CPU-s and [`MIN_TAU`] integrated autocorrelation times (at most
//! [`MAX_CPU`]). Its standard error (Sokal's windowed τ_int, [`mean_with_error`]) scales
//! as T^−½, so the sampling needs `cpu_run · (se/0.01)²` CPU-s for 0.01 σ_c0; the
//! burn-in adds the 250 steps of the scenes plus 20 τ_int steps at the chosen step. The
//! curve's cost is the sum over the strains, each at its cheapest candidate step (an
//! ideal step search; the per-step rows give each step's own sum). One trajectory per
//! strain: splitting it over cores adds one burn-in per trajectory.
//!
//! The 24 strains are spread like the scenes' 12 `strain_ratios` (piecewise linear in
//! the index, [`curve_ratios`]). Every mean is also compared with the exact discrete
//! theory of the same mesh ([`AreaTheory::discrete`]): the `max |z|` column, which should
//! stay below ~3.5 for an exact chain.
//!
//! CPU time is the thread's own (`CLOCK_THREAD_CPUTIME_ID`). Fixed seeds; the figures vary
//! with the timing noise of a shared machine (±20 %) and the statistical error of τ_int.
//!
//! ```sh
//! cargo bench --bench membrane_area_cost             # 24 strains, 4 steps (~10 min)
//! cargo bench --bench membrane_area_cost -- quick    # 6 of the 24 strains, 3 steps (~2 min)
//! ```
//!
//! Further arguments: `soft` or `stiff` (one set-up), a proposal's name (`crank-nicolson`,
//! `newton`, `newton-slow`, `ornstein-uhlenbeck`, `crank-nicolson+radial`,
//! `newton-slow+radial`, `independence`, `independence+rb`, `independence-split+rb`:
//! those only), `verbose` (each strain on stderr). The `independence` rows replace every
//! step by an independence move ([`ModalMetropolis::with_independence_moves`]; no step
//! size, one row): after the scenes' burn-in, the proposal's load is the best by
//! acceptance (over [`TUNING_MOVES`] moves each) of the burn-in's mean force and three
//! loads between it and the first buckling load; `+rb` records the Rao–Blackwellized
//! `E[σ | direction]` ([`ModalMetropolis::conditional_force`]) instead of σ; `-split`
//! gives the slowest shell its own radius. `newton-slow` is
//! [`Proposal::Newton`] with the rank-one term on the slowest groups only
//! ([`ModalMetropolis::with_rank_one_limit`], rates ≤ 5 λ_1); `+radial` adds a radial move
//! after every step from the end of the scenes' burn-in on
//! ([`ModalMetropolis::with_radial_moves`]).

#[path = "common/cpu.rs"]
mod cpu;

use cpu::cpu_now;
use langevin_fem::dynamics::{ModalMetropolis, Proposal, Trajectory};
use langevin_fem::fem::area::AreaMembrane;
use langevin_fem::fem::plate_area::{AreaParams, AreaTheory};
use langevin_fem::fem::plate_modes::PlateModes;
use langevin_fem::rng::trajectory_rng;
use langevin_fem::spectral::membrane::{MembraneBoundary, MembraneParams};
use langevin_fem::stats::mean_with_error;

/// Master seed.
const SEED: u64 = 20_261_210;
/// Mesh: elements per side.
const ELEMENTS: usize = 16;
/// Area modulus K_A (units a = kT = 1).
const AREA_MODULUS: f64 = 1e6;
/// `newton-slow`: the rank-one term on the groups with rates ≤ this × λ_1
/// ([`ModalMetropolis::with_rank_one_limit`]): the buckling modes only.
const SLOW_RATES: f64 = 5.0;
/// Number of strains of the curve.
const STRAINS: usize = 24;
/// Target standard error of ⟨σ⟩/σ_c0.
const TARGET: f64 = 0.01;
/// The scenes' burn-in: 5 τ1 at 0.02 τ1.
const SCENE_BURN_IN_STEPS: u64 = 250;
const SCENE_BURN_IN_DT_TAU1: f64 = 0.02;
/// Untimed steps at the candidate step before the timed run.
const OWN_BURN_IN: u64 = 500;
/// Timed run per point: at least this CPU time and this many τ_int, at most `MAX_CPU`.
const MIN_CPU: f64 = 0.25;
const MIN_TAU: f64 = 200.0;
const MAX_CPU: f64 = 2.0;

/// One set-up: a scene's membrane on the bench's mesh.
struct SetUp {
    name: &'static str,
    membrane: MembraneParams,
    /// The scene's `strain_ratios`.
    scene_ratios: &'static [f64],
}

fn set_ups() -> [SetUp; 2] {
    let base = MembraneParams {
        tension: 0.0,
        drag: 1.0,
        kt: 1.0,
        width: 1.0,
        height: 1.0,
        ..MembraneParams::default()
    };
    [
        SetUp {
            name: "soft (kappa 20, periodic)",
            membrane: MembraneParams {
                bending_rigidity: 20.0,
                boundary: MembraneBoundary::Periodic,
                ..base
            },
            scene_ratios: &[
                -5.0, 0.0, 2.0, 4.0, 6.0, 8.0, 10.0, 12.0, 14.0, 16.0, 20.0, 30.0,
            ],
        },
        SetUp {
            name: "stiff (kappa 200, simply supported)",
            membrane: MembraneParams {
                bending_rigidity: 200.0,
                boundary: MembraneBoundary::SimplySupported,
                ..base
            },
            scene_ratios: &[
                -2.0, -1.0, 0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 6.0, 10.0,
            ],
        },
    ]
}

/// `STRAINS` ratios spread like `scene`: `scene` piecewise linear in its index, sampled
/// at `STRAINS` equally spaced positions from the first to the last.
fn curve_ratios(scene: &[f64]) -> Vec<f64> {
    let last = (scene.len() - 1) as f64;
    (0..STRAINS)
        .map(|i| {
            let x = i as f64 * last / (STRAINS - 1) as f64;
            let j = (x.floor() as usize).min(scene.len() - 2);
            let t = x - j as f64;
            scene[j] + t * (scene[j + 1] - scene[j])
        })
        .collect()
}

/// How the chain moves and what it records.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Sampler {
    /// The proposal's steps; σ recorded.
    Chain,
    /// Independence moves (`ModalMetropolis::with_independence_moves`); σ recorded.
    Independence,
    /// Independence moves; the Rao–Blackwellized `E[σ | direction]` recorded
    /// (`ModalMetropolis::conditional_force`).
    RaoBlackwell,
    /// Independence moves with the slowest modes' own radius
    /// (rates ≤ [`SPLIT_RATES`] λ_1); `E[σ | direction]` recorded.
    SplitRaoBlackwell,
}

/// The split independence moves: the modes with rates ≤ this × λ_1 get their own radius
/// (the slowest shell only).
const SPLIT_RATES: f64 = 1.5;

/// Independence moves per candidate load when the bench picks the load.
const TUNING_MOVES: usize = 300;

/// What one timed run gives.
struct Point {
    acceptance: f64,
    /// τ_int of σ in steps (½-convention).
    tau_int: f64,
    ns_per_step: f64,
    /// CPU-s for se = `TARGET`, burn-in included.
    cpu_needed: f64,
    /// (⟨σ⟩ − exact)/se.
    z: f64,
}

/// Runs one point (see the module docs).
#[allow(clippy::too_many_arguments)]
fn run_point(
    model: &AreaMembrane,
    modes: &PlateModes,
    (kind, rank_one_limit, radial, sampler): (Proposal, Option<f64>, bool, Sampler),
    dt_tau1: f64,
    tau1: f64,
    exact: f64,
    stream: u64,
) -> Point {
    let unit = model.buckling_stress();
    let mut rng = trajectory_rng(SEED, stream);
    let burn_dt = SCENE_BURN_IN_DT_TAU1 * tau1;
    let mut chain = ModalMetropolis::for_membrane(model, modes, burn_dt, &mut rng)
        .expect("chain")
        .with_proposal(kind)
        .expect("proposal");
    if let Some(limit) = rank_one_limit {
        chain = chain.with_rank_one_limit(limit / tau1);
    }
    for _ in 0..SCENE_BURN_IN_STEPS {
        chain.step(&mut rng);
    }
    // Radial moves from equilibrium on: from the buckled start, far from it (aᵀΛa ≈ 5N kT
    // at 20 ε_c0), the first one shrinks the state into a compressed saddle region that
    // the Crank–Nicolson proposal, with its frozen force, cannot leave.
    if radial {
        chain = chain.with_radial_moves();
    }
    chain.set_dt(dt_tau1 * tau1).expect("dt");
    if sampler != Sampler::Chain {
        // the independence proposal's load: the mean force over the burn-in (below the
        // first buckling load), then the best of a few loads up to that limit by acceptance
        let mut mean = 0.0;
        for _ in 0..OWN_BURN_IN {
            chain.step(&mut rng);
            mean += chain.force() / OWN_BURN_IN as f64;
        }
        let limit = chain.independence_force_limit();
        let mean = mean.min(limit - 1e-3 * limit.abs());
        let candidates = [
            mean,
            0.5 * (mean + limit),
            0.9 * limit + 0.1 * mean,
            0.99 * limit + 0.01 * mean,
        ];
        let mut best: Option<(f64, ModalMetropolis)> = None;
        for load in candidates.into_iter().filter(|l| *l < limit) {
            let slow = (sampler == Sampler::SplitRaoBlackwell).then_some(SPLIT_RATES / tau1);
            let Ok(mut trial) = chain.clone().with_independence_moves(load, slow) else {
                continue;
            };
            for _ in 0..TUNING_MOVES {
                trial.step(&mut rng);
            }
            let acc = trial.acceptance();
            if best.as_ref().is_none_or(|(b, _)| acc > *b) {
                best = Some((acc, trial));
            }
        }
        chain = best.expect("an independence load").1;
    }
    for _ in 0..OWN_BURN_IN {
        chain.step(&mut rng);
    }
    assert!(chain.is_finite(), "diverged");
    let (p0, a0) = (chain.proposed, chain.accepted);
    let mut sigma: Vec<f64> = Vec::new();
    let mut cpu = 0.0;
    let mut chunk = 1000_usize;
    let estimate = loop {
        let start = cpu_now();
        for _ in 0..chunk {
            chain.step(&mut rng);
            let f = if matches!(sampler, Sampler::RaoBlackwell | Sampler::SplitRaoBlackwell) {
                chain.conditional_force()
            } else {
                chain.force()
            };
            sigma.push(-f / unit);
        }
        cpu += (cpu_now() - start).as_secs_f64();
        chunk = sigma.len();
        if cpu < MIN_CPU {
            continue;
        }
        match mean_with_error(&sigma) {
            Ok(e) if e.tau_int * MIN_TAU <= sigma.len() as f64 || cpu >= MAX_CPU => break Some(e),
            // a chain that (nearly) never moves has no τ_int: its cost is infinite
            Err(_) if cpu >= MAX_CPU => break None,
            _ => {}
        }
    };
    let acceptance = (chain.accepted - a0) as f64 / (chain.proposed - p0) as f64;
    let steps = sigma.len() as f64;
    let ns_per_step = cpu * 1e9 / steps;
    let Some(estimate) = estimate else {
        return Point {
            acceptance,
            tau_int: f64::INFINITY,
            ns_per_step,
            cpu_needed: f64::INFINITY,
            z: f64::NAN,
        };
    };
    let sampling = cpu * (estimate.std_error / TARGET).powi(2);
    let burn_in = (SCENE_BURN_IN_STEPS as f64 + 20.0 * estimate.tau_int) * ns_per_step * 1e-9;
    Point {
        acceptance,
        tau_int: estimate.tau_int,
        ns_per_step,
        cpu_needed: sampling + burn_in,
        z: (estimate.mean - exact) / estimate.std_error,
    }
}

fn main() {
    let quick = std::env::args().any(|a| a == "quick");
    let steps: &[f64] = if quick {
        &[0.08, 0.32, 1.0]
    } else {
        &[0.02, 0.08, 0.32, 1.0]
    };
    // (name, proposal, rank-one term on the groups with rates ≤ this × λ_1 only, radial
    // moves)
    use Sampler::{Chain, Independence, RaoBlackwell, SplitRaoBlackwell};
    let proposals = [
        (
            "crank-nicolson",
            Proposal::CrankNicolson,
            None,
            false,
            Chain,
        ),
        ("newton", Proposal::Newton, None, false, Chain),
        (
            "newton-slow",
            Proposal::Newton,
            Some(SLOW_RATES),
            false,
            Chain,
        ),
        (
            "ornstein-uhlenbeck",
            Proposal::OrnsteinUhlenbeck,
            None,
            false,
            Chain,
        ),
        (
            "crank-nicolson+radial",
            Proposal::CrankNicolson,
            None,
            true,
            Chain,
        ),
        (
            "newton-slow+radial",
            Proposal::Newton,
            Some(SLOW_RATES),
            true,
            Chain,
        ),
        (
            "independence",
            Proposal::CrankNicolson,
            None,
            false,
            Independence,
        ),
        (
            "independence+rb",
            Proposal::CrankNicolson,
            None,
            false,
            RaoBlackwell,
        ),
        (
            "independence-split+rb",
            Proposal::CrankNicolson,
            None,
            false,
            SplitRaoBlackwell,
        ),
    ];
    println!(
        "membrane under imposed area, {ELEMENTS} x {ELEMENTS} elements, {STRAINS} strains, se <= {TARGET} sigma_c0{}",
        if quick {
            " (quick: every 4th strain, sums scaled by 4)"
        } else {
            ""
        }
    );
    println!(
        "| set-up | proposal | dt/tau1 | acceptance | tau_int of sigma (steps, min-max) | CPU ns/step | max abs z | **CPU-s for the curve** |"
    );
    println!("|---|---|---:|---:|---:|---:|---:|---:|");
    let args: Vec<String> = std::env::args().collect();
    let chosen = |name: &str, all: &[&str]| {
        !all.iter().any(|n| args.iter().any(|a| a == n)) || args.iter().any(|a| a == name)
    };
    for set_up in set_ups() {
        if !chosen(
            set_up.name.split(' ').next().unwrap_or(""),
            &["soft", "stiff"],
        ) {
            continue;
        }
        let k_a = AREA_MODULUS;
        let base = AreaMembrane::new(set_up.membrane, ELEMENTS, ELEMENTS, k_a, 0.0).expect("model");
        let modes = PlateModes::new(base.plate()).expect("plate modes");
        let sigma_c0 = base.buckling_stress();
        let tau1 = set_up.membrane.tau1();
        let theory = AreaTheory::discrete(
            &AreaParams::from_membrane(&set_up.membrane, k_a),
            ELEMENTS,
            ELEMENTS,
        )
        .expect("theory");
        let all = curve_ratios(set_up.scene_ratios);
        let ratios: Vec<(usize, f64)> = all
            .iter()
            .copied()
            .enumerate()
            .filter(|(i, _)| !quick || i % 4 == 1)
            .collect();
        let scale = STRAINS as f64 / ratios.len() as f64;
        let models: Vec<(usize, f64, AreaMembrane, f64)> = ratios
            .iter()
            .map(|&(i, r)| {
                let m =
                    AreaMembrane::new(set_up.membrane, ELEMENTS, ELEMENTS, k_a, r * sigma_c0 / k_a)
                        .expect("model");
                (i, r, m, theory.tension_ratio(r).expect("exact tension"))
            })
            .collect();
        for (label, kind, limit, radial, sampler) in proposals {
            if !chosen(label, &proposals.map(|p| p.0)) {
                continue;
            }
            // best[strain] = the cheapest step's CPU-s
            let mut best = vec![f64::INFINITY; models.len()];
            let mut best_dt = vec![0.0; models.len()];
            // independence moves have no step: one row (the burn-in's step is the first)
            let own_steps = if sampler == Chain { steps } else { &steps[..1] };
            for &dt_tau1 in own_steps {
                let points: Vec<Point> = models
                    .iter()
                    .map(|(i, _, m, exact)| {
                        run_point(
                            m,
                            &modes,
                            (kind, limit, radial, sampler),
                            dt_tau1,
                            tau1,
                            *exact,
                            *i as u64,
                        )
                    })
                    .collect();
                let total: f64 = points.iter().map(|p| p.cpu_needed).sum::<f64>() * scale;
                for (j, p) in points.iter().enumerate() {
                    if p.cpu_needed < best[j] {
                        best[j] = p.cpu_needed;
                        best_dt[j] = dt_tau1;
                    }
                }
                let acc = points.iter().map(|p| p.acceptance).sum::<f64>() / points.len() as f64;
                let tmin = points
                    .iter()
                    .map(|p| p.tau_int)
                    .fold(f64::INFINITY, f64::min);
                let tmax = points.iter().map(|p| p.tau_int).fold(0.0, f64::max);
                let ns = points.iter().map(|p| p.ns_per_step).sum::<f64>() / points.len() as f64;
                let zmax = points.iter().map(|p| p.z.abs()).fold(0.0, f64::max); // NaN (stuck) ignored
                println!(
                    "| {} | {label} | {dt_tau1} | {acc:.3} | {tmin:.1}-{tmax:.0} | {ns:.0} | {zmax:.1} | {total:.1} |",
                    set_up.name
                );
                if std::env::args().any(|a| a == "verbose") {
                    for ((_, r, _, _), p) in models.iter().zip(&points) {
                        eprintln!(
                            "    eps/eps_c0 {r:6.2}: acc {:.3} tau {:.1} ns {:.0} cpu {:.3} z {:+.2}",
                            p.acceptance, p.tau_int, p.ns_per_step, p.cpu_needed, p.z
                        );
                    }
                }
            }
            let total: f64 = best.iter().sum::<f64>() * scale;
            let chosen: Vec<String> = best_dt.iter().map(|d| format!("{d}")).collect();
            println!(
                "| {} | {label} | best per strain ({}) | | | | | **{total:.1}** |",
                set_up.name,
                chosen.join(" ")
            );
        }
    }
}
