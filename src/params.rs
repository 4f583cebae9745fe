//! Physical parameters of a filament, their units and dimensionless groups.
//!
//! [`FilamentParams`] holds them in any consistent unit system; [`physical`] converts a
//! filament given in physical units (µm, pN, Pa·s, K, …) to the consistent units µm, s,
//! pN.

pub mod ends;
pub mod physical;

pub use ends::{End, Ends};

use crate::error::{Result, require_positive};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Physical parameters of an elastic filament in a viscous medium. Any consistent unit
/// system may be used; all times are then in the units implied by `drag`, `length` and
/// `bending_rigidity`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FilamentParams {
    /// Filament length L.
    pub length: f64,
    /// Bending rigidity EI (energy × length).
    pub bending_rigidity: f64,
    /// Stretching rigidity EA (force). Used only by the finite-deflection model.
    pub stretch_rigidity: f64,
    /// Transverse drag coefficient per unit length ξ.
    pub drag: f64,
    /// Thermal energy k_B T.
    pub kt: f64,
}

impl Default for FilamentParams {
    /// All parameters 1, except EA = 10⁶ (so EA·L/kT = 10⁶ as in the paper's Fig. 2).
    fn default() -> Self {
        FilamentParams {
            length: 1.0,
            bending_rigidity: 1.0,
            stretch_rigidity: 1.0e6,
            drag: 1.0,
            kt: 1.0,
        }
    }
}

impl FilamentParams {
    /// Checks every parameter is finite and strictly positive.
    ///
    /// # Errors
    /// [`crate::Error::InvalidParameter`] naming the first offending parameter.
    pub fn validate(&self) -> Result<()> {
        require_positive("length", self.length)?;
        require_positive("bending_rigidity", self.bending_rigidity)?;
        require_positive("stretch_rigidity", self.stretch_rigidity)?;
        require_positive("drag", self.drag)?;
        require_positive("kt", self.kt)?;
        Ok(())
    }

    /// Slowest relaxation time of the hinged filament, τ₁ = ξL⁴/(π⁴EI) (eq. 4, n = 1).
    pub fn tau1(&self) -> f64 {
        self.drag * self.length.powi(4) / (PI.powi(4) * self.bending_rigidity)
    }

    /// Persistence length over length, ℓp/L = EI/(kT·L).
    pub fn persistence_ratio(&self) -> f64 {
        self.bending_rigidity / (self.kt * self.length)
    }

    /// Dimensionless stretching rigidity EA·L/kT.
    pub fn stretch_ratio(&self) -> f64 {
        self.stretch_rigidity * self.length / self.kt
    }

    /// Euler buckling load F_c0 = π²EI/L².
    pub fn euler_load(&self) -> f64 {
        PI * PI * self.bending_rigidity / (self.length * self.length)
    }

    /// Euler buckling strain ε_c0 = π²EI/(EA·L²).
    pub fn euler_strain(&self) -> f64 {
        self.euler_load() / self.stretch_rigidity
    }
}
