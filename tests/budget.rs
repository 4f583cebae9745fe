//! Budgets by target precision of compression scenes (`target_std_error`, `pilot_tau1`,
//! `max_duration_tau1`): the duration rule on a synthetic AR(1) series whose needed
//! duration is known in closed form, a scene using them parses and runs, and bad values
//! are refused with exit 2 naming the file and key.

mod common;

use common::{TempDir, describe, run, stderr_of, write_scene};
use langevin_fem::rng::trajectory_rng;
use langevin_fem::scene::Scene;
use langevin_fem::scene::compression::{DURATION_SAFETY, targeted_duration};
use langevin_fem::stats;
use rand::RngExt;
use rand_distr::StandardNormal;
use std::path::Path;

/// A stationary Gaussian AR(1) series x_{k+1} = ρ x_k + sqrt(1 − ρ²) z_k (unit variance)
/// of `n` samples from stream `index`.
fn ar1(rho: f64, n: usize, index: u64) -> Vec<f64> {
    let mut rng = trajectory_rng(20261201, index);
    let mut x: f64 = rng.sample(StandardNormal);
    let c = (1.0 - rho * rho).sqrt();
    (0..n)
        .map(|_| {
            x = rho * x + c * rng.sample::<f64, _>(StandardNormal);
            x
        })
        .collect()
}

/// The standard error of the mean of `m` independent AR(1) series of `n` samples, each
/// with its autocorrelation-aware error, combined as the runner does.
fn ensemble_se(rho: f64, m: usize, n: usize, first: u64) -> f64 {
    let parts: Vec<_> = (0..m as u64)
        .map(|j| stats::mean_with_error(&ar1(rho, n, first + j)).unwrap())
        .collect();
    stats::combine_independent(&parts).1
}

/// The duration rule on AR(1): the exact standard error of the mean of `m` series of `n`
/// samples is sqrt((1 + ρ)/((1 − ρ) n m)), so the target `t` needs
/// n* = (1 + ρ)/((1 − ρ) m t²) samples. The rule, fed a pilot's estimated error, must
/// return about `DURATION_SAFETY · n*` (the pilot's error scatters by some per cent), and
/// a fresh main stage of that length must reach the target.
#[test]
fn duration_rule_on_ar1_reaches_the_target() {
    let (rho, m, pilot_n, target) = (0.9, 16, 800, 0.01);
    let exact_n = (1.0 + rho) / ((1.0 - rho) * m as f64 * target * target);
    let max_n = 1e6;
    let mut missed = 0;
    let reps = 4;
    for r in 0..reps {
        // Pilot streams 0.., main streams from 1000 on: independent of each other.
        let pilot_se = ensemble_se(rho, m, pilot_n, 100 * r);
        let n = targeted_duration(pilot_se, pilot_n as f64, target, max_n);
        let ratio = n / (DURATION_SAFETY * exact_n);
        assert!(
            (0.7..1.3).contains(&ratio),
            "rep {r}: rule gave {n:.0} samples, exact need {exact_n:.0} x safety {DURATION_SAFETY} (ratio {ratio:.3})"
        );
        let main_se = ensemble_se(rho, m, n.round() as usize, 1000 + 100 * r);
        if main_se > target {
            missed += 1;
        }
    }
    assert_eq!(
        missed, 0,
        "main stages above the target: {missed} of {reps}"
    );
}

/// Clamping: never shorter than the pilot, never longer than the cap, the cap for a
/// non-finite pilot error; exactly the T^(-1/2) law in between.
#[test]
fn duration_rule_clamps() {
    // Pilot already 10 times better than the target: the pilot's duration.
    assert_eq!(targeted_duration(0.001, 40.0, 0.01, 2000.0), 40.0);
    // Needs far more than the cap: the cap.
    assert_eq!(targeted_duration(0.1, 40.0, 0.01, 2000.0), 2000.0);
    assert_eq!(targeted_duration(f64::NAN, 40.0, 0.01, 2000.0), 2000.0);
    assert_eq!(targeted_duration(f64::INFINITY, 40.0, 0.01, 2000.0), 2000.0);
    // Twice the target: four times the pilot, times the safety factor.
    let d = targeted_duration(0.02, 40.0, 0.01, 1e6);
    assert!((d - DURATION_SAFETY * 160.0).abs() < 1e-9, "{d}");
}

/// A small compression scene (4 elements, 3 strains) whose `full` budget is `full`.
fn scene_text(full: &str) -> String {
    format!(
        r#"description = "budget by target precision test"
seed = 7
dims = 2
model = "compression"
checks = ["force-strain"]

[filament]
length = 1.0
bending_rigidity = 100.0
stretch_rigidity = 1.0e6
drag = 1.0
kt = 1.0

[mesh]
elements = 4

[compression]
strain_ratios = [0.0, 2.0, 5.0]
burn_in_tau1 = 2.0
sample_every_tau1 = 0.05

[[runs]]
name = "metropolis"
integrator = "metropolis-crank-nicolson"
dt_tau1 = 0.02
quick = {{ trajectories = 4, duration_tau1 = 10.0 }}
standard = {{ trajectories = 4, duration_tau1 = 10.0 }}
full = {full}
"#
    )
}

const GOOD_FULL: &str =
    "{ trajectories = 4, target_std_error = 0.05, pilot_tau1 = 5.0, max_duration_tau1 = 40.0 }";

#[test]
fn a_scene_with_target_std_error_parses() {
    let s = Scene::parse(&scene_text(GOOD_FULL), Path::new("target.toml")).unwrap();
    let t = s.runs[0]
        .full
        .precision_target()
        .expect("a precision target");
    assert_eq!(
        (t.std_error, t.pilot_tau1, t.max_duration_tau1),
        (0.05, 5.0, 40.0)
    );
    assert!(s.runs[0].full.duration_tau1.is_nan());
    assert!(s.runs[0].quick.precision_target().is_none());
    assert_eq!(s.runs[0].quick.duration_tau1, 10.0);
}

/// The shipped Fig. 2 scenes use a target at the full budget.
#[test]
fn fig2_scenes_use_a_target_at_the_full_budget() {
    for name in ["compression-2d", "compression-3d"] {
        let s = common::verification_scene(name);
        let t = s.runs[0].full.precision_target().expect(name);
        assert_eq!(t.std_error, 0.01, "{name}");
    }
}

/// Runs `verify --budget full` on `scene` into `dir/<out>` (with `RAYON_NUM_THREADS =
/// threads` if given), asserts that it ran (exit 0, or 1 for a failed check) and returns
/// its `summary.json`.
fn run_full(dir: &TempDir, scene: &Path, out: &str, threads: Option<&str>) -> String {
    let out_s = dir.join_str(out);
    let args = [
        "verify",
        "--scene",
        scene.to_str().unwrap(),
        "--budget",
        "full",
        "--out",
        &out_s,
    ];
    let mut c = common::command();
    c.args(args);
    if let Some(t) = threads {
        c.env("RAYON_NUM_THREADS", t);
    }
    let o = c.output().expect("binary runs");
    assert!(
        matches!(o.status.code(), Some(0 | 1)),
        "{}",
        describe(&args, &o)
    );
    std::fs::read_to_string(dir.join(&format!("{out}/summary.json"))).unwrap()
}

/// The targeted budget runs end to end: the note names the pilot, the main stage and why
/// the errors stay honest; the quick (fixed) budget's note is unchanged in form.
#[test]
fn a_targeted_budget_runs_and_says_so() {
    let dir = TempDir::new("budget-run");
    let path = write_scene(&dir, "target", scene_text(GOOD_FULL).as_bytes());
    let summary = run_full(&dir, &path, "out", None);
    assert!(summary.contains("budget by target precision"), "{summary}");
    assert!(summary.contains("no optional-stopping bias"), "{summary}");
    assert!(!summary.contains("NaN"), "{summary}");
}

const SEARCH_FULL: &str = "{ trajectories = 4, target_std_error = 0.05, pilot_tau1 = 5.0, max_duration_tau1 = 40.0, max_dt_tau1 = 0.32, min_acceptance = 0.6 }";

/// The step search runs end to end: every strain gets a step from the ladder
/// 0.02·2^k ≤ 0.32 (the note lists them with their probe acceptance), the search
/// reaches larger steps than the scene's 0.02 in tension (acceptance there is high), and
/// every chosen step's probe met the acceptance asked, or it is the scene's own step.
#[test]
fn a_step_search_chooses_steps_per_strain_and_says_so() {
    let dir = TempDir::new("budget-search");
    let path = write_scene(&dir, "search", scene_text(SEARCH_FULL).as_bytes());
    let summary = run_full(&dir, &path, "out", None);
    let v: serde_json::Value = serde_json::from_str(&summary).unwrap();
    let notes = v["scenes"][0]["notes"].to_string();
    let start = notes.find("Chosen dt per strain (tau1): ").expect(&notes) + 29;
    let chosen: Vec<f64> = notes[start..]
        .split(';')
        .next()
        .unwrap()
        .split(", ")
        .map(|x| x.parse().unwrap())
        .collect();
    let start = notes.find("probe acceptance at the chosen dt: ").unwrap() + 35;
    let acc: Vec<f64> = notes[start..]
        .split(". Then")
        .next()
        .unwrap()
        .split(", ")
        .map(|x| x.parse().unwrap())
        .collect();
    assert_eq!(chosen.len(), 3, "{notes}");
    for (&d, &a) in chosen.iter().zip(&acc) {
        let k = (d / 0.02).log2();
        assert!((k - k.round()).abs() < 1e-9 && d <= 0.32, "{d}");
        assert!(a >= 0.6 || d == 0.02, "dt {d} with acceptance {a}");
    }
    assert!(chosen[0] > 0.02, "{chosen:?}");
    assert!(!summary.contains("NaN"), "{summary}");
}

/// The step search and the budget it drives do not depend on the thread count: the
/// full budget with a search (probes and pilot in parallel over strains, main stage over
/// strain × trajectory) writes byte-identical CSV files with 1 and 2 threads.
#[test]
fn a_step_search_does_not_depend_on_the_thread_count() {
    let dir = TempDir::new("budget-threads");
    let path = write_scene(&dir, "search", scene_text(SEARCH_FULL).as_bytes());
    let mut csv = Vec::new();
    for threads in ["1", "2"] {
        let out = format!("out{threads}");
        run_full(&dir, &path, &out, Some(threads));
        csv.push(std::fs::read(dir.join(&format!("{out}/search/force-strain.csv"))).unwrap());
    }
    assert!(
        csv[0] == csv[1],
        "force-strain.csv differs between 1 and 2 threads"
    );
}

/// A bad scene `text` (written as `bad.toml`): `verify` exits 2 without a panic, and the
/// message names the file and contains every one of `needles`.
fn assert_text_refused(text: &str, needles: &[&str]) {
    let dir = TempDir::new("budget-bad");
    let path = write_scene(&dir, "bad", text.as_bytes());
    let out = dir.join_str("out");
    let args = [
        "verify",
        "--scene",
        path.to_str().unwrap(),
        "--budget",
        "quick",
        "--out",
        &out,
    ];
    let o = run(&args);
    assert_eq!(o.status.code(), Some(2), "{}", describe(&args, &o));
    let err = stderr_of(&o);
    for want in std::iter::once(&"bad.toml").chain(needles) {
        assert!(err.contains(want), "{want:?} not in: {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
}

/// A bad targeted budget: exit 2, the message names the file, the key and the value.
fn assert_refused(full: &str, key: &str, value: &str) {
    assert_text_refused(&scene_text(full), &[key, value]);
}

#[test]
fn bad_targets_are_refused_naming_the_key() {
    assert_refused(
        "{ trajectories = 4, target_std_error = -0.01, pilot_tau1 = 5.0, max_duration_tau1 = 40.0 }",
        "runs[0].full.target_std_error",
        "-0.01",
    );
    assert_refused(
        "{ trajectories = 4, target_std_error = 0.05, pilot_tau1 = 50.0, max_duration_tau1 = 40.0 }",
        "runs[0].full.pilot_tau1",
        "<= max_duration_tau1 = 40",
    );
    assert_refused(
        "{ trajectories = 4, target_std_error = 0.05, max_duration_tau1 = 40.0 }",
        "runs[0].full.pilot_tau1",
        "given with target_std_error",
    );
    assert_refused(
        "{ trajectories = 4, duration_tau1 = 10.0, target_std_error = 0.05, pilot_tau1 = 5.0, max_duration_tau1 = 40.0 }",
        "runs[0].full.duration_tau1",
        "left out when target_std_error",
    );
    assert_refused(
        "{ trajectories = 4, duration_tau1 = 10.0, pilot_tau1 = 5.0 }",
        "runs[0].full.pilot_tau1",
        "unless target_std_error",
    );
    assert_refused(
        "{ trajectories = 4 }",
        "runs[0].full.duration_tau1",
        "given (sampled duration",
    );
    assert_refused(
        "{ trajectories = 4, target_std_error = 0.05, pilot_tau1 = 0.1, max_duration_tau1 = 40.0 }",
        "runs[0].full.pilot_tau1",
        ">= 16 x sample_every_tau1",
    );
}

/// A compression step so small that a trajectory would take more than 1e10 steps (or
/// overflow the step count) is refused naming dt_tau1, before anything runs.
#[test]
fn a_vanishing_compression_step_is_refused() {
    for dt in ["1.0e-300", "1.0e-9"] {
        let text = scene_text(GOOD_FULL).replace("dt_tau1 = 0.02", &format!("dt_tau1 = {dt}"));
        assert_text_refused(&text, &["runs[0].dt_tau1", "1e10 steps per trajectory"]);
    }
}

/// A Δt-halving pair naming one run twice would compare the run with itself: refused.
#[test]
fn a_halving_pair_of_one_run_is_refused() {
    let text = scene_text(GOOD_FULL)
        .replace(
            "checks = [\"force-strain\"]",
            "checks = [\"force-strain\", \"dt-halving\"]",
        )
        .replace(
            "sample_every_tau1 = 0.05",
            "sample_every_tau1 = 0.05\nhalving = [\"metropolis\", \"metropolis\"]",
        );
    assert_text_refused(
        &text,
        &["compression.halving[1]", "metropolis", "another run"],
    );
}

#[test]
fn bad_step_searches_are_refused_naming_the_key() {
    let with = |extra: &str| {
        format!(
            "{{ trajectories = 4, target_std_error = 0.05, pilot_tau1 = 5.0, max_duration_tau1 = 40.0, {extra} }}"
        )
    };
    assert_refused(
        &with("max_dt_tau1 = 0.32"),
        "runs[0].full.min_acceptance",
        "given with max_dt_tau1",
    );
    assert_refused(
        &with("min_acceptance = 0.6"),
        "runs[0].full.max_dt_tau1",
        "given with min_acceptance",
    );
    assert_refused(
        &with("max_dt_tau1 = 0.01, min_acceptance = 0.6"),
        "runs[0].full.max_dt_tau1",
        "in [dt_tau1 = 0.02, 100]",
    );
    assert_refused(
        &with("max_dt_tau1 = 0.32, min_acceptance = 1.0"),
        "runs[0].full.min_acceptance",
        "in (0, 1)",
    );
    assert_refused(
        "{ trajectories = 4, duration_tau1 = 10.0, max_dt_tau1 = 0.32 }",
        "runs[0].full.max_dt_tau1",
        "unless target_std_error",
    );
    // Only for the Metropolis scheme (exact at any dt).
    let text = scene_text(&with("max_dt_tau1 = 0.32, min_acceptance = 0.6"))
        .replace("metropolis-crank-nicolson", "crank-nicolson");
    assert_text_refused(&text, &["runs[0].full.max_dt_tau1", "exact at any dt"]);
}

/// A target in a linear scene is refused (budgets by target precision are for
/// compression scenes).
#[test]
fn a_target_in_a_linear_scene_is_refused() {
    let text =
        std::fs::read_to_string(common::fixture("tests/scenes/good/tiny-linear.toml")).unwrap();
    let full_line = text
        .lines()
        .find(|l| l.trim_start().starts_with("full ="))
        .expect("a full budget line");
    let text = text.replace(
        full_line,
        "full = { trajectories = 4, target_std_error = 0.05, pilot_tau1 = 5.0, max_duration_tau1 = 40.0 }",
    );
    assert_text_refused(&text, &["full.target_std_error", "model = \"compression\""]);
}
