//! `langevin-fem fit`: the bending rigidity and the drag (and, with EI known, the noise
//! temperature) that a filament's or a membrane's data imply, with 95 % intervals
//! ([`langevin_fem::verify::fit`]), from the checks `check` applies to the same data.

use super::Verbosity;
use super::check::{CheckArgs, evaluate, load_data, print_verdict};
use clap::Args;
use langevin_fem::data::{DataFilament, DataMembrane, DataSidecar};
use langevin_fem::error::{Error, Result};
use langevin_fem::report::write_report;
use langevin_fem::spectral::membrane::Membrane;
use langevin_fem::verify::diagnosis::membrane_sensitivities;
use langevin_fem::verify::fit::{
    FitBase, JointFit, RunFit, SensitivityOf, estimate_text, fit_runs, number_text,
};
use langevin_fem::verify::summary::SceneSummary;
use serde::Serialize;
use std::time::Instant;

/// The examples of `fit --help`.
const EXAMPLES: &str = "\
Examples:
  langevin-fem run -s hinged-linear-2d --run crank-nicolson -o traj
  langevin-fem fit -s hinged-linear-2d -d traj -o traj-fit
  langevin-fem run -s membrane-periodic --run crank-nicolson -o mem
  langevin-fem fit -s membrane-periodic -d mem -o mem-fit       kappa; kappa and sigma

Prints per run EI (a membrane: kappa) from the mode variances with kT known, xi from the
decay rates with that EI, and kT with EI known instead, each with its 95 % interval;
writes them to fit.json in the output directory, beside the report of `check` on the same
data. For a membrane, kappa is fitted with the tension sigma held at the sidecar's value
(its modes' variances regressed on their bending shares kappa q^4/(kappa q^4 + sigma q^2)),
then kappa and sigma together. Exit 0 when every run gave a fit, 3 when a run's checks
hold no mode variance to fit, 2 on bad input.";

/// Command-line arguments of `langevin-fem fit`: those of `check`.
#[derive(Debug, Args)]
#[command(after_help = EXAMPLES)]
pub struct FitArgs {
    #[command(flatten)]
    pub(super) check: CheckArgs,
}

/// What `fit.json` holds.
#[derive(Serialize)]
struct FitFile<'a> {
    scene: &'a str,
    data: String,
    level: f64,
    runs: &'a [RunFit],
}

/// The object of a data set, as `fit` scales its parameters.
enum FitObject {
    /// A filament: EI, every mode's bending share 1.
    Filament(DataFilament),
    /// A membrane: κ, with the tension σ held at the sidecar's value.
    Membrane(DataMembrane, Option<Membrane>),
}

impl FitObject {
    /// The object of `sidecar`, if it has one `fit` serves.
    fn of(sidecar: &DataSidecar) -> Option<FitObject> {
        match (&sidecar.filament, &sidecar.membrane) {
            (Some(f), _) => Some(FitObject::Filament(*f)),
            (None, Some(m)) => Some(FitObject::Membrane(*m, Membrane::new(m.params()).ok())),
            (None, None) => None,
        }
    }

    /// The name of the bending rigidity in the printed fit.
    fn name(&self) -> &'static str {
        match self {
            FitObject::Filament(_) => "EI",
            FitObject::Membrane(..) => "kappa",
        }
    }

    /// What is held known besides kT (`, sigma = 20 held`), or nothing.
    fn held(&self) -> String {
        match self {
            FitObject::Membrane(m, _) if m.tension != 0.0 => {
                format!(", sigma = {} held", m.tension)
            }
            _ => String::new(),
        }
    }

    /// The log sensitivities of checked mode `mode` ([`membrane_sensitivities`]); `None`
    /// for a filament.
    fn sensitivities(&self, mode: &str) -> Option<[f64; 2]> {
        let FitObject::Membrane(_, Some(m)) = self else {
            return None;
        };
        membrane_sensitivities(m, mode)
    }

    /// The sidecar's parameters, with a membrane's tension and `sensitivities` (this
    /// object's [`Self::sensitivities`]).
    fn base<'a>(&self, sensitivities: SensitivityOf<'a>) -> FitBase<'a> {
        match self {
            FitObject::Filament(f) => FitBase {
                bending_rigidity: f.bending_rigidity,
                drag: f.drag,
                kt: f.kt,
                tension: None,
            },
            FitObject::Membrane(m, _) => FitBase {
                bending_rigidity: m.bending_rigidity,
                drag: m.drag,
                kt: m.kt,
                tension: Some((m.tension, sensitivities)),
            },
        }
    }
}

/// Runs the checks of `check`, then the fit of every run; prints the fits after the
/// scene lines.
pub fn run(args: FitArgs, verbosity: Verbosity) -> Result<i32> {
    let start = Instant::now();
    let args = args.check;
    let sidecar = load_data(&args)?;
    let object = FitObject::of(&sidecar).ok_or_else(|| {
        Error::invalid(
            "--data",
            args.data.display(),
            "filament or membrane data (a `filament` or `membrane` table in data.json): fit estimates their bending rigidity and drag",
        )
    })?;
    let (scene, mut summary, report) = evaluate(&args, &sidecar, verbosity.progress())?;
    if scene.compression.is_some() {
        return Err(Error::invalid(
            "--scene",
            &scene.name,
            "a linear scene (mode variances and decay rates): a compression scene's force data do not fit EI this way",
        ));
    }
    let sensitivities = |mode: &str| object.sensitivities(mode);
    let fits = fit_runs(&summary.scenes[0], &object.base(&sensitivities));
    let mut lines = Vec::new();
    for f in &fits {
        let (Some(v), Some(kt)) = (&f.variance, &f.kt_given_bending_rigidity) else {
            return Err(no_variances(&summary.scenes[0], &f.run));
        };
        // Under tension, κ with σ held comes from the modes' bending shares.
        let Some(ei) = &f.bending_rigidity else {
            return Err(no_bending_fit(&object, &f.run, &v.modes));
        };
        let (name, held) = (object.name(), object.held());
        let bending = f.bending_regression.as_ref().unwrap_or(v);
        let mut parts = vec![estimate_text(
            name,
            ei,
            bending,
            "variances",
            &format!("kT known{held}"),
            f.bending_regression.is_some(),
        )];
        if let (Some(r), Some(xi)) = (&f.rate, &f.drag) {
            parts.push(estimate_text(
                "xi",
                xi,
                r,
                "decay rates",
                &format!("with that {name}"),
                false,
            ));
        }
        parts.push(estimate_text(
            "kT",
            kt,
            v,
            "variances",
            &format!("{name} known instead"),
            false,
        ));
        if let Some(j) = &f.joint {
            parts.push(joint_text(j));
        }
        summary.scenes[0].notes.push(format!(
            "fit, run {} (95 % intervals): {}",
            f.run,
            parts.join("; ")
        ));
        lines.push(format!("fit {} (95 % intervals):", f.run));
        lines.extend(parts.iter().map(|p| format!("    {p}")));
    }
    report.write_json(
        &args.out.join("fit.json"),
        &FitFile {
            scene: &scene.name,
            data: args.data.display().to_string(),
            level: langevin_fem::verify::fit::LEVEL,
            runs: &fits,
        },
    )?;
    write_report(report, &summary)?;
    print_verdict(&args, &summary, verbosity, start, &lines);
    Ok(0)
}

/// Why run `run` has no pooled variance: its checks' estimates are not positive (data
/// of all but zero variance), its scene has no `mode-variance` checks, or every one was
/// skipped (named with the first reason).
fn no_variances(scene: &SceneSummary, run: &str) -> Error {
    let prefix = format!("{run}/mode-variance/");
    let skipped = scene
        .skipped
        .iter()
        .filter(|c| c.name.starts_with(&prefix))
        .collect::<Vec<_>>();
    let checked: Vec<_> = scene
        .checks
        .iter()
        .filter(|c| c.name.starts_with(&prefix))
        .collect();
    let (value, allowed) = match (checked.first(), skipped.first()) {
        (Some(c), _) => (
            format!("{} without a positive estimate", checked.len()),
            format!(
                "checks whose estimated variance is positive and finite, for a ratio to the reference (the first: {} estimates {:e} against {:e}: are the data's heights or amplitudes all but zero?)",
                c.name,
                c.estimate.unwrap_or(f64::NAN),
                c.reference.unwrap_or(f64::NAN)
            ),
        ),
        (None, None) => (
            "none".to_string(),
            "at least one (the scene's checks must include mode-variance)".to_string(),
        ),
        (None, Some(first)) => (
            format!("{} skipped", skipped.len()),
            format!(
                "at least one that the data allow (the first skipped: {}: {})",
                first.name, first.reason
            ),
        ),
    };
    Error::run_failed(
        format!("data run {run}"),
        "fit",
        Error::invalid("mode-variance checks", value, allowed),
    )
}

/// Why a membrane's κ with σ held could not be fitted in run `run` from `modes`: a mode
/// without a bending share (not `n=k`), or shares that cannot carry κ (all near 0: the
/// tension sets the variances; or the fit in the law did not converge).
fn no_bending_fit(object: &FitObject, run: &str, modes: &[String]) -> Error {
    let shares: Option<Vec<f64>> = modes
        .iter()
        .map(|m| object.sensitivities(m).map(|s| s[0]))
        .collect();
    let inner = match shares {
        None => Error::invalid(
            "mode-variance checks",
            modes.join(", "),
            "checked modes n=k of the membrane, each with a bending share",
        ),
        Some(shares) => {
            let (lo, hi) = shares.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &s| {
                (lo.min(s), hi.max(s))
            });
            Error::invalid(
                "membrane.bending_rigidity",
                format!(
                    "one whose modes' bending shares κq⁴/(κq⁴ + σq²) lie in [{lo:.3e}, {hi:.3e}]"
                ),
                "fittable with sigma held, but the fit in the stiffness law did not converge (with shares near 0 the tension sets the variances and κ cannot be seen: check that κ and σ in data.json are the simulated ones)",
            )
        }
    };
    Error::run_failed(format!("data run {run}"), "fit", inner)
}

/// `kappa = 1.0989 [1.0954, 1.1025] and sigma = 19.93 [19.21, 20.65] together from the
/// variances of modes 1, …, 24, kT known (correlation -0.93; χ² p = 0.559); with them xi =
/// 1.0027 [0.9990, 1.0064] from the decay rates`.
fn joint_text(j: &JointFit) -> String {
    let f = number_text;
    let (k, s) = (&j.bending_rigidity, &j.tension);
    let xi = j.drag.as_ref().map_or(String::new(), |x| {
        format!(
            "; with them xi = {} [{}, {}] from the decay rates",
            f(x.value),
            f(x.interval[0]),
            f(x.interval[1])
        )
    });
    format!(
        "kappa = {} [{}, {}] and sigma = {} [{}, {}] together from the variances of modes {}, kT known (correlation {:.2}; χ² p = {:.3}){xi}",
        f(k.value),
        f(k.interval[0]),
        f(k.interval[1]),
        f(s.value),
        f(s.interval[0]),
        f(s.interval[1]),
        j.modes
            .iter()
            .map(|m| m.trim_start_matches("n="))
            .collect::<Vec<_>>()
            .join(", "),
        j.correlation,
        j.p_value
    )
}
