//! What a linear run's tables and figures say about the object it simulates (issue #27):
//! the words, equations, mode labels and continuum curves that differ between the hinged
//! filament (eqs. 2–4, [`HingedBeam`]) and the Helfrich membrane ((M1)–(M5),
//! [`Membrane`]). The writers of the [runner](super) are shared by both objects; each
//! asks the run's [`Subject`] for what differs, so that a filament's outputs are those
//! written before membranes ran through `verify`, byte for byte.
//!
//! # The membrane's modal amplitudes
//! A finite-element run's modal amplitudes are normalized by the damping matrix C
//! (φᵀCφ = 1), so their continuum variance is kT/λ_q = kTξ/c_q; the spectral model's are
//! the amplitudes of the sine (or cos and sin) modes, of variance kT/(c_q‖φ‖²) (M3). The
//! run's tables keep the run's normalization; the height spectrum puts both into that of
//! (M3), a height squared, multiplying a finite-element variance by 1/(ξ‖φ‖²)
//! ([`Subject::Membrane::to_sine`]), the same constant for every mode.

use crate::error::Result;
use crate::output::AxisUnits;
use crate::scene::linear::ModeReference;
use crate::scene::{ModelKind, Scene};
use crate::spectral::EndedBeam;
use crate::spectral::membrane::{Membrane, MembraneBoundary, MembraneMode, ModeShape};

/// Points on each continuum curve drawn in the profile, two-time and spectrum figures.
const CURVE_POINTS: usize = 81;

/// Tolerance of the membrane's continuum curves, relative to the variance of its slowest
/// mode ([`Membrane::point_variance`], [`Membrane::correlation`]): a hundred times below
/// what a figure resolves (a pixel is about 2·10⁻³ of an axis). Tighter costs much more
/// for nothing to see: at 10⁻⁹ the 81 points of a profile take 0.1–0.4 s, and the
/// equal-time point of a two-time curve sums the cap of 10⁷ modes, for every run.
const MEMBRANE_CURVE_TOLERANCE: f64 = 1e-5;

/// The most terms of each part of a membrane curve point's mode sum ([`CURVE_POINTS`] of
/// them per figure): a curve point costs milliseconds, not the second the full caps take.
const CURVE_MAX_TERMS: usize = 100_000;

/// The accuracy a curve point must reach to be drawn, relative to the slowest mode's
/// variance (the scale of [`MEMBRANE_CURVE_TOLERANCE`]).
const CURVE_ACCURACY: f64 = 1e-3;

/// The words of one figure that depend on the object (empty where a figure has no such
/// item).
#[derive(Debug, Clone, Default, PartialEq)]
pub(super) struct Words {
    /// Title.
    pub title: String,
    /// Label of the horizontal axis, with its unit.
    pub x_label: String,
    /// Label of the vertical axis, with its unit.
    pub y_label: String,
    /// Legend of the continuum reference (curve or line).
    pub continuum: String,
    /// Legend of the exact discrete reference.
    pub discrete: String,
    /// Caption: what the figure shows and what a reader should see.
    pub caption: String,
}

/// What a figure whose references are all the continuum's says first (data whose
/// discretization this tool does not model, issue #31).
pub(super) const CONTINUUM_PREFIX: &str = "References: the continuum (eqs. 2-4, or (M3)-(M5) of \
     the membrane), since the data declare no discretization this tool models; the data's own \
     mesh and time-step errors are part of what the markers' distance from the references \
     shows. ";

/// The caption phrases that describe an exact discrete reference, and what they say of a
/// continuum reference.
const DISCRETE_PHRASES: [(&str, &str); 8] = [
    ("kT/λᵢ of the discrete mode", "kT/λᵢ of the continuum mode"),
    (
        "the exact variance of the discretized system and integrator",
        "the continuum variance",
    ),
    (
        "the exact rate −ln(m)/Δt of the discrete update, m its one-step multiplier",
        "the continuum rate",
    ),
    (
        "the exact rate −ln(ρ)/Δt of the discrete update, ρ its one-step multiplier",
        "the continuum rate",
    ),
    (
        "the exact value of the discretized filament",
        "the continuum value",
    ),
    (
        "the exact value of the discretized membrane",
        "the continuum value",
    ),
    (
        "the exact value of the discretized system and integrator",
        "the continuum value",
    ),
    (
        "its exact expectation for the sampled discrete process",
        "the continuum's expectation for the sampled process",
    ),
];

/// The caption sentences (or clauses) about the distance between the exact discrete
/// reference and the continuum: left out when the reference is the continuum.
const DISCRETE_CLAUSES: [&str; 6] = [
    " The solid line's distance from 1 is the time step's exact bias, the dashed line's the mesh's.",
    " The solid line's distance from 1 is the time step's exact bias.",
    "; its distance from 1 is the discretization's (mesh and time step) effect on the dynamics",
    "; the discs lie on the curve up to the discretization error",
    ", and the discs on their curves up to the discretization error",
    ", and the discs on the curve up to the discretization error",
];

/// A caption of a figure whose references are the continuum's: [`CONTINUUM_PREFIX`],
/// then `caption` with its discrete-reference phrases said of the continuum and its
/// clauses on the discretization error left out.
pub(super) fn continuum_caption(caption: &str) -> String {
    let mut c = caption.to_string();
    for (from, to) in DISCRETE_PHRASES {
        c = c.replace(from, to);
    }
    for clause in DISCRETE_CLAUSES {
        c = c.replace(clause, "");
    }
    format!("{CONTINUUM_PREFIX}{c}")
}

impl Words {
    /// The words of a figure whose references are all the continuum's (data whose
    /// discretization this tool does not model): the legend of the exact discrete
    /// reference says "continuum", the caption [`continuum_caption`].
    pub(super) fn continuum_referenced(mut self) -> Words {
        if !self.discrete.is_empty() {
            self.discrete = "reference: the continuum (discretization not modelled)".to_string();
        }
        self.caption = continuum_caption(&self.caption);
        self
    }
}

/// The object of a linear scene, as its tables and figures describe it.
#[derive(Debug, Clone, Copy)]
pub(super) enum Subject {
    /// The hinged filament of eq. (2) (`None`: parameters the continuum refuses, and no
    /// continuum curves are drawn).
    Filament {
        /// Its continuum.
        beam: Option<EndedBeam>,
        /// Its length L, the unit of the two-time figure's positions.
        length: f64,
    },
    /// The membrane of (M1), sampled on its midline y = b/2.
    Membrane {
        /// Its continuum.
        membrane: Membrane,
        /// The factor that takes the run's modal variances to those of (M3): 1/(ξ‖φ‖²)
        /// for finite-element modes (normalized by the damping matrix), 1 for the
        /// spectral model's sine and cos modes (see the [module docs](self)).
        to_sine: f64,
    },
}

impl Subject {
    /// The object of `scene`: its membrane if it has one, else its filament.
    ///
    /// # Errors
    /// [`Membrane::new`]'s, for membrane parameters that do not validate (a scene that
    /// loaded has valid ones).
    pub(super) fn of(scene: &Scene) -> Result<Subject> {
        Ok(match scene.membrane {
            None => Subject::Filament {
                beam: EndedBeam::new(scene.filament, scene.ends).ok(),
                length: scene.filament.length,
            },
            Some(p) => {
                let membrane = Membrane::new(p)?;
                let to_sine = match scene.model {
                    ModelKind::Spectral => 1.0,
                    ModelKind::Fem | ModelKind::Compression => {
                        1.0 / (p.drag * membrane.mode_norm_sq())
                    }
                };
                Subject::Membrane { membrane, to_sine }
            }
        })
    }

    /// Whether this is a membrane.
    pub(super) fn is_membrane(&self) -> bool {
        matches!(self, Subject::Membrane { .. })
    }

    /// A filament whose ends are not both hinged (issue #29): the ends' name and their
    /// characteristic equation; `None` for the hinged filament and the membrane.
    fn other_ends(&self) -> Option<(String, &'static str)> {
        match self {
            Subject::Filament { beam: Some(b), .. } if !b.ends.is_hinged() => {
                Some((b.ends.to_string(), b.characteristic_equation().formula()))
            }
            _ => None,
        }
    }

    /// How the rigid modes of a filament's ends are treated, for captions (empty without).
    fn rigid_words(&self) -> String {
        match self {
            Subject::Filament { beam: Some(b), .. } if b.ends.rigid_modes() > 0 => {
                let names: Vec<String> = b.rigid_modes().iter().map(|m| m.name()).collect();
                format!(
                    " (its rigid motion, {}, projected out: the elastic shape)",
                    names.join(" and ")
                )
            }
            _ => String::new(),
        }
    }

    /// The wavenumber |q| of a membrane's mode `mr` (NaN for a filament's mode, or a mode
    /// without a label).
    pub(super) fn wavenumber(&self, mr: &ModeReference) -> f64 {
        match (self, mr.label) {
            (Subject::Membrane { membrane, .. }, Some(l)) => membrane.wavenumber_sq(l).sqrt(),
            _ => f64::NAN,
        }
    }

    /// The header of a per-mode table: `mode`, then for a membrane its lattice indices
    /// `m`, `n` and wavenumber `q`, then `rest`.
    pub(super) fn mode_header<'a>(&self, rest: &[&'a str]) -> Vec<&'a str> {
        let label: &[&str] = match self {
            Subject::Filament { .. } => &["mode"],
            Subject::Membrane { .. } => &["mode", "m", "n", "q"],
        };
        label.iter().chain(rest).copied().collect()
    }

    /// The first columns of mode `mr`'s row, under [`Subject::mode_header`]: its number,
    /// and a membrane's m, n and |q| (NaN for a mode without a label).
    pub(super) fn mode_columns(&self, mr: &ModeReference) -> Vec<f64> {
        let n = mr.n as f64;
        match self {
            Subject::Filament { .. } => vec![n],
            Subject::Membrane { .. } => {
                let (m, k) = mr
                    .label
                    .map_or((f64::NAN, f64::NAN), |l| (l.m as f64, l.n as f64));
                vec![n, m, k, self.wavenumber(mr)]
            }
        }
    }

    /// Label of the mode-number axis.
    pub(super) fn mode_axis(&self) -> &'static str {
        match self {
            Subject::Filament { .. } => "mode n (dimensionless)",
            Subject::Membrane { .. } => "mode i, slowest first (dimensionless)",
        }
    }

    /// A membrane mode's lattice indices, `(1, 2)`, with its shape when periodic:
    /// `(1, 0) cos`.
    fn lattice(mode: MembraneMode) -> String {
        let shape = match mode.shape {
            ModeShape::SineSine => "",
            ModeShape::Cosine => " cos",
            ModeShape::Sine => " sin",
        };
        format!("({}, {}){shape}", mode.m, mode.n)
    }

    /// The name of mode `n` in a legend: `mode 3`, a membrane's `mode 3 = (2, 1)`.
    pub(super) fn mode_name(&self, n: usize, modes: &[ModeReference]) -> String {
        let label = modes.iter().find(|m| m.n == n).and_then(|m| m.label);
        match (self, label) {
            (Subject::Membrane { .. }, Some(l)) => format!("mode {n} = {}", Self::lattice(l)),
            _ => format!("mode {n}"),
        }
    }

    /// A membrane's sentence naming its modes i by their lattice indices (m, n); empty
    /// for a filament.
    fn mode_list(&self, modes: &[ModeReference]) -> String {
        match self {
            Subject::Filament { .. } => String::new(),
            Subject::Membrane { membrane, .. } => {
                let list: Vec<String> = modes
                    .iter()
                    .map(|m| match m.label {
                        Some(l) => format!("{}: {}", m.n, Self::lattice(l)),
                        None => format!("{}: ?", m.n),
                    })
                    .collect();
                let q = match membrane.params.boundary {
                    MembraneBoundary::SimplySupported => "q = π(m/a, n/b)",
                    MembraneBoundary::Periodic => "q = 2π(m/a, n/b)",
                };
                format!(
                    " Modes i, slowest first, by the lattice indices (m, n) of {q}: {}.",
                    list.join(", ")
                )
            }
        }
    }

    /// The words of the modes figure (variance relative to equipartition per mode) of
    /// run `name`.
    pub(super) fn variance_words(&self, name: &str, modes: &[ModeReference]) -> Words {
        let title = format!("{name}: stationary variance of each mode");
        let x_label = self.mode_axis().to_string();
        let discrete = "exact, discretized system and integrator".to_string();
        match self {
            Subject::Filament { .. } => Words {
                title,
                x_label,
                y_label: "⟨aₙ²⟩ / (kT/λᵢ) (dimensionless)".to_string(),
                continuum: "continuum kT/λₙ".to_string(),
                discrete,
                caption: "Stationary variance of each mode aₙ relative to equipartition kT/λᵢ of \
                          the discrete mode, simulated (markers, ±1 s.e.) against the exact \
                          variance of the discretized system and integrator (solid line) and the \
                          continuum value (dashed line). The markers should scatter about the \
                          solid line within their error bars; a systematic offset is an integrator \
                          or noise bias. The solid line's distance from 1 is the time step's exact \
                          bias."
                    .to_string(),
            },
            Subject::Membrane { .. } => Words {
                title,
                x_label,
                y_label: "⟨aᵢ²⟩ / (kT/λᵢ) (dimensionless)".to_string(),
                continuum: "continuum kT/λ_q, λ_q = c_q/ξ".to_string(),
                discrete,
                caption: format!(
                    "Stationary variance of each mode's amplitude aᵢ relative to equipartition \
                     kT/λᵢ of the discrete mode, simulated (markers, ±1 s.e.) against the exact \
                     variance of the discretized system and integrator (solid line) and the \
                     continuum value kT/λ_q, λ_q = c_q/ξ = (κq⁴ + σq²)/ξ (dashed line). The \
                     markers should scatter about the solid line within their error bars; a \
                     systematic offset is an integrator or noise bias. The solid line's distance \
                     from 1 is the time step's exact bias, the dashed line's the mesh's.{}",
                    self.mode_list(modes)
                ),
            },
        }
    }

    /// The words of the rates figure (relaxation rate relative to the continuum per mode)
    /// of run `name`; `discrete` is the legend of the exact discrete rate, `continuum`
    /// that of the line at 1.
    pub(super) fn rate_words(&self, name: &str, modes: &[ModeReference]) -> Words {
        let title = format!("{name}: relaxation rate of each mode");
        let x_label = self.mode_axis().to_string();
        match self {
            Subject::Filament { .. } => Words {
                title,
                x_label,
                y_label: "rate / λₙ (dimensionless)".to_string(),
                continuum: match self.other_ends() {
                    None => "continuum λₙ = n⁴/τ₁".to_string(),
                    Some((ends, eq)) => format!("continuum λₙ = EI qₙ⁴/ξ ({ends}: {eq})"),
                },
                discrete: "exact, discrete update: −ln(m)/Δt".to_string(),
                caption:
                    "Decay rate of each mode's autocorrelation relative to the continuum rate λₙ = \
                     n⁴/τ₁, simulated (markers, ±1 s.e.) against the exact rate −ln(m)/Δt of the \
                     discrete update, m its one-step multiplier (solid line); the dashed line at 1 \
                     is the continuum. The markers should scatter about the solid line; its \
                     distance from 1 is the discretization's (mesh and time step) effect on the \
                     dynamics."
                        .to_string(),
            },
            Subject::Membrane { .. } => Words {
                title,
                x_label,
                y_label: "rate / λ_q (dimensionless)".to_string(),
                continuum: "continuum λ_q = c_q/ξ".to_string(),
                discrete: "exact, discrete update: −ln(ρ)/Δt".to_string(),
                caption: format!(
                    "Decay rate of each mode's autocorrelation relative to the continuum rate λ_q \
                     = c_q/ξ = (κq⁴ + σq²)/ξ of its wavevector q (M2), simulated (markers, ±1 \
                     s.e.) against the exact rate −ln(ρ)/Δt of the discrete update, ρ its one-step \
                     multiplier (solid line); the dashed line at 1 is the continuum. The markers \
                     should scatter about the solid line; its distance from 1 is the \
                     discretization's (mesh and time step) effect on the dynamics.{}",
                    self.mode_list(modes)
                ),
            },
        }
    }

    /// The membrane's continuum law (M3) as a function of the wavenumber:
    /// ⟨a²⟩ = kT/(c_q‖φ‖²), c_q = κq⁴ + σq² (`None` where c_q ≤ 0, and for a filament).
    pub(super) fn continuum_variance(&self, q: f64) -> Option<f64> {
        let Subject::Membrane { membrane, .. } = self else {
            return None;
        };
        let p = membrane.params;
        let c = (p.bending_rigidity * q * q + p.tension) * q * q;
        (c > 0.0).then(|| p.kt / (c * membrane.mode_norm_sq()))
    }

    /// [`Subject::continuum_variance`] on log-spaced wavenumbers from below the smallest
    /// to above the largest of `qs` (empty for a filament).
    pub(super) fn spectrum_curve(&self, qs: &[f64]) -> Vec<(f64, f64)> {
        let lo = qs.iter().copied().fold(f64::INFINITY, f64::min) * 0.8;
        let hi = qs.iter().copied().fold(0.0, f64::max) * 1.25;
        if !(lo > 0.0 && hi > lo) {
            return Vec::new();
        }
        (0..CURVE_POINTS)
            .filter_map(|k| {
                let q = lo * (hi / lo).powf(k as f64 / (CURVE_POINTS - 1) as f64);
                Some((q, self.continuum_variance(q)?))
            })
            .collect()
    }

    /// The words of the height spectrum of run `name` (a membrane's; empty words for a
    /// filament).
    pub(super) fn spectrum_words(
        &self,
        name: &str,
        units: AxisUnits,
        modes: &[ModeReference],
    ) -> Words {
        let Subject::Membrane { membrane, to_sine } = self else {
            return Words::default();
        };
        let p = membrane.params;
        let (law, boundary) = match p.boundary {
            MembraneBoundary::SimplySupported => (
                "4kT/(A c_q)",
                "simply supported: the amplitudes of sin(mπx/a) sin(nπy/b)",
            ),
            MembraneBoundary::Periodic => (
                "2kT/(A c_q)",
                "periodic: the amplitudes of cos(q·r) and sin(q·r), each of variance twice \
                 ⟨|h_q|²⟩ = kT/(A c_q), h_q = A⁻¹∫h e^{−iq·r} d²r",
            ),
        };
        let scaled = if *to_sine == 1.0 {
            ""
        } else {
            " (the finite-element modes' amplitudes, normalized by the damping matrix, times \
             1/(ξ‖φ‖²), the same factor for every mode)"
        };
        let law_shape = if p.tension > 0.0 {
            format!(
                "falls as q⁻⁴ where bending dominates and as q⁻² where tension does (crossover \
                 at q = √(σ/κ) = {:.4})",
                (p.tension / p.bending_rigidity).sqrt()
            )
        } else if p.tension == 0.0 {
            "falls as q⁻⁴ (no tension)".to_string()
        } else {
            format!(
                "falls as q⁻⁴ at large q and more steeply towards the buckling wavenumber \
                 √(−σ/κ) = {:.4} (a negative tension)",
                (-p.tension / p.bending_rigidity).sqrt()
            )
        };
        Words {
            title: format!("{name}: height fluctuation spectrum ⟨a²⟩ against |q|"),
            x_label: format!("wavenumber |q| [1/{}]", units.length),
            y_label: format!("mode variance ⟨a²⟩ (M3) {}", units.area()),
            continuum: format!("continuum (M3): {law}, c_q = κq⁴ + σq²"),
            discrete: "exact, discretized system and integrator".to_string(),
            caption: format!(
                "Height fluctuation spectrum: the stationary variance ⟨a²⟩ of each checked mode's \
                 amplitude against its wavenumber |q| (log–log), in the normalization of (M3), \
                 {boundary}{scaled}; simulated (markers, ±1 s.e.) against the exact value of the \
                 discretized system and integrator (light discs) and the continuum law ⟨a²⟩ = \
                 {law}, c_q = κq⁴ + σq² (dashed curve), which {law_shape}. Each marker should \
                 sit on its disc within its error bar, and the discs on the curve up to the \
                 discretization error; modes of equal |q| share a position.{}",
                self.mode_list(modes)
            ),
        }
    }

    /// The continuum profile curve over the whole object: ⟨w²(x)⟩ along the filament, or
    /// ⟨h²(x, b/2)⟩ (M5) along the membrane's midline (points where it fails left out).
    pub(super) fn profile_curve(&self) -> Vec<(f64, f64)> {
        match self {
            Subject::Filament { beam, length } => match beam {
                Some(beam) => (0..CURVE_POINTS)
                    .map(|k| {
                        let x = length * k as f64 / (CURVE_POINTS - 1) as f64;
                        (x, beam.profile_variance(x))
                    })
                    .collect(),
                None => Vec::new(),
            },
            Subject::Membrane { membrane, .. } => {
                let (a, y) = (membrane.params.width, 0.5 * membrane.params.height);
                (0..CURVE_POINTS)
                    .filter_map(|k| {
                        let x = (a * k as f64 / (CURVE_POINTS - 1) as f64).min(a);
                        let v = membrane
                            .point_variance_capped(x, y, MEMBRANE_CURVE_TOLERANCE, CURVE_MAX_TERMS)
                            .ok()?;
                        // A point the capped sums leave inaccurate (a tension far above
                        // κq_min²) is left out rather than drawn wrong.
                        (v.truncation_error <= CURVE_ACCURACY * membrane.variance_scale())
                            .then_some((x, v.value))
                    })
                    .collect()
            }
        }
    }

    /// The words of the profile figure of run `name`.
    pub(super) fn profile_words(&self, name: &str, units: AxisUnits) -> Words {
        match self {
            Subject::Filament { .. } if self.other_ends().is_some() => {
                let (ends, _) = self.other_ends().unwrap_or_default();
                let rigid = self.rigid_words();
                Words {
                    title: format!("{name}: equilibrium profile ⟨w²(x)⟩"),
                    x_label: format!("position x {}", units.length()),
                    y_label: format!("⟨w²(x)⟩ {}", units.area()),
                    continuum: format!("continuum, {ends} ends (closed form)"),
                    discrete: "exact, discretized filament".to_string(),
                    caption: format!(
                        "Equilibrium variance of the deflection ⟨w²(x)⟩ of the filament with {ends} \
                         ends{rigid} at the scene's profile points, simulated (markers, ±1 s.e.) \
                         against the exact value of the discretized filament (light discs) and \
                         the continuum's closed form, kT/EI times the Green's function of the \
                         ends (dashed curve). Each marker should sit on its disc within its error \
                         bar; the discs lie on the curve up to the discretization error."
                    ),
                }
            }
            Subject::Filament { .. } => Words {
                title: format!("{name}: equilibrium profile ⟨w²(x)⟩"),
                x_label: format!("position x {}", units.length()),
                y_label: format!("⟨w²(x)⟩ {}", units.area()),
                continuum: "continuum kT x²(L−x)²/(3EI·L)".to_string(),
                discrete: "exact, discretized filament".to_string(),
                caption:
                    "Equilibrium variance of the deflection ⟨w²(x)⟩ at the scene's profile points, \
                     simulated (markers, ±1 s.e.) against the exact value of the discretized \
                     filament (light discs) and the continuum kT x²(L−x)²/(3EI·L) (dashed curve). \
                     Each marker should sit on its disc within its error bar; the discs lie on the \
                     curve up to the discretization error."
                        .to_string(),
            },
            Subject::Membrane { membrane, .. } => {
                let boundary = match membrane.params.boundary {
                    MembraneBoundary::SimplySupported => {
                        "The membrane is simply supported (h = ∇²h = 0 on its edges), so the \
                         variance vanishes at x = 0 and x = a."
                    }
                    MembraneBoundary::Periodic => {
                        "The membrane is periodic: heights are measured from the spatial mean (the \
                         q = 0 translation, which has no restoring force, excluded), so the \
                         continuum is the same at every x."
                    }
                };
                Words {
                    title: format!(
                        "{name}: equilibrium height profile ⟨h²(x, b/2)⟩ on the midline"
                    ),
                    x_label: format!("position x on the midline y = b/2 {}", units.length()),
                    y_label: format!("⟨h²(x, b/2)⟩ {}", units.area()),
                    continuum: "continuum (M5): Σ ⟨a²⟩ φ(x, b/2)²".to_string(),
                    discrete: "exact, discretized membrane".to_string(),
                    caption: format!(
                        "Equilibrium variance of the membrane's height ⟨h²(x, b/2)⟩ at the scene's \
                         profile points on its midline y = b/2, simulated (markers, ±1 s.e.) \
                         against the exact value of the discretized membrane (light discs) and the \
                         continuum (M5), Σ ⟨a²⟩ φ(x, b/2)² over every mode (dashed curve). Each \
                         marker should sit on its disc within its error bar; the discs lie on the \
                         curve up to the discretization error. {boundary}"
                    ),
                }
            }
        }
    }

    /// The two-time continuum curve at the positions x, y (of the filament, or of the
    /// membrane's midline) from the earlier time t: (η/τ₁, correlation) for η from t to
    /// `eta_max`, eq. (4) or (M4) (points where it fails left out).
    pub(super) fn two_time_curve(
        &self,
        (x, y, t): (f64, f64, f64),
        eta_max: f64,
        tau1: f64,
    ) -> Vec<(f64, f64)> {
        let eta = |j: usize| t + (eta_max - t).max(0.0) * j as f64 / (CURVE_POINTS - 1) as f64;
        match self {
            Subject::Filament { beam, .. } => beam
                .iter()
                .flat_map(|b| {
                    (0..CURVE_POINTS).filter_map(move |j| {
                        let e = eta(j);
                        let c = b.correlation(x, y, t, e, 1e-9).ok()?;
                        Some((e / tau1, c.value))
                    })
                })
                .collect(),
            Subject::Membrane { membrane, .. } => {
                let m = 0.5 * membrane.params.height;
                (0..CURVE_POINTS)
                    .filter_map(|j| {
                        let e = eta(j);
                        let c = membrane
                            .correlation((x, m), (y, m), t, e, MEMBRANE_CURVE_TOLERANCE)
                            .ok()?;
                        Some((e / tau1, c.value))
                    })
                    .collect()
            }
        }
    }

    /// The words of the two-time figure of run `name` (its horizontal axis, the later
    /// time, is the same for every object); `discrete` is the legend of the discs.
    pub(super) fn two_time_words(&self, name: &str, units: AxisUnits) -> Words {
        let x_label = "later time η / τ₁".to_string();
        match self {
            Subject::Filament { .. } => Words {
                title: format!("{name}: two-time correlation from rest (eq. 4)"),
                x_label,
                y_label: format!("⟨w(x,t) w(y,η)⟩ {}", units.area()),
                continuum: String::new(),
                discrete: "exact, discretized filament (disc)".to_string(),
                caption: "Two-time correlation ⟨w(x,t) w(y,η)⟩ of the filament started from rest, \
                          at the scene's points (x, y, t, η), one colour per point: simulated \
                          (markers, ±1 s.e.) against eq. (4) of the continuum as a function of the \
                          later time η at the point's x, y and t (light curve) and the exact value \
                          of the discretized filament (light disc). Each marker should sit on its \
                          disc within its error bar, and the discs on their curves up to the \
                          discretization error."
                    .to_string(),
            },
            Subject::Membrane { membrane, .. } => {
                let height = match membrane.params.boundary {
                    MembraneBoundary::SimplySupported => "height",
                    MembraneBoundary::Periodic => {
                        "height, measured from its spatial mean (the membrane is periodic),"
                    }
                };
                Words {
                    title: format!("{name}: two-time correlation from rest (M4)"),
                    x_label,
                    y_label: format!("⟨h(x,b/2,t) h(y,b/2,η)⟩ {}", units.area()),
                    continuum: String::new(),
                    discrete: "exact, discretized membrane (disc)".to_string(),
                    caption: format!(
                        "Two-time correlation ⟨h(x,b/2,t) h(y,b/2,η)⟩ of the membrane's {height} \
                         started from rest (h = 0 at time 0), at the scene's points (x, y, t, η) \
                         on its midline y = b/2, one colour per point: simulated (markers, ±1 \
                         s.e.) against (M4) of the continuum membrane as a function of the later \
                         time η at the point's x, y and t (light curve) and the exact value of the \
                         discretized membrane (light disc). Each marker should sit on its disc \
                         within its error bar, and the discs on their curves up to the \
                         discretization error."
                    ),
                }
            }
        }
    }

    /// How a two-time point is named in a legend: the unit of its positions (the
    /// filament's length L or the membrane's width a) with its symbol, and the equation.
    pub(super) fn two_time_legend(&self) -> (f64, &'static str, &'static str) {
        match self {
            Subject::Filament { length, .. } => (*length, "L", "eq. (4)"),
            Subject::Membrane { membrane, .. } => (membrane.params.width, "a", "(M4)"),
        }
    }

    /// The Welch spectra's caption for the modes `shown` (1, 3 and 6).
    pub(super) fn welch_caption(&self, shown: &[usize], modes: &[ModeReference]) -> String {
        match self {
            Subject::Filament { .. } => {
                "One-sided power spectral density of the modal amplitudes aₙ of modes 1, 3 and 6, \
                 one colour per mode: the Welch estimate pooled over trajectories (markers) \
                 against its exact expectation for the sampled discrete process, window included \
                 (light line). The markers should follow the line of their mode at every \
                 frequency; a systematic departure at high frequency is a time-step error, at low \
                 frequency a run too short to resolve the mode's relaxation."
                    .to_string()
            }
            Subject::Membrane { .. } => {
                let names: Vec<String> = shown.iter().map(|&n| self.mode_name(n, modes)).collect();
                format!(
                    "One-sided power spectral density of the modal amplitudes aᵢ of the membrane's \
                     {} (slowest first, lattice indices (m, n)), one colour per mode: the Welch \
                     estimate pooled over trajectories (markers) against its exact expectation for \
                     the sampled discrete process, window included (light line). The markers \
                     should follow the line of their mode at every frequency; a systematic \
                     departure at high frequency is a time-step error, at low frequency a run too \
                     short to resolve the mode's relaxation.",
                    names.join(", ")
                )
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::linear::LinearRun;
    use std::path::Path;

    /// A scene file of the repository.
    fn scene(path: &str) -> Scene {
        Scene::load(Path::new(path)).expect(path)
    }

    /// The height spectrum's normalization (module docs): a finite-element run's continuum
    /// variance kTξ/c_q of its damping-normalized amplitudes, times `to_sine`, is (M3)'s
    /// kT/(c_q‖φ‖²) of the same mode (simply supported and periodic), the spectral
    /// model's is (M3) as it stands; and the spectrum's continuum law passes through (M3)
    /// at every checked mode's |q|. Exact up to rounding (1e-12).
    #[test]
    fn the_height_spectrum_puts_every_run_on_m3() {
        for (path, spectral) in [
            ("tests/scenes/good/membrane-hinged.toml", false),
            ("verification/membrane-periodic.toml", false),
            ("tests/scenes/good/membrane-pbc.toml", true),
        ] {
            let sc = scene(path);
            let subject = Subject::of(&sc).expect("membrane");
            let Subject::Membrane { membrane, to_sine } = subject else {
                panic!("{path}: not a membrane");
            };
            assert_eq!(to_sine == 1.0, spectral, "{path}");
            let run = LinearRun::prepare(&sc, &sc.runs[0]).expect("prepares");
            for mr in &run.reference.modes {
                let m3 = membrane.mode_variance(mr.label.expect("labelled"));
                let close = |v: f64| (v / m3 - 1.0).abs() < 1e-12;
                assert!(
                    close(to_sine * mr.variance_continuum),
                    "{path} mode {}",
                    mr.n
                );
                let law = subject.continuum_variance(subject.wavenumber(mr));
                assert!(law.is_some_and(close), "{path} mode {}", mr.n);
            }
        }
    }

    /// A membrane's per-mode rows carry (mode, m, n, |q|) after `mode`; a filament's only
    /// `mode`, as before membranes.
    #[test]
    fn mode_tables_name_the_membrane_modes() {
        let sc = scene("tests/scenes/good/membrane-hinged.toml");
        let subject = Subject::of(&sc).expect("membrane");
        let run = LinearRun::prepare(&sc, &sc.runs[0]).expect("prepares");
        assert_eq!(
            subject.mode_header(&["variance"]),
            ["mode", "m", "n", "q", "variance"]
        );
        // The slowest mode of the unit square: (1, 1), |q| = π√2.
        let q = std::f64::consts::PI * 2f64.sqrt();
        let row = subject.mode_columns(&run.reference.modes[0]);
        assert_eq!(row[..3], [1.0, 1.0, 1.0]);
        assert!((row[3] / q - 1.0).abs() < 1e-15, "{row:?}");

        let filament = Subject::of(&scene("tests/scenes/good/tiny-linear.toml")).expect("ok");
        assert!(!filament.is_membrane());
        assert_eq!(filament.mode_header(&["variance"]), ["mode", "variance"]);
        assert!(filament.continuum_variance(1.0).is_none());
        assert!(filament.spectrum_curve(&[1.0, 2.0]).is_empty());
    }

    /// The membrane's curves: the profile (M5) along the whole midline, zero at the simply
    /// supported ends and the same at every x when periodic; the two-time curve (M4)
    /// starts at the earlier time, as the filament's; the words name the membrane and
    /// its equations, not the filament's.
    #[test]
    fn membrane_curves_and_words() {
        let hinged = Subject::of(&scene("tests/scenes/good/membrane-hinged.toml")).unwrap();
        let curve = hinged.profile_curve();
        assert_eq!(curve.len(), CURVE_POINTS);
        assert_eq!((curve[0].0, curve[CURVE_POINTS - 1].0), (0.0, 1.0));
        assert!(curve[0].1.abs() < 1e-12 && curve[CURVE_POINTS - 1].1.abs() < 1e-12);
        assert!(curve[CURVE_POINTS / 2].1 > 1e-3, "{curve:?}");

        let pbc = Subject::of(&scene("tests/scenes/good/membrane-pbc.toml")).unwrap();
        let curve = pbc.profile_curve();
        assert_eq!(curve.len(), CURVE_POINTS);
        assert!(curve.iter().all(|p| (p.1 / curve[0].1 - 1.0).abs() < 1e-9));

        let tau1 = 2.0e-3;
        let tt = hinged.two_time_curve((0.5, 0.25, 0.5 * tau1), 2.0 * tau1, tau1);
        assert_eq!(tt.len(), CURVE_POINTS);
        assert_eq!(tt[0].0, 0.5);
        assert!((tt[CURVE_POINTS - 1].0 - 2.0).abs() < 1e-12);

        let units = AxisUnits::new(false);
        let profile = hinged.profile_words("cn", units);
        assert!(profile.caption.contains("membrane") && profile.caption.contains("(M5)"));
        assert!(!profile.caption.contains("filament") && !profile.continuum.contains("EI"));
        assert!(
            pbc.profile_words("cn", units)
                .caption
                .contains("spatial mean")
        );
        let two_time = pbc.two_time_words("cn", units);
        assert!(two_time.title.contains("(M4)") && two_time.caption.contains("spatial mean"));
        let rates = hinged.rate_words("cn", &[]);
        assert!(!rates.continuum.contains('⁴') && rates.caption.contains("c_q/ξ"));
    }

    /// Issue #31: every figure of a run referenced to the continuum says so — its legend
    /// and its caption, which keeps nothing of the discrete reference or of its distance
    /// from the continuum (for each object's every figure; a new caption phrase about the
    /// discrete reference fails here until `DISCRETE_PHRASES` knows it).
    #[test]
    fn continuum_referenced_figures_say_continuum() {
        let units = AxisUnits::new(false);
        for path in [
            "tests/scenes/good/tiny-linear.toml",
            "tests/scenes/good/membrane-hinged.toml",
            "tests/scenes/good/membrane-pbc.toml",
        ] {
            let sc = scene(path);
            let subject = Subject::of(&sc).expect(path);
            let run = LinearRun::prepare(&sc, &sc.runs[0]).expect("prepares");
            let refs = &run.reference.modes;
            let mut all = vec![
                subject.variance_words("r", refs),
                subject.rate_words("r", refs),
                subject.profile_words("r", units),
                subject.two_time_words("r", units),
                Words {
                    caption: subject.welch_caption(&[1, 3, 6], refs),
                    ..Words::default()
                },
            ];
            if subject.is_membrane() {
                all.push(subject.spectrum_words("r", units, refs));
            }
            for w in all {
                let before = w.caption.clone();
                let w = w.continuum_referenced();
                let body = w.caption.strip_prefix(CONTINUUM_PREFIX).expect("prefix");
                for word in [
                    "discretized",
                    "discrete mode",
                    "discrete update",
                    "discrete process",
                    "discretization",
                ] {
                    assert!(
                        !body.contains(word),
                        "{path}: {word:?} left in {body:?} (from {before:?})"
                    );
                }
                assert!(body.contains("continuum"), "{path}: {body:?}");
                assert!(w.discrete.is_empty() || w.discrete.contains("continuum"));
            }
        }
        // Said of the discrete reference, the same caption is unchanged.
        let plain = Subject::of(&scene("tests/scenes/good/tiny-linear.toml")).unwrap();
        assert!(
            plain
                .variance_words("r", &[])
                .caption
                .contains("discretized system")
        );
    }
}
