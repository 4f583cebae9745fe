//! Cost of one time step of every integrator × noise model, against the cost of drawing
//! the step's standard normals alone.
//!
//! ```sh
//! cargo bench --bench step_cost            # 10, 100 and 1000 elements
//! cargo bench --bench step_cost -- quick   # 10 and 100 elements only
//! ```
//!
//! A small self-contained harness (no criterion). Every figure is the median over
//! [`REPS`] timed loops whose iteration count is calibrated so that one loop lasts at
//! least [`TARGET`]. The machine is shared, so the loops of the O(n) integrators and of
//! the normals-alone baselines are run round-robin (repetition 1 of every case, then
//! repetition 2, ...): a change of background load then affects all of them alike
//! instead of biasing the cases that happened to run during it.
//!
//! The "normals alone" baseline fills a buffer of `draws_per_step()` standard normals
//! (one per free DOF for consistent noise, one per element for element-uniform noise)
//! from the same generator type (`Pcg64` from `trajectory_rng`) with
//! `rand_distr::StandardNormal`, as the noise generator draws them, without the banded
//! products, solves or load scatter.
//!
//! Time steps: Euler–Maruyama at half its explicit limit (Δt = 0.5 · 2/λ_max, stable),
//! every other integrator at Δt = 10⁻³ τ₁. `exact-modal` needs the dense generalized
//! eigen-decomposition (O(n³) setup). Its setup (modes + integrator) runs on a helper
//! thread while the main thread only waits; if it has not finished within
//! [`EXACT_SETUP_LIMIT`], that size and every larger one is reported as skipped. The
//! `exact-modal` cases run last, so an abandoned setup never competes with a measurement.

use langevin_fem::FilamentParams;
use langevin_fem::dynamics::{
    BatchTrajectory, ComponentBatch, Components, Integrator, IntegratorKind, ThetaBatch,
    Trajectory, build_integrator,
};
use langevin_fem::fem::banded::LANES;
use langevin_fem::fem::modal::{GeneralizedModes, generalized_modes};
use langevin_fem::fem::{BeamModel, Mesh, NoiseGenerator, NoiseModel};
use langevin_fem::rng::{TrajectoryRng, trajectory_rng};
use rand::RngExt;
use rand_distr::StandardNormal;
use std::hint::black_box;
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// Minimum duration of one timed loop.
const TARGET: Duration = Duration::from_millis(50);
/// Timed loops per figure; the median is reported.
const REPS: usize = 9;
/// Longest acceptable `exact-modal` setup (generalized modes + integrator).
const EXACT_SETUP_LIMIT: Duration = Duration::from_secs(30);
/// Master seed of the benchmark's random streams.
const SEED: u64 = 20_261_123;
/// The noise models, in table order.
const NOISES: [NoiseModel; 2] = [NoiseModel::Consistent, NoiseModel::ElementUniform];

/// Something to time: one integrator step, or one step's worth of standard normals.
enum Work {
    Step {
        filament: Components<Box<dyn Integrator>>,
        rng: TrajectoryRng,
    },
    Normals {
        buf: Vec<f64>,
        rng: TrajectoryRng,
    },
    /// One step of [`LANES`] trajectories in lockstep.
    Batch {
        batch: Box<ComponentBatch>,
        rngs: Vec<TrajectoryRng>,
    },
}

impl Work {
    fn step(integ: Box<dyn Integrator>, n_dofs: usize, stream: u64) -> Self {
        Work::Step {
            filament: Components::at_rest(integ, 1, n_dofs),
            rng: trajectory_rng(SEED, stream),
        }
    }

    fn batch(integ: ThetaBatch, stream: u64) -> Self {
        Work::Batch {
            batch: Box::new(ComponentBatch::at_rest(integ, 1)),
            rngs: (0..LANES as u64)
                .map(|l| trajectory_rng(SEED, stream * 8 + l))
                .collect(),
        }
    }

    /// Trajectory-steps per call.
    fn lanes(&self) -> usize {
        match self {
            Work::Batch { rngs, .. } => rngs.len(),
            Work::Step { .. } | Work::Normals { .. } => 1,
        }
    }

    fn normals(count: usize, stream: u64) -> Self {
        Work::Normals {
            buf: vec![0.0; count],
            rng: trajectory_rng(SEED ^ 0x5EED, stream),
        }
    }

    /// Wall time of `iters` calls.
    fn run(&mut self, iters: u64) -> Duration {
        let t = Instant::now();
        match self {
            Work::Step { filament, rng } => {
                for _ in 0..iters {
                    black_box(&mut *filament).step(rng);
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
            Work::Batch { batch, rngs } => {
                for _ in 0..iters {
                    black_box(&mut *batch).step(rngs);
                }
            }
        }
        t.elapsed()
    }

    /// Warms up and returns an iteration count for which one loop lasts ≥ [`TARGET`].
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

    /// ns per trajectory-step (per call, over the lanes of a batch) of one loop of
    /// `iters` calls.
    fn sample(&mut self, iters: u64) -> f64 {
        self.run(iters).as_secs_f64() * 1e9 / (iters * self.lanes() as u64) as f64
    }

    fn state_is_finite(&self) -> bool {
        match self {
            Work::Step { filament, .. } => filament.is_finite(),
            Work::Normals { .. } => true,
            Work::Batch { batch, rngs } => (0..rngs.len()).all(|l| batch.lane_is_finite(l)),
        }
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Median ns per call of `work`, measured on its own.
fn measure_alone(work: &mut Work) -> f64 {
    let iters = work.calibrate();
    median((0..REPS).map(|_| work.sample(iters)).collect())
}

/// Median ns per call of every work item, the repetitions interleaved round-robin.
fn measure_round_robin(works: &mut [Work]) -> Vec<f64> {
    let iters: Vec<u64> = works.iter_mut().map(Work::calibrate).collect();
    let mut samples = vec![Vec::with_capacity(REPS); works.len()];
    for _ in 0..REPS {
        for ((w, &it), s) in works.iter_mut().zip(&iters).zip(&mut samples) {
            s.push(w.sample(it));
        }
    }
    samples.into_iter().map(median).collect()
}

fn beam(n_elements: usize) -> BeamModel {
    let params = FilamentParams::default();
    BeamModel::new(
        params,
        Mesh::uniform(params.length, n_elements).expect("mesh"),
    )
    .expect("beam")
}

/// Δt of the benchmark for `kind`: half the explicit limit for Euler–Maruyama (any scheme
/// with a stability limit), 10⁻³ τ₁ otherwise.
fn time_step(kind: IntegratorKind, beam: &BeamModel, max_rate: f64) -> f64 {
    match kind.stability_limit(max_rate) {
        Some(limit) => 0.5 * limit,
        None => 1e-3 * beam.params().tau1(),
    }
}

/// Builds the `exact-modal` integrator for `noise` from the generalized modes.
fn exact_modal(
    beam: &BeamModel,
    max_rate: f64,
    modes: &GeneralizedModes,
    noise: NoiseModel,
) -> Box<dyn Integrator> {
    let dt = time_step(IntegratorKind::ExactModal, beam, max_rate);
    build_integrator(
        IntegratorKind::ExactModal,
        beam,
        noise,
        dt,
        max_rate,
        Some(modes),
    )
    .expect("exact-modal integrator")
}

/// One line of the table.
struct Row {
    elements: usize,
    kind: IntegratorKind,
    noise: NoiseModel,
    /// Trajectories stepped in lockstep (1, or [`LANES`] for [`ComponentBatch`]).
    lanes: usize,
    /// `None` if skipped (per trajectory-step).
    step_ns: Option<f64>,
    normals: usize,
    normals_ns: f64,
}

/// A stream index unique to (size, integrator, noise).
fn stream(elements: usize, kind: IntegratorKind, noise: NoiseModel) -> u64 {
    let k = IntegratorKind::LINEAR
        .iter()
        .position(|&k| k == kind)
        .unwrap_or(9);
    let z = NOISES.iter().position(|&z| z == noise).unwrap_or(9);
    (elements * 100 + k * 10 + z) as u64
}

/// The normals-alone baselines: (elements, noise, normals per step, ns).
type Baselines = Vec<(usize, NoiseModel, usize, f64)>;

/// The normals per step and their cost alone at `ne` elements with `noise`.
fn normals_ns(baselines: &Baselines, ne: usize, noise: NoiseModel) -> (usize, f64) {
    baselines
        .iter()
        .find(|b| b.0 == ne && b.1 == noise)
        .map(|b| (b.2, b.3))
        .expect("normals baseline")
}

/// θ-schemes and normals-alone baselines, measured interleaved: the table rows, the
/// baselines, and the beams with their λ_max for the `exact-modal` part.
fn measure_theta_schemes(sizes: &[usize]) -> (Vec<Row>, Baselines, Vec<(BeamModel, f64)>) {
    struct Case {
        elements: usize,
        kind: Option<IntegratorKind>,
        lanes: usize,
        noise: NoiseModel,
        normals: usize,
    }
    let mut cases = Vec::new();
    let mut works = Vec::new();
    let mut beams = Vec::new();
    for &ne in sizes {
        let b = beam(ne);
        let max_rate = b.max_rate().expect("max_rate");
        for noise in NOISES {
            let normals = NoiseGenerator::new(noise, &b)
                .expect("noise generator")
                .draws_per_step();
            cases.push(Case {
                elements: ne,
                kind: None,
                lanes: 1,
                noise,
                normals,
            });
            works.push(Work::normals(normals, (ne * 100 + 90) as u64));
            for kind in IntegratorKind::LINEAR
                .into_iter()
                .filter(|k| k.theta().is_some())
            {
                let dt = time_step(kind, &b, max_rate);
                let integ = build_integrator(kind, &b, noise, dt, max_rate, None)
                    .expect("θ-scheme integrator");
                cases.push(Case {
                    elements: ne,
                    kind: Some(kind),
                    lanes: 1,
                    noise,
                    normals,
                });
                works.push(Work::step(integ, b.n_dofs(), stream(ne, kind, noise)));
                let batch = ThetaBatch::build(kind, &b, noise, dt, max_rate)
                    .expect("batched θ-scheme")
                    .expect("lane sweeps serve the Hermite band");
                cases.push(Case {
                    elements: ne,
                    kind: Some(kind),
                    lanes: LANES,
                    noise,
                    normals,
                });
                works.push(Work::batch(batch, stream(ne, kind, noise)));
            }
        }
        beams.push((b, max_rate));
    }
    eprintln!(
        "measuring {} O(n) cases round-robin ({REPS} repetitions)...",
        works.len()
    );
    let medians = measure_round_robin(&mut works);
    for (w, c) in works.iter().zip(&cases) {
        assert!(
            w.state_is_finite(),
            "{:?} {} at {} elements: non-finite state",
            c.kind,
            c.noise,
            c.elements
        );
    }
    drop(works);
    let baselines: Baselines = cases
        .iter()
        .zip(&medians)
        .filter(|(c, _)| c.kind.is_none())
        .map(|(c, &m)| (c.elements, c.noise, c.normals, m))
        .collect();
    let rows: Vec<Row> = cases
        .iter()
        .zip(&medians)
        .filter_map(|(c, &m)| {
            c.kind.map(|kind| {
                let (normals, normals_ns) = normals_ns(&baselines, c.elements, c.noise);
                Row {
                    elements: c.elements,
                    kind,
                    noise: c.noise,
                    lanes: c.lanes,
                    step_ns: Some(m),
                    normals,
                    normals_ns,
                }
            })
        })
        .collect();
    (rows, baselines, beams)
}

/// `exact-modal`: dense setup under a deadline, measured last. The table rows and the
/// setup notes.
fn measure_exact_modal(
    beams: Vec<(BeamModel, f64)>,
    baselines: &Baselines,
) -> (Vec<Row>, Vec<String>) {
    let mut rows = Vec::new();
    let mut setup_notes = Vec::new();
    let mut skipping = false;
    for (b, max_rate) in beams {
        let ne = b.mesh().n_elements();
        let setup = if skipping {
            None
        } else {
            eprintln!("exact-modal setup at {ne} elements...");
            let (tx, rx) = mpsc::channel();
            let b2 = b.clone();
            let t = Instant::now();
            std::thread::spawn(move || {
                let modes = generalized_modes(&b2).expect("generalized modes");
                let integ = exact_modal(&b2, max_rate, &modes, NOISES[0]);
                // the receiver may have given up; nothing to do then
                let _ = tx.send((modes, integ));
            });
            match rx.recv_timeout(EXACT_SETUP_LIMIT) {
                Ok(done) => {
                    setup_notes.push(format!("{ne} elements: {:.2} s", t.elapsed().as_secs_f64()));
                    Some(done)
                }
                Err(_) => {
                    setup_notes.push(format!(
                        "{ne} elements: not finished after {:.0} s, skipped",
                        EXACT_SETUP_LIMIT.as_secs_f64()
                    ));
                    skipping = true;
                    None
                }
            }
        };
        let (modes, mut first) = match setup {
            Some((m, i)) => (Some(m), Some(i)),
            None => (None, None),
        };
        for noise in NOISES {
            let (normals, normals_ns) = normals_ns(baselines, ne, noise);
            let step_ns = modes.as_ref().map(|modes| {
                let integ = first
                    .take()
                    .unwrap_or_else(|| exact_modal(&b, max_rate, modes, noise));
                let mut w = Work::step(
                    integ,
                    b.n_dofs(),
                    stream(ne, IntegratorKind::ExactModal, noise),
                );
                let ns = measure_alone(&mut w);
                assert!(w.state_is_finite(), "exact-modal {noise}: non-finite state");
                ns
            });
            rows.push(Row {
                elements: ne,
                kind: IntegratorKind::ExactModal,
                noise,
                lanes: 1,
                step_ns,
                normals,
                normals_ns,
            });
        }
    }
    (rows, setup_notes)
}

/// Prints the table and the linearity and cost summaries.
fn report(mut rows: Vec<Row>, sizes: &[usize], setup_notes: &[String], cores: usize) {
    let order = |r: &Row| {
        let k = IntegratorKind::LINEAR.iter().position(|&k| k == r.kind);
        let z = NOISES.iter().position(|&z| z == r.noise);
        (r.elements, k, z, r.lanes)
    };
    rows.sort_by_key(order);

    println!("step_cost: wall time of one step, median of {REPS} loops of >= {TARGET:?} each");
    println!(
        "available parallelism {cores}, measured single-threaded; dt: euler-maruyama \
         0.5*2/lambda_max, others 1e-3*tau1"
    );
    println!(
        "exact-modal setup (modes + integrator): {}",
        setup_notes.join("; ")
    );
    println!();
    println!(
        "| elements | integrator | noise | lockstep | ns/step | ns/element/step | normals/step \
         | ns normals alone | step/normals |"
    );
    println!("|---:|---|---|---:|---:|---:|---:|---:|---:|");
    for r in &rows {
        let (step, per_elem, ratio) = match r.step_ns {
            Some(s) => (
                format!("{s:.0}"),
                format!("{:.1}", s / r.elements as f64),
                format!("{:.2}", s / r.normals_ns),
            ),
            None => (
                "skipped (dense setup O(n^3))".to_string(),
                "-".to_string(),
                "-".to_string(),
            ),
        };
        println!(
            "| {} | {} | {} | {} | {} | {} | {} | {:.0} | {} |",
            r.elements, r.kind, r.noise, r.lanes, step, per_elem, r.normals, r.normals_ns, ratio
        );
    }
    println!();

    let per_elem = |ne: usize, k: IntegratorKind, z: NoiseModel, lanes: usize| {
        rows.iter()
            .find(|r| r.elements == ne && r.kind == k && r.noise == z && r.lanes == lanes)
            .and_then(|r| r.step_ns.map(|s| s / ne as f64))
    };
    if sizes.contains(&1000) {
        println!(
            "Linearity of the theta-schemes: ns/element/step at 1000 over at 100 (1 = linear)"
        );
        println!();
        println!("| integrator | noise | lockstep | ratio 1000/100 |");
        println!("|---|---|---:|---:|");
        for kind in IntegratorKind::LINEAR
            .into_iter()
            .filter(|k| k.theta().is_some())
        {
            for noise in NOISES {
                for lanes in [1, LANES] {
                    if let (Some(a), Some(b)) = (
                        per_elem(1000, kind, noise, lanes),
                        per_elem(100, kind, noise, lanes),
                    ) {
                        println!("| {kind} | {noise} | {lanes} | {:.2} |", a / b);
                    }
                }
            }
        }
        println!();
    }
    println!("crank-nicolson + consistent noise, step/normals (aim: <= 2 at >= 100 elements):");
    for r in rows
        .iter()
        .filter(|r| r.kind == IntegratorKind::CrankNicolson && r.noise == NoiseModel::Consistent)
    {
        if let Some(s) = r.step_ns {
            println!(
                "  {:>5} elements, {} in lockstep: {:.2}",
                r.elements,
                r.lanes,
                s / r.normals_ns
            );
        }
    }
}

fn main() {
    let quick = std::env::args().skip(1).any(|a| a == "quick");
    let sizes: &[usize] = if quick { &[10, 100] } else { &[10, 100, 1000] };
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    let started = Instant::now();
    let (mut rows, baselines, beams) = measure_theta_schemes(sizes);
    let (exact_rows, setup_notes) = measure_exact_modal(beams, &baselines);
    rows.extend(exact_rows);
    report(rows, sizes, &setup_notes, cores);
    println!();
    println!(
        "total benchmark time {:.1} s",
        started.elapsed().as_secs_f64()
    );
}
