//! Exact continuum theory of the linear filament with any ends (issue #29).
//!
//! The filament of eq. (2), ξ ∂w/∂t + EI ∂⁴w/∂x⁴ = f(x,t) with the white load of eq. (1),
//! ⟨f(x,t) f(y,τ)⟩ = 2ξkT δ(x−y) δ(t−τ), on [0, L], with each end hinged (w = w″ = 0),
//! clamped (w = w′ = 0) or free (w″ = w‴ = 0) — [`Ends`], left end at x = 0. Both ends
//! hinged is the paper's filament, [`HingedBeam`]; [`EndedBeam`] reproduces it exactly
//! and extends every result to the other eight pairs of ends.
//!
//! # Modes
//!
//! The operator ∂⁴/∂x⁴ with any of these end conditions is self-adjoint and non-negative
//! on L²(0, L): for two functions that satisfy them, ∫₀ᴸ φ″″ψ dx = ∫₀ᴸ φ″ψ″ dx because the
//! boundary terms [φ‴ψ − φ″ψ′]₀ᴸ vanish at every end (hinged: ψ = φ″ = 0; clamped:
//! ψ = ψ′ = 0; free: φ″ = φ‴ = 0). Its eigenfunctions φₙ″″ = qₙ⁴ φₙ are complete and
//! orthogonal. With u = x/L and β = qL they are combinations of cos βu, sin βu, cosh βu,
//! sinh βu; the end conditions are four homogeneous equations on the four coefficients,
//! whose determinant vanishes on the roots βₙ of the characteristic equation
//! ([`CharacteristicEquation`]):
//!
//! | ends (either order)                | equation            | βₙ = qₙL →  | rigid modes |
//! |------------------------------------|---------------------|-------------|-------------|
//! | hinged–hinged                      | sin β = 0           | nπ (exact)  | —           |
//! | clamped–clamped, free–free         | cos β cosh β = 1    | (n + ½)π    | ff: 2       |
//! | clamped–free                       | cos β cosh β = −1   | (n − ½)π    | —           |
//! | clamped–hinged, hinged–free        | tan β = tanh β      | (n + ¼)π    | hf: 1       |
//!
//! Mode numbers n = 1, 2, … count the **elastic** modes (q > 0) in ascending order; the
//! root β = 0 of the free–free and hinged–free equations is the rigid motion, listed
//! separately by [`EndedBeam::rigid_modes`]. A mirror pair (clamped–free and
//! free–clamped) has the same wavenumbers and mirrored shapes.
//!
//! **Roots to full precision.** The equations are solved in a form that stays well
//! conditioned for every n. With β = β⁰ₙ + δ and β⁰ₙ the asymptote above:
//! cos β cosh β = ±1 becomes sin δ = (−1)ⁿ⁺¹ sech(β⁰ₙ + δ) (for both signs, with
//! β⁰ₙ = (n ± ½)π), solved by Newton's method from δ = 0; tan β = tanh β becomes
//! δ = −arctan e^{−2(β⁰ₙ + δ)} (because tan(π/4 + δ) = tanh β and
//! arctan(tanh β) − π/4 = arctan(−e^{−2β})), a contraction by a factor below 4·10⁻³,
//! iterated to a fixed point. δ is tiny for large n (|δ| ≈ 2e^{−β}) and computed to full
//! relative precision, so βₙ carries the rounding of β⁰ₙ only.
//!
//! **Shapes, evaluated stably.** The textbook form cosh βu − cos βu − σₙ(sinh βu − sin βu)
//! subtracts numbers of size e^{β}/2 (10⁶⁸ at n = 50) to get an O(1) result and loses every
//! digit. Here every mode is written
//!
//! φₙ(x) = A cos βu + B sin βu + C e^{−βu} + D e^{−β(1−u)},  u = x/L, β = βₙ,
//!
//! in which no term exceeds its O(1) coefficient: C is the boundary layer at x = 0, D the
//! one at x = L. The two conditions at x = 0 leave a two-dimensional family of
//! coefficient vectors (e.g. clamped: A = −C − De^{−β}, B = C − De^{−β}); the two
//! conditions at x = L on that family form a 2 × 2 matrix, singular at βₙ, with O(1)
//! entries; its null vector is read off its larger row. Hinged–hinged uses sin(nπu) itself,
//! with exact zeros at the ends.
//!
//! **Normalization and sign.** ∫₀ᴸ φₙ² dx = L/2 (so hinged–hinged gives exactly
//! sin(nπx/L), as [`HingedBeam`]), computed from the closed-form integrals of the
//! products of the four terms. The sign makes the first non-zero Taylor coefficient of φₙ
//! at x = 0 positive: φₙ′(0) > 0 at a hinged left end, φₙ″(0) > 0 at a clamped one,
//! φₙ(0) > 0 at a free one. (Those coefficients never vanish: if, say, φ, φ′ and φ″ all
//! vanished at a clamped end, φ would be a multiple of sinh βu − sin βu, which satisfies no
//! end condition at u = 1 for β > 0; likewise for the other two ends.)
//!
//! # Dynamics and equipartition
//!
//! Writing w = Σₙ aₙ φₙ + Σₖ bₖ ψₖ (ψₖ the rigid modes, same normalization) and projecting
//! eq. (2) on φₙ gives, as for the hinged beam, independent Ornstein–Uhlenbeck processes
//! daₙ/dt = −λₙ aₙ + gₙ with λₙ = EI qₙ⁴/ξ and ⟨gₙ(t) gₘ(τ)⟩ = δₙₘ (4kT/(ξL)) δ(t−τ); the
//! stationary variance is σₙ² = (4kT/(ξL))/(2λₙ) = 2kT/(EI qₙ⁴ L) (also equipartition: the
//! bending energy (EI/2)∫w″² = Σₙ ½ (EI qₙ⁴ L/2) aₙ², by the self-adjointness above). The
//! two-time correlation from rest (eq. 4 generalized, elastic modes) is
//!
//! ⟨w(x,t) w(y,η)⟩ = Σₙ σₙ² φₙ(x) φₙ(y) [e^{−λₙ(η−t)} − e^{−λₙ(η+t)}],  0 ≤ t ≤ η.
//!
//! A rigid mode has no restoring force: dbₖ/dt = gₖ, a free diffusion with
//! ⟨(bₖ(t) − bₖ(0))²⟩ = 4kT t/(ξL); from rest it adds Σₖ ψₖ(x)ψₖ(y)·4kT t/(ξL) to the
//! correlation ([`EndedBeam::rigid_correlation`]), which never becomes stationary.
//!
//! # Equilibrium covariance in closed form
//!
//! The t = η → ∞ limit of the elastic correlation is kT·G(x, y) with G = Σₙ φₙφₙ/(EI qₙ⁴
//! L/2), the Green's function of EI d⁴/dx⁴ with these ends: EI ∂⁴G/∂x⁴ = δ(x−y) −
//! P(x, y), where P = Σₖ ψₖ(x)ψₖ(y)/(L/2) projects on the rigid modes (P = 0 without them;
//! with them G is the pseudo-inverse, ∫₀ᴸ G(x, y) ψₖ(x) dx = 0). G is a polynomial in x on
//! each side of y (cubic, or quintic where P ≠ 0) satisfying the end conditions, with
//! G, ∂G/∂x, ∂²G/∂x² continuous and EI ∂³G/∂x³ jumping by 1 at x = y; those conditions and
//! the orthogonality fix it. With u = x/L, v = y/L, a = min(u, v), b = max(u, v),
//! ā = 1 − a, b̄ = 1 − b and s = u − ½, t = v − ½, G = (L³/EI)·g:
//!
//! | ends     | g(u, v)                                                                      | g(u, u) (profile ⟨w²⟩/(kTL³/EI)) |
//! |----------|------------------------------------------------------------------------------|-------------------------------------|
//! | h–h      | a b̄ (2b − a² − b²)/6                                                         | u²(1−u)²/3                          |
//! | c–c      | a² b̄² [3(b − a) + 2a b̄]/6                                                    | u³(1−u)³/3                          |
//! | c–f      | a² (3b − a)/6                                                                | u³/3                                |
//! | c–h      | a² b̄ [3(b − a) + b̄(3b + a b̄)]/12                                            | u³(1−u)²(4−u)/12                    |
//! | h–f      | a [198b − 420b² + 210b³ − 21b⁵ − 140a² + 210a²b − 21a⁴b]/840                   | u²(99 − 280u + 210u² − 21u⁴)/420    |
//! | f–f      | \|s−t\|³/12 + 1/320 − (s²+t²)/16 − (s⁴+t⁴)/24 + st[33/560 + (s²+t²)/4 − (s⁴+t⁴)/10] | 1/320 − 37s²/560 + 5s⁴/12 − s⁶/5 |
//!
//! and the mirrors (f–c, h–c, f–h) by u → 1 − u, v → 1 − v. Checks: clamped–free has the
//! cantilever's tip compliance L³/(3EI), so ⟨w²(L)⟩ = kT L³/(3EI); clamped–clamped at
//! midspan L³/(192EI), the classical fixed–fixed compliance; the free–free ends have
//! kTL³/(105EI), hinged–free's free end 2kTL³/(105EI). The clamped forms are written
//! with (b − a) ≥ 0 and b̄ so that every term is non-negative: no cancellation near the
//! ends, where the variance vanishes. Every row is tested against the mode sums with
//! their rigorous tail bounds (`tests/ends_theory.rs`).
//!
//! # Truncation bounds
//!
//! Tails of the mode sums are bounded by three facts, each proved where it is computed:
//! a bound K ≥ supₓ |φₙ(x)| valid for every n ([`EndedBeam::mode_shape_bound`]); a lower
//! bound βₙ ≥ (n + c)π with a constant c per equation
//! ([`EndedBeam::wavenumber_lower_bound`]); and, by the convexity of (n + c)⁻⁴,
//! Σ_{n>N} βₙ⁻⁴ ≤ β_{N+1}⁻⁴ + 1/(3π⁴(N + 3/2 + c)³) ([`EndedBeam::inverse_fourth_power_tail`]).
//!
//! # Conventions
//!
//! As [`HingedBeam`]: mode numbers start at 1 and the per-mode functions return NaN for
//! n = 0; functions returning a plain `f64` of a position return NaN outside [0, L]; the
//! fallible ones return [`Error::InvalidParameter`] naming the argument.

use super::{
    HingedBeam, MAX_MODES, SeriesValue, check_two_times, ou_lorentzian, ou_sampled_spectrum, sin_pi,
};
use crate::error::{Error, Result, require_in_range, require_positive};
use crate::params::{End, Ends, FilamentParams};
use std::f64::consts::{FRAC_1_SQRT_2, PI};

/// The number of modes whose shapes [`EndedBeam::mode_shape_bound`] bounds one by one
/// before the analytic bound takes over.
const SHAPE_BOUND_MODES: usize = 100;

/// Relative safety margin on bounds computed from floating-point coefficients (their
/// rounding is of order 10⁻¹⁵).
const ROUNDING_MARGIN: f64 = 1.0e-12;

/// The characteristic equation whose positive roots βₙ = qₙL give the elastic modes of a
/// pair of ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CharacteristicEquation {
    /// sin β = 0 (hinged–hinged): βₙ = nπ.
    SinZero,
    /// cos β cosh β = 1 (clamped–clamped, free–free): βₙ → (n + ½)π.
    CosCoshPlusOne,
    /// cos β cosh β = −1 (clamped–free, free–clamped): βₙ → (n − ½)π.
    CosCoshMinusOne,
    /// tan β = tanh β (clamped–hinged, hinged–clamped, hinged–free, free–hinged):
    /// βₙ → (n + ¼)π.
    TanTanh,
}

impl CharacteristicEquation {
    /// The equation of a pair of ends (the same for a pair and its mirror).
    pub fn of(ends: Ends) -> Self {
        use End::{Clamped, Free, Hinged};
        match (ends.left, ends.right) {
            (Hinged, Hinged) => Self::SinZero,
            (Clamped, Clamped) | (Free, Free) => Self::CosCoshPlusOne,
            (Clamped, Free) | (Free, Clamped) => Self::CosCoshMinusOne,
            (Clamped, Hinged) | (Hinged, Clamped) | (Hinged, Free) | (Free, Hinged) => {
                Self::TanTanh
            }
        }
    }

    /// The equation as text, in qL.
    pub fn formula(self) -> &'static str {
        match self {
            Self::SinZero => "sin qL = 0",
            Self::CosCoshPlusOne => "cos qL cosh qL = 1",
            Self::CosCoshMinusOne => "cos qL cosh qL = -1",
            Self::TanTanh => "tan qL = tanh qL",
        }
    }

    /// The offset ν of the asymptote βₙ → (n + ν)π: 0, ½, −½ or ¼.
    pub fn asymptotic_offset(self) -> f64 {
        match self {
            Self::SinZero => 0.0,
            Self::CosCoshPlusOne => 0.5,
            Self::CosCoshMinusOne => -0.5,
            Self::TanTanh => 0.25,
        }
    }

    /// A constant c with βₙ ≥ (n + c)π for every n ≥ 1: 0, 0.47, −0.53 or 0.249.
    ///
    /// Proof. sin β = 0: βₙ = nπ. cos β cosh β = ±1: βₙ = (n + ν)π + δₙ with
    /// sin δₙ = ±sech βₙ and |δₙ| < π/2, so βₙ lies in ((n + ν − ½)π, (n + ν + ½)π).
    /// For ν = ½, and for ν = −½ with n ≥ 2, that gives βₙ > π, hence
    /// |δₙ| = arcsin(sech βₙ) < arcsin(sech π) < 0.0864 < 0.03π, and βₙ > (n + ν − 0.03)π.
    /// For ν = −½ and n = 1, δ₁ > 0 (sin δ₁ = +sech β₁), so β₁ > π/2 > 0.47π.
    /// tan β = tanh β: δₙ = −arctan e^{−2βₙ} ∈ (−e^{−2βₙ}, 0) with βₙ > nπ ≥ π, so
    /// |δₙ| < e^{−2π} < 0.001π and βₙ > (n + 0.249)π.
    pub fn lower_bound_offset(self) -> f64 {
        match self {
            Self::SinZero => 0.0,
            Self::CosCoshPlusOne => 0.47,
            Self::CosCoshMinusOne => -0.53,
            Self::TanTanh => 0.249,
        }
    }

    /// The n-th positive root βₙ = qₙL (n ≥ 1; NaN for n = 0), to full double precision
    /// (see the module docs for the well-conditioned forms solved).
    pub fn root(self, n: usize) -> f64 {
        if n == 0 {
            return f64::NAN;
        }
        let b0 = (n as f64 + self.asymptotic_offset()) * PI;
        match self {
            Self::SinZero => n as f64 * PI,
            Self::CosCoshPlusOne | Self::CosCoshMinusOne => {
                // cos((n + ½)π + δ) = −(−1)ⁿ sin δ and cos((n − ½)π + δ) = (−1)ⁿ sin δ, so
                // cos β = sech β (β⁰ = (n + ½)π) and cos β = −sech β (β⁰ = (n − ½)π) both
                // read sin δ = σ sech(β⁰ + δ), σ = (−1)ⁿ⁺¹. Newton's method on
                // g(δ) = sin δ − σ sech(β⁰ + δ), started at the fixed-point iterate
                // arcsin(σ sech β⁰).
                let sigma = if n % 2 == 1 { 1.0 } else { -1.0 };
                let mut d = (sigma * sech(b0)).asin();
                for _ in 0..60 {
                    let b = b0 + d;
                    let sh = sech(b);
                    let g = d.sin() - sigma * sh;
                    let dg = d.cos() + sigma * sh * b.tanh();
                    let step = g / dg;
                    d -= step;
                    if step.is_nan() || step.abs() <= 0.25 * f64::EPSILON * b0 {
                        break;
                    }
                }
                b0 + d
            }
            Self::TanTanh => {
                // δ = −arctan e^{−2(β⁰ + δ)}: a contraction by 2e^{−2β} < 4·10⁻³.
                let mut d = 0.0_f64;
                for _ in 0..60 {
                    let next = -(-2.0 * (b0 + d)).exp().atan();
                    if next == d {
                        break;
                    }
                    d = next;
                }
                b0 + d
            }
        }
    }
}

/// sech x for x ≥ 0, without overflow: 2e^{−x}/(1 + e^{−2x}).
fn sech(x: f64) -> f64 {
    let e = (-x).exp();
    2.0 * e / (1.0 + e * e)
}

/// One elastic mode in the stable form of the module docs, unnormalized or normalized.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Mode {
    /// sin(nπu) (hinged–hinged).
    Sine { n: usize },
    /// A cos βu + B sin βu + C e^{−βu} + D e^{−β(1−u)}.
    General {
        beta: f64,
        a: f64,
        b: f64,
        c: f64,
        d: f64,
    },
}

impl Mode {
    /// The general-form mode of `ends` at the root `beta`, normalized (∫₀¹ φ² du = ½) and
    /// signed (first non-zero Taylor coefficient at u = 0 positive).
    fn general(ends: Ends, beta: f64) -> Mode {
        let e = (-beta).exp();
        let (s, c) = beta.sin_cos();
        // Coefficient vectors (A, B, C, D) spanning the solutions of the left conditions.
        let (v1, v2) = match ends.left {
            End::Hinged => ([0.0, 1.0, 0.0, 0.0], [0.0, 0.0, -e, 1.0]),
            End::Clamped => ([-1.0, 1.0, 1.0, 0.0], [-e, -e, 0.0, 1.0]),
            End::Free => ([1.0, -1.0, 1.0, 0.0], [e, e, 0.0, 1.0]),
        };
        // Rows of φ, φ′/β, φ″/β², φ‴/β³ at u = 1.
        let value = [c, s, e, 1.0];
        let d1 = [-s, c, -e, 1.0];
        let d2 = [-c, -s, e, 1.0];
        let d3 = [s, -c, -e, 1.0];
        let rows = match ends.right {
            End::Hinged => [value, d2],
            End::Clamped => [value, d1],
            End::Free => [d2, d3],
        };
        let dot = |r: &[f64; 4], v: &[f64; 4]| r.iter().zip(v).map(|(p, q)| p * q).sum::<f64>();
        let m: Vec<[f64; 2]> = rows.iter().map(|r| [dot(r, &v1), dot(r, &v2)]).collect();
        let size = |r: &[f64; 2]| r[0].hypot(r[1]);
        let row = if size(&m[0]) >= size(&m[1]) {
            m[0]
        } else {
            m[1]
        };
        let (al1, al2) = (-row[1], row[0]);
        let coef: Vec<f64> = (0..4).map(|k| al1 * v1[k] + al2 * v2[k]).collect();
        let raw = Mode::General {
            beta,
            a: coef[0],
            b: coef[1],
            c: coef[2],
            d: coef[3],
        };
        let mut scale = 1.0 / (2.0 * raw.norm_squared()).sqrt();
        let lead_order = match ends.left {
            End::Free => 0,
            End::Hinged => 1,
            End::Clamped => 2,
        };
        if raw.derivative(lead_order, 0.0, 1.0) < 0.0 {
            scale = -scale;
        }
        raw.scaled(scale)
    }

    /// The mode with every coefficient multiplied by `k`.
    fn scaled(self, k: f64) -> Mode {
        match self {
            Mode::Sine { .. } => self,
            Mode::General { beta, a, b, c, d } => Mode::General {
                beta,
                a: a * k,
                b: b * k,
                c: c * k,
                d: d * k,
            },
        }
    }

    /// ∫₀¹ φ² du in closed form (general form; ½ for the sine). With E = e^{−β}:
    /// ∫cos² = ½ + sin 2β/(4β), ∫sin² = ½ − sin 2β/(4β), ∫cos·sin = sin²β/(2β),
    /// ∫e^{−2βu} = ∫e^{−2β(1−u)} = (1 − E²)/(2β), ∫e^{−βu}e^{−β(1−u)} = E,
    /// J₁ = ∫cos βu e^{−βu} = (1 + E(sin β − cos β))/(2β),
    /// J₂ = ∫sin βu e^{−βu} = (1 − E(sin β + cos β))/(2β), and by u → 1 − u
    /// ∫cos βu e^{−β(1−u)} = cos β J₁ + sin β J₂, ∫sin βu e^{−β(1−u)} = sin β J₁ − cos β J₂.
    fn norm_squared(&self) -> f64 {
        match *self {
            Mode::Sine { .. } => 0.5,
            Mode::General { beta, a, b, c, d } => {
                let e = (-beta).exp();
                let (s, co) = beta.sin_cos();
                let s2 = 2.0 * s * co;
                let tb = 2.0 * beta;
                let icc = 0.5 + s2 / (2.0 * tb);
                let iss = 0.5 - s2 / (2.0 * tb);
                let ics = s * s / tb;
                let iee = -(-tb).exp_m1() / tb;
                let j1 = (1.0 + e * (s - co)) / tb;
                let j2 = (1.0 - e * (s + co)) / tb;
                let j3 = co * j1 + s * j2;
                let j4 = s * j1 - co * j2;
                a * a * icc
                    + b * b * iss
                    + 2.0 * a * b * ics
                    + (c * c + d * d) * iee
                    + 2.0 * c * d * e
                    + 2.0 * (a * c * j1 + b * c * j2 + a * d * j3 + b * d * j4)
            }
        }
    }

    /// d^k φ/du^k divided by βᵏ (β = nπ for the sine), at u with ū = 1 − u given
    /// separately (for accuracy near u = 1).
    fn derivative(&self, order: u32, u: f64, ubar: f64) -> f64 {
        match *self {
            Mode::Sine { n } => sin_pi(n as f64 * u + 0.5 * (order % 4) as f64),
            Mode::General { beta, a, b, c, d } => {
                let (s, co) = (beta * u).sin_cos();
                let left = (-beta * u).exp();
                let right = (-beta * ubar).exp();
                let sign = if order.is_multiple_of(2) { 1.0 } else { -1.0 };
                let osc = match order % 4 {
                    0 => a * co + b * s,
                    1 => -a * s + b * co,
                    2 => -a * co - b * s,
                    _ => a * s - b * co,
                };
                osc + sign * c * left + d * right
            }
        }
    }

    /// A rigorous bound on sup over u of |φ(u)|, from the triangle inequality:
    /// |A cos + B sin| ≤ √(A² + B²), and C e^{−βu} + D e^{−β(1−u)} is convex in u, so
    /// its modulus is at most max(|C| + |D|E, |C|E + |D|).
    fn sup_bound(&self) -> f64 {
        match *self {
            Mode::Sine { .. } => 1.0,
            Mode::General { beta, a, b, c, d } => {
                let e = (-beta).exp();
                let layers = (c.abs() + d.abs() * e).max(c.abs() * e + d.abs());
                (a.hypot(b) + layers) * (1.0 + ROUNDING_MARGIN)
            }
        }
    }
}

/// The kind of a rigid-body (zero-stiffness) motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RigidMotion {
    /// A uniform translation, w = const (free–free).
    Translation,
    /// A rotation about the point x = `pivot`, w ∝ x − pivot (free–free: the centre
    /// L/2; hinged–free: the hinge, 0 or L).
    Rotation {
        /// The fixed point of the rotation.
        pivot: f64,
    },
}

/// A rigid-body mode of a filament with a free end and no clamp: its shape in the
/// normalization of the elastic modes and its diffusion laws.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RigidMode {
    /// Translation or rotation (about which point).
    pub motion: RigidMotion,
    /// Filament length L.
    pub length: f64,
    /// Diffusivity of the amplitude b in w = … + b ψ(x): ⟨(b(t) − b(0))²⟩ =
    /// `amplitude_msd_rate`·t with `amplitude_msd_rate` = 4kT/(ξL), the same for every
    /// rigid mode (as for every mode normalized to ∫ψ² = L/2: the projected noise has
    /// intensity 4kT/(ξL)).
    pub amplitude_msd_rate: f64,
    /// Diffusivity of the physical coordinate ([`RigidMode::physical_quantity`]):
    /// translation, the centre-of-mass deflection w̄ = (1/L)∫w dx, 2kT/(ξL); rotation,
    /// the angle θ of the rigid rotation (its slope), 2kT/(ξ I_ζ) with
    /// I_ζ = ∫₀ᴸ (x − pivot)² dx ([`RigidMode::moment_of_inertia`]): L³/12 about the
    /// centre, L³/3 about an end.
    pub physical_msd_rate: f64,
}

impl RigidMode {
    /// A rigid mode of a filament with parameters `p`.
    fn new(motion: RigidMotion, p: &FilamentParams) -> Self {
        let amplitude_msd_rate = 4.0 * p.kt / (p.drag * p.length);
        let physical_msd_rate = match motion {
            RigidMotion::Translation => 2.0 * p.kt / (p.drag * p.length),
            RigidMotion::Rotation { pivot } => {
                2.0 * p.kt / (p.drag * second_moment(p.length, pivot))
            }
        };
        RigidMode {
            motion,
            length: p.length,
            amplitude_msd_rate,
            physical_msd_rate,
        }
    }

    /// The mode's name, e.g. `rotation about the centre`.
    pub fn name(&self) -> String {
        match self.motion {
            RigidMotion::Translation => "translation".into(),
            RigidMotion::Rotation { pivot: 0.0 } => "rotation about the hinge at x = 0".into(),
            RigidMotion::Rotation { pivot } if pivot == self.length => {
                "rotation about the hinge at x = L".into()
            }
            RigidMotion::Rotation { .. } => "rotation about the centre".into(),
        }
    }

    /// The moment I_ζ = ∫₀ᴸ (x − pivot)² dx of a rotation (None for a translation).
    pub fn moment_of_inertia(&self) -> Option<f64> {
        match self.motion {
            RigidMotion::Translation => None,
            RigidMotion::Rotation { pivot } => Some(second_moment(self.length, pivot)),
        }
    }

    /// The shape ψ(x), normalized like the elastic modes, ∫₀ᴸ ψ² dx = L/2, and signed like
    /// them (ψ(0) > 0, or ψ′(0) > 0 where ψ(0) = 0) (NaN outside [0, L]):
    /// translation 1/√2; rotation √(L/(2I_ζ))·|x − pivot| with the sign of pivot − x, or of
    /// x for a pivot at 0 — about the centre √6 (½ − x/L), about x = 0 √(3/2) x/L, about
    /// x = L √(3/2) (1 − x/L).
    pub fn shape(&self, x: f64) -> f64 {
        let l = self.length;
        if !(x.is_finite() && (0.0..=l).contains(&x)) {
            return f64::NAN;
        }
        match self.motion {
            RigidMotion::Translation => FRAC_1_SQRT_2,
            RigidMotion::Rotation { pivot } => {
                let k = (l / (2.0 * second_moment(l, pivot))).sqrt();
                if pivot == 0.0 { k * x } else { k * (pivot - x) }
            }
        }
    }

    /// [`RigidMode::shape`] as text, e.g. `√(3/2) x/L`.
    pub fn shape_formula(&self) -> &'static str {
        match self.motion {
            RigidMotion::Translation => "1/√2",
            RigidMotion::Rotation { pivot: 0.0 } => "√(3/2) x/L",
            RigidMotion::Rotation { pivot } if pivot == self.length => "√(3/2) (1 − x/L)",
            RigidMotion::Rotation { .. } => "√6 (1/2 − x/L)",
        }
    }

    /// ⟨(b(t) − b(0))²⟩ = 4kT t/(ξL) of the amplitude b (NaN for t < 0 or non-finite).
    pub fn amplitude_msd(&self, t: f64) -> f64 {
        if !(t.is_finite() && t >= 0.0) {
            return f64::NAN;
        }
        self.amplitude_msd_rate * t
    }

    /// The mean-square displacement over a time t of [`RigidMode::physical_quantity`]:
    /// 2kT t/(ξL) for the centre of mass, 2kT t/(ξ I_ζ) for the angle (NaN for t < 0 or
    /// non-finite).
    ///
    /// Derivation. The rigid part of w is b ψ(x). Translation: w̄ = (1/L)∫w dx = b/√2
    /// (the elastic modes are orthogonal to the constant), so the MSD is ½·4kT t/(ξL).
    /// Rotation: b ψ(x) = ±b √(L/(2I_ζ)) (x − pivot), so θ = ±b √(L/(2I_ζ)) and its MSD
    /// is (L/(2I_ζ))·4kT t/(ξL) = 2kT t/(ξI_ζ): the rotational diffusion of a rod of drag
    /// ξ per length about the pivot.
    pub fn physical_msd(&self, t: f64) -> f64 {
        if !(t.is_finite() && t >= 0.0) {
            return f64::NAN;
        }
        self.physical_msd_rate * t
    }

    /// What [`RigidMode::physical_msd`] measures.
    pub fn physical_quantity(&self) -> &'static str {
        match self.motion {
            RigidMotion::Translation => "centre-of-mass deflection (1/L)∫w dx",
            RigidMotion::Rotation { .. } => "angle of the rigid rotation (its slope)",
        }
    }
}

/// ∫₀ᴸ (x − p)² dx = (p³ + (L − p)³)/3.
fn second_moment(l: f64, pivot: f64) -> f64 {
    (pivot.powi(3) + (l - pivot).powi(3)) / 3.0
}

/// The linear filament of eq. (2) with any ends: exact modal results, the closed-form
/// equilibrium covariance, and the rigid modes. See the module docs for the modes, their
/// normalization and sign, and the closed forms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EndedBeam {
    /// Physical parameters (only L, EI, ξ and kT enter; EA does not).
    pub params: FilamentParams,
    /// The ends, left at x = 0.
    pub ends: Ends,
}

impl EndedBeam {
    /// A filament with validated parameters and the given ends.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if any parameter is not finite and > 0.
    pub fn new(params: FilamentParams, ends: Ends) -> Result<Self> {
        params.validate()?;
        Ok(EndedBeam { params, ends })
    }

    /// The characteristic equation of the ends.
    pub fn characteristic_equation(&self) -> CharacteristicEquation {
        CharacteristicEquation::of(self.ends)
    }

    /// The hinged beam with these parameters (for delegation when both ends are hinged).
    fn hinged(&self) -> Option<HingedBeam> {
        self.ends.is_hinged().then_some(HingedBeam {
            params: self.params,
        })
    }

    /// βₙ = qₙL of elastic mode n ≥ 1 (NaN for n = 0).
    fn beta(&self, n: usize) -> f64 {
        self.characteristic_equation().root(n)
    }

    /// Wavenumber qₙ of elastic mode n ≥ 1, ascending in n (NaN for n = 0): βₙ/L with βₙ
    /// the n-th positive root of the characteristic equation
    /// ([`CharacteristicEquation::root`]); nπ/L when both ends are hinged.
    pub fn wavenumber(&self, n: usize) -> f64 {
        self.beta(n) / self.params.length
    }

    /// A rigorous lower bound (n + c)π/L ≤ qₙ valid for every n ≥ 1, with c from
    /// [`CharacteristicEquation::lower_bound_offset`] (NaN for n = 0).
    pub fn wavenumber_lower_bound(&self, n: usize) -> f64 {
        if n == 0 {
            return f64::NAN;
        }
        let c = self.characteristic_equation().lower_bound_offset();
        (n as f64 + c) * PI / self.params.length
    }

    /// A rigorous upper bound on Σ_{n>N} (qₙL)⁻⁴ with N = `n_modes`:
    /// β_{N+1}⁻⁴ + 1/(3π⁴(N + 3/2 + c)³).
    ///
    /// Proof. The first term is the mode N + 1 itself. For n ≥ N + 2, βₙ ≥ (n + c)π
    /// ([`EndedBeam::wavenumber_lower_bound`]) and (u + c)⁻⁴ is convex for u > −c, so
    /// ((n + c)π)⁻⁴ ≤ ∫_{n−½}^{n+½} ((u + c)π)⁻⁴ du (midpoint rule); summing,
    /// Σ_{n≥N+2} βₙ⁻⁴ ≤ ∫_{N+3/2}^∞ ((u + c)π)⁻⁴ du = 1/(3π⁴(N + 3/2 + c)³)
    /// (N + 3/2 + c > 0 since c > −1).
    pub fn inverse_fourth_power_tail(&self, n_modes: usize) -> f64 {
        let c = self.characteristic_equation().lower_bound_offset();
        let m = n_modes as f64 + 1.5 + c;
        self.beta(n_modes + 1).powi(-4) + 1.0 / (3.0 * PI.powi(4) * m * m * m)
    }

    /// Relaxation rate λₙ = EI qₙ⁴/ξ of elastic mode n (NaN for n = 0); equal to
    /// [`HingedBeam::mode_rate`] when both ends are hinged.
    pub fn mode_rate(&self, n: usize) -> f64 {
        if let Some(h) = self.hinged() {
            return h.mode_rate(n);
        }
        let p = &self.params;
        p.bending_rigidity * self.wavenumber(n).powi(4) / p.drag
    }

    /// Stationary variance of the amplitude aₙ in w = Σₙ aₙ φₙ(x) (+ rigid modes) with
    /// ∫₀ᴸ φₙ² dx = L/2 (NaN for n = 0): σₙ² = 2kT/(EI qₙ⁴ L), by equipartition — the
    /// bending energy is Σₙ ½ kₙ aₙ² with kₙ = EI qₙ⁴ L/2 (module docs) — and by the OU
    /// law, (4kT/(ξL))/(2λₙ). Equal to [`HingedBeam::mode_variance`] for hinged ends.
    pub fn mode_variance(&self, n: usize) -> f64 {
        if let Some(h) = self.hinged() {
            return h.mode_variance(n);
        }
        self.variance_scale() / self.beta(n).powi(4)
    }

    /// Stationary autocovariance of aₙ at a time lag: σₙ² e^{−λₙ|lag|}.
    pub fn mode_autocovariance(&self, n: usize, lag: f64) -> f64 {
        self.mode_variance(n) * (-self.mode_rate(n) * lag.abs()).exp()
    }

    /// 2kT L³/EI: σₙ² = scale/βₙ⁴.
    fn variance_scale(&self) -> f64 {
        let p = &self.params;
        2.0 * p.kt * p.length.powi(3) / p.bending_rigidity
    }

    /// The mode n ≥ 1 in its evaluation form.
    fn mode(&self, n: usize) -> Mode {
        if self.ends.is_hinged() {
            Mode::Sine { n }
        } else {
            Mode::general(self.ends, self.beta(n))
        }
    }

    /// Shape φₙ(x) of elastic mode n, normalized to ∫₀ᴸ φₙ² dx = L/2 with the first
    /// non-zero Taylor coefficient at x = 0 positive (module docs), evaluated stably for
    /// every n (NaN for n = 0 or x outside [0, L]). Both ends hinged: exactly
    /// [`HingedBeam::mode_shape`], sin(nπx/L).
    pub fn mode_shape(&self, n: usize, x: f64) -> f64 {
        if let Some(h) = self.hinged() {
            return h.mode_shape(n, x);
        }
        self.mode_shape_derivative(n, 0, x)
    }

    /// The derivative dᵏφₙ/dxᵏ of order k = `order` at x (NaN for n = 0 or x outside
    /// [0, L]): qₙᵏ times the u-derivative of the stable form divided by βₙᵏ, e.g. the
    /// slope (k = 1, the finite elements' nodal rotation) or the curvature (k = 2).
    pub fn mode_shape_derivative(&self, n: usize, order: u32, x: f64) -> f64 {
        if n == 0 || !self.in_span(x) {
            return f64::NAN;
        }
        let l = self.params.length;
        let (u, ubar) = (x / l, (l - x) / l);
        self.mode(n).derivative(order, u, ubar) * self.wavenumber(n).powi(order as i32)
    }

    /// A rigorous bound K ≥ sup over x in [0, L] of |φₙ(x)|, valid for every n ≥ 1:
    /// 1 when both ends are hinged; otherwise the larger of the bounds of the first
    /// 100 modes, computed one by one, and an analytic bound for all the others.
    ///
    /// Per mode (computed): |A cos βu + B sin βu| ≤ R = √(A² + B²), and the boundary
    /// layers C e^{−βu} + D e^{−β(1−u)}, convex in u, are at most
    /// max(|C| + |D|e^{−β}, |C|e^{−β} + |D|) (times 1 + 10⁻¹² for rounding).
    ///
    /// Analytic, for βₙ ≥ β* = β₁₀₁: split φ = φ_osc + φ_exp (the oscillating and the
    /// exponential parts). Since φ_osc″ = −β²φ_osc and φ_exp″ = β²φ_exp (u-derivatives),
    /// φ″/β² = φ_exp − φ_osc and φ‴/β³ = (φ_exp′ − φ_osc′)/β. At x = 0,
    /// C = (φ_exp(0) − φ_exp′(0)/β)/2, and the end condition gives φ_exp = ∓φ_osc,
    /// φ_exp′ = ∓φ_osc′ there (clamped −, free +), so |C| ≤ (|φ_osc(0)| + |φ_osc′(0)|/β)/2
    /// ≤ R/√2 because φ_osc(0)² + (φ_osc′(0)/β)² = A² + B² = R²; at a hinged end
    /// φ_exp(0) = 0 gives C = −De^{−β}, smaller still. Likewise |D| ≤ R/√2. So
    /// |φ| ≤ R(1 + (1 + e^{−β})/√2). For R: ∫₀¹φ_osc² du = R²(½ + O) with
    /// |O| ≤ 1/(2β), and ‖φ_exp‖ ≤ (|C| + |D|)/√(2β) ≤ R/√β in L²(0, 1); with
    /// ‖φ‖ = 1/√2, the triangle inequality gives R ≤ 1/(√(1 − 1/β) − √(2/β)) for β > 3.
    /// Both bounds decrease in β and βₙ increases with n, so their value at β* holds for
    /// every n > 100.
    pub fn mode_shape_bound(&self) -> f64 {
        if self.ends.is_hinged() {
            return 1.0;
        }
        let computed = (1..=SHAPE_BOUND_MODES)
            .map(|n| self.mode(n).sup_bound())
            .fold(0.0, f64::max);
        let beta = self.beta(SHAPE_BOUND_MODES + 1);
        let r = 1.0 / ((1.0 - 1.0 / beta).sqrt() - (2.0 / beta).sqrt());
        let analytic = r * (1.0 + (1.0 + (-beta).exp()) * FRAC_1_SQRT_2);
        computed.max(analytic * (1.0 + ROUNDING_MARGIN))
    }

    /// The rigid-body (zero-stiffness) modes: free–free, the translation and the
    /// rotation about the centre; hinged–free and free–hinged, the rotation about the
    /// hinge; otherwise none. Their shapes ([`RigidMode::shape`]) have the elastic modes'
    /// normalization ∫ψ² = L/2, are mutually orthogonal and orthogonal to every elastic
    /// mode (both are eigenfunctions of the self-adjoint operator, for different
    /// eigenvalues); each amplitude diffuses freely with MSD 4kT t/(ξL).
    pub fn rigid_modes(&self) -> Vec<RigidMode> {
        let p = &self.params;
        match (self.ends.left, self.ends.right) {
            (End::Free, End::Free) => vec![
                RigidMode::new(RigidMotion::Translation, p),
                RigidMode::new(
                    RigidMotion::Rotation {
                        pivot: 0.5 * p.length,
                    },
                    p,
                ),
            ],
            (End::Hinged, End::Free) => {
                vec![RigidMode::new(RigidMotion::Rotation { pivot: 0.0 }, p)]
            }
            (End::Free, End::Hinged) => {
                vec![RigidMode::new(RigidMotion::Rotation { pivot: p.length }, p)]
            }
            _ => Vec::new(),
        }
    }

    /// The rigid modes' part of ⟨w(x,t) w(y,η)⟩ from rest, η ≥ t:
    /// Σₖ ψₖ(x) ψₖ(y) · 4kT t/(ξL) (0 without rigid modes), growing without bound.
    ///
    /// # Errors
    /// As [`EndedBeam::correlation`] (without the tolerance).
    pub fn rigid_correlation(&self, x: f64, y: f64, t: f64, eta: f64) -> Result<f64> {
        self.check_correlation_args(x, y, t, eta)?;
        Ok(self
            .rigid_modes()
            .iter()
            .map(|m| m.shape(x) * m.shape(y) * m.amplitude_msd(t))
            .sum())
    }

    /// Equilibrium variance of the elastic deflection at x (the rigid modes projected
    /// out), in closed form (NaN outside [0, L]): kT·G(x, x) with the diagonal of the
    /// Green's function of the module docs, u = x/L, s = u − ½:
    ///
    /// - hinged–hinged: kT L³ u²(1−u)²/(3EI) ([`HingedBeam::profile_variance`]);
    /// - clamped–clamped: kT L³ u³(1−u)³/(3EI) (midspan kT L³/(192EI));
    /// - clamped–free: kT x³/(3EI) (tip kT L³/(3EI), the cantilever's compliance);
    /// - clamped–hinged: kT L³ u³(1−u)²(4−u)/(12EI);
    /// - hinged–free: kT L³ u²(99 − 280u + 210u² − 21u⁴)/(420EI) (free end
    ///   2kTL³/(105EI));
    /// - free–free: kT L³ (1/320 − 37s²/560 + 5s⁴/12 − s⁶/5)/EI (ends kTL³/(105EI),
    ///   centre kTL³/(320EI));
    /// - the mirrors by u → 1 − u.
    ///
    /// Derivation: see [`EndedBeam::equilibrium_covariance`] at y = x.
    pub fn profile_variance(&self, x: f64) -> f64 {
        if let Some(h) = self.hinged() {
            return h.profile_variance(x);
        }
        if !self.in_span(x) {
            return f64::NAN;
        }
        let l = self.params.length;
        let (u, ub) = (x / l, (l - x) / l);
        let (ends, u, ub) = self.canonical(u, ub);
        let g = match (ends.left, ends.right) {
            (End::Clamped, End::Clamped) => (u * ub).powi(3) / 3.0,
            (End::Clamped, End::Free) => u.powi(3) / 3.0,
            (End::Clamped, End::Hinged) => u.powi(3) * ub * ub * (3.0 + ub) / 12.0,
            (End::Hinged, End::Free) => {
                let u2 = u * u;
                u2 * (99.0 - 280.0 * u + 210.0 * u2 - 21.0 * u2 * u2) / 420.0
            }
            (End::Free, End::Free) => {
                let s2 = (u - 0.5).powi(2);
                1.0 / 320.0 + s2 * (-37.0 / 560.0 + s2 * (5.0 / 12.0 - s2 / 5.0))
            }
            _ => unreachable!("canonical ends"),
        };
        self.kt_l3_over_ei() * g
    }

    /// Equilibrium covariance ⟨w(x) w(y)⟩ of the elastic deflection (rigid modes
    /// projected out) in closed form, kT·G(x, y) (NaN if x or y is outside [0, L]), G the
    /// Green's function of EI d⁴/dx⁴ with these ends (the pseudo-inverse where there are
    /// rigid modes), tabulated in the module docs. It is the t = η → ∞ limit of
    /// [`EndedBeam::correlation`], Σₙ σₙ² φₙ(x) φₙ(y).
    ///
    /// Derivation. Expanding δ(x−y) − P(x, y) = Σₙ φₙ(x)φₙ(y)/(L/2) over the elastic
    /// modes and solving EI ∂⁴G/∂x⁴ = δ − P mode by mode gives
    /// G = Σₙ φₙφₙ/(EI qₙ⁴ L/2) = (1/kT) Σₙ σₙ² φₙφₙ. In closed form, on each side of y, G
    /// is a polynomial in x: a cubic where P = 0, plus the particular solution
    /// −∫₀ˣ (x−ξ)³/6 · P(ξ, y) dξ/EI (a quintic) where there are rigid modes. The two end
    /// conditions on each side, continuity of G, ∂G/∂x, ∂²G/∂x² at x = y and the unit
    /// jump of EI ∂³G/∂x³ there are eight linear equations for the eight coefficients;
    /// with rigid modes they leave the rigid motions free, which the orthogonality
    /// ∫₀ᴸ G ψₖ dx = 0 fixes. The solutions (obtained symbolically by
    /// `docs/dev/ends_green.py`, then simplified so that no term cancels near a clamped or
    /// hinged end) are the table of the module docs; each is symmetric in (x, y), and each
    /// is tested against the mode sums.
    ///
    /// Worked example, clamped–free (u = x/L, v = y/L, G in units L³/EI). For u < v the
    /// clamp leaves G = αu² + βu³; for u > v the free end (G″ = G‴ = 0) leaves
    /// G = γ + δu. The jump G‴(v⁺) − G‴(v⁻) = −6β = 1 gives β = −1/6; continuity of G″,
    /// 2α + 6βv = 0, gives α = v/2; continuity of G′ and G gives δ = v²/2 and
    /// γ = −v³/6. So G = u²(3v − u)/6 for u ≤ v, the cantilever's deflection at x under a
    /// unit load at y, and G(u, u) = u³/3: ⟨w²(x)⟩ = kT x³/(3EI).
    pub fn equilibrium_covariance(&self, x: f64, y: f64) -> f64 {
        if let Some(h) = self.hinged() {
            return h.equilibrium_covariance(x, y);
        }
        if !self.in_span(x) || !self.in_span(y) {
            return f64::NAN;
        }
        let l = self.params.length;
        let (u, ub) = (x / l, (l - x) / l);
        let (v, vb) = (y / l, (l - y) / l);
        let (ends, u, ub) = self.canonical(u, ub);
        let (_, v, vb) = self.canonical(v, vb);
        // a = min, b = max, with their complements.
        let (a, _ab, b, bb) = if u <= v {
            (u, ub, v, vb)
        } else {
            (v, vb, u, ub)
        };
        let g = match (ends.left, ends.right) {
            (End::Clamped, End::Clamped) => a * a * bb * bb * (3.0 * (b - a) + 2.0 * a * bb) / 6.0,
            (End::Clamped, End::Free) => a * a * (2.0 * b + (b - a)) / 6.0,
            (End::Clamped, End::Hinged) => {
                a * a * bb * (3.0 * (b - a) + bb * (3.0 * b + a * bb)) / 12.0
            }
            (End::Hinged, End::Free) => {
                let (a2, b2) = (a * a, b * b);
                a * (198.0 * b - 420.0 * b2 + 210.0 * b2 * b - 21.0 * b2 * b2 * b - 140.0 * a2
                    + 210.0 * a2 * b
                    - 21.0 * a2 * a2 * b)
                    / 840.0
            }
            (End::Free, End::Free) => {
                let (s, t) = (u - 0.5, v - 0.5);
                let (s2, t2) = (s * s, t * t);
                let (sum2, sum4) = (s2 + t2, s2 * s2 + t2 * t2);
                (s - t).abs().powi(3) / 12.0 + 1.0 / 320.0 - sum2 / 16.0 - sum4 / 24.0
                    + s * t * (33.0 / 560.0 + sum2 / 4.0 - sum4 / 10.0)
            }
            _ => unreachable!("canonical ends"),
        };
        self.kt_l3_over_ei() * g
    }

    /// kT L³/EI.
    fn kt_l3_over_ei(&self) -> f64 {
        self.variance_scale() / 2.0
    }

    /// The ends of the closed-form table (c–c, c–f, c–h, h–f, f–f; not h–h) that these
    /// ends are, or mirror, and the position (u, 1 − u) in their frame.
    fn canonical(&self, u: f64, ubar: f64) -> (Ends, f64, f64) {
        use End::{Clamped, Free, Hinged};
        match (self.ends.left, self.ends.right) {
            (Free, Clamped) | (Hinged, Clamped) | (Free, Hinged) => (self.ends.mirrored(), ubar, u),
            _ => (self.ends, u, ubar),
        }
    }

    /// The mode sum Σ_{n=1}^{N} σₙ² φₙ(x) φₙ(y) of the equilibrium covariance with
    /// N = `n_modes` (NaN if x or y is outside [0, L]), and the rigorous bound
    /// K²·(2kTL³/EI)·Σ_{n>N} βₙ⁻⁴ on the omitted modes (K = [`EndedBeam::mode_shape_bound`],
    /// the sum bounded by [`EndedBeam::inverse_fourth_power_tail`]).
    pub fn covariance_series(&self, x: f64, y: f64, n_modes: usize) -> SeriesValue {
        let value = if self.in_span(x) && self.in_span(y) {
            self.mode_sum(x, y, n_modes, |_| 1.0)
        } else {
            f64::NAN
        };
        let k = self.mode_shape_bound();
        SeriesValue {
            value,
            truncation_error: k
                * k
                * self.variance_scale()
                * self.inverse_fourth_power_tail(n_modes),
            n_modes,
        }
    }

    /// [`EndedBeam::covariance_series`] at y = x: the mode sum of ⟨w²(x)⟩ with its bound.
    pub fn profile_variance_series(&self, x: f64, n_modes: usize) -> SeriesValue {
        self.covariance_series(x, x, n_modes)
    }

    /// ⟨w(x,t) w(y,η)⟩ of the elastic modes from rest, w(x,0) = 0, for 0 ≤ t ≤ η (eq. 4
    /// with these ends' modes, module docs), summing modes until the rigorous tail bound
    /// is at most `tolerance`·σ₁² (σ₁² = [`EndedBeam::mode_variance`] of mode 1, which is
    /// [`HingedBeam`]'s scale 2kTL³/(π⁴EI) for hinged ends), but never more than
    /// [`MAX_MODES`] modes; the reported `truncation_error` is the bound achieved. Both
    /// ends hinged: exactly [`HingedBeam::correlation`]. Add
    /// [`EndedBeam::rigid_correlation`] for the whole deflection of a filament with
    /// rigid modes.
    ///
    /// The tail bound. For n > N: |φₙ(x) φₙ(y)| ≤ K² (K = [`EndedBeam::mode_shape_bound`]);
    /// the bracket e^{−λₙ(η−t)} − e^{−λₙ(η+t)} lies in [0, e^{−λₙ(η−t)}] ⊂
    /// [0, e^{−λ_{N+1}(η−t)}] since λₙ increases with n; and σₙ² = (2kTL³/EI) βₙ⁻⁴ with
    /// Σ_{n>N} βₙ⁻⁴ bounded by [`EndedBeam::inverse_fourth_power_tail`]. So the omitted
    /// tail is at most K² (2kTL³/EI) e^{−λ_{N+1}(η−t)} Σ_{n>N} βₙ⁻⁴. At t = 0 every term
    /// vanishes and the result is exactly 0 with zero error.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if x or y is outside [0, L], t < 0, t > η, t or η is
    /// not finite, or `tolerance` is not finite and > 0.
    pub fn correlation(
        &self,
        x: f64,
        y: f64,
        t: f64,
        eta: f64,
        tolerance: f64,
    ) -> Result<SeriesValue> {
        if let Some(h) = self.hinged() {
            return h.correlation(x, y, t, eta, tolerance);
        }
        self.check_correlation_args(x, y, t, eta)?;
        require_positive("tolerance", tolerance)?;
        let target = tolerance * self.mode_variance(1);
        let k2 = self.mode_shape_bound().powi(2);
        let mut n = 1;
        while n < MAX_MODES && self.correlation_tail_bound(t, eta, n, k2) > target {
            n += 1;
        }
        Ok(self.correlation_sum(x, y, t, eta, n, k2))
    }

    /// ⟨w(x,t) w(y,η)⟩ of the elastic modes truncated to the first `n_modes` modes, with
    /// the rigorous tail bound of [`EndedBeam::correlation`] (exactly
    /// [`HingedBeam::correlation_truncated`] for hinged ends).
    ///
    /// # Errors
    /// As [`EndedBeam::correlation`]; also if `n_modes` > [`MAX_MODES`].
    pub fn correlation_truncated(
        &self,
        x: f64,
        y: f64,
        t: f64,
        eta: f64,
        n_modes: usize,
    ) -> Result<SeriesValue> {
        if let Some(h) = self.hinged() {
            return h.correlation_truncated(x, y, t, eta, n_modes);
        }
        self.check_correlation_args(x, y, t, eta)?;
        if n_modes > MAX_MODES {
            return Err(Error::invalid(
                "n_modes",
                n_modes,
                format!("<= {MAX_MODES}"),
            ));
        }
        let k2 = self.mode_shape_bound().powi(2);
        Ok(self.correlation_sum(x, y, t, eta, n_modes, k2))
    }

    /// One-sided Lorentzian power spectral density of the stationary amplitude aₙ,
    /// S(f) = 4σₙ²λₙ/(λₙ² + (2πf)²), ∫₀^∞ S df = σₙ² (as [`HingedBeam::lorentzian`]).
    pub fn lorentzian(&self, n: usize, f: f64) -> f64 {
        ou_lorentzian(self.mode_variance(n), self.mode_rate(n), f)
    }

    /// Exact one-sided spectral density of aₙ sampled every `dt` (an AR(1) sequence), on
    /// 0 ≤ f ≤ 1/(2dt) (NaN if dt is not finite and > 0); derivation at
    /// [`HingedBeam::sampled_spectrum`].
    pub fn sampled_spectrum(&self, n: usize, dt: f64, f: f64) -> f64 {
        ou_sampled_spectrum(self.mode_variance(n), self.mode_rate(n), dt, f)
    }

    /// Slowest elastic relaxation time τ₁ = 1/λ₁ = ξL⁴/(EI β₁⁴) (for hinged ends
    /// [`FilamentParams::tau1`], ξL⁴/(π⁴EI); for clamped–free, with β₁ = 1.8751…,
    /// about 7.9 times longer).
    pub fn tau1(&self) -> f64 {
        if self.ends.is_hinged() {
            return self.params.tau1();
        }
        1.0 / self.mode_rate(1)
    }

    fn in_span(&self, x: f64) -> bool {
        x.is_finite() && (0.0..=self.params.length).contains(&x)
    }

    fn check_correlation_args(&self, x: f64, y: f64, t: f64, eta: f64) -> Result<()> {
        let l = self.params.length;
        require_in_range("x", x, 0.0, l)?;
        require_in_range("y", y, 0.0, l)?;
        check_two_times(t, eta, "eq. 4")
    }

    /// Rigorous bound on the modes n > N of the correlation (see
    /// [`EndedBeam::correlation`]); `k2` = K².
    fn correlation_tail_bound(&self, t: f64, eta: f64, n_modes: usize, k2: f64) -> f64 {
        if t == 0.0 {
            return 0.0;
        }
        let decay = (-self.mode_rate(n_modes + 1) * (eta - t)).exp();
        k2 * self.variance_scale() * decay * self.inverse_fourth_power_tail(n_modes)
    }

    /// Σ_{n=1}^{N} σₙ² φₙ(x) φₙ(y) wₙ, smallest terms first (positions already checked).
    fn mode_sum(&self, x: f64, y: f64, n_modes: usize, weight: impl Fn(usize) -> f64) -> f64 {
        let l = self.params.length;
        let (u, ub, v, vb) = (x / l, (l - x) / l, y / l, (l - y) / l);
        (1..=n_modes)
            .rev()
            .map(|n| {
                let m = self.mode(n);
                self.mode_variance(n) * m.derivative(0, u, ub) * m.derivative(0, v, vb) * weight(n)
            })
            .sum()
    }

    /// Partial sum of the correlation over modes 1..=N (arguments already validated).
    fn correlation_sum(
        &self,
        x: f64,
        y: f64,
        t: f64,
        eta: f64,
        n_modes: usize,
        k2: f64,
    ) -> SeriesValue {
        let value = self.mode_sum(x, y, n_modes, |n| {
            let lam = self.mode_rate(n);
            // e^{−λ(η−t)} − e^{−λ(η+t)} = e^{−λ(η−t)} (1 − e^{−2λt}), no cancellation.
            (-lam * (eta - t)).exp() * -(-2.0 * lam * t).exp_m1()
        });
        SeriesValue {
            value,
            truncation_error: self.correlation_tail_bound(t, eta, n_modes, k2),
            n_modes,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params() -> FilamentParams {
        FilamentParams {
            length: 2.5,
            bending_rigidity: 0.7,
            stretch_rigidity: 1.0e6,
            drag: 3.0,
            kt: 0.4,
        }
    }

    // What: the general (A, B, C, D) machinery, applied to hinged–hinged at β = nπ,
    // reproduces sin(nπu) — the special case is a shortcut, not a different answer.
    // Reference: sin(nπu). Tolerance: 1e-13 absolute (β = nπ rounded, n ≤ 40).
    #[test]
    fn general_form_reproduces_the_sine_for_hinged_ends() {
        for n in [1usize, 2, 5, 17, 40] {
            let m = Mode::general(Ends::HINGED, n as f64 * PI);
            for k in 0..=20 {
                let u = k as f64 / 20.0;
                let got = m.derivative(0, u, 1.0 - u);
                let want = sin_pi(n as f64 * u);
                assert!((got - want).abs() < 1e-13, "n={n} u={u}: {got} vs {want}");
            }
        }
    }

    // What: the roots satisfy the textbook equations (evaluated where they are still
    // accurate, small n) and approach their asymptotes from the right side.
    // Reference: the characteristic equations. Tolerance: residual 1e-12·cosh β.
    #[test]
    fn roots_satisfy_their_equations() {
        for eq in [
            CharacteristicEquation::CosCoshPlusOne,
            CharacteristicEquation::CosCoshMinusOne,
            CharacteristicEquation::TanTanh,
        ] {
            for n in 1..=6 {
                let b = eq.root(n);
                let r = match eq {
                    CharacteristicEquation::CosCoshPlusOne => b.cos() * b.cosh() - 1.0,
                    CharacteristicEquation::CosCoshMinusOne => b.cos() * b.cosh() + 1.0,
                    _ => (b.sin() * b.cosh() - b.cos() * b.sinh()) / b.cosh(),
                };
                assert!(r.abs() < 1e-12 * b.cosh(), "{eq:?} n={n}: residual {r}");
            }
        }
        assert!(CharacteristicEquation::TanTanh.root(0).is_nan());
    }

    // What: the per-mode sup bound is a bound: no sampled |φₙ| exceeds it.
    #[test]
    fn per_mode_sup_bound_holds_on_a_grid() {
        for ends in Ends::all().filter(|e| !e.is_hinged()) {
            let b = EndedBeam::new(params(), ends).unwrap();
            let k = b.mode_shape_bound();
            for n in [1usize, 2, 3, 10, 101, 500] {
                let mut sup: f64 = 0.0;
                for i in 0..=2000 {
                    let x = b.params.length * i as f64 / 2000.0;
                    sup = sup.max(b.mode_shape(n, x).abs());
                }
                assert!(sup <= b.mode(n).sup_bound(), "{ends} n={n}");
                assert!(sup <= k, "{ends} n={n}: {sup} > {k}");
            }
        }
    }
}
