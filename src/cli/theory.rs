//! `langevin-fem theory …`: exact results as JSON.

use clap::{Args, Subcommand};
use langevin_fem::FilamentParams;
use langevin_fem::dynamics::{IntegratorKind, ModeLaw};
use langevin_fem::error::{Error, Result, require_in_range, require_positive};
use langevin_fem::fem::noise::{NoiseModel, element_uniform_mode_ratio};
use langevin_fem::fem::plate::PlateModel;
use langevin_fem::fem::plate_area::{
    AREA_BENDING_RANGE, AreaCutoff, AreaParams, AreaTheory, MAX_AREA_ASPECT_RATIO,
    MAX_AREA_CUTOFF_INDEX, MAX_AREA_ELEMENTS, max_area_strain_ratio, mesh_convergence,
};
use langevin_fem::fem::plate_modes::PlateModes;
use langevin_fem::params::Ends;
use langevin_fem::spectral::{
    EndedBeam, HingedBeam, Membrane, MembraneBoundary, MembraneMode, MembraneParams, ModeShape,
};
use langevin_fem::theory::{
    CompressionTheory, DEFAULT_CONTINUUM_MODES, Dims, MAX_DISCRETE_ELEMENTS, MIN_STRAIN_RATIO,
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
    /// Ends of the filament, `<left>-<right>` with the left end at x = 0, each hinged
    /// (w = w'' = 0), clamped (w = w' = 0) or free (w'' = w''' = 0), e.g. clamped-free; one
    /// name for both ends. Other than hinged, the output adds the ends and, where the ends
    /// allow rigid motions (free-free, hinged-free, free-hinged), their diffusion laws.
    #[arg(long, default_value = "hinged")]
    ends: String,
}

/// The values `--ends` allows.
const ENDS_ALLOWED: &str = "`<left>-<right>` (left end at x = 0) with each of hinged, clamped, \
                            free (e.g. clamped-free), or one name for both ends";

impl PhysicalArgs {
    /// The parsed `--ends`.
    fn parsed_ends(&self) -> Result<Ends> {
        self.ends
            .parse::<Ends>()
            .map_err(|_| Error::invalid("--ends", format!("{:?}", self.ends), ENDS_ALLOWED))
    }

    /// Validates the flags (naming them as typed) and builds the filament with its ends.
    fn ended(&self) -> Result<EndedBeam> {
        let ends = self.parsed_ends()?;
        let hinged = self.beam()?;
        EndedBeam::new(hinged.params, ends)
    }

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
  langevin-fem theory mode --n 3 --ends clamped-free
  langevin-fem theory variance --x 1 --ends clamped-free
  langevin-fem theory compression --dims 2 --strain-ratio 0,1,3,10 --elements 20
  langevin-fem theory membrane --boundary periodic --m 1 --n 0 --tension 0.5 --cutoff 100
  langevin-fem theory area --strain-ratio -10,0,1,3,10 --elements 16

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
    /// Equilibrium variance ⟨w²(x)⟩ of the filament (closed form of the equipartition
    /// sum, the t → ∞ limit of eq. 4); with --ends other than hinged, of its elastic part
    /// (rigid modes projected out).
    Variance {
        /// Position along the filament, in [0, L].
        #[arg(long, allow_negative_numbers = true)]
        x: f64,
        #[command(flatten)]
        phys: PhysicalArgs,
    },
    /// Two-time correlation ⟨w(x,t) w(y,η)⟩ from w(x,0) = 0, eq. (4), with a rigorous
    /// bound on the truncation error of the mode sum; with --ends other than hinged, over
    /// the elastic modes of those ends, with the rigid modes' part given separately.
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
    /// Relaxation rate λ_n and stationary variance of mode n; with --ends other than
    /// hinged, of elastic mode n of those ends, with its wavenumber q_n, the convention and
    /// the rigid modes' diffusion laws.
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
        /// S/P², 10⁸ at the largest; the work grows with ε/ε_c0) or, in tension, in
        /// [-1e8, 0].
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
    /// Exact continuum results of the Helfrich membrane ξ∂h/∂t = −κ∇⁴h + σ∇²h + f on an
    /// a × b rectangle: wavevector, stiffness c_q = κq⁴ + σq², rate c_q/ξ and variance of
    /// mode (m, n) with its convention; the point variance ⟨h²(x, y)⟩ with a rigorous
    /// bound; with --cutoff, the excess area ⟨ΔA⟩ and Var ΔA of the modes with |q| ≤ Q.
    Membrane(MembraneArgs),
    /// Exact equilibrium tension ⟨σ⟩/σ_c0 of a fluid membrane (true area A₀ = ab, bending
    /// rigidity κ, area modulus K_A) whose frame imposes the projected area (1 − ε)A₀, at
    /// strains ε/ε_c0 (σ_c0 = κq²_min, ε_c0 = σ_c0/K_A; no mean-field approximation): the
    /// filament's Fig. 2 theory with EA → K_A, L → A₀, F → −σ. Units kT = 1: κ is in kT,
    /// --stretch-ratio S = K_A·A₀/kT, σ in kT per squared length unit. The result depends on
    /// κ and S only through S/κ², which must lie in [1e-2, 1e12], and on the sides only
    /// through b/a. Either the exact Bogner–Fox–Schmit mesh (--elements) or the continuum
    /// cut off at lattice indices (--cutoff: its ⟨ΔA⟩ grows as the log of the cutoff).
    Area(AreaArgs),
}

/// Flags of `theory area` (units kT = 1).
#[derive(Debug, Clone, Args)]
pub struct AreaArgs {
    /// Boundary conditions.
    #[arg(long, value_enum, default_value = "simply-supported")]
    boundary: BoundaryArg,
    /// Side a along x.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    width: f64,
    /// Side b along y, with b/a in [0.1, 10].
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    height: f64,
    /// Bending rigidity κ/kT, in [1e-3, 1e6] (with S/κ² in [1e-2, 1e12]).
    #[arg(long, default_value_t = 20.0, allow_negative_numbers = true)]
    bending_rigidity: f64,
    /// Stretch ratio S = K_A·A₀/kT, with S/κ² in [1e-2, 1e12].
    #[arg(long, default_value_t = 1.0e6, allow_negative_numbers = true)]
    stretch_ratio: f64,
    /// Comma-separated strain ratios ε/ε_c0, each in [0, 100·√S·π²/(κq²_min·A₀)]
    /// (compression; the work grows with ε/ε_c0) or in [-1e8, 0] (tension).
    #[arg(long, allow_hyphen_values = true)]
    strain_ratio: String,
    /// The exact discrete theory of a uniform N × NY Bogner–Fox–Schmit mesh (`N` or
    /// `N,NY`; NY defaults to N), each in [1, 128] ([2, 128] periodic).
    #[arg(long, allow_hyphen_values = true, conflicts_with = "cutoff")]
    elements: Option<String>,
    /// The continuum with the acoustic modes of an NX × NY mesh (`NX` or `NX,NY`): simply
    /// supported 1 ≤ m < NX, 1 ≤ n < NY; periodic 2|m| < NX, 2|n| < NY; each in [2, 256]
    /// ([3, 256] periodic).
    #[arg(long, allow_hyphen_values = true)]
    cutoff: Option<String>,
    /// Convergence over meshes: comma-separated element counts per side, strictly
    /// ascending, each in [2, 64] ([3, 64] periodic). Per mesh: the whole mesh's curve
    /// (which drifts with the mesh: its thermal excess area grows as the log of the mode
    /// cutoff, Helfrich–Servuss), the continuum at the mesh's own cutoff, and the
    /// discretization error separated from that drift: the mesh's modes within the first
    /// mesh's lattice cutoff against the continuum at that fixed cutoff, with the observed
    /// order (4 for these elements).
    #[arg(long, allow_hyphen_values = true, conflicts_with_all = ["elements", "cutoff"])]
    mesh_convergence: Option<String>,
}

/// `theory membrane --boundary`.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
enum BoundaryArg {
    /// h = ∇²h = 0 on the edges: modes sin(mπx/a) sin(nπy/b), m, n ≥ 1.
    SimplySupported,
    /// Periodic in x and y: modes cos(q·r), sin(q·r), q = 2π(m/a, n/b) ≠ 0.
    Periodic,
}

/// Flags of `theory membrane` (consistent units).
#[derive(Debug, Clone, Args)]
pub struct MembraneArgs {
    /// Boundary conditions.
    #[arg(long, value_enum, default_value = "simply-supported")]
    boundary: BoundaryArg,
    /// Bending rigidity κ (energy).
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    bending_rigidity: f64,
    /// Tension σ (energy per area), above the buckling tension −κ·q_min².
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    tension: f64,
    /// Friction ξ per unit area.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    drag: f64,
    /// Thermal energy k_B T.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    kt: f64,
    /// Side a along x.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    width: f64,
    /// Side b along y.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    height: f64,
    /// Mode index m along x (≥ 1 simply supported; any integer periodic, (m, n) ≠ (0, 0)).
    #[arg(long, default_value_t = 1, allow_negative_numbers = true)]
    m: i64,
    /// Mode index n along y (≥ 1 simply supported; any integer periodic).
    #[arg(long, default_value_t = 1, allow_negative_numbers = true)]
    n: i64,
    /// Position x of the point variance, in [0, a] (default a/2).
    #[arg(long, allow_negative_numbers = true)]
    x: Option<f64>,
    /// Position y of the point variance, in [0, b] (default b/2).
    #[arg(long, allow_negative_numbers = true)]
    y: Option<f64>,
    /// Bound on the truncation error of the point variance, relative to the variance of
    /// the slowest mode, in (0, 1).
    #[arg(long, default_value = "1e-10", allow_negative_numbers = true)]
    tolerance: f64,
    /// Wavenumber cutoff Q of the excess area (modes with |q| ≤ Q; ⟨ΔA⟩ grows as ln Q).
    #[arg(long, allow_negative_numbers = true)]
    cutoff: Option<f64>,
    /// Also the finite elements: a uniform mesh of this many Bogner–Fox–Schmit plate
    /// elements along x (the discrete rate and variance of mode (m, n), its error, the
    /// element-uniform noise's variance ratio; with --dt, the exact discrete law of
    /// --integrator). At most 64 (the plate's separable modes are computed in full).
    #[arg(long)]
    elements: Option<usize>,
    /// Elements along y (default: --elements).
    #[arg(long, requires = "elements")]
    elements_y: Option<usize>,
    /// Time step of the discrete law (consistent time units), with --elements.
    #[arg(long, requires = "elements", allow_negative_numbers = true)]
    dt: Option<f64>,
    /// Integrator of the discrete law: euler-maruyama, backward-euler, crank-nicolson or
    /// exact-modal.
    #[arg(long, default_value = "crank-nicolson", requires = "dt")]
    integrator: String,
    /// Noise of the discrete law: consistent or element-uniform.
    #[arg(long, default_value = "consistent", requires = "dt")]
    noise: String,
}

/// The smallest rate·Δt of the mode `theory membrane --dt` gives the discrete law of.
const MIN_RATE_DT: f64 = 1e-9;

/// The most plate elements per side `theory membrane --elements` takes.
const MAX_THEORY_PLATE_ELEMENTS: usize = 64;

/// The finite-element part of `theory membrane`: the acoustic plate mode converging to
/// `mode` on `nx × ny` elements, its rate and (continuum-convention) variance, the
/// element-uniform noise's ratio (eq. 5 per element area) and, with `dt`, the exact
/// discrete law of `integrator` with `noise` ([`ModeLaw`], the diagonal of the whole law).
fn membrane_fem(
    args: &MembraneArgs,
    mb: &Membrane,
    mode: MembraneMode,
    nx: usize,
) -> Result<serde_json::Value> {
    let ny = args.elements_y.unwrap_or(nx);
    for (flag, v) in [("--elements", nx), ("--elements-y", ny)] {
        if !(1..=MAX_THEORY_PLATE_ELEMENTS).contains(&v) {
            return Err(Error::invalid(
                flag,
                v,
                format!("in [1, {MAX_THEORY_PLATE_ELEMENTS}]"),
            ));
        }
    }
    // The library names the mesh sizes nx and ny; here they are the two flags.
    let plate = PlateModel::new(mb.params, nx, ny).map_err(|e| {
        let flag = match &e {
            Error::InvalidParameter { name, .. } if name == "nx" => "--elements",
            Error::InvalidParameter { name, .. } if name == "ny" => "--elements-y",
            _ => return as_flag(e),
        };
        as_flag_named(flag)(e)
    })?;
    let modes = PlateModes::new(&plate)?;
    let Some(fe) = modes.acoustic(mode) else {
        return Err(Error::invalid(
            "--m/--n",
            format!("({}, {})", mode.m, mode.n),
            format!("a mode the {nx} x {ny} mesh resolves (index below its element count)"),
        ));
    };
    let rate = fe.rate;
    let exact = mb.mode_rate(mode);
    // The continuum amplitude's variance scaled by the ratio of the rates: the variance
    // of the discrete mode's amplitude (kT/λ_h of its C-normalized amplitude) in the
    // continuum's convention.
    let variance = mb.mode_variance(mode) * exact / rate;
    let index = modes.position(mode).ok_or_else(|| Error::Numerical {
        routine: "theory membrane".into(),
        detail: "the acoustic mode has no index among the modes".into(),
    })?;
    let uniform_ratio = element_uniform_mode_ratio(&plate, &modes.mode_vector(index));
    // The separable modes are all of them: the largest rate is λ_max, exactly (the banded
    // inertia bisection would cost O(n·bw²) per step at 64 × 64).
    let max_rate = modes.rates().into_iter().fold(0.0, f64::max);
    let mut out = json!({
        "elements": [nx, ny],
        "unknowns": plate.n_dofs(),
        "rate": rate,
        "rate_relative_error": rate / exact - 1.0,
        "variance": variance,
        "element_uniform_variance_ratio": uniform_ratio,
        "max_rate": max_rate,
    });
    if let Some(dt) = args.dt {
        out["discrete"] = membrane_discrete(
            args,
            &plate,
            dt,
            (rate, max_rate),
            (variance, uniform_ratio),
        )?;
    }
    Ok(out)
}

/// The `discrete` part of `theory membrane --elements --dt`: the exact discrete law
/// ([`ModeLaw`]) of the plate mode of generalized rate `rate` under `--integrator` and
/// `--noise` at step `dt` (`max_rate`: the mesh's λ_max), its variance in the continuum's
/// convention (`variance` at equipartition) and, for the element-uniform load, its noise
/// ratio `uniform_ratio`.
fn membrane_discrete(
    args: &MembraneArgs,
    plate: &PlateModel,
    dt: f64,
    (rate, max_rate): (f64, f64),
    (variance, uniform_ratio): (f64, f64),
) -> Result<serde_json::Value> {
    require_positive("--dt", dt)?;
    let integrator: IntegratorKind = args
        .integrator
        .parse()
        .map_err(as_flag_named("--integrator"))?;
    if !IntegratorKind::LINEAR.contains(&integrator) {
        return Err(Error::invalid(
            "--integrator",
            integrator,
            IntegratorKind::list(&IntegratorKind::LINEAR),
        ));
    }
    let noise = match args.noise.as_str() {
        "consistent" => NoiseModel::Consistent,
        "element-uniform" => NoiseModel::ElementUniform,
        other => {
            return Err(Error::invalid(
                "--noise",
                other,
                "consistent or element-uniform",
            ));
        }
    };
    if let Some(limit) = integrator.stability_limit(max_rate)
        && dt >= limit
    {
        return Err(Error::invalid(
            "--dt",
            dt,
            format!("< {limit:e}, the {integrator} stability limit 2/lambda_max of this mesh"),
        ));
    }
    // Crank–Nicolson is A-stable, but this mode's multiplier (1 − a/2)/(1 + a/2) rounds
    // to −1 in f64 once a = rate·Δt passes about 2⁵⁵: its stationary variance is 0/0.
    if let Some(limit) = integrator.rounding_limit(rate)
        && dt >= limit
    {
        return Err(Error::invalid(
            "--dt",
            format!("{dt:e}"),
            format!(
                "< {limit:e}: past it this mode's {integrator} multiplier rounds to -1 in f64 (rate x dt about 2^55) and its stationary variance is 0/0; give a smaller --dt, or --integrator backward-euler or exact-modal"
            ),
        ));
    }
    // At rate·Δt below about 1e-9 the multiplier 1 − O(rate·Δt) keeps fewer than seven
    // digits of its distance from 1 in f64 (and rounds to 1 below ε): the law is lost.
    let floor = MIN_RATE_DT / rate;
    if dt < floor {
        return Err(Error::invalid(
            "--dt",
            format!("{dt:e}"),
            format!(
                ">= {floor:e}: below it this mode's rate x dt is under {MIN_RATE_DT:e} and its multiplier 1 - O(rate x dt) loses its digits in f64 (it rounds to 1 below about 1e-16)"
            ),
        ));
    }
    let noise_variance = match noise {
        NoiseModel::Consistent => 1.0,
        NoiseModel::ElementUniform => uniform_ratio,
    };
    let law = ModeLaw::new(rate, noise_variance, integrator, dt, plate.kt())?;
    let ratio = law.variance / law.equipartition;
    let mut out = json!({
        "dt": dt,
        "integrator": integrator.name(),
        "noise": noise.name(),
        "multiplier": law.multiplier,
        "variance": ratio * variance,
        "variance_ratio_to_equipartition": ratio,
    });
    match law.decay_rate {
        Some(r) => out["decay_rate"] = json!(r),
        None => {
            out["decay_rate_note"] =
                json!("multiplier <= 0: the mode alternates in sign and has no decay rate")
        }
    }
    Ok(out)
}

/// Renames the parameter of an [`Error::InvalidParameter`] to `flag`.
fn as_flag_named(flag: &'static str) -> impl Fn(Error) -> Error {
    move |err| match err {
        Error::InvalidParameter { value, allowed, .. } => Error::InvalidParameter {
            name: flag.to_string(),
            value,
            allowed,
        },
        other => other,
    }
}

/// Parses `--strain-ratio`: a non-empty comma-separated list of numbers in
/// `[MIN_STRAIN_RATIO, max]` (`max` = [`max_strain_ratio`] of the already validated
/// parameters, `context` names them).
fn parse_strain_ratios(list: &str, max: f64, context: &str) -> Result<Vec<f64>> {
    let min = MIN_STRAIN_RATIO;
    let allowed = || {
        format!(
            "a non-empty comma-separated list of numbers in [0, {max:e}] {context} (compression) \
             or in [{min:e}, 0] (tension)"
        )
    };
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
            Ok(r) if r.is_finite() && (min..=max).contains(&r) => Ok(r),
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

/// The convention line of `theory mode --ends` (other than hinged).
const ENDED_MODE_CONVENTION: &str = "w = Σ a_n φ_n(x) + Σ_k b_k ψ_k(x) (ψ_k the rigid modes), \
     ∫₀ᴸ φ_n² dx = ∫₀ᴸ ψ_k² dx = L/2 (hinged-hinged: φ_n = sin(nπx/L)), the first non-zero \
     Taylor coefficient of φ_n at x = 0 positive; variance = ⟨a_n²⟩ = 2kT/(EI q_n⁴ L), rate = \
     EI q_n⁴/ξ; a rigid amplitude diffuses, ⟨(b_k(t) − b_k(0))²⟩ = amplitude_msd_rate·t";

/// `theory mode --ends` (other than hinged): the elastic mode n's wavenumber, rate and
/// variance with their convention, and the rigid modes with their diffusion laws.
fn ended_mode(beam: &EndedBeam, n: usize) -> serde_json::Value {
    let rigid: Vec<serde_json::Value> = beam
        .rigid_modes()
        .iter()
        .map(|m| {
            let mut r = json!({
                "name": m.name(),
                "shape": m.shape_formula(),
                "amplitude_msd_rate": m.amplitude_msd_rate,
                "physical_quantity": m.physical_quantity(),
                "physical_msd_rate": m.physical_msd_rate,
            });
            if let Some(i) = m.moment_of_inertia() {
                r["moment_of_inertia"] = json!(i);
            }
            r
        })
        .collect();
    json!({
        "ends": beam.ends.to_string(),
        "n": n,
        "characteristic_equation": beam.characteristic_equation().formula(),
        "wavenumber": beam.wavenumber(n),
        "wavenumber_length": beam.wavenumber(n) * beam.params.length,
        "rate": beam.mode_rate(n),
        "variance": beam.mode_variance(n),
        "convention": ENDED_MODE_CONVENTION,
        "rigid_modes": rigid,
    })
}

/// `err` with the library's parameter name turned into the flag (`tension` → `--tension`).
fn as_flag(err: Error) -> Error {
    match err {
        Error::InvalidParameter {
            name,
            value,
            allowed,
        } => Error::InvalidParameter {
            name: format!("--{}", name.replace('_', "-")),
            value,
            allowed,
        },
        other => other,
    }
}

/// The real mode of `theory membrane --m --n` (for a periodic membrane the half-lattice
/// representative of ±q, cosine) and the sign of q relative to it.
fn membrane_mode(boundary: MembraneBoundary, m: i64, n: i64) -> Result<(MembraneMode, f64)> {
    match boundary {
        MembraneBoundary::SimplySupported => {
            if m < 1 {
                return Err(Error::invalid("--m", m, ">= 1 (simply supported)"));
            }
            if n < 1 {
                return Err(Error::invalid("--n", n, ">= 1 (simply supported)"));
            }
            let shape = ModeShape::SineSine;
            Ok((MembraneMode { m, n, shape }, 1.0))
        }
        MembraneBoundary::Periodic => {
            if m == 0 && n == 0 {
                return Err(Error::invalid(
                    "--n",
                    n,
                    "nonzero when --m is 0 (periodic: the q = 0 mode, a uniform displacement \
                     without restoring force, is excluded)",
                ));
            }
            let flip = m < 0 || (m == 0 && n < 0);
            let (m, n, sign) = if flip { (-m, -n, -1.0) } else { (m, n, 1.0) };
            let shape = ModeShape::Cosine;
            Ok((MembraneMode { m, n, shape }, sign))
        }
    }
}

/// The convention line of `theory membrane`.
fn membrane_convention(boundary: MembraneBoundary) -> &'static str {
    match boundary {
        MembraneBoundary::SimplySupported => {
            "h = Σ a_mn sin(mπx/a) sin(nπy/b), m, n ≥ 1; variance = ⟨a_mn²⟩ = 4kT/(A·c_q), \
             c_q = κq⁴ + σq², A = ab, rate = c_q/ξ"
        }
        MembraneBoundary::Periodic => {
            "h_q = A⁻¹∫h e^{−iq·r} d²r, q = 2π(m/a, n/b) ≠ 0 (q = 0 excluded): \
             fourier_variance = ⟨|h_q|²⟩ = kT/(A·c_q), c_q = κq⁴ + σq², A = ab (h_q = L⁻¹∫… \
             gives kT/c_q; a raw N×N FFT gives N⁴ times ours); real form \
             h = Σ_{q: m>0, or m=0, n>0} [A_q cos(q·r) + B_q sin(q·r)]: variance = ⟨A_q²⟩ = \
             ⟨B_q²⟩ = 2kT/(A·c_q); rate = c_q/ξ"
        }
    }
}

/// The membrane query: validates the flags and evaluates the exact references.
fn membrane(args: &MembraneArgs) -> Result<serde_json::Value> {
    let boundary = match args.boundary {
        BoundaryArg::SimplySupported => MembraneBoundary::SimplySupported,
        BoundaryArg::Periodic => MembraneBoundary::Periodic,
    };
    let params = MembraneParams {
        bending_rigidity: args.bending_rigidity,
        tension: args.tension,
        drag: args.drag,
        kt: args.kt,
        width: args.width,
        height: args.height,
        boundary,
    };
    let mb = Membrane::new(params).map_err(as_flag)?;
    let (mode, sign) = membrane_mode(boundary, args.m, args.n)?;
    let (x, y) = (
        args.x.unwrap_or(args.width / 2.0),
        args.y.unwrap_or(args.height / 2.0),
    );
    require_in_range("--x", x, 0.0, args.width)?;
    require_in_range("--y", y, 0.0, args.height)?;
    if !(args.tolerance.is_finite() && args.tolerance > 0.0 && args.tolerance < 1.0) {
        return Err(Error::invalid("--tolerance", args.tolerance, "in (0, 1)"));
    }
    let pv = mb.point_variance(x, y, args.tolerance).map_err(as_flag)?;
    // At the lattice form's term caps, or at the proper-time form's smallest t (σ/κ
    // beyond about 1e270), the bound reached may exceed the one asked for: said, not
    // hidden.
    let proper_time = mb.point_variance_by_proper_time();
    let target = args.tolerance * mb.variance_scale();
    let tolerance_met = pv.truncation_error <= target;
    if !tolerance_met {
        let met_at = args.tolerance * pv.truncation_error / target * 1.5;
        let advice = if met_at < 1.0 {
            format!("raise --tolerance to {met_at:.0e} or more to have it met")
        } else {
            format!(
                "no --tolerance in (0, 1) is met at sigma/(kappa q_min^2) = {:.1e}, beyond what f64 resolves",
                params.tension_ratio()
            )
        };
        eprintln!(
            "warning: point_variance: --tolerance {:e} ({target:e} absolute) is not met within {} {}; the bound reached is {:e} ({:.1e} of the value): {advice}",
            args.tolerance,
            pv.n_modes,
            if proper_time {
                "quadrature nodes"
            } else {
                "terms"
            },
            pv.truncation_error,
            pv.truncation_error / pv.value.abs(),
        );
    }
    let [qx, qy] = mb.wavevector(mode);
    let mut out = json!({
        "boundary": params.boundary.name(),
        "m": args.m,
        "n": args.n,
        "wavevector": [sign * qx, sign * qy],
        "wavenumber": mb.wavenumber_sq(mode).sqrt(),
        "stiffness": mb.stiffness(mode),
        "rate": mb.mode_rate(mode),
        "variance": mb.mode_variance(mode),
        "buckling_tension": params.buckling_tension(),
        "convention": membrane_convention(boundary),
        "point_variance": {
            "x": x, "y": y,
            "value": pv.value,
            "truncation_error": pv.truncation_error,
            "tolerance_met": tolerance_met,
            "terms": pv.n_modes,
            "method": if proper_time { "proper-time" } else { "lattice" },
        },
    });
    if boundary == MembraneBoundary::Periodic {
        out["fourier_variance"] = json!(mb.fourier_variance(args.m, args.n));
    }
    if let Some(nx) = args.elements {
        out["finite_elements"] = membrane_fem(args, &mb, mode, nx)?;
    }
    if let Some(cutoff) = args.cutoff {
        let ea = mb.excess_area(cutoff).map_err(as_flag)?;
        out["excess_area"] = json!({
            "cutoff": ea.cutoff,
            "modes": ea.n_modes,
            "mean": ea.mean,
            "variance": ea.variance,
            "variance_tail_bound": ea.variance_tail_bound,
        });
    }
    Ok(out)
}

/// Runs a theory query and prints one JSON object.
pub fn run(args: TheoryArgs) -> Result<i32> {
    let value = match args.query {
        Query::Variance { x, phys } => {
            let ended = phys.ended()?;
            require_in_range("--x", x, 0.0, phys.length)?;
            if ended.ends.is_hinged() {
                json!({ "x": x, "variance": ended.profile_variance(x) })
            } else {
                json!({
                    "ends": ended.ends.to_string(),
                    "x": x,
                    "variance": ended.profile_variance(x),
                    "rigid_modes": ended.rigid_modes().len(),
                })
            }
        }
        Query::Correlation {
            x,
            y,
            t,
            eta,
            tolerance,
            phys,
        } => {
            let ended = phys.ended()?;
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
            let c = ended.correlation(x, y, t, eta, tolerance)?;
            let mut out = json!({
                "x": x, "y": y, "t": t, "eta": eta,
                "correlation": c.value,
                "truncation_error": c.truncation_error,
                "modes": c.n_modes,
            });
            if !ended.ends.is_hinged() {
                out["ends"] = json!(ended.ends.to_string());
                out["rigid_correlation"] = json!(ended.rigid_correlation(x, y, t, eta)?);
            }
            out
        }
        Query::Mode { n, phys } => {
            let ended = phys.ended()?;
            if n < 1 {
                return Err(Error::invalid("--n", n, ">= 1"));
            }
            let n = n as usize;
            if ended.ends.is_hinged() {
                json!({ "n": n, "rate": ended.mode_rate(n), "variance": ended.mode_variance(n) })
            } else {
                ended_mode(&ended, n)
            }
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
        Query::Membrane(args) => membrane(&args)?,
        Query::Area(args) => area(&args)?,
    };
    if let Some(bad) = non_finite_number(&value) {
        return Err(Error::invalid(
            format!("the result's `{bad}`"),
            "a number beyond f64 (an overflow)",
            "finite: rescale the units of the parameter flags given (e.g. --length, --bending-rigidity, --drag, --kt) so that the result fits in f64",
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

/// Parses `N` or `N,NY` of `flag` (each an integer in `[min, max]`; NY defaults to N).
fn parse_pair(flag: &str, text: &str, min: usize, max: usize) -> Result<(usize, usize)> {
    let allowed = || format!("N or N,NY with integers in [{min}, {max}]");
    let items: Vec<&str> = text.split(',').map(str::trim).collect();
    if items.is_empty() || items.len() > 2 {
        return Err(Error::invalid(flag, format!("{text:?}"), allowed()));
    }
    let parsed = items
        .iter()
        .map(|item| match item.parse::<usize>() {
            Ok(n) if (min..=max).contains(&n) => Ok(n),
            _ => Err(Error::invalid(flag, format!("{item:?}"), allowed())),
        })
        .collect::<Result<Vec<usize>>>()?;
    Ok((parsed[0], *parsed.last().unwrap_or(&parsed[0])))
}

/// The largest element count of `theory area --mesh-convergence` (the theory of a
/// 64 × 64 mesh, 16 384 modes, takes about a second per strain).
const MAX_CONVERGENCE_ELEMENTS: usize = 64;

/// The mesh of an area query.
#[derive(Debug, Clone)]
enum AreaMesh {
    /// The exact theory of an `nx × ny` mesh.
    Elements(usize, usize),
    /// The continuum within a lattice cutoff.
    Cutoff(usize, usize),
    /// Convergence over square meshes of these sizes.
    Convergence(Vec<usize>),
}

/// The range of `theory area --width`.
const AREA_SIDE_RANGE: (f64, f64) = (1e-100, 1e100);

/// The validated geometry, moduli and mesh (or cutoff) of an area query.
fn area_params(args: &AreaArgs) -> Result<(AreaParams, AreaMesh)> {
    let boundary = match args.boundary {
        BoundaryArg::SimplySupported => MembraneBoundary::SimplySupported,
        BoundaryArg::Periodic => MembraneBoundary::Periodic,
    };
    area_sides(args)?;
    let (kappa, stretch) = area_moduli(args)?;
    let mesh = area_mesh(args, boundary)?;
    let params = AreaParams {
        bending_rigidity: kappa,
        area_modulus: stretch / (args.width * args.height),
        kt: 1.0,
        width: args.width,
        height: args.height,
        boundary,
    };
    Ok((params, mesh))
}

/// Checks `--width` ([`AREA_SIDE_RANGE`]) and `--height` (b/a at most
/// [`MAX_AREA_ASPECT_RATIO`] either way).
fn area_sides(args: &AreaArgs) -> Result<()> {
    require_positive("--width", args.width)?;
    require_positive("--height", args.height)?;
    // The result depends on the sides only through b/a; their scale must keep A₀, K_A =
    // S·kT/A₀ and q²_min inside f64.
    let (w_lo, w_hi) = AREA_SIDE_RANGE;
    if !(w_lo..=w_hi).contains(&args.width) {
        return Err(Error::invalid(
            "--width",
            format!("{:e}", args.width),
            format!(
                "in [{w_lo:e}, {w_hi:e}] (the tension ratio depends on the sides only through b/a; this keeps A₀ and q²_min inside f64)"
            ),
        ));
    }
    let (lo, hi) = (
        args.width / MAX_AREA_ASPECT_RATIO,
        args.width * MAX_AREA_ASPECT_RATIO,
    );
    if !(lo..=hi).contains(&args.height) {
        return Err(Error::invalid(
            "--height",
            format!("{:e}", args.height),
            format!(
                "in [{lo:e}, {hi:e}] (b/a in [0.1, 10] at --width {:e})",
                args.width
            ),
        ));
    }
    Ok(())
}

/// `--bending-rigidity` (in [`AREA_BENDING_RANGE`]) and `--stretch-ratio` (S/κ² in
/// [`STRETCH_BEND_RATIO_RANGE`]), checked.
fn area_moduli(args: &AreaArgs) -> Result<(f64, f64)> {
    let kappa = args.bending_rigidity;
    let (k_lo, k_hi) = AREA_BENDING_RANGE;
    if !(kappa.is_finite() && kappa >= k_lo && kappa <= k_hi) {
        return Err(Error::invalid(
            "--bending-rigidity",
            format!("{kappa:e}"),
            format!("in [{k_lo:e}, {k_hi:e}] (kT units)"),
        ));
    }
    let (l_lo, l_hi) = STRETCH_BEND_RATIO_RANGE;
    let (s_lo, s_hi) = (l_lo * kappa * kappa, l_hi * kappa * kappa);
    let stretch = args.stretch_ratio;
    if !(stretch.is_finite() && stretch >= s_lo && stretch <= s_hi) {
        return Err(Error::invalid(
            "--stretch-ratio",
            format!("{stretch:e}"),
            format!(
                "in [{s_lo:e}, {s_hi:e}] at --bending-rigidity {kappa:e} (S/κ² in \
                 [{l_lo:e}, {l_hi:e}]: the tension ratio depends on S/κ² only; outside, the \
                 exact theory is too slow or at a known limit, see --help)"
            ),
        ));
    }
    Ok((kappa, stretch))
}

/// The mesh, cutoff or convergence sizes of an area query: exactly one of `--elements`,
/// `--cutoff` and `--mesh-convergence`, within their ranges for `boundary`.
fn area_mesh(args: &AreaArgs, boundary: MembraneBoundary) -> Result<AreaMesh> {
    let min = match boundary {
        MembraneBoundary::SimplySupported => 1,
        MembraneBoundary::Periodic => 2,
    };
    let mesh = match (&args.elements, &args.cutoff, &args.mesh_convergence) {
        (Some(e), None, None) => {
            let (nx, ny) = parse_pair("--elements", e, min, MAX_AREA_ELEMENTS)?;
            AreaMesh::Elements(nx, ny)
        }
        (None, Some(c), None) => {
            let (nx, ny) = parse_pair("--cutoff", c, min + 1, MAX_AREA_CUTOFF_INDEX)?;
            AreaMesh::Cutoff(nx, ny)
        }
        (None, None, Some(list)) => {
            let lo = min + 1;
            let allowed = format!(
                "strictly ascending element counts, each an integer in [{lo}, {MAX_CONVERGENCE_ELEMENTS}]"
            );
            let sizes: Vec<usize> = super::parse_list("--mesh-convergence", list, &allowed)?;
            if let Some(bad) = sizes
                .iter()
                .find(|n| !(lo..=MAX_CONVERGENCE_ELEMENTS).contains(n))
            {
                return Err(Error::invalid("--mesh-convergence", bad, allowed));
            }
            if sizes.is_empty() || sizes.windows(2).any(|w| w[1] <= w[0]) {
                return Err(Error::invalid(
                    "--mesh-convergence",
                    format!("{list:?}"),
                    allowed,
                ));
            }
            AreaMesh::Convergence(sizes)
        }
        _ => {
            return Err(Error::invalid(
                "--elements/--cutoff/--mesh-convergence",
                "none",
                "exactly one of --elements N[,NY] (the mesh), --cutoff NX[,NY] (the continuum) \
                 or --mesh-convergence N1,N2,... (convergence over meshes)",
            ));
        }
    };
    Ok(mesh)
}

/// The area query: validates the flags ([`area_params`]) and evaluates the exact theory.
fn area(args: &AreaArgs) -> Result<serde_json::Value> {
    let (params, mesh) = area_params(args)?;
    let (kappa, stretch) = (args.bending_rigidity, args.stretch_ratio);
    let ratios = parse_strain_ratios(
        &args.strain_ratio,
        max_area_strain_ratio(&params),
        &format!(
            "(100·√S·π²/(κ·q²_min·A₀) at --bending-rigidity {kappa:e} and --stretch-ratio \
             {stretch:e})"
        ),
    )?;
    let theory = match &mesh {
        AreaMesh::Elements(nx, ny) => AreaTheory::discrete(&params, *nx, *ny)?,
        AreaMesh::Cutoff(nx, ny) => {
            AreaTheory::continuum(&params, AreaCutoff::Lattice { nx: *nx, ny: *ny })?
        }
        AreaMesh::Convergence(sizes) => return area_convergence(args, &params, sizes, &ratios),
    };
    let sigma_c0 = params.reference_tension();
    let eps_c0 = params.reference_strain();
    let points = ratios
        .iter()
        .map(|&r| {
            let eps = r * eps_c0;
            Ok(json!({
                "strain_ratio": r,
                "tension_ratio": theory.tension_ratio(r)?,
                "mean_field_tension_ratio": theory.mean_field_tension(eps)? / sigma_c0,
                "std_dev_ratio": theory.tension_variance(eps)?.sqrt() / sigma_c0,
            }))
        })
        .collect::<Result<Vec<_>>>()?;
    let mut out = json!({
        "boundary": params.boundary.name(),
        "width": args.width,
        "height": args.height,
        "bending_rigidity": kappa,
        "stretch_ratio": stretch,
        "modes": theory.theory().law().weights.len(),
        "reference_tension": sigma_c0,
        "reference_strain": eps_c0,
        "free_excess_area_ratio": theory.free_excess_area_ratio(),
        "points": points,
    });
    match mesh {
        AreaMesh::Elements(nx, ny) => out["elements"] = json!([nx, ny]),
        AreaMesh::Cutoff(nx, ny) => out["cutoff"] = json!([nx, ny]),
        AreaMesh::Convergence(_) => {}
    }
    Ok(out)
}

/// `theory area --mesh-convergence` ([`mesh_convergence`]).
fn area_convergence(
    args: &AreaArgs,
    params: &AreaParams,
    sizes: &[usize],
    ratios: &[f64],
) -> Result<serde_json::Value> {
    let (continuum_fixed, rows) = mesh_convergence(params, sizes, ratios)?;
    let fixed = sizes[0];
    let rows: Vec<_> = rows
        .iter()
        .map(|r| {
            json!({
                "elements": r.elements,
                "modes": r.modes,
                "free_excess_area_ratio": r.free_excess_area_ratio,
                "tension_ratio": r.tension_ratio,
                "continuum_at_mesh_cutoff": r.continuum_at_mesh,
                "fixed_cutoff_tension_ratio": r.fixed_cutoff,
                "fixed_cutoff_error": r.fixed_error,
                "fixed_cutoff_order": r.fixed_order,
            })
        })
        .collect();
    Ok(json!({
        "boundary": params.boundary.name(),
        "width": args.width,
        "height": args.height,
        "bending_rigidity": args.bending_rigidity,
        "stretch_ratio": args.stretch_ratio,
        "reference_tension": params.reference_tension(),
        "reference_strain": params.reference_strain(),
        "strain_ratios": ratios,
        "fixed_cutoff": [fixed, fixed],
        "fixed_cutoff_continuum": continuum_fixed,
        "note": format!(
            "tension_ratio (the whole mesh) drifts with the mesh: the thermal excess area \
             grows as the log of the mode cutoff (Helfrich-Servuss), physics, not error: \
             each mesh is a membrane with another cutoff (continuum_at_mesh_cutoff beside \
             it). The discretization error is fixed_cutoff_error: the mesh's modes within \
             the {fixed} x {fixed} lattice cutoff against the continuum at that cutoff, \
             converging at fixed_cutoff_order (4 for Bogner-Fox-Schmit elements)."
        ),
        "meshes": rows,
    }))
}
