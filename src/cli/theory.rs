//! `langevin-fem theory …`: exact results as JSON.

use clap::{Args, Subcommand};
use langevin_fem::FilamentParams;
use langevin_fem::error::{Error, Result, require_in_range, require_positive};
use langevin_fem::spectral::HingedBeam;
use langevin_fem::theory::{
    CompressionTheory, DEFAULT_CONTINUUM_MODES, Dims, MAX_DISCRETE_ELEMENTS,
    PERSISTENCE_RATIO_RANGE, STRETCH_BEND_RATIO_RANGE, StoredLengthLaw, max_strain_ratio,
};
use serde_json::json;

/// Physical parameters shared by the theory subcommands (consistent units; times in the
/// units these imply).
#[derive(Debug, Clone, Args)]
pub struct PhysicalArgs {
    /// Filament length L.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    length: f64,
    /// Bending rigidity EI.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    bending_rigidity: f64,
    /// Transverse drag per unit length ξ.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    drag: f64,
    /// Thermal energy k_B T.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    kt: f64,
}

impl PhysicalArgs {
    /// Validates the flags (naming them as typed) and builds the hinged beam.
    fn beam(&self) -> Result<HingedBeam> {
        require_positive("--length", self.length)?;
        require_positive("--bending-rigidity", self.bending_rigidity)?;
        require_positive("--drag", self.drag)?;
        require_positive("--kt", self.kt)?;
        HingedBeam::new(FilamentParams {
            length: self.length,
            bending_rigidity: self.bending_rigidity,
            drag: self.drag,
            kt: self.kt,
            ..FilamentParams::default()
        })
    }
}

/// The examples of `theory --help`.
const EXAMPLES: &str = "\
Examples:
  langevin-fem theory variance --x 0.5
  langevin-fem theory mode --n 3 --length 10 --bending-rigidity 17 --drag 1 --kt 4.1e-3
  langevin-fem theory correlation --x 0.5 --y 0.5 --t 0.1 --eta 0.2
  langevin-fem theory compression --dims 2 --strain-ratio 0,1,3,10 --elements 20

Every result is one JSON object on stdout.";

/// Command-line arguments of `langevin-fem theory`.
#[derive(Debug, Args)]
#[command(after_help = EXAMPLES)]
pub struct TheoryArgs {
    #[command(subcommand)]
    query: Query,
}

#[derive(Debug, Subcommand)]
enum Query {
    /// Equilibrium variance ⟨w²(x)⟩ of the hinged filament (closed form of the
    /// equipartition sum, the t → ∞ limit of eq. 4).
    Variance {
        /// Position along the filament, in [0, L].
        #[arg(long, allow_negative_numbers = true)]
        x: f64,
        #[command(flatten)]
        phys: PhysicalArgs,
    },
    /// Two-time correlation ⟨w(x,t) w(y,η)⟩ from w(x,0) = 0, eq. (4), with a rigorous
    /// bound on the truncation error of the mode sum.
    Correlation {
        /// First position, in [0, L].
        #[arg(long, allow_negative_numbers = true)]
        x: f64,
        /// Second position, in [0, L].
        #[arg(long, allow_negative_numbers = true)]
        y: f64,
        /// Earlier time t, in [0, η].
        #[arg(long, allow_negative_numbers = true)]
        t: f64,
        /// Later time η ≥ t.
        #[arg(long, allow_negative_numbers = true)]
        eta: f64,
        /// Relative tolerance for the truncation bound of the mode sum.
        #[arg(long, default_value = "1e-12", allow_negative_numbers = true)]
        tolerance: f64,
        #[command(flatten)]
        phys: PhysicalArgs,
    },
    /// Relaxation rate λ_n and stationary variance of mode n (hinged ends).
    Mode {
        /// Mode number n ≥ 1.
        #[arg(long, allow_negative_numbers = true)]
        n: i64,
        #[command(flatten)]
        phys: PhysicalArgs,
    },
    /// Exact equilibrium mean compressive force ⟨F⟩/F_c0 of a hinged filament at imposed
    /// strains ε/ε_c0 (the paper's Fig. 2; no mean-field approximation). Units
    /// L = kT = ξ = 1, so EI = P and EA = S. The result depends on P and S only through
    /// S/P², which must lie in [1e-2, 1e12]: below, the filament is at the Euler limit
    /// min(ε/ε_c0, 1) and the quadrature work grows as 1/√(S/P²); above, it is under a large
    /// tension at every strain and the exact mode sum grows as (S/P²)^(1/3).
    Compression {
        /// Spatial dimension: 2 (planar) or 3.
        #[arg(long, value_enum)]
        dims: DimsArg,
        /// Comma-separated strain ratios ε/ε_c0, each in [0, 100·√S/P] (10 at the smallest
        /// S/P², 10⁸ at the largest; the work grows with ε/ε_c0).
        #[arg(long, allow_hyphen_values = true)]
        strain_ratio: String,
        /// Number of Hermite-cubic elements (the discretized filament), in [1, 2000];
        /// without it, the continuum.
        #[arg(long, allow_negative_numbers = true)]
        elements: Option<i64>,
        /// Persistence ratio P = EI/(kT·L), in [1e-3, 1e6] (with S/P² in [1e-2, 1e12]).
        #[arg(long, default_value_t = 100.0, allow_negative_numbers = true)]
        persistence_ratio: f64,
        /// Stretch ratio S = EA·L/kT, with S/P² in [1e-2, 1e12], i.e. S in
        /// [1e-2·P², 1e12·P²].
        #[arg(long, default_value_t = 1.0e6, allow_negative_numbers = true)]
        stretch_ratio: f64,
    },
}

/// Parses `--strain-ratio`: a non-empty comma-separated list of numbers in `[0, max]`
/// (`max` = [`max_strain_ratio`] of the already validated P and S, `context` names them).
fn parse_strain_ratios(list: &str, max: f64, context: &str) -> Result<Vec<f64>> {
    let allowed =
        || format!("a non-empty comma-separated list of numbers in [0, {max:e}] {context}");
    let items: Vec<&str> = list.split(',').map(str::trim).collect();
    if items.iter().all(|s| s.is_empty()) {
        return Err(Error::invalid(
            "--strain-ratio",
            format!("{list:?}"),
            allowed(),
        ));
    }
    items
        .iter()
        .map(|item| match item.parse::<f64>() {
            Ok(r) if r.is_finite() && (0.0..=max).contains(&r) => Ok(r),
            _ => Err(Error::invalid(
                "--strain-ratio",
                format!("{item:?}"),
                allowed(),
            )),
        })
        .collect()
}

/// Checks `--persistence-ratio` and `--stretch-ratio` against [`PERSISTENCE_RATIO_RANGE`]
/// and [`STRETCH_BEND_RATIO_RANGE`] (the latter as bounds on S at the given P, compared and
/// printed exactly, so that a bound copied from the message is accepted).
fn check_ratios(persistence_ratio: f64, stretch_ratio: f64) -> Result<()> {
    let (p_lo, p_hi) = PERSISTENCE_RATIO_RANGE;
    if !(persistence_ratio.is_finite() && persistence_ratio >= p_lo && persistence_ratio <= p_hi) {
        return Err(Error::invalid(
            "--persistence-ratio",
            format!("{persistence_ratio:e}"),
            format!("in [{p_lo:e}, {p_hi:e}]"),
        ));
    }
    let (k_lo, k_hi) = STRETCH_BEND_RATIO_RANGE;
    let p2 = persistence_ratio * persistence_ratio;
    let (s_lo, s_hi) = (k_lo * p2, k_hi * p2);
    if !(stretch_ratio.is_finite() && stretch_ratio >= s_lo && stretch_ratio <= s_hi) {
        return Err(Error::invalid(
            "--stretch-ratio",
            format!("{stretch_ratio:e}"),
            format!(
                "in [{s_lo:e}, {s_hi:e}] at --persistence-ratio {persistence_ratio:e} (S/P² in \
                 [{k_lo:e}, {k_hi:e}]: the force ratio depends on S/P² only; outside, the \
                 exact theory is too slow or at a known limit, see --help)"
            ),
        ));
    }
    Ok(())
}

/// `theory compression --dims`: 2 or 3.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
enum DimsArg {
    /// Planar.
    #[value(name = "2")]
    Two,
    /// Three-dimensional.
    #[value(name = "3")]
    Three,
}

/// The compression query: validates the flags and evaluates the exact theory.
fn compression(
    dims: DimsArg,
    strain_ratio: &str,
    elements: Option<i64>,
    persistence_ratio: f64,
    stretch_ratio: f64,
) -> Result<serde_json::Value> {
    let dims = Dims::from_u32(match dims {
        DimsArg::Two => 2,
        DimsArg::Three => 3,
    })?;
    check_ratios(persistence_ratio, stretch_ratio)?;
    let elements = match elements {
        None => None,
        Some(n) if n >= 1 && n <= MAX_DISCRETE_ELEMENTS as i64 => Some(n as usize),
        Some(n) => {
            return Err(Error::invalid(
                "--elements",
                n,
                format!("an integer in [1, {MAX_DISCRETE_ELEMENTS}]"),
            ));
        }
    };
    let ratios = parse_strain_ratios(
        strain_ratio,
        max_strain_ratio(persistence_ratio, stretch_ratio),
        &format!(
            "(100·√S/P at --persistence-ratio {persistence_ratio:e} and --stretch-ratio \
             {stretch_ratio:e})"
        ),
    )?;
    let params = FilamentParams {
        length: 1.0,
        bending_rigidity: persistence_ratio,
        stretch_rigidity: stretch_ratio,
        drag: 1.0,
        kt: 1.0,
    };
    let law = match elements {
        Some(n) => StoredLengthLaw::discrete(&params, dims, n)?,
        None => StoredLengthLaw::continuum(&params, dims, DEFAULT_CONTINUUM_MODES)?,
    };
    let theory = CompressionTheory::new(&params, law)?;
    let points = ratios
        .iter()
        .map(|&r| Ok(json!({ "strain_ratio": r, "force_ratio": theory.force_ratio(r)? })))
        .collect::<Result<Vec<_>>>()?;
    Ok(json!({ "dims": dims.as_u32(), "points": points }))
}

/// Runs a theory query and prints one JSON object.
pub fn run(args: TheoryArgs) -> Result<i32> {
    let value = match args.query {
        Query::Variance { x, phys } => {
            let beam = phys.beam()?;
            require_in_range("--x", x, 0.0, phys.length)?;
            json!({ "x": x, "variance": beam.profile_variance(x) })
        }
        Query::Correlation {
            x,
            y,
            t,
            eta,
            tolerance,
            phys,
        } => {
            let beam = phys.beam()?;
            require_in_range("--x", x, 0.0, phys.length)?;
            require_in_range("--y", y, 0.0, phys.length)?;
            if !(eta.is_finite() && eta >= 0.0) {
                return Err(Error::invalid("--eta", eta, "finite and >= 0"));
            }
            if !(t.is_finite() && (0.0..=eta).contains(&t)) {
                return Err(Error::invalid(
                    "--t",
                    t,
                    format!("in [0, --eta] = [0, {eta}] (the earlier time of the pair)"),
                ));
            }
            if !(tolerance.is_finite() && tolerance > 0.0 && tolerance < 1.0) {
                return Err(Error::invalid("--tolerance", tolerance, "in (0, 1)"));
            }
            let c = beam.correlation(x, y, t, eta, tolerance)?;
            json!({
                "x": x, "y": y, "t": t, "eta": eta,
                "correlation": c.value,
                "truncation_error": c.truncation_error,
                "modes": c.n_modes,
            })
        }
        Query::Mode { n, phys } => {
            let beam = phys.beam()?;
            if n < 1 {
                return Err(Error::invalid("--n", n, ">= 1"));
            }
            let n = n as usize;
            json!({ "n": n, "rate": beam.mode_rate(n), "variance": beam.mode_variance(n) })
        }
        Query::Compression {
            dims,
            strain_ratio,
            elements,
            persistence_ratio,
            stretch_ratio,
        } => compression(
            dims,
            &strain_ratio,
            elements,
            persistence_ratio,
            stretch_ratio,
        )?,
    };
    if let Some(bad) = non_finite_number(&value) {
        return Err(Error::invalid(
            bad,
            "a non-finite result",
            "parameters whose result is representable in f64 (rescale the units)",
        ));
    }
    println!("{value}");
    Ok(0)
}

/// The key of the first number in `value` that is not finite (serde_json prints those as
/// `null`), so that an overflow is an error and not a silent `null`.
fn non_finite_number(value: &serde_json::Value) -> Option<String> {
    match value {
        serde_json::Value::Object(map) => map.iter().find_map(|(k, v)| match v {
            serde_json::Value::Null => Some(k.clone()),
            serde_json::Value::Number(n) if n.as_f64().is_some_and(|f| !f.is_finite()) => {
                Some(k.clone())
            }
            other => non_finite_number(other),
        }),
        serde_json::Value::Array(items) => items.iter().find_map(non_finite_number),
        _ => None,
    }
}
