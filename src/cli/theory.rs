//! `langevin-fem theory …`: exact results as JSON.

use clap::{Args, Subcommand};
use langevin_fem::FilamentParams;
use langevin_fem::error::{Error, Result, require_in_range, require_positive};
use langevin_fem::spectral::HingedBeam;
use serde_json::json;

/// Physical parameters shared by the theory subcommands (consistent units; times in the
/// units these imply).
#[derive(Debug, Clone, Args)]
pub struct PhysicalArgs {
    /// Filament length L.
    #[arg(long, default_value_t = 1.0)]
    length: f64,
    /// Bending rigidity EI.
    #[arg(long, default_value_t = 1.0)]
    bending_rigidity: f64,
    /// Transverse drag per unit length ξ.
    #[arg(long, default_value_t = 1.0)]
    drag: f64,
    /// Thermal energy k_B T.
    #[arg(long, default_value_t = 1.0)]
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

#[derive(Debug, Args)]
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
        #[arg(long, default_value_t = 1e-12)]
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
            require_in_range("--t", t, 0.0, eta)?;
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
    };
    println!("{value}");
    Ok(0)
}
