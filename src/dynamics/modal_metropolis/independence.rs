//! Independence moves of the membrane chain under imposed projected area (issue #28,
//! point 4 "Speed"), and the Rao–Blackwellized force.
//!
//! The global constraint acts on one direction only: with `a = √t u` (`|u| = 1`), the
//! energy `U(√t u) = ½ t uᵀΛu + (Sℓ/2)(t s_u − ε)²` (`2ℓ s_u = uᵀBu`) depends on the
//! radius through two scalars of the direction. In `(u, x = ln t)` the target density is
//! `π(u, x) ∝ exp((N/2)x − U(e^{x/2}u)/kT)` (the volume element `r^{N−1}dr dΩ =
//! ½ t^{N/2} dx dΩ`). An independence move proposes the pair afresh:
//!
//! - the direction of a Gaussian vector `y ~ N(0, kT(Λ − F̂B)⁻¹)` at a fixed load `F̂`
//!   (one `k × k` Cholesky factor per block, k ≤ 4, computed once): the angular central
//!   Gaussian law, density `∝ (uᵀ(Λ − F̂B)u)^{−N/2}` on the sphere;
//! - the log-radius from a defensive Gaussian–Student t mixture ([`RADIUS_DOF`]) on the
//!   scale of the Laplace approximation of `π(x | u')`, `N(x*(u'), v(u'))` (as the radial move's,
//!   [`ModalMetropolis::with_radial_moves`]),
//!
//! and accepts with `π(u', x') q(u, x) / (π(u, x) q(u', x'))`: an exact
//! Metropolis–Hastings update whatever `F̂` is. The Gaussian's law of `s` is far wider
//! than the constrained one (its spread is the whole excess area's, `√(2/N)` ≈ 4 % at
//! N ≈ 10³, against the stiff constraint's), but that mismatch is the radial one, which the
//! Laplace draw removes; what is left is the mismatch of the direction's law, a function of
//! the two scalars `uᵀΛu`, `uᵀBu`, each of which spreads by O(N^{−½}): the acceptance
//! stays O(1) at N ≈ 10³ (measured in `benches/membrane_area_cost.rs`).
//!
//! [`ModalMetropolis::conditional_force`] is the force averaged over the radius at the
//! current direction, `E[F | u]` (a one-dimensional integral by the trapezoidal rule on the
//! Laplace scale): its mean is ⟨F⟩ and its variance the part of F's variance the direction
//! carries, for any chain of the same law.

use super::{ModalMetropolis, cholesky, jacobi_eigen, spd_inverse};
use crate::error::{Error, Result};
use crate::rng::TrajectoryRng;
use rand::RngExt;
use rand_distr::{ChiSquared, StandardNormal};
use statrs::function::gamma::ln_gamma;

/// The trapezoidal grid of [`ModalMetropolis::conditional_force`]: nodes `x* ± j·h·√v`,
/// `j ≤ HALF_WIDTH / h`. The conditional density of `x` is log-concave and exponentially
/// narrow in its lower tail (`(N/2)x`); its upper tail is not bounded by the Laplace
/// Gaussian's (buckled, ±8 Laplace widths left out 5e-12 of the force), so the grid spans
/// ±12. On an analytic integrand the trapezoidal rule's error is `O(e^{−2π²/h²})`, about
/// 1e-34 at h = ½. Tested against the rule 4× finer and 2× wider (1e-12 relative).
const GRID_STEP: f64 = 0.5;
const HALF_WIDTH: f64 = 12.0;

/// The law of the log-radii of the independence moves is a defensive mixture on their
/// Laplace scale: the Laplace Gaussian with weight `1 − w` and a Student t with ν degrees
/// of freedom with weight `w`. The t's polynomial tails are heavier than the exponential
/// ones of the target's log-radius (`e^{h x}` as `x → −∞`, h half a part's dimension: ½
/// for a single slow mode), so the ratio of target to proposal stays bounded and the chain
/// cannot stick in a tail the proposal misses (with Gaussian log-radii alone, the single
/// slowest mode of the simply supported patch did: its means drifted by up to 3.6 standard
/// errors); the Gaussian keeps the acceptance where the Laplace law is good (a t alone
/// costs up to 5× in acceptance on the whole-vector radius, h ≈ 500).
const RADIUS_DOF: f64 = 4.0;
/// The Student t's weight `w` in the defensive mixture ([`RADIUS_DOF`]).
const DEFENSIVE_WEIGHT: f64 = 0.1;

/// The fixed Gaussian proposal of the independence moves.
#[derive(Debug, Clone)]
pub(super) struct Independence {
    /// `F̂`.
    force: f64,
    /// Per group, the lower Cholesky factor of `kT(Λ_b − F̂B_b)⁻¹` (row-major, stride 4).
    factors: Vec<[f64; 16]>,
    /// The proposed vector `y` (scratch).
    y: Vec<f64>,
    /// The part (radius) of each coordinate: 0, or 0 (slow) and 1 (the rest).
    part: Vec<usize>,
    /// Half the number of coordinates of each part.
    half_dims: Vec<f64>,
    /// `ln π − ln q` of the current state (`None`: not yet computed); the state changes
    /// only by this move's acceptance, which sets it.
    current_weight: Option<f64>,
}

/// The per-part scalars of a state's direction: `|v_p|²`, `v_pᵀΛv_p`, `v_pᵀBv_p`.
#[derive(Debug, Clone, Copy, Default)]
struct PartSums {
    norm2: f64,
    q: f64,
    two_l_s: f64,
}

/// The joint Laplace law of the parts' log-radii: mode and the Cholesky factor of the
/// Hessian (`k ≤ 2` parts, stride 4).
#[derive(Debug, Clone, Copy)]
struct Laplace {
    mode: [f64; 2],
    chol: [f64; 16],
}

impl ModalMetropolis<'_> {
    /// The largest load `F̂` at which `Λ − F̂B` is positive definite (`+∞` if `B` has no
    /// positive direction): the smallest buckling load `1/μ_max` over the blocks, `μ_max`
    /// the largest eigenvalue of `Λ_b^{−½} B_b Λ_b^{−½}`. The independence moves need
    /// `F̂` below it.
    pub fn independence_force_limit(&self) -> f64 {
        self.groups
            .iter()
            .map(|grp| {
                let k = grp.k;
                let mut m = [0.0; 16];
                for r in 0..k {
                    for c in 0..k {
                        m[4 * r + c] = grp.b[4 * r + c] / (grp.rates[r] * grp.rates[c]).sqrt();
                    }
                }
                let (values, _) = jacobi_eigen(&m, k);
                let top = values[..k].iter().copied().fold(0.0_f64, f64::max);
                if top > 0.0 { 1.0 / top } else { f64::INFINITY }
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Every step an independence move (module docs) with the Gaussian proposal at load
    /// `force` (`F̂`, below [`Self::independence_force_limit`]; in equilibrium the mean
    /// force is a good choice): an equilibrium sampler of the constrained law, exact at any
    /// `F̂`, with no dynamics (the step's Δt is not used). With `slow_rates = Some(r)` the
    /// coordinates of the blocks whose slowest rate is at most `r` get a radius of their own
    /// (two radii, drawn jointly from their Laplace law): on the buckled branch the
    /// buckled modes hold a sharp share of the excess area, which the direction of a
    /// Gaussian vector (a χ² law of the few buckled coordinates) would miss. A step draws N
    /// normals, one normal per radius and one uniform. Membrane chains only.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a filament chain, or if `Λ − F̂B` is not positive
    /// definite (`force` at or above the limit, or not finite).
    pub fn with_independence_moves(mut self, force: f64, slow_rates: Option<f64>) -> Result<Self> {
        let membrane = self.pairs.is_empty() && self.singles.is_empty() && self.components == 1;
        if !membrane {
            return Err(Error::invalid(
                "independence moves",
                "a filament chain",
                "a membrane chain (one component, general blocks)",
            ));
        }
        let limit = self.independence_force_limit();
        let invalid = || {
            Error::invalid(
                "independence load",
                force,
                format!("finite and below the first buckling load {limit:e}"),
            )
        };
        if !force.is_finite() {
            return Err(invalid());
        }
        let mut factors = Vec::with_capacity(self.groups.len());
        let mut part = Vec::with_capacity(self.n());
        for grp in &self.groups {
            let k = grp.k;
            let (inv, _) = spd_inverse(&grp.linearized(force), k).ok_or_else(invalid)?;
            let cov = inv.map(|v| v * self.kt);
            factors.push(cholesky(&cov, k).ok_or_else(invalid)?.0);
            let slowest = grp.rates[..k].iter().copied().fold(f64::INFINITY, f64::min);
            let slow = slow_rates.is_some_and(|r| slowest <= r);
            part.extend(std::iter::repeat_n(usize::from(!slow), k));
        }
        // one part only: number it 0
        if part.iter().all(|&p| p == 1) {
            part.iter_mut().for_each(|p| *p = 0);
        }
        let parts = 1 + part.iter().copied().max().unwrap_or(0);
        let mut half_dims = vec![0.0; parts];
        for &p in &part {
            half_dims[p] += 0.5;
        }
        self.independence = Some(Independence {
            force,
            factors,
            y: vec![0.0; self.n()],
            part,
            half_dims,
            current_weight: None,
        });
        Ok(self)
    }

    /// `(x*, v)`: the mode and Laplace variance of `x = ln τ` under
    /// `p(x) ∝ e^{(N/2)x − U(√τ a)/kT}` for a state `a` with `aᵀΛa = q` and `aᵀBa = two_l_s`
    /// (see [`Self::with_radial_moves`]); `None` where it has no finite positive mode.
    pub(super) fn radial_laplace(&self, q: f64, two_l_s: f64) -> Option<(f64, f64)> {
        let half_n = self.half_dimension();
        let p = &self.constraint;
        let c = &p.constraint;
        let s = p.excess(two_l_s);
        let a = c.stiffness * c.measure * s * s / self.kt;
        let b = (0.5 * q - c.stiffness * c.measure * s * p.strain) / self.kt;
        let disc = (b * b + 4.0 * a * half_n).sqrt();
        // The positive root of Aτ² + Bτ − N/2 = 0, without cancellation.
        let tau_star = if b > 0.0 {
            2.0 * half_n / (b + disc)
        } else {
            (disc - b) / (2.0 * a)
        };
        if !(tau_star.is_finite() && tau_star > 0.0) {
            return None;
        }
        Some((tau_star.ln(), 1.0 / (half_n + a * tau_star * tau_star)))
    }

    /// `N/2`, N the number of coordinates of all components.
    pub(super) fn half_dimension(&self) -> f64 {
        0.5 * (self.n() * self.components) as f64
    }

    /// `(N/2)x − U(√τ a)/kT` at `x = ln τ` for `aᵀΛa = q`, `aᵀBa = two_l_s`.
    fn radial_log_target(&self, q: f64, two_l_s: f64, x: f64) -> f64 {
        let tau = x.exp();
        let p = &self.constraint;
        self.half_dimension() * x - (0.5 * tau * q + p.energy(tau * p.excess(two_l_s))) / self.kt
    }

    /// The per-part sums of `v` (module docs) under the parts of `ind`.
    fn part_sums(&self, ind: &Independence, v: &[f64]) -> [PartSums; 2] {
        let mut sums = [PartSums::default(); 2];
        let mut at = 0;
        for grp in &self.groups {
            let k = grp.k;
            let ps = &mut sums[ind.part[at]];
            for r in 0..k {
                let vr = v[at + r];
                let bv: f64 = (0..k).map(|c| grp.b[4 * r + c] * v[at + c]).sum();
                ps.norm2 += vr * vr;
                ps.q += grp.rates[r] * vr * vr;
                ps.two_l_s += vr * bv;
            }
            at += k;
        }
        sums
    }

    /// `Σ_p h_p x_p − U/kT` at log-radii `x` for unit directions with scalars `unit`
    /// (`h_p` half of part p's dimension).
    fn parts_log_target(&self, ind: &Independence, unit: &[PartSums; 2], x: &[f64; 2]) -> f64 {
        let (mut lin, mut bend, mut two_l_s) = (0.0, 0.0, 0.0);
        for (p, &h) in ind.half_dims.iter().enumerate() {
            let tau = x[p].exp();
            lin += h * x[p];
            bend += tau * unit[p].q;
            two_l_s += tau * unit[p].two_l_s;
        }
        let c = &self.constraint;
        lin - (0.5 * bend + c.energy(c.excess(two_l_s))) / self.kt
    }

    /// The joint Laplace law of the log-radii for unit directions with scalars `unit`.
    /// At the mode each radius balances its part at one force `F`:
    /// `τ_p = 2h_p kT/(q_p − F b_p)`, and `F = S(ε − Σ_p τ_p b_p/(2ℓ))`, an increasing
    /// convex equation in `F < min_p q_p/b_p`, solved by Newton from the right (monotone).
    /// The Hessian of `−ln π` in `x` is `diag(h) + (S/(4ℓkT)) c cᵀ`, `c_p = τ_p b_p`.
    /// `None` without a finite mode.
    fn parts_laplace(&self, ind: &Independence, unit: &[PartSums; 2]) -> Option<Laplace> {
        let parts = ind.half_dims.len();
        let g = &self.constraint;
        let (stiff, ell, kt) = (g.constraint.stiffness, g.constraint.measure, self.kt);
        let f_max = (0..parts)
            .filter(|&p| unit[p].two_l_s > 0.0)
            .map(|p| unit[p].q / unit[p].two_l_s)
            .fold(f64::INFINITY, f64::min);
        // φ(F) = F − S(ε − s(F)), s(F) = Σ h_p kT b_p/(ℓ(q_p − F b_p)): value and slope
        let phi = |f: f64| {
            let (mut s, mut ds) = (0.0, 0.0);
            for (u, &h) in unit.iter().zip(&ind.half_dims) {
                let (b, d) = (u.two_l_s, u.q - f * u.two_l_s);
                s += h * kt * b / (ell * d);
                ds += h * kt * b * b / (ell * d * d);
            }
            (f - stiff * (g.strain - s), 1.0 + stiff * ds)
        };
        if !f_max.is_finite() {
            return None;
        }
        let scale = f_max.abs() + stiff * g.strain.abs() + 1.0;
        let mut delta = scale;
        let mut f = f_max - delta;
        while phi(f).0 <= 0.0 {
            delta *= 0.25;
            f = f_max - delta;
            if delta < 1e-300 {
                return None;
            }
        }
        for _ in 0..200 {
            let (v, d) = phi(f);
            let step = v / d;
            f -= step;
            if step.is_nan() || step.abs() <= 1e-15 * (f.abs() + 1.0) {
                break;
            }
        }
        let mut mode = [0.0; 2];
        let mut c = [0.0; 2];
        for p in 0..parts {
            let tau = 2.0 * ind.half_dims[p] * kt / (unit[p].q - f * unit[p].two_l_s);
            if !(tau.is_finite() && tau > 0.0) {
                return None;
            }
            mode[p] = tau.ln();
            c[p] = tau * unit[p].two_l_s;
        }
        let w = stiff / (4.0 * ell * kt);
        let mut hess = [0.0; 16];
        for r in 0..parts {
            for col in 0..parts {
                hess[4 * r + col] = w * c[r] * c[col];
            }
            hess[5 * r] += ind.half_dims[r];
        }
        let (chol, _) = cholesky(&hess, parts)?;
        Some(Laplace { mode, chol })
    }

    /// `ln q(u, x)` of the independence proposal up to a constant, for directions with
    /// scalars `unit` and log-radii `x`: the angular central Gaussian densities
    /// `(u_pᵀ(Λ − F̂B)u_p)^{−h_p}` of the parts and the law of `x` on the scale of `lap`
    /// (the Laplace law of those directions).
    fn independence_log_density(
        &self,
        ind: &Independence,
        unit: &[PartSums; 2],
        x: &[f64; 2],
        lap: &Laplace,
    ) -> f64 {
        #[cfg(test)]
        let angular = if self.drop_log_det { 0.0 } else { 1.0 };
        #[cfg(not(test))]
        let angular = 1.0;
        let parts = ind.half_dims.len();
        let mut out = 0.0;
        for (p, &h) in ind.half_dims.iter().enumerate() {
            out -= angular * h * (unit[p].q - ind.force * unit[p].two_l_s).ln();
        }
        // the mixture on the Laplace scale, r² = |Lᵀ(x − x*)|²: ln det L plus the log of
        // (1 − w) e^{−r²/2}/(2π)^{m/2} + w Γ((ν+m)/2)/(Γ(ν/2)(νπ)^{m/2}) (1 + r²/ν)^{−(ν+m)/2}
        let mut r2 = 0.0;
        for r in 0..parts {
            let v: f64 = (r..parts)
                .map(|c| lap.chol[4 * c + r] * (x[c] - lap.mode[c]))
                .sum();
            r2 += v * v;
            out += lap.chol[5 * r].ln();
        }
        let m = parts as f64;
        let (nu, w) = (RADIUS_DOF, DEFENSIVE_WEIGHT);
        let log_gauss = (1.0 - w).ln() - 0.5 * r2 - 0.5 * m * (2.0 * std::f64::consts::PI).ln();
        let log_t = w.ln() + ln_gamma(0.5 * (nu + m))
            - ln_gamma(0.5 * nu)
            - 0.5 * m * (nu * std::f64::consts::PI).ln()
            - 0.5 * (nu + m) * (r2 / nu).ln_1p();
        let top = log_gauss.max(log_t);
        out + top + ((log_gauss - top).exp() + (log_t - top).exp()).ln()
    }

    /// One independence move from `self.current` (module docs); `true` if accepted.
    pub(super) fn independence_move(&mut self, rng: &mut TrajectoryRng) -> bool {
        let Some(mut ind) = self.independence.take() else {
            return false;
        };
        for z in &mut self.z {
            *z = rng.sample(StandardNormal);
        }
        let parts = ind.half_dims.len();
        let mut zeta = [0.0; 2];
        for z in zeta.iter_mut().take(parts) {
            *z = rng.sample(StandardNormal);
        }
        let chi2: f64 =
            rng.sample(ChiSquared::new(RADIUS_DOF).expect("positive degrees of freedom"));
        let component: f64 = rng.random();
        let uniform: f64 = rng.random();
        if component < DEFENSIVE_WEIGHT {
            let spread = (RADIUS_DOF / chi2).sqrt();
            for z in zeta.iter_mut().take(parts) {
                *z *= spread;
            }
        }
        // y = C z per group
        let mut at = 0;
        for (grp, l) in self.groups.iter().zip(&ind.factors) {
            for r in 0..grp.k {
                ind.y[at + r] = (0..=r).map(|c| l[4 * r + c] * self.z[at + c]).sum();
            }
            at += grp.k;
        }
        self.proposed += 1;
        let accepted = self.accept_independent(&mut ind, zeta, uniform);
        if accepted {
            self.accepted += 1;
        }
        self.independence = Some(ind);
        accepted
    }

    /// The Hastings ratio of the independence move to the direction of `ind.y` at the
    /// log-radii drawn with the normals `zeta`; accepted against `uniform`, the state moved
    /// and evaluated.
    fn accept_independent(&mut self, ind: &mut Independence, zeta: [f64; 2], uniform: f64) -> bool {
        let parts = ind.half_dims.len();
        let unit = |sums: [PartSums; 2]| {
            let mut u = sums;
            for s in u.iter_mut().take(parts) {
                *s = PartSums {
                    norm2: s.norm2,
                    q: s.q / s.norm2,
                    two_l_s: s.two_l_s / s.norm2,
                };
            }
            u
        };
        let new_sums = self.part_sums(ind, &ind.y);
        if (0..parts).any(|p| !(new_sums[p].norm2 > 0.0 && new_sums[p].norm2.is_finite())) {
            return false;
        }
        let new_unit = unit(new_sums);
        let Some(lap) = self.parts_laplace(ind, &new_unit) else {
            return false;
        };
        let current_weight = match ind.current_weight {
            Some(w) => w,
            None => {
                let cur_sums = self.part_sums(ind, &self.current.a);
                let mut x = [0.0; 2];
                for p in 0..parts {
                    x[p] = cur_sums[p].norm2.ln();
                }
                let cur_unit = unit(cur_sums);
                let w = match self.parts_laplace(ind, &cur_unit) {
                    Some(cur_lap) if self.current.energy.is_finite() => {
                        self.parts_log_target(ind, &cur_unit, &x)
                            - self.independence_log_density(ind, &cur_unit, &x, &cur_lap)
                    }
                    // a state the proposal cannot make: leave it at the first chance
                    _ => f64::NEG_INFINITY,
                };
                ind.current_weight = Some(w);
                w
            }
        };
        // x' = x* + L⁻ᵀ ζ (back substitution)
        let mut x_new = [0.0; 2];
        for r in (0..parts).rev() {
            let tail: f64 = (r + 1..parts)
                .map(|c| lap.chol[4 * c + r] * (x_new[c] - lap.mode[c]))
                .sum();
            x_new[r] = lap.mode[r] + (zeta[r] - tail) / lap.chol[5 * r];
        }
        let new_weight = self.parts_log_target(ind, &new_unit, &x_new)
            - self.independence_log_density(ind, &new_unit, &x_new, &lap);
        let log_alpha = new_weight - current_weight;
        if !(log_alpha >= 0.0 || uniform < log_alpha.exp()) {
            return false;
        }
        let mut factor = [0.0; 2];
        for p in 0..parts {
            factor[p] = (x_new[p].exp() / new_sums[p].norm2).sqrt();
        }
        let mut cur = std::mem::take(&mut self.current);
        cur.a.clear();
        cur.a
            .extend(ind.y.iter().zip(&ind.part).map(|(v, &p)| v * factor[p]));
        self.evaluate_state(&mut cur);
        let ok = cur.energy.is_finite();
        self.current = cur;
        ind.current_weight = Some(new_weight);
        ok
    }

    /// `E[F | u]`: the compressive force averaged over the radius at the current state's
    /// direction under the chain's law (module docs), by the trapezoidal rule in `x = ln t`
    /// on the Laplace scale ([`GRID_STEP`], [`HALF_WIDTH`]). Its mean over any chain of the
    /// same law is ⟨F⟩, with less variance than F's (Rao–Blackwell). The current force if
    /// the conditional law has no finite mode.
    pub fn conditional_force(&self) -> f64 {
        self.conditional_force_on(GRID_STEP, HALF_WIDTH)
    }

    /// [`Self::conditional_force`] on the grid `x* + j·step·√v`, `|j·step| ≤ half_width`.
    fn conditional_force_on(&self, step: f64, half_width: f64) -> f64 {
        let cur = &self.current;
        let t: f64 = cur.a.iter().map(|v| v * v).sum();
        let (qc, bc) = (cur.bend / t, cur.two_l_s / t);
        let Some((x_star, var)) = (t > 0.0).then(|| self.radial_laplace(qc, bc)).flatten() else {
            return cur.force;
        };
        let sd = var.sqrt();
        let m = (half_width / step).round() as i64;
        let log_p0 = self.radial_log_target(qc, bc, x_star);
        let p = &self.constraint;
        let (mut num, mut den) = (0.0, 0.0);
        for j in -m..=m {
            let x = x_star + j as f64 * step * sd;
            let w = (self.radial_log_target(qc, bc, x) - log_p0).exp();
            num += w * p.force(p.excess(x.exp() * bc));
            den += w;
        }
        num / den
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{membrane_tau1, model, tiny_membrane};
    use super::{GRID_STEP, HALF_WIDTH};
    use crate::dynamics::{ModalMetropolis, Trajectory};
    use crate::fem::plate_area::{AreaParams, AreaTheory};
    use crate::rng::trajectory_rng;
    use crate::spectral::membrane::MembraneBoundary;

    /// `(z of ⟨F⟩, z of the mean of E[F | u], acceptance)` of an independence chain on the
    /// 3 × 3 simply supported membrane (κ = 20 kT, `K_A` = 2e4) at `ratio` ε_c0 against
    /// the exact discrete theory, after a Crank–Nicolson burn-in whose mean force is the
    /// proposal's load (with a radius of their own for the slowest modes if `split`);
    /// `drop_angular` drops the proposal's angular density from the
    /// Hastings ratio (a wrong chain).
    fn independence_z(
        ratio: f64,
        split: bool,
        drop_angular: bool,
        steps: usize,
    ) -> (f64, f64, f64) {
        let k_a = 2e4;
        let (m, modes) = tiny_membrane(MembraneBoundary::SimplySupported, 3, k_a, ratio);
        let tau1 = membrane_tau1(&m);
        let mut rng = trajectory_rng(47, ratio.to_bits() ^ u64::from(drop_angular));
        let mut chain = ModalMetropolis::for_membrane(&m, &modes, 0.02 * tau1, &mut rng).unwrap();
        let mut mean = 0.0;
        for i in 0..1000 {
            chain.step(&mut rng);
            if i >= 500 {
                mean += chain.force() / 500.0;
            }
        }
        let load = mean.min(0.99 * chain.independence_force_limit());
        let lam1 = chain.rates.iter().copied().fold(f64::INFINITY, f64::min);
        let slow = split.then_some(1.5 * lam1);
        let mut chain = chain.with_independence_moves(load, slow).unwrap();
        chain.drop_log_det = drop_angular;
        for _ in 0..1000 {
            chain.step(&mut rng);
        }
        let (p0, a0) = (chain.proposed, chain.accepted);
        let (mut forces, mut conditional) = (Vec::new(), Vec::new());
        for _ in 0..steps {
            chain.step(&mut rng);
            forces.push(chain.force());
            conditional.push(chain.conditional_force());
        }
        let params = AreaParams::from_membrane(m.plate().params(), k_a);
        let exact = -AreaTheory::discrete(&params, 3, 3)
            .unwrap()
            .mean_tension(m.strain())
            .unwrap();
        let z = |v: &[f64]| {
            let e = crate::stats::mean_with_error(v).unwrap();
            (e.mean - exact) / e.std_error
        };
        let acc = (chain.accepted - a0) as f64 / (chain.proposed - p0) as f64;
        (z(&forces), z(&conditional), acc)
    }

    /// What: the independence chain is exact, with one radius and with the slowest modes'
    /// own: in tension, at buckling and buckled, ⟨F⟩
    /// and the mean of the Rao–Blackwellized `E[F | u]` agree with the exact discrete
    /// theory within 4 standard errors (autocorrelation-aware), and the same test catches a
    /// wrong Hastings ratio (the angular density dropped).
    #[test]
    fn independence_moves_keep_the_exact_mean_force() {
        for split in [false, true] {
            for ratio in [-2.0, 1.0, 4.0] {
                let (z, z_rb, acc) = independence_z(ratio, split, false, 100_000);
                eprintln!(
                    "split {split} ratio {ratio}: z {z:.2} z_rb {z_rb:.2} acceptance {acc:.3}"
                );
                assert!(
                    z.abs() < 4.0 && z_rb.abs() < 4.0,
                    "ratio {ratio}: z = {z}, {z_rb}"
                );
                assert!(acc > 0.05, "ratio {ratio}: acceptance {acc}");
            }
        }
        let (z_wrong, _, _) = independence_z(1.0, true, true, 100_000);
        eprintln!("without the angular density: z {z_wrong:.1}");
        assert!(
            z_wrong.abs() > 4.0,
            "without the angular density: z = {z_wrong}"
        );
    }

    /// What: the trapezoidal `E[F | u]` equals the same integral on a grid 4× finer and
    /// 2× wider to 1e-12 relative, at a state in tension and one buckled.
    #[test]
    fn conditional_force_quadrature_is_converged() {
        for ratio in [-2.0, 4.0] {
            let (m, modes) = tiny_membrane(MembraneBoundary::Periodic, 4, 1e5, ratio);
            let tau1 = membrane_tau1(&m);
            let mut rng = trajectory_rng(5, 0);
            let mut chain =
                ModalMetropolis::for_membrane(&m, &modes, 0.05 * tau1, &mut rng).unwrap();
            for _ in 0..300 {
                chain.step(&mut rng);
            }
            let coarse = chain.conditional_force();
            let fine = chain.conditional_force_on(GRID_STEP / 4.0, 2.0 * HALF_WIDTH);
            let scale = m.buckling_stress();
            assert!(
                (coarse - fine).abs() <= 1e-12 * scale.max(fine.abs()),
                "ratio {ratio}: {coarse} vs {fine}"
            );
        }
    }

    /// What: a filament chain and a load at or above the first buckling load are refused.
    #[test]
    fn independence_moves_refuse_a_filament_and_an_unstable_load() {
        let (m, modes) = tiny_membrane(MembraneBoundary::SimplySupported, 3, 2e4, 0.0);
        let mut rng = trajectory_rng(1, 0);
        let chain = ModalMetropolis::for_membrane(&m, &modes, 1e-4, &mut rng).unwrap();
        let limit = chain.independence_force_limit();
        assert!(limit.is_finite() && limit > 0.0);
        assert!(
            chain
                .clone()
                .with_independence_moves(1.01 * limit, None)
                .is_err()
        );
        assert!(
            chain
                .clone()
                .with_independence_moves(f64::NAN, None)
                .is_err()
        );
        assert!(chain.with_independence_moves(0.99 * limit, None).is_ok());
        let filament = model(2, 6, 0.0);
        let paired = crate::fem::paired::PairedModes::new(filament.beam()).unwrap();
        let chain = ModalMetropolis::new(&filament, &paired, 1e-4, &mut rng).unwrap();
        assert!(chain.with_independence_moves(0.0, None).is_err());
    }
}
