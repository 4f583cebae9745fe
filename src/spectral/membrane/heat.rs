//! The point variance (M5) as a proper-time (heat-kernel) integral: the form that stays
//! fast and exact for a tension far above κq_min², where the lattice sums of `levy.rs`
//! need millions of terms (their tension correction cancels the tensionless sum).
//!
//! # The integral
//!
//! With k² = σ/κ, c_q = κq²(q² + k²) and, for q² + k² > 0 (every mode above buckling),
//!
//! 1/(q²(q² + k²)) = ∫₀^∞ e^{−q²t} g(t) dt,  g(t) = (1 − e^{−k²t})/k²  (g = t at k² = 0),
//!
//! so that (M5) becomes one integral over the heat kernel at coincident points,
//!
//! ⟨h²(r)⟩ = (kT/κ) ∫₀^∞ P(r, t) g(t) dt,  P(r, t) = Σ_φ φ(r)² e^{−q²t}/‖φ‖²   (M5c)
//!
//! - simply supported: P = p_a(x, t) p_b(y, t), the product of the Dirichlet heat kernels
//!   of the two sides, p_a(x, t) = (2/a) Σ_{m≥1} sin²(mπx/a) e^{−(mπ/a)²t}
//!   = (4πt)^{−½} Σ_{j∈ℤ} [e^{−j²a²/t} − e^{−(x+ja)²/t}] (images; Poisson summation);
//! - periodic (q = 0 excluded): P = [(1 + 2S_a)(1 + 2S_b) − 1]/A,
//!   S_a(t) = Σ_{m≥1} e^{−(2πm/a)²t}, 1 + 2S_a = a(4πt)^{−½} Σ_{j∈ℤ} e^{−j²a²/(4t)}.
//!
//! Each kernel is summed in the form whose terms fall fastest (modes for t above the
//! side's a²/π² or a²/(4π²), images below), every term to below 10⁻¹⁷ of the first.
//!
//! # Quadrature and its rigorous bound
//!
//! In w = ln t the integrand f(w) = t P(t) g(t) decays exponentially at both ends, and
//! the plain trapezoidal sum h Σ_j f(jh) over the whole line converges exponentially
//! (L. N. Trefethen and J. A. C. Weideman, SIAM Review 56, 385 (2014), Theorem 5.1): if
//! f is analytic in the strip |Im w| < d with ∫|f(w + iy)| dw ≤ M there, the error is at
//! most 2M/(e^{2πd/h} − 1). Here d = π/4: for t = e^{w+iy}, r = Re t ≥ |t|/√2, the
//! kernels have positive coefficients, so |P(t)| ≤ P(r), and |g(t)| = |t ∫₀¹ e^{−k²ts} ds|
//! ≤ |t| g(r)/r; hence |f(w + iy)| ≤ |t|² P(r) g(r)/r ≤ 2r P(r) g(r) and, with dw = dr/r,
//! M ≤ 2I (I the exact integral). With h = 1/8 the factor δ = 4/(e^{π²/(2h)} − 1) is
//! 2.8·10⁻¹⁷: the discretization error is below the rounding of the sum.
//!
//! The sum is truncated to the nodes in [ln t_lo, ln t_hi]. The nodes left out are bounded
//! by integrals of monotone bounding functions (a Riemann sum of a monotone function over
//! its tail is at most its integral):
//! - below t_lo: P(t) ≤ C_lo/(4πt) (the Dirichlet kernels lie below the free one, C_lo = 1;
//!   periodic C_lo = (1 + 2ε_a)(1 + 2ε_b), ε_a = e^{−a²/(4t_lo)}/(1 − e^{−3a²/(4t_lo)}), from
//!   j² ≥ 1 + 3(j − 1)), and g(t) ≤ t e^{νt} (ν = max(0, −k²)), so
//!   f ≤ C_lo e^{νt_lo} t/(4π): nodes below add at most C_lo e^{νt_lo} t_lo/(4π);
//! - above t_hi: P(t) ≤ (C_hi/A) e^{−q_min²t} (from Σ_{m≥1} e^{−αm²t} ≤ e^{−αt}/(1 − e^{−3αt}),
//!   C_hi evaluated at t_hi, decreasing in t) and g(t) ≤ 1/k² (k² > 0) or g(t) ≤ t e^{νt}, so
//!   the nodes above add at most C_hi e^{−r t_hi}/(A q_min² k²), or
//!   (C_hi/A) e^{−r t_hi}(t_hi/r + 1/r²), r = q_min² − ν > 0 (t_hi ≥ 2/r, where the bounding
//!   function decreases).
//!
//! With D the bound on the nodes left out and T the sum kept, |I − T| ≤ D + δ(T + D)/(1 − δ)
//! (as I ≤ (T + D)/(1 − δ)): the reported truncation error, rigorous but for the rounding
//! of the sum (about 10⁻¹⁶ relative), as for every [`SeriesValue`].
//!
//! Tested against the lattice form where both converge, against the σ = 0 closed forms,
//! and for the periodic membrane far above κq_min² against its closed form from the
//! torus Green's function (Kronecker's limit formula):
//! σ⟨h²⟩/kT = (1/2π)[ln(k/2) + γ − ln(2π η(i)²)] + 1/(Ak²) + O(e^{−kL}) on an L = 1 square.

use super::{Membrane, MembraneBoundary};
use crate::error::{Error, Result, require_positive};
use crate::spectral::{SeriesValue, sin_pi};
use std::f64::consts::PI;

/// Node spacing in ln t; the strip theorem's factor 4/(e^{π²/(2h)} − 1) is then 2.8e-17.
const STEP: f64 = 0.125;

/// Largest number of nodes: ln(t_hi/t_lo) ≤ 10⁵/8, far beyond any finite tolerance's
/// range (about 10³ nodes from σ = 0 to σ = 10³⁰ κq_min² at 10⁻¹²).
const MAX_NODES: f64 = 1.0e5;

/// Smallest t_lo: below it the free kernel 1/(4πt) nears the f64 overflow. It binds only
/// where the tolerance asks for less than 10⁻²⁹¹ in the integral's units (σ/κ beyond
/// about 10²⁷⁰), and then the bound reached is reported, as at any term cap.
const MIN_T: f64 = 1.0e-290;

/// Terms of each one-dimensional kernel: in the form used, term j is at most e^{−j²}
/// (modes) or e^{−π²j²} (images) of the first, below 10⁻¹⁷ from j = 7 and j = 2.
const KERNEL_MODES: u32 = 7;
const KERNEL_IMAGES: i32 = 3;

/// Largest number of doublings of t_hi and of divisions of t_lo by 10 (either ends long
/// before: the bounds fall exponentially and linearly).
const MAX_END_STEPS: usize = 2_000;

/// The side's one-dimensional heat kernel at coincident points.
#[derive(Clone, Copy, Debug)]
enum Side {
    /// Dirichlet on [0, a] at x: p_a(x, t).
    Dirichlet { a: f64, x: f64 },
    /// Periodic of period a: S_a(t) = Σ_{m≥1} e^{−(2πm/a)²t}.
    Periodic { a: f64 },
}

impl Side {
    /// The Dirichlet kernel p_a(x, t), or the periodic S_a(t), as (λ, v) with the kernel
    /// = e^{−λt}·v: in the mode form λ is the first mode's rate (so that neither factor
    /// underflows at large t), in the image form 0.
    fn scaled(self, t: f64) -> (f64, f64) {
        match self {
            Side::Dirichlet { a, x } => dirichlet_kernel(a, x, t),
            Side::Periodic { a } => periodic_excess(a, t),
        }
    }
}

/// p_a(x, t) = (2/a) Σ_{m≥1} sin²(mπx/a) e^{−(mπ/a)²t} as in [`Side::scaled`], by modes
/// for t ≥ a²/π², by images below (with x folded to min(x, a − x), the kernel's symmetry).
fn dirichlet_kernel(a: f64, x: f64, t: f64) -> (f64, f64) {
    let alpha = (PI / a).powi(2);
    if alpha * t >= 1.0 {
        let u = x / a;
        let sum: f64 = (1..=KERNEL_MODES)
            .rev()
            .map(|m| {
                let s = sin_pi(f64::from(m) * u);
                s * s * (-alpha * f64::from(m * m - 1) * t).exp()
            })
            .sum();
        (alpha, 2.0 * sum / a)
    } else {
        let x = x.min(a - x).max(0.0);
        let mut s = -(-x * x / t).exp_m1();
        for j in (1..=KERNEL_IMAGES).rev() {
            let ja = f64::from(j) * a;
            s += 2.0 * (-ja * ja / t).exp()
                - (-(x + ja).powi(2) / t).exp()
                - (-(ja - x).powi(2) / t).exp();
        }
        (0.0, s / (4.0 * PI * t).sqrt())
    }
}

/// S_a(t) = Σ_{m≥1} e^{−(2πm/a)²t} as in [`Side::scaled`], by modes for (2π/a)²t ≥ 1,
/// else from the images: 1 + 2S_a = a(4πt)^{−½} Σ_j e^{−j²a²/(4t)} (then a(4πt)^{−½} > √π,
/// no cancellation).
fn periodic_excess(a: f64, t: f64) -> (f64, f64) {
    let alpha = (2.0 * PI / a).powi(2);
    if alpha * t >= 1.0 {
        let sum = (1..=KERNEL_MODES)
            .rev()
            .map(|m| (-alpha * f64::from(m * m - 1) * t).exp())
            .sum();
        (alpha, sum)
    } else {
        let images: f64 = (1..=KERNEL_IMAGES)
            .rev()
            .map(|j| 2.0 * (-f64::from(j * j) * a * a / (4.0 * t)).exp())
            .sum::<f64>()
            + 1.0;
        (0.0, 0.5 * (a / (4.0 * PI * t).sqrt() * images - 1.0))
    }
}

/// Σ_{m≥1} e^{−αm²t} ≤ e^{−αt}/(1 − e^{−3αt}) (m² ≥ 1 + 3(m − 1)).
fn sum_bound(alpha: f64, t: f64) -> f64 {
    (-alpha * t).exp() / -(-3.0 * alpha * t).exp_m1()
}

/// The integrand's pieces for one membrane and point.
struct ProperTime {
    sides: [Side; 2],
    area: f64,
    /// k² = σ/κ.
    k2: f64,
    /// q_min².
    q2: f64,
    periodic: bool,
}

impl ProperTime {
    /// P(r, t)·g(t) of (M5c), each exponential e^{−λt} of the kernels taken into g
    /// ([`ProperTime::damped_g`]): below buckling's ν, g grows as e^{νt} while P decays
    /// faster, and neither may overflow or underflow alone.
    fn integrand(&self, t: f64) -> f64 {
        let ((la, pa), (lb, pb)) = (self.sides[0].scaled(t), self.sides[1].scaled(t));
        if self.periodic {
            (2.0 * pa * self.damped_g(la, t)
                + 2.0 * pb * self.damped_g(lb, t)
                + 4.0 * pa * pb * self.damped_g(la + lb, t))
                / self.area
        } else {
            pa * pb * self.damped_g(la + lb, t)
        }
    }

    /// e^{−λt} g(t), g(t) = (1 − e^{−k²t})/k² (t at k² = 0); for k² = −ν < 0 and νt > 1
    /// as (e^{−(λ−ν)t} − e^{−λt})/ν (no overflow, no cancellation).
    fn damped_g(&self, lambda: f64, t: f64) -> f64 {
        let k2 = self.k2;
        if k2 == 0.0 {
            (-lambda * t).exp() * t
        } else if k2 > 0.0 || -k2 * t <= 1.0 {
            (-lambda * t).exp() * -(-k2 * t).exp_m1() / k2
        } else {
            ((-(lambda + k2) * t).exp() - (-lambda * t).exp()) / -k2
        }
    }

    /// ν = max(0, −k²).
    fn nu(&self) -> f64 {
        (-self.k2).max(0.0)
    }

    /// Bound on the trapezoid's nodes below ln `t` (module docs).
    fn lower_bound(&self, t: f64) -> f64 {
        let c = if self.periodic {
            let eps = |side: Side| match side {
                Side::Periodic { a } => sum_bound(a * a / 4.0, 1.0 / t),
                Side::Dirichlet { .. } => 0.0,
            };
            (1.0 + 2.0 * eps(self.sides[0])) * (1.0 + 2.0 * eps(self.sides[1]))
        } else {
            1.0
        };
        c * (self.nu() * t).exp() * t / (4.0 * PI)
    }

    /// Bound on the trapezoid's nodes above ln `t`, t ≥ 2/r (module docs), with
    /// C_hi e^{−q_min²t} factored so that neither overflows (t may be far above 1/q_min²
    /// near buckling).
    fn upper_bound(&self, t: f64) -> f64 {
        let alpha = |side: Side| match side {
            Side::Dirichlet { a, .. } => (PI / a).powi(2),
            Side::Periodic { a } => (2.0 * PI / a).powi(2),
        };
        let (al, be) = (alpha(self.sides[0]), alpha(self.sides[1]));
        // Σ_{m≥1} e^{−αm²t}·e^{q t} ≤ e^{−(α − q)t}/(1 − e^{−3αt}), α ≥ q.
        let scaled = |alpha: f64, q: f64| (-(alpha - q) * t).exp() / -(-3.0 * alpha * t).exp_m1();
        let c = if self.periodic {
            let (sa, sb) = (scaled(al, self.q2), scaled(be, self.q2));
            2.0 * sa + 2.0 * sb + 4.0 * sa * sb * (-self.q2 * t).exp()
        } else {
            4.0 * scaled(al, al) * scaled(be, be)
        };
        let r = self.q2 - self.nu();
        if self.k2 > 0.0 {
            c * (-r * t).exp() / (self.area * self.q2 * self.k2)
        } else {
            c / self.area * (-r * t).exp() * (t / r + 1.0 / (r * r))
        }
    }
}

impl Membrane {
    /// (M5) as the proper-time integral (M5c) of the module docs of `heat.rs`: the heat
    /// kernel at (x, y) integrated against g(t) = (1 − e^{−k²t})/k², k² = σ/κ, by the
    /// trapezoidal rule in ln t, with a rigorous bound on the nodes left out and on the
    /// discretization (the Trefethen–Weideman strip theorem), together at most
    /// `tolerance`·[`Membrane::variance_scale`] unless that is below the rounding of the
    /// sum. Its cost, about 10³ nodes, does not grow with σ/(κq_min²): the form
    /// [`Membrane::point_variance`] takes far above κq_min². `n_modes` counts the nodes.
    ///
    /// # Errors
    /// [`crate::Error::InvalidParameter`] naming `x` or `y` outside the rectangle, or
    /// `tolerance` if it is not finite and > 0.
    pub fn point_variance_proper_time(
        &self,
        x: f64,
        y: f64,
        tolerance: f64,
    ) -> Result<SeriesValue> {
        self.check_point("x", "y", (x, y))?;
        require_positive("tolerance", tolerance)?;
        let p = &self.params;
        let periodic = p.boundary == MembraneBoundary::Periodic;
        let sides = if periodic {
            [
                Side::Periodic { a: p.width },
                Side::Periodic { a: p.height },
            ]
        } else {
            [
                Side::Dirichlet { a: p.width, x },
                Side::Dirichlet { a: p.height, x: y },
            ]
        };
        let pt = ProperTime {
            sides,
            area: p.area(),
            k2: p.tension / p.bending_rigidity,
            q2: p.min_wavenumber_sq(),
            periodic,
        };
        // The integral's own units: ⟨h²⟩ = (kT/κ)·I.
        let target = 0.45 * tolerance * self.variance_scale() * p.bending_rigidity / p.kt;
        let (t_lo, t_hi) = proper_time_ends(&pt, target);
        let (w_lo, w_hi) = (t_lo.ln(), t_hi.ln());
        let span = (w_hi - w_lo) / STEP;
        if !(span.is_finite() && span < MAX_NODES) {
            return Err(Error::Numerical {
                routine: "point_variance_proper_time".into(),
                detail: format!(
                    "no finite integration range in ln t for tolerance {tolerance:e} (t from {t_lo:e} to {t_hi:e})"
                ),
            });
        }
        let nodes = span.ceil() as usize + 1;
        let sum: f64 = (0..nodes)
            .rev()
            .map(|j| {
                let t = (w_lo + j as f64 * STEP).exp();
                t * pt.integrand(t)
            })
            .sum::<f64>()
            * STEP;
        let left_out = pt.lower_bound(t_lo) + pt.upper_bound(t_hi);
        let delta = 4.0 / (PI * PI / (2.0 * STEP)).exp_m1();
        let bound = left_out + delta * (sum + left_out) / (1.0 - delta);
        let scale = p.kt / p.bending_rigidity;
        Ok(SeriesValue {
            value: scale * sum,
            truncation_error: scale * bound,
            n_modes: nodes,
        })
    }
}

/// t_lo and t_hi whose left-out nodes are each bounded by `target` (in the integral's
/// units): t_lo from the linear lower bound, t_hi doubled from 2/r.
fn proper_time_ends(pt: &ProperTime, target: f64) -> (f64, f64) {
    let mut t_lo = 4.0 * PI * target;
    for _ in 0..MAX_END_STEPS {
        if pt.lower_bound(t_lo) <= target {
            break;
        }
        t_lo *= 0.1;
    }
    let mut t_hi = 2.0 / (pt.q2 - pt.nu());
    for _ in 0..MAX_END_STEPS {
        if pt.upper_bound(t_hi) <= target {
            break;
        }
        t_hi *= 2.0;
    }
    (t_lo.max(MIN_T), t_hi.max(t_lo))
}

#[cfg(test)]
mod tests {
    use super::super::{
        MembraneParams, PROPER_TIME_ASPECT_RATIO, PROPER_TIME_TENSION_RATIO, test_membrane,
    };
    use super::*;

    fn membrane(boundary: MembraneBoundary, tension: f64, width: f64, height: f64) -> Membrane {
        Membrane::new(MembraneParams {
            boundary,
            tension,
            bending_rigidity: 0.8,
            kt: 1.3,
            width,
            height,
            ..MembraneParams::default()
        })
        .unwrap()
    }

    // What: each one-dimensional kernel in the form it uses, on both sides of the switch
    // between images and modes, against its mode sum taken to convergence.
    // Reference: (2/a)Σ_{m≤M} sin²(mπx/a)e^{−(mπ/a)²t} and Σ_{m≤M} e^{−(2πm/a)²t} with M
    // such that the next term is below 10⁻³⁰⁰. Tolerance: 1e-14 of the kernel's scale
    // (the free kernel (4πt)^{−½}, or 1 + 2S_a).
    #[test]
    fn the_kernels_match_their_mode_sums_on_both_branches() {
        let a = 1.7;
        for &t in &[
            1e-4,
            0.01,
            0.25,
            0.99 * a * a / (PI * PI),
            a * a / (PI * PI),
            0.5,
            3.0,
        ] {
            let scale = 1.0 / (4.0 * PI * t).sqrt();
            for &x in &[0.0, 1e-3, 0.2, 0.85, 1.1, a - 1e-3, a] {
                let mut sum = 0.0;
                for m in (1..=20_000u32).rev() {
                    let s = sin_pi(f64::from(m) * x / a);
                    sum += s * s * (-(f64::from(m) * PI / a).powi(2) * t).exp();
                }
                let want = 2.0 * sum / a;
                let (rate, v) = dirichlet_kernel(a, x, t);
                let got = (-rate * t).exp() * v;
                assert!(
                    (got - want).abs() <= 1e-14 * scale,
                    "t={t} x={x}: {got:e} vs {want:e}"
                );
            }
            let alpha = (2.0 * PI / a).powi(2);
            for &tt in &[t, 0.999 / alpha, 1.0 / alpha] {
                let want: f64 = (1..=20_000u32)
                    .rev()
                    .map(|m| (-alpha * f64::from(m * m) * tt).exp())
                    .sum();
                let (rate, v) = periodic_excess(a, tt);
                let got = (-rate * tt).exp() * v;
                assert!(
                    (got - want).abs() <= 1e-14 * (1.0 + 2.0 * want),
                    "t={tt}: {got:e} vs {want:e}"
                );
            }
        }
    }

    // What: the proper-time form against the lattice form of `levy.rs`, two independent
    // derivations of (M5), where both converge: both boundaries, both orientations and a
    // 10 × 1 strip (the widest the lattice form takes), tensions from near buckling to 10 κq_min², points inside, near and
    // on the edges.
    // Reference: `point_variance` below PROPER_TIME_TENSION_RATIO and
    // PROPER_TIME_ASPECT_RATIO (the lattice form).
    // Tolerance: the two rigorous bounds plus 1e-13 of the value (rounding).
    #[test]
    fn the_proper_time_form_agrees_with_the_lattice_form() {
        for boundary in [
            MembraneBoundary::SimplySupported,
            MembraneBoundary::Periodic,
        ] {
            for (width, height) in [(1.0, 0.7), (0.7, 1.0), (2.0, 2.0), (10.0, 1.0)] {
                let q2 = membrane(boundary, 0.0, width, height)
                    .params
                    .min_wavenumber_sq();
                // The thin strip's lattice sums are long: fewer cases, a looser tolerance.
                let (ratios, tolerance): (&[f64], f64) = if width > 5.0 {
                    (&[-0.5, 9.9], 1e-9)
                } else {
                    (&[-0.95, 0.0, 0.4, 3.0, 9.9], 1e-12)
                };
                for &ratio in ratios {
                    let mb = membrane(boundary, ratio * 0.8 * q2, width, height);
                    assert!(!mb.point_variance_by_proper_time());
                    for (u, v) in [
                        (0.5, 0.5),
                        (0.3, 0.8),
                        (0.02, 0.6),
                        (1e-4, 1e-4),
                        (0.0, 0.3),
                    ] {
                        let (x, y) = (u * width, v * height);
                        let lattice = mb.point_variance(x, y, tolerance).unwrap();
                        let proper = mb.point_variance_proper_time(x, y, tolerance).unwrap();
                        let gap = (lattice.value - proper.value).abs();
                        assert!(
                            gap <= lattice.truncation_error
                                + proper.truncation_error
                                + 1e-13 * lattice.value,
                            "{boundary:?} {width}x{height} ratio {ratio} at ({x}, {y}): \
                             {lattice:?} vs {proper:?}"
                        );
                    }
                }
            }
        }
    }

    // What: the tensionless periodic square, and the periodic square far above κq_min²,
    // in closed form. Reference: ⟨h²⟩₀ = kT L² G/(24π²κ) (Catalan's G; `levy.rs`); for
    // k² = σ/κ ≫ q_min², from the zero-mean torus Green's function −(1/2π)ln|r| + R with
    // R = −(1/2π)ln(2π η(i)² L⁻¹·L)… on the unit square R = −(1/2π)ln(2πη(i)²)
    // (Kronecker's limit formula; η(i) = Γ(¼)/(2π^{3/4})) and the free kernel of
    // −∇² + k², (1/2π)K₀(kρ): σ⟨h²⟩/kT = (1/2π)[ln(k/2) + γ − ln(2πη(i)²)] + 1/(Ak²),
    // up to images of relative size e^{−kL}. Tolerance: 1e-13 relative.
    #[test]
    fn the_periodic_square_matches_its_closed_forms() {
        let square = |tension: f64| {
            Membrane::new(MembraneParams {
                boundary: MembraneBoundary::Periodic,
                tension,
                ..MembraneParams::default()
            })
            .unwrap()
        };
        let catalan = 0.915_965_594_177_219;
        let zero = square(0.0)
            .point_variance_proper_time(0.4, 0.1, 1e-14)
            .unwrap();
        let want = catalan / (24.0 * PI * PI);
        assert!(
            (zero.value / want - 1.0).abs() < 1e-13,
            "{zero:?} vs {want:e}"
        );
        let gamma_quarter = 3.625_609_908_221_908;
        let eta = gamma_quarter / (2.0 * PI.powf(0.75));
        let euler_gamma = 0.577_215_664_901_532_9;
        for sigma in [1e4, 1e8, 1e16, 1e30] {
            let mb = square(sigma);
            assert!(mb.point_variance_by_proper_time());
            let got = mb.point_variance(0.5, 0.5, 1e-14).unwrap();
            let k = sigma.sqrt();
            let want =
                ((k / 2.0).ln() + euler_gamma - (2.0 * PI * eta * eta).ln()) / (2.0 * PI) / sigma
                    + 1.0 / (sigma * k * k);
            assert!(
                (got.value / want - 1.0).abs() < 1e-13,
                "σ={sigma}: {got:?} vs {want:e}"
            );
            assert!(got.truncation_error < 1e-12 * got.value);
        }
    }

    // What: far above κq_min² the simply supported point variance takes the form
    // (kT/4πσ)[ln k² + c(x, y)] with c independent of σ (the same Green's-function
    // argument, with images of the Dirichlet rectangle); the proper-time cost stays below
    // 10³ nodes. Reference: c at σ = 10¹² against c at 10²⁰ and 10³⁰. Tolerance: 1e-12 of
    // ln k² (the images of the −∇² + k² kernel are e^{−k·distance}, nil here).
    #[test]
    fn the_simply_supported_variance_has_its_high_tension_form() {
        let mb = |sigma| membrane(MembraneBoundary::SimplySupported, sigma, 1.0, 0.7);
        let c = |sigma: f64, x: f64, y: f64| {
            let m = mb(sigma);
            let pv = m.point_variance(x, y, 1e-12).unwrap();
            assert!(pv.n_modes < 1000, "{pv:?}");
            let k2 = sigma / 0.8;
            (4.0 * PI * sigma * pv.value / 1.3 - k2.ln(), k2.ln())
        };
        for (x, y) in [(0.5, 0.35), (0.2, 0.6)] {
            let (c0, _) = c(1e12, x, y);
            for sigma in [1e20, 1e30] {
                let (c1, l) = c(sigma, x, y);
                assert!(
                    (c1 - c0).abs() < 1e-12 * l,
                    "({x}, {y}) σ={sigma}: {c1} vs {c0}"
                );
            }
        }
    }

    // What: the reported bound is honest when it binds: at a loose tolerance the value
    // lies within the bound of the value at a tight one; and `point_variance` switches
    // form at PROPER_TIME_TENSION_RATIO and PROPER_TIME_ASPECT_RATIO.
    // Reference: the tolerance-1e-14 value. Tolerance: the loose bound (plus the tight
    // one).
    #[test]
    fn a_loose_tolerance_reports_an_honest_bound() {
        for boundary in [
            MembraneBoundary::SimplySupported,
            MembraneBoundary::Periodic,
        ] {
            for tension in [0.0, 300.0, 1e9] {
                let mb = test_membrane(boundary, tension);
                let tight = mb.point_variance_proper_time(0.3, 0.2, 1e-14).unwrap();
                for tolerance in [1e-2, 1e-5, 1e-8] {
                    let loose = mb.point_variance_proper_time(0.3, 0.2, tolerance).unwrap();
                    let gap = (loose.value - tight.value).abs();
                    assert!(loose.n_modes < tight.n_modes);
                    assert!(
                        loose.truncation_error <= tolerance * mb.variance_scale(),
                        "{loose:?}"
                    );
                    assert!(
                        gap <= loose.truncation_error + tight.truncation_error,
                        "{boundary:?} σ={tension} tol={tolerance}: {gap:e} vs {loose:?}"
                    );
                }
            }
            let q2 = test_membrane(boundary, 0.0).params.min_wavenumber_sq();
            let at =
                |ratio: f64| test_membrane(boundary, ratio * q2).point_variance_by_proper_time();
            assert!(!at(PROPER_TIME_TENSION_RATIO) && at(PROPER_TIME_TENSION_RATIO * 1.001));
            let strip = |width: f64| membrane(boundary, 0.0, width, 1.0);
            assert!(!strip(PROPER_TIME_ASPECT_RATIO).point_variance_by_proper_time());
            assert!(strip(PROPER_TIME_ASPECT_RATIO * 1.001).point_variance_by_proper_time());
        }
    }
}
