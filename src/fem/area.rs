//! The fluid membrane under imposed projected area (issue #28): the analogue of the
//! compressed von Kármán filament ([`super::vonkarman`]) for the Helfrich patch.
//!
//! A membrane of true area A₀ = ab and area modulus K_A is held by a frame that imposes
//! the projected area `A_p = (1 − ε)A₀`. Its tension is one global scalar,
//!
//! ```text
//! σ = K_A (A_p + ΔA(h) − A₀)/A₀ = K_A (s − ε),   s = ΔA/A₀,   ΔA = ½∫|∇h|² = ½ hᵀG h,
//! ```
//!
//! and the energy, with the bending energy of the Bogner–Fox–Schmit plate at zero tension
//! (`½ hᵀK_b h = ½∫κ(∇²h)²`, [`super::PlateModel`]), is
//!
//! ```text
//! U(h) = ½ hᵀK_b h + (K_A A₀/2)(s − ε)²,   −∂U/∂h = −K_b h − σ G h,
//! ```
//!
//! exactly the filament's form with `EA → K_A`, `L → A₀` and the compressive force
//! `F = −σ` ([`GlobalStrain`]). The buckling stress of the continuum is
//! `σ_c0 = κ q²_min` ([`MembraneParams::min_wavenumber_sq`]), and the strain at which a
//! membrane without thermal area would buckle is `ε_c0 = σ_c0/K_A`. Heights of a periodic
//! patch are measured from their spatial mean: the uniform translation (the plate's zero
//! mode) carries neither bending energy nor area and is left out.

use super::plate::PlateModel;
use super::vonkarman::GlobalStrain;
use crate::error::{Error, Result};
use crate::spectral::membrane::MembraneParams;
use crate::theory::compression::GlobalConstraint;

/// The membrane under imposed projected area on a uniform BFS mesh.
#[derive(Debug, Clone)]
pub struct AreaMembrane {
    plate: PlateModel,
    area_modulus: f64,
    strain: f64,
    /// Multiplies the area matrix G of the dynamics (1; fault injection only).
    area_scale: f64,
}

impl AreaMembrane {
    /// The membrane of `params` (whose tension must be 0: the tension is `K_A(s − ε)`) on
    /// an `nx × ny` mesh, with area modulus `area_modulus` (energy per area) and imposed
    /// area strain `strain = 1 − A_p/A₀`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a nonzero tension, a non-positive or non-finite
    /// area modulus, a non-finite strain, or what [`PlateModel::new`] refuses.
    pub fn new(
        params: MembraneParams,
        nx: usize,
        ny: usize,
        area_modulus: f64,
        strain: f64,
    ) -> Result<Self> {
        if params.tension != 0.0 {
            return Err(Error::invalid(
                "membrane.tension",
                params.tension,
                "0 under imposed projected area (the tension is K_A (s - eps))",
            ));
        }
        if !(area_modulus.is_finite() && area_modulus > 0.0) {
            return Err(Error::invalid(
                "area_modulus",
                area_modulus,
                "finite and > 0",
            ));
        }
        if !strain.is_finite() {
            return Err(Error::invalid("strain", strain, "finite"));
        }
        Ok(AreaMembrane {
            plate: PlateModel::new(params, nx, ny)?,
            area_modulus,
            strain,
            area_scale: 1.0,
        })
    }

    /// The same membrane whose dynamics use the area matrix `G × scale` (a bug in the
    /// excess area, e.g. a missing ½ in `ΔA = ½∫|∇h|²` at scale 2): a fault hook
    /// ([`crate::fault`]); the references keep the true G.
    #[cfg(any(test, feature = "faults"))]
    pub(crate) fn with_area_scale(mut self, scale: f64) -> Self {
        self.area_scale = scale;
        self
    }

    /// The factor on the area matrix of the dynamics (1 unless a fault is injected).
    pub fn area_scale(&self) -> f64 {
        self.area_scale
    }

    /// The bending plate (`K_b`, `C`, zero tension).
    pub fn plate(&self) -> &PlateModel {
        &self.plate
    }

    /// The area modulus K_A.
    pub fn area_modulus(&self) -> f64 {
        self.area_modulus
    }

    /// The imposed area strain ε = 1 − A_p/A₀.
    pub fn strain(&self) -> f64 {
        self.strain
    }

    /// The buckling stress of the continuum, `σ_c0 = κ q²_min`.
    pub fn buckling_stress(&self) -> f64 {
        let p = self.plate.params();
        p.bending_rigidity * p.min_wavenumber_sq()
    }

    /// The global constraint: S = K_A, ℓ = A₀, F = −σ, reference load σ_c0 and strain
    /// ε_c0 = σ_c0/K_A.
    pub fn global_strain(&self) -> GlobalStrain {
        let p = self.plate.params();
        let sigma_c0 = self.buckling_stress();
        GlobalStrain {
            constraint: GlobalConstraint {
                stiffness: self.area_modulus,
                measure: p.area(),
                kt: p.kt,
                reference_load: sigma_c0,
                reference_strain: sigma_c0 / self.area_modulus,
            },
            strain: self.strain,
        }
    }

    /// The tension `σ = K_A(s − ε)` at excess area ratio `s = ΔA/A₀`.
    pub fn tension(&self, s: f64) -> f64 {
        -self.global_strain().force(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectral::membrane::MembraneBoundary;

    /// What: the constraint's scales. Reference: σ_c0 = κπ²(1/a² + 1/b²) simply
    /// supported and κ(2π/max(a, b))² periodic, and σ = K_A(s − ε) by hand.
    #[test]
    fn scales_and_tension() {
        for (boundary, q2) in [
            (
                MembraneBoundary::SimplySupported,
                2.0 * std::f64::consts::PI.powi(2),
            ),
            (
                MembraneBoundary::Periodic,
                4.0 * std::f64::consts::PI.powi(2),
            ),
        ] {
            let p = MembraneParams {
                bending_rigidity: 20.0,
                boundary,
                ..MembraneParams::default()
            };
            let m = AreaMembrane::new(p, 4, 4, 1e4, 0.01).unwrap();
            assert!((m.buckling_stress() - 20.0 * q2).abs() < 1e-12 * 20.0 * q2);
            assert!((m.tension(0.03) - 1e4 * 0.02).abs() < 1e-9);
            assert_eq!(m.global_strain().constraint.measure, 1.0);
        }
        let bad = MembraneParams {
            tension: 1.0,
            ..MembraneParams::default()
        };
        assert!(AreaMembrane::new(bad, 4, 4, 1.0, 0.0).is_err());
        assert!(AreaMembrane::new(MembraneParams::default(), 4, 4, 0.0, 0.0).is_err());
    }
}
