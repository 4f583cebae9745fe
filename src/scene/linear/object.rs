//! The object a linear run simulates, as the rest of the pipeline sees it: its continuum
//! reference ([`Continuum`]) and its finite-element model ([`FemObject`]). Everything else
//! — the integrators, the discrete references ([`DiscreteLaw`](crate::dynamics::DiscreteLaw)),
//! the observers, the checks — speaks of a [`LinearSystem`], its modes and positions on a
//! sampling line, whichever object it is.
//!
//! **Positions.** A linear run samples its object on a line: the filament's axis,
//! x ∈ [0, L]; the membrane's midline y = b/2, x ∈ [0, a]. Profile points and two-time
//! points are positions on that line (fractions of its length in the scene file).

use crate::error::Result;
use crate::fem::beam::BeamModel;
use crate::fem::modal::{GeneralizedModes, generalized_modes};
use crate::fem::system::LinearSystem;
use crate::spectral::HingedBeam;
use crate::spectral::membrane::{Membrane, MembraneMode};

/// Relative tolerance of the membrane's continuum mode sums (their rigorous truncation
/// bound, relative to the variance of the slowest mode).
const MEMBRANE_TOLERANCE: f64 = 1e-12;

/// The continuum reference of a linear run's object.
#[derive(Debug, Clone)]
pub(crate) enum Continuum {
    /// The hinged filament of eq. (2).
    Filament(HingedBeam),
    /// The Helfrich membrane of (M1) on its midline, with its checked modes (slowest
    /// first, [`Membrane::modes`]).
    #[allow(dead_code)] // built by the membrane scenes (issue #27), next to be wired
    Membrane {
        /// The membrane.
        membrane: Membrane,
        /// The checked modes.
        modes: Vec<MembraneMode>,
    },
}

impl Continuum {
    /// The membrane with its `count` slowest modes checked.
    ///
    /// # Errors
    /// As [`Membrane::modes`].
    #[allow(dead_code)] // called by the membrane scenes (issue #27), next to be wired
    pub(crate) fn membrane(membrane: Membrane, count: usize) -> Result<Self> {
        let modes = membrane.modes(count)?;
        Ok(Continuum::Membrane { membrane, modes })
    }

    /// Length of the sampling line: L, or the membrane's width a.
    pub(crate) fn line_length(&self) -> f64 {
        match self {
            Continuum::Filament(b) => b.params.length,
            Continuum::Membrane { membrane, .. } => membrane.params.width,
        }
    }

    /// The continuum rate of checked mode `n` (1-based): π⁴n⁴EI/(ξL⁴), or c_q/ξ.
    pub(crate) fn mode_rate(&self, n: usize) -> f64 {
        match self {
            Continuum::Filament(b) => b.mode_rate(n),
            Continuum::Membrane { membrane, modes } => membrane.mode_rate(modes[n - 1]),
        }
    }

    /// The continuum ⟨w²(x)⟩ at position `x` of the sampling line.
    ///
    /// # Errors
    /// The membrane's mode-sum errors (a position outside the rectangle).
    pub(crate) fn profile_variance(&self, x: f64) -> Result<f64> {
        match self {
            Continuum::Filament(b) => Ok(b.profile_variance(x)),
            Continuum::Membrane { membrane, .. } => Ok(membrane
                .point_variance(x, midline(membrane), MEMBRANE_TOLERANCE)?
                .value),
        }
    }

    /// The continuum ⟨w(x, t) w(y, η)⟩ from rest (eq. 4, or (M4) on the midline).
    ///
    /// # Errors
    /// Invalid positions or times.
    pub(crate) fn correlation(&self, x: f64, y: f64, t: f64, eta: f64) -> Result<f64> {
        match self {
            Continuum::Filament(b) => Ok(b.correlation(x, y, t, eta, 1e-12)?.value),
            Continuum::Membrane { membrane, .. } => {
                let m = midline(membrane);
                Ok(membrane
                    .correlation((x, m), (y, m), t, eta, MEMBRANE_TOLERANCE)?
                    .value)
            }
        }
    }
}

/// The membrane's sampling line y = b/2.
fn midline(membrane: &Membrane) -> f64 {
    0.5 * membrane.params.height
}

/// The finite-element model of a linear run's object.
#[derive(Debug, Clone)]
pub(crate) enum FemObject {
    /// Hermite-cubic beam elements.
    Beam(Box<BeamModel>),
}

impl FemObject {
    /// The linear system the model assembles.
    pub(crate) fn system(&self) -> &LinearSystem {
        match self {
            FemObject::Beam(b) => b,
        }
    }

    /// The largest rate λ_max of `(K, C)` by an O(n) inertia bisection
    /// ([`BeamModel::max_rate`]).
    ///
    /// # Errors
    /// As [`BeamModel::max_rate`].
    pub(crate) fn max_rate(&self) -> Result<f64> {
        match self {
            FemObject::Beam(b) => b.max_rate(),
        }
    }

    /// The generalized modes of `(K, C)`, signed by the object's rule; the first ones are
    /// those of the continuum's checked modes, in their order.
    ///
    /// # Errors
    /// As [`generalized_modes`].
    pub(crate) fn modes(&self) -> Result<GeneralizedModes> {
        match self {
            FemObject::Beam(b) => generalized_modes(b),
        }
    }

    /// The field at position `x` of the sampling line for state `state` (NaN outside).
    pub(crate) fn value_at(&self, state: &[f64], x: f64) -> f64 {
        match self {
            FemObject::Beam(b) => b.deflection_at(state, x),
        }
    }

    /// The positions of the mesh nodes on the sampling line (where the trajectory files
    /// record the field).
    pub(crate) fn line_nodes(&self) -> Vec<f64> {
        match self {
            FemObject::Beam(b) => b.mesh().nodes().to_vec(),
        }
    }

    /// The beam, if the object is one (its nodal slopes feed the small-slope warning).
    pub(crate) fn beam(&self) -> Option<&BeamModel> {
        match self {
            FemObject::Beam(b) => Some(b),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectral::membrane::{MembraneBoundary, MembraneParams};

    /// The membrane's continuum on its midline is the membrane's own (M3)–(M4) at y = b/2,
    /// its checked modes slowest first.
    #[test]
    fn membrane_continuum_is_the_midline_of_the_membrane() {
        let mb = Membrane::new(MembraneParams {
            tension: 3.0,
            height: 0.6,
            boundary: MembraneBoundary::SimplySupported,
            ..MembraneParams::default()
        })
        .unwrap();
        let c = Continuum::membrane(mb, 4).unwrap();
        assert_eq!(c.line_length(), 1.0);
        let rates: Vec<f64> = (1..=4).map(|n| c.mode_rate(n)).collect();
        assert!(rates.windows(2).all(|w| w[0] <= w[1]), "{rates:?}");
        let want = mb.point_variance(0.3, 0.3, 1e-12).unwrap().value;
        assert_eq!(c.profile_variance(0.3).unwrap(), want);
        let want = mb
            .correlation((0.3, 0.3), (0.5, 0.3), 0.01, 0.02, 1e-12)
            .unwrap()
            .value;
        assert_eq!(c.correlation(0.3, 0.5, 0.01, 0.02).unwrap(), want);
        assert!(c.profile_variance(1.5).is_err());
    }
}
