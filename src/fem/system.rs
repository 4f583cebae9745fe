//! The linear Langevin system every finite-element object reduces to:
//!
//! ```text
//! C ẋ = −K x + F(t),   ⟨F(t) F(t')ᵀ⟩ = 2kT Σ_ζ δ(t − t'),
//! ```
//!
//! over the free degrees of freedom `x` of one transverse component, with symmetric
//! banded stiffness `K` and damping `C` (the semi-discrete form of eq. 2 for the filament,
//! of the Helfrich membrane's `ξ ∂h/∂t = −κ∇⁴h + σ∇²h + f` for the plate). The noise, the
//! integrators, the generalized modes and every exact discrete reference are written for a
//! [`LinearSystem`], whichever object assembled it: the beam ([`super::BeamModel`]) and the
//! Bogner–Fox–Schmit plate of the membrane are two ways of building one.
//!
//! The paper's element-uniform noise (eq. 5) needs one more thing per element: a uniform
//! random load `f_e` with `var f_e = 2ξkT/(|Ω_e| Δt)` on an element of measure `|Ω_e|`
//! (length or area), turned into nodal forces by `b_e = ∫_{Ω_e} N`. An [`ElementLoad`]
//! carries `sqrt(ξ/|Ω_e|)` and `b_e` with the free index of each local DOF.

use super::banded::SymBanded;
use crate::error::{Error, Result};

/// One element's share of the element-uniform noise (eq. 5): `ζ += amplitude · z_e · b_e`
/// with `z_e` a standard normal, `amplitude = sqrt(ξ/|Ω_e|)` and `b_e = ∫_{Ω_e} N` (local
/// DOF order), scattered to the free indices `dofs` (`None` for a constrained DOF).
#[derive(Debug, Clone, PartialEq)]
pub struct ElementLoad {
    /// `sqrt(ξ/|Ω_e|)`.
    pub amplitude: f64,
    /// `b_e = ∫_{Ω_e} N`, one entry per local DOF.
    pub load: Vec<f64>,
    /// Free index of each local DOF (`None` where constrained), as long as `load`.
    pub dofs: Vec<Option<usize>>,
}

/// `C ẋ = −K x + F` over `n` free DOFs at temperature `kT` (see the module docs).
#[derive(Debug, Clone)]
pub struct LinearSystem {
    kt: f64,
    stiffness: SymBanded,
    damping: SymBanded,
    loads: Vec<ElementLoad>,
}

impl LinearSystem {
    /// The system with stiffness `K`, damping `C`, thermal energy `kT` and the element
    /// loads of the element-uniform noise.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if `kT` is not finite and positive, `K` and `C` differ
    /// in size, or an element load's DOFs are not free indices of the system or differ in
    /// number from its load entries.
    pub fn new(
        kt: f64,
        stiffness: SymBanded,
        damping: SymBanded,
        loads: Vec<ElementLoad>,
    ) -> Result<Self> {
        if !(kt.is_finite() && kt > 0.0) {
            return Err(Error::invalid("kt", kt, "finite and > 0"));
        }
        let n = stiffness.n();
        if damping.n() != n {
            return Err(Error::invalid(
                "damping matrix size",
                damping.n(),
                format!("= stiffness matrix size {n}"),
            ));
        }
        for (e, l) in loads.iter().enumerate() {
            if l.load.len() != l.dofs.len() || l.dofs.iter().flatten().any(|&i| i >= n) {
                return Err(Error::invalid(
                    format!("element load {e}"),
                    format!("{} entries on DOFs {:?}", l.load.len(), l.dofs),
                    format!("one entry per local DOF, free indices < {n}"),
                ));
            }
        }
        Ok(LinearSystem {
            kt,
            stiffness,
            damping,
            loads,
        })
    }

    /// Thermal energy `kT`.
    pub fn kt(&self) -> f64 {
        self.kt
    }

    /// Number of free DOFs `n`.
    pub fn n_dofs(&self) -> usize {
        self.stiffness.n()
    }

    /// Stiffness `K` over the free DOFs.
    pub fn stiffness(&self) -> &SymBanded {
        &self.stiffness
    }

    /// Damping `C` over the free DOFs.
    pub fn damping(&self) -> &SymBanded {
        &self.damping
    }

    /// The element loads of the element-uniform noise, in element order.
    pub fn element_loads(&self) -> &[ElementLoad] {
        &self.loads
    }

    /// Assembled load vector `b = Σ_e b_e` over the free DOFs, so that the integral of the
    /// field over the object is `bᵀx`.
    pub fn assembled_load_vector(&self) -> Vec<f64> {
        let mut b = vec![0.0; self.n_dofs()];
        for l in &self.loads {
            for (v, d) in l.load.iter().zip(&l.dofs) {
                if let Some(i) = d {
                    b[*i] += v;
                }
            }
        }
        b
    }

    /// Largest generalized eigenvalue `λ_max` of `K φ = λ C φ` by Sturm-sequence bisection,
    /// without any eigensolver: the number of eigenvalues below `s` equals the number of
    /// negative pivots of the banded `LDLᵀ` of `K − sC` (Sylvester's law of inertia; a
    /// zero pivot is avoided by shifting `s` by a relative 1e-13, up to 8 times).
    ///
    /// The bracket: `upper` is a proven upper bound (e.g. Fried's element bound
    /// `max_e λ_max(K_e, C_e)`), confirmed by its count and doubled until no eigenvalue lies
    /// above it; the Rayleigh quotient of `trial` (times `1 − 10⁻⁹`) is a lower bound, used
    /// if its count confirms it (else 0). Bisection then runs to a relative width of 1e-13.
    /// Cost `O(n·bw²)` per step, about 45 steps. Shared by [`super::BeamModel::max_rate`]
    /// and [`super::PlateModel::max_rate`].
    ///
    /// # Errors
    /// [`Error::Numerical`] if the bracket cannot be established.
    ///
    /// # Panics
    /// If `trial.len() != n_dofs()`.
    pub fn max_rate_bisection(&self, upper: f64, trial: &[f64]) -> Result<f64> {
        let n = self.n_dofs();
        let count_above = |sigma: f64| -> Result<usize> {
            let mut s = sigma;
            let mut last = None;
            for _ in 0..8 {
                let a = SymBanded::linear_combination(1.0, self.stiffness(), -s, self.damping())?;
                match a.negative_eigenvalue_count() {
                    // eigenvalues of (K, C) below s = negative pivots; none equals s
                    Ok(neg) => return Ok(n - neg),
                    Err(e) => {
                        last = Some(e);
                        s *= 1.0 + 1e-13;
                    }
                }
            }
            Err(last.unwrap_or_else(|| Error::Numerical {
                routine: "max_rate".into(),
                detail: "inertia count failed".into(),
            }))
        };
        let mut hi = upper;
        let mut tries = 0;
        while count_above(hi)? > 0 {
            hi *= 2.0;
            tries += 1;
            if tries > 60 {
                return Err(Error::Numerical {
                    routine: "max_rate".into(),
                    detail: "no upper bound for lambda_max found".into(),
                });
            }
        }
        let rq = self.stiffness().quadratic_form(trial) / self.damping().quadratic_form(trial);
        let mut lo = rq * (1.0 - 1e-9);
        if !(lo.is_finite() && lo > 0.0 && lo < hi && count_above(lo)? >= 1) {
            lo = 0.0;
        }
        for _ in 0..200 {
            if hi - lo <= 1e-13 * hi {
                break;
            }
            let mid = 0.5 * (lo + hi);
            if count_above(mid)? >= 1 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Ok(0.5 * (lo + hi))
    }

    /// A fault's system ([`crate::fault`]; test and `faults` builds only): `K` and `C`
    /// multiplied by `k` and `c` (the element loads unchanged).
    ///
    /// # Errors
    /// As [`SymBanded::linear_combination`].
    #[cfg(any(test, feature = "faults"))]
    pub(crate) fn scale_matrices(&mut self, k: f64, c: f64) -> Result<()> {
        let scale = |m: &SymBanded, f: f64| SymBanded::linear_combination(f, m, 0.0, m);
        self.stiffness = scale(&self.stiffness, k)?;
        self.damping = scale(&self.damping, c)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_inconsistent_parts() {
        let m = SymBanded::new(3, 1);
        assert!(LinearSystem::new(0.0, m.clone(), m.clone(), vec![]).is_err());
        assert!(LinearSystem::new(1.0, m.clone(), SymBanded::new(2, 1), vec![]).is_err());
        let bad = ElementLoad {
            amplitude: 1.0,
            load: vec![1.0, 2.0],
            dofs: vec![Some(0), Some(3)],
        };
        assert!(LinearSystem::new(1.0, m.clone(), m.clone(), vec![bad]).is_err());
        let good = ElementLoad {
            amplitude: 1.0,
            load: vec![1.0, 2.0],
            dofs: vec![Some(0), None],
        };
        let s = LinearSystem::new(1.0, m.clone(), m, vec![good]).unwrap();
        assert_eq!(s.assembled_load_vector(), vec![1.0, 0.0, 0.0]);
    }
}
