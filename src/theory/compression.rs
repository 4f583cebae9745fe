//! Exact equilibrium force–strain relation of a thermally fluctuating, compressed,
//! hinged filament (the paper's Fig. 2).
//!
//! # The model (the contract shared with the simulator)
//!
//! A filament of length L, hinged at both ends, with transverse deflection w (2D) or two
//! deflections (w, v) (3D) and axial displacement u, `u(0) = 0`, `u(L) = −Δ`; the imposed
//! nominal compressive strain is `ε = Δ/L`. The energy is the paper's von Kármán energy
//! `∫ [EA/2 (u' + ½w'²)² + EI/2 w''²] dx` (3D: `w'² → w'² + v'²`, `w''² → w''² + v''²`).
//!
//! **Elimination of the fast variable u.** u uses linear elements; the stretching energy
//! of element e is evaluated with the element-mean strain `u'_e + s_e`,
//! `s_e = (1/2h_e) ∫_e w'² dx` (i.e. `½w'²` is replaced by its element average), so the
//! element stretching energy is `(EA h_e/2)(u'_e + s_e)²`. Axial equilibrium for fixed w
//! (minimizing over the interior nodal u) makes the element force `EA(u'_e + s_e)` the
//! same in every element: `N = (EA/L)(−Δ + ½∫w'² dx)`, exactly as in the continuum, where
//! `½w'²` is pointwise and `N` is uniform. Substituting back, the energy is a function of
//! w alone:
//!
//! ```text
//! U(w) = ½ wᵀK w + (EA·L/2)(s(w) − ε)²,   s(w) = (1/2L)∫ w'² dx = wᵀG w/(2L),
//! ```
//!
//! (3D: s sums over w and v), and the compressive force is `F = −N = EA(ε − s)`. K and G
//! are the Hermite-cubic bending and geometric matrices over the free DOFs of
//! [`crate::fem::BeamModel`]; in the continuum, `K → EI∫w''²` and `G → ∫w'²`.
//!
//! # The stored-length law
//!
//! Under the bending-only Gaussian ensemble `w ~ N(0, kT K⁻¹)`, write `K = LLᵀ`,
//! `w = √kT L⁻ᵀ z`: then `s = Σ_i c_i χ²_{d,i}` with independent χ² variables of
//! `d = 1` (2D) or `d = 2` (3D) degrees of freedom and weights `c_i = kT μ_i/(2L)`, `μ_i`
//! the eigenvalues of `L⁻¹GL⁻ᵀ`, i.e. of `K⁻¹G` (the generalized eigenvalues of
//! `(G, K)`; `1/μ_i` are the buckling loads of the discretized filament). In the
//! continuum `μ_n = 1/(EI(nπ/L)²)`, `c_n = kT L/(2EI n²π²)`. [`StoredLengthLaw`] holds
//! the weights and, for the continuum, the omitted modes `n > M`, which it sums exactly
//! (see *The continuum* below).
//!
//! For the uniform hinged mesh the pencil `(K, G)` block-diagonalizes exactly in
//! sine/cosine modes (a hinge is a mirror), which gives all `2N` buckling loads in closed
//! form ([`discrete_buckling_loads`]); [`StoredLengthLaw::discrete`] uses it, and
//! [`StoredLengthLaw::discrete_dense`] solves the dense generalized eigenproblem of the
//! assembled [`BeamModel`] matrices as a cross-check (they agree to ≤ 10⁻¹¹ for N ≤ 32;
//! the dense route's rounding error grows as `ε_mach·N⁴`). Two properties of the mesh,
//! both tested: its weights converge to the continuum's as `h⁴` mode by mode, but the
//! total stored length is only first order, exactly `⟨s⟩₀,h = ⟨s⟩₀(1 − 2h/(5L))` (the
//! per-element clamped–clamped "bubble" fluctuations that cubics cannot represent; −4%
//! at N = 10).
//!
//! Its characteristic function and cumulant generating function are
//!
//! ```text
//! φ(t) = E e^{its} = Π_i (1 − 2i c_i t)^{−d/2},
//! ψ(η) = ln E e^{ηs} = −(d/2) Σ_i ln(1 − 2c_i η),   η < 1/(2 c_max),
//! ```
//!
//! the products and sums running over all modes (for the Gaussian-tail reference of the
//! continuum, the omitted modes contribute `e^{i t m_T − t² v_T/2}` and `η m_T + η² v_T/2`).
//!
//! # The exact average at imposed strain
//!
//! The Boltzmann weight of a configuration is `e^{−U/kT}`; integrating out everything but
//! s, the stored length has density `p_ε(s) ∝ p₀(s) e^{−A(s−ε)²}`, `A = EA·L/(2kT)`, with
//! p₀ the density of the law above, and `⟨F⟩ = EA(ε − ⟨s⟩_ε)`. No mean-field
//! approximation is made.
//!
//! **Fourier route.** With `g(s) = e^{−A(s−ε)²}`, `ĝ(t) = ∫ g e^{−its} ds =
//! √(π/A) e^{−itε − t²/(4A)}` and Parseval `∫ p₀ g ds = (1/2π)∫ φ(t) ĝ(t) dt`:
//!
//! ```text
//! Z(ε)            ∝ J₀ = ∫ φ(t) E(t) dt,              E(t) = e^{−itε − t²/(4A)},
//! ∫ s p₀ g ds     ∝ ∫ φ(t) (ε − it/(2A)) E(t) dt      (FT of s·g is i∂_t ĝ),
//! ∫ (ε−s)² p₀ g ds ∝ ∫ φ(t) (1/(2A) − t²/(4A²)) E(t) dt.
//! ```
//!
//! Hence, with `J_k = ∫ t^k φ E dt` and `EA/(2A) = kT/L`,
//!
//! ```text
//! ⟨F⟩ = (kT/L) · i J₁/J₀,     ⟨F²⟩ = EA·kT/L − (kT/L)² J₂/J₀,
//! ```
//!
//! which involve no cancellation between ε and ⟨s⟩.
//!
//! **Saddle-point contour.** The integrand is analytic in `Im t > −1/(2c_max)` (the
//! singularities of φ lie at `t = −i/(2c_i)`), so the line of integration may be moved to
//! `t = τ − iη` for any `η < 1/(2c_max)` without changing J_k. The code takes η = η̂,
//! the saddle point `ψ'(η̂) + η̂/(2A) = ε` (unique: the left side increases from −∞ to +∞).
//! With `m = ε − η̂/(2A)` the integrand becomes, up to a constant factor,
//!
//! ```text
//! f(τ) = φ_η(τ) e^{−iτm} e^{−τ²/(4A)},     φ_η(τ) = φ(τ − iη̂)/φ(−iη̂),
//! ```
//!
//! the characteristic function of `Y = (s_η − m) + G`, where `s_η` has the exponentially
//! tilted density `p₀(s)e^{η̂s}/φ(−iη̂)` (mean m) and `G ~ N(0, 1/(2A))` is independent.
//! `f(0) = 1`, so there is no exponentially small normalization (without the shift, Z(ε)
//! is of order `e^{−ε/(2c₁)}` at large compression and `e^{−Aε²}` at large tension, and
//! the real-line integral would cancel catastrophically). Then, with the moments
//! `M_k = ∫τ^k f dτ / ∫ f dτ`,
//!
//! ```text
//! ⟨F⟩ = (kT/L)(η̂ + i M₁),      Var F = EA·kT/L − (kT/L)² (M₂ − M₁²).
//! ```
//!
//! `(kT/L)η̂` alone is the Gaussian mean-field force (self-consistent tension in the
//! Gaussian ensemble, [`CompressionTheory::mean_field_force`]); it can never exceed the
//! buckling load `(kT/L)/(2c_max)`, because `η̂ < 1/(2c_max)`. The term `i M₁` is the exact
//! correction; in 2D it takes ⟨F⟩ above the buckling load.
//!
//! **Quadrature.** `f(−τ) = conj f(τ)`, so the full-line trapezoid rule uses τ ≥ 0 only.
//! By Poisson summation, the trapezoid rule with step h integrates a characteristic
//! function exactly up to the aliased density: `h Σ_j f(jh) = 2π Σ_k p_Y(2πk/h)`, so the
//! error relative to `2π p_Y(0)` is the density of Y at distance `P = 2π/h` and beyond.
//! The code chooses `P = max(x_L, x_R) + √(T/A)`, where `x_R`, `x_L` are Chernoff bounds
//! `P(±(s_η − m) > x) ≤ e^{−T}` minimized over a ladder of exponents (on the right the
//! ladder stays below the distance `δ = 1/(2c_max) − η̂` to the nearest singularity, which
//! is the exponential rate of the right tail: this is the strip-width constraint) and
//! `√(T/A)` covers the Gaussian part. The level is `T = 40` plus `ln(σ_Y/σ_G) + 2`, which
//! accounts for `p_Y(0)` being smaller than the Gaussian peak; the aliasing error is then
//! below `≈ 2e^{−40}` relative. The range is `τ ≤ √(4A(T + 10))` (Gaussian factor below
//! `e^{−50}`), cut earlier when `|f(τ)|` (which is monotone decreasing in |τ|) times the
//! largest remaining weight and the number of remaining nodes falls below `e^{−T}` of the
//! running sum. [`QuadratureOptions`] scales the step and the level; the tests check that
//! halving the step changes ⟨F⟩ by less than 10⁻¹⁰ relative.
//!
//! **Evaluation of φ_η.** `φ_η(τ) = Π (1 − i b_i τ)^{−d/2}` with
//! `b_i = 2c_i/(1 − 2c_iη̂)` (times `e^{iτ(m_T + η̂v_T) − τ²v_T/2}` for a Gaussian tail),
//! evaluated as a sum of logarithms (`−¼ d ln(1 + b²τ²) + ½ d i·atan(bτ)` per mode, taken
//! two modes at a time: `ln((1 − ix)(1 − iy)) = ½ln(1 + x² + y² + x²y²) −
//! i·atan2(x + y, 1 − xy)`, exact as x, y have the same sign). Modes with `b_i τ_max ≤ ¼`
//! are summed through the power series `−ln(1 − z) = Σ z^k/k` with the power sums
//! `Σ b_i^k`, 30 terms (remainder below `4^{−29}/31` of the first-order term), so the cost
//! per node is independent of the number of small modes.
//!
//! # The distribution of F
//!
//! With the same tilt, `p_ε(s) ∝ q(s) e^{−A(s−m)²}`, q the tilted density. The
//! characteristic function of `X = s − m` under `p_ε` is, by Parseval again,
//!
//! ```text
//! χ(u) = ∫ φ_η(τ) e^{−iτm} e^{−(τ−u)²/(4A)} dτ / ∫ φ_η(τ) e^{−iτm} e^{−τ²/(4A)} dτ,
//! ```
//!
//! evaluated with the same trapezoid nodes. The CDF of X follows from the Fourier series
//! of its periodization over a window `[x₀, x₀ + P_s)` that holds all but `e^{−T}` of the
//! mass (`|X| ≤ √((T + ln 1/Z)/A)`, narrowed by the Chernoff bounds of q):
//!
//! ```text
//! P(X ≤ x) = (x − x₀)/P_s − (1/π) Σ_{k≥1} Im[χ(kΔ)(e^{−ikΔx} − e^{−ikΔx₀})]/k,   Δ = 2π/P_s,
//! ```
//!
//! truncated at the first `K = 2^j ≥ 16` for which every `|χ(kΔ)|`, `K/2 < k ≤ K`, is
//! below 10⁻¹⁴ (observed decay), or at the point where a rigorous bound on |χ| (from the
//! monotonicity of |φ_η|) falls below 10⁻¹⁴, whichever comes first. The rigorous bound
//! ignores the oscillation of `e^{−iτm}` under the Gaussian kernel, which suppresses |χ|
//! by up to `e^{−Am²}`; at large compression it asks for hundreds of times more terms than
//! needed. A density with a jump (a single element in 2D) gives `|χ| ∝ 1/u`; the series
//! is then capped at 2·10⁵ terms. The CDF of `F = EA(ε − s)` is `1 − P(X ≤ (F_mf − F)/EA)`, `F_mf = (kT/L)η̂`.
//!
//! # The continuum
//!
//! [`StoredLengthLaw::continuum`] keeps M modes explicitly ([`DEFAULT_CONTINUUM_MODES`]
//! = 64) and sums all the others, `c_n = c₁/n²` for `n ≥ N = M + 1`
//! ([`Tail::InverseSquare`]), exactly to rounding. Every quantity the method needs is a
//! sum over the tail of a function of `z/n²`, where `z` is `x = 2c₁η` (real: ψ, ψ′, ψ″ at
//! the saddle and in the Chernoff bounds), `x + 2ic₁τ` (φ_η) or `2ic₁t` (φ). Expanding in
//! powers of `r = z/N²` and exchanging the sums gives series in the scaled Hurwitz zeta
//! values `ζ̃_{2j}(N) = N^{2j} ζ(2j, N) = Σ_{n≥N} (N/n)^{2j}` (all in `[1, N/(2j−1) + 1]`):
//!
//! ```text
//! L(z)            = −Σ_{n≥N} ln(1 − z/n²)  = Σ_{j≥1} r^j ζ̃_{2j}(N)/j,
//! Σ_{n≥N} b_n^k   = (2c₁/N²)^k Σ_{j≥0} C(k+j−1, j) r^j ζ̃_{2(k+j)}(N),   b_n = 2c₁/(n² − x),
//! ```
//!
//! so the tail's part of ψ is `(d/2)L(x)`, of ψ′ and ψ″ `(d/2)Σb_n` and `(d/2)Σb_n²`, of
//! `ln φ_η(τ)` `(d/2)[L(x + 2ic₁τ) − L(x)]`, which enters the contour through the power
//! sums `Σ b_n^k`, k ≤ 30, of *Evaluation of φ_η* above. The series are used for
//! `|r| ≤ 1/16`; a larger `|z|` (far out on the left Chernoff ladder, or a wide
//! [`ForceDistribution`] range) moves the base to `N′ = ⌈4√|z|⌉` and sums the modes
//! `N ≤ n < N′` one by one; the modes with `b_n τ_max > ¼` are always explicit. The terms
//! fall by `|r| ≤ 1/16` (after the binomial's rise for large k) and are summed until below
//! 10⁻¹⁸ of the sum. `ζ̃_{2j}(N)` is computed once per theory: Euler–Maclaurin at
//! `K_j = max(N, 3(j + 8))` with the Bernoulli terms up to `B₁₆`, whose first omitted term
//! bounds the error by `2((2j + 16)/(2πK_j))^{18} < 10⁻¹⁷` relative, plus the terms
//! `N ≤ n < K_j`. The cost per evaluation is O(M + 30) instead of O(number of modes).
//!
//! **Reference.** [`StoredLengthLaw::continuum_gaussian_tail`] keeps M modes explicitly
//! and replaces the rest by a Gaussian with their exact mean `m_T = d c₁ Σ_{n>M} n⁻²` and
//! variance `v_T = 2d c₁² Σ_{n>M} n⁻⁴` (tail sums by Euler–Maclaurin). The omitted part
//! of `ln φ(t)` is then `(d/2) Σ_{k≥3} (2it)^k p_k/k`, `p_k = Σ_{n>M} c_n^k`, bounded by
//! [`continuum_tail_log_char_bound`]:
//! `(d/2)(2|t|)³ p₃ / (3(1 − 2c_{M+1}|t|))`, `p₃ ≤ c₁³/(5(M+½)⁵)`. For P = EI/(kT·L) = 100,
//! EA·L/kT = 10⁶ and M = 10⁴ the contour reaches `|t| ≲ 2·10⁴` and the bound is below
//! 10⁻¹⁷ (relative error of φ, hence of ⟨F⟩ − F_mf). This brute-force route (O(M) per
//! evaluation) checks the exact tail in `tests/compression_theory.rs`: ⟨F⟩/F_c0 agree to
//! ≤ 10⁻¹⁴ over ε/ε_c0 ∈ [0, 10] for EI/(kT·L) ∈ {10, 100, 1000} and
//! EA·L/kT ∈ {10⁴, 10⁶, 10⁸}.
//!
//! # Tension
//!
//! Nothing above assumes ε > 0: for ε < ⟨s⟩₀ the saddle point is negative (a tension), the
//! tilted law is narrow and the contour needs ≈ 500 mode evaluations at any tension. The
//! CLI accepts `ε/ε_c0 ≥` [`MIN_STRAIN_RATIO`] `= −10⁸`. Two closed-form limits are tested
//! (`tests/tension_theory.rs`): far in tension (continuum, `x = |⟨F⟩|/F_c0 ≫ 1`)
//! `⟨F⟩ = EAε − (EA d kT/(4√(EI·EA|ε|)))(1 − 1/(π√|r|) + O(|r|^{−3/2}))`, `r = ε/ε_c0`,
//! from `Σ_n 1/(n² + x) = (π√x coth π√x − 1)/(2x)`, with the exact force → mean field; and
//! the inextensible entropic-stretching limit (large `S = EA·L/kT`, ε → 0⁺), where
//! `⟨F⟩ → −(kT/L)(ln p₀)'(⟨s⟩)` and the Laplace form of p₀ gives
//! `f = −⟨F⟩ = f₀(1 − (2 + 6/d)/(π√x₀) + O(1/x₀))`, `f₀ = (d kT/(4⟨s⟩))²/EI`,
//! `x₀ = f₀/F_c0` (−2/(π√x₀) from the mean field's `−1/(2x)` term, −6/(πd√x₀) from the
//! fluctuation term `ψ‴/(2ψ″²)` of the Laplace prefactor).
//!
//! # Other constrained objects
//!
//! Only three numbers of the filament enter the method: the stiffness EA of the constraint,
//! the measure L (through `A = EA·L/(2kT)` and the force unit `kT/L`) and kT, plus the
//! reference scales F_c0, ε_c0 of [`CompressionTheory::force_ratio`]. [`GlobalConstraint`]
//! holds them; [`CompressionTheory::with_constraint`] builds the theory for any object
//! whose stored measure `s` is a quadratic form `xᵀGx/(2X)` of Gaussian variables
//! `x ~ N(0, kT K⁻¹)` and whose energy adds `(S·X/2)(s − ε)²`: the weights are
//! `c_i = kT μ_i/(2X)` ([`StoredLengthLaw::from_weights`]). The fluid membrane under an
//! imposed projected area is one ([`crate::fem::plate_area`]: `S = K_A`, `X = A₀`,
//! `F = −σ`).

use crate::error::{Error, Result};
use crate::fem::{BeamModel, Mesh};
use crate::params::FilamentParams;
use nalgebra::{Complex, DMatrix};
use std::f64::consts::PI;

/// Number of explicit continuum modes used by default (e.g. by the CLI); the others are
/// summed exactly ([`Tail::InverseSquare`]), so this only splits the work: 64 keeps the
/// Hurwitz series at `|r| ≤ 1/16` for saddle points `|2c₁η̂| ≤ 264` without moving the base.
pub const DEFAULT_CONTINUUM_MODES: usize = 64;

/// Largest mesh accepted by [`StoredLengthLaw::discrete`] and
/// [`buckling_load_discrete`] (the generalized eigenproblem is solved densely, `O(N³)`).
pub const MAX_DISCRETE_ELEMENTS: usize = 2000;

/// Range of the persistence ratio `P = EI/(kT·L)` over which the theory is verified
/// (`theory compression --persistence-ratio`). The force ratio ⟨F⟩/F_c0 depends on P and
/// `S = EA·L/kT` only through `S/P²` (with `L = kT = 1`, every weight `c_i` scales as
/// `1/P`; substituting `s = s̃/P` leaves `A(s − ε)² = (S/2P²)(s̃ − rπ²P²/S)²`), so this range
/// only keeps the intermediate quantities (`c₁ ∝ 1/P`, `A ∝ S`, their powers in the series)
/// far from overflow and underflow: at `P = 10¹⁰⁰` the power sums of the small modes
/// underflow and ⟨F⟩ drifts by 10⁻⁷ relative; at `P = 10⁻³⁰` the quadrature overflows.
/// Values below `P ≈ 1` are outside the small-slope (von Kármán) model anyway: the RMS
/// slope of the free filament is `√(d/(6P))`.
pub const PERSISTENCE_RATIO_RANGE: (f64, f64) = (1e-3, 1e6);

/// Range of `κ = S/P² = EA·L³·kT/EI²` (stretch ratio over persistence ratio squared), the
/// one combination of P and S that ⟨F⟩/F_c0 depends on (see [`PERSISTENCE_RATIO_RANGE`]).
/// For a rod of radius of gyration r_g, `κ = (L/r_g)²/P`: the paper's filament has κ = 100,
/// microtubules to DNA ≈ 10³ … 10⁸. The ends: at κ = 10⁻² (stiff, nearly inextensible in
/// bending terms) the force is the Euler limit `min(ε/ε_c0, 1)·F_c0` up to a thermal
/// correction of order κ (10⁻⁴ relative; 5·10⁻³ within the crossover ε ≈ ε_c0), and the
/// quadrature work grows as `(ε/ε_c0)/√κ`; at κ = 10¹² (floppy) the filament is under a
/// tension of `≈ (dκ/4π³)^{2/3} F_c0` at every allowed strain, the saddle point sits at
/// `2c₁|η̂| ≈ 10⁸` and the exact tail sums `≈ 4√(2c₁|η|)` modes one by one (the work grows
/// as `κ^{1/3}`; at κ = 10²⁶ it runs for minutes).
pub const STRETCH_BEND_RATIO_RANGE: (f64, f64) = (1e-2, 1e12);

/// The largest strain ratio ε/ε_c0 accepted is this times `√κ = √S/P`
/// ([`max_strain_ratio`]): the trapezoid step must resolve the tilted law of the stored
/// length, whose width at large compression is ≈ ε, within a Gaussian range `√(4A·50)`, so
/// the number of nodes grows as `ε√S ∝ (ε/ε_c0)/√κ`; at this bound the work
/// ([`CompressionTheory::quadrature_work`]) stays below 3·10⁷ mode evaluations (≈ 0.3 s)
/// over the whole κ range (tested). At the smallest κ the bound is 10 ε_c0, where ⟨F⟩ is
/// within 10⁻⁵ of F_c0; at κ = 100 (the paper) it is 10³ ε_c0.
pub const STRAIN_RATIO_SCALE: f64 = 100.0;

/// The smallest (most tensile) strain ratio ε/ε_c0 accepted by the CLI
/// (`theory compression`, `theory area`), at every stretch ratio. In tension the tilted law
/// of the stored length is narrow and the quadrature needs ≈ 500 mode evaluations whatever
/// the strain (tested); the cost is the saddle point and the Chernoff ladder of the exact
/// continuum tail, which sums `≈ 4√(|⟨F⟩|/F_c0)` modes one by one per evaluation:
/// `≤ 4·10⁴` at this bound (≈ 0.25 s per strain; 1.2 s at 10¹⁰). A discrete or membrane law
/// costs `O(weights)` per evaluation at any strain.
pub const MIN_STRAIN_RATIO: f64 = -1e8;

/// The largest strain ratio ε/ε_c0 verified at persistence ratio `p` and stretch ratio `s`:
/// [`STRAIN_RATIO_SCALE`]`·√s/p`.
pub fn max_strain_ratio(persistence_ratio: f64, stretch_ratio: f64) -> f64 {
    STRAIN_RATIO_SCALE * stretch_ratio.sqrt() / persistence_ratio
}

/// The input of a filament that puts it outside the exact theory's domain
/// ([`domain_violation`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DomainInput {
    /// EI (through the persistence ratio P = EI/(kT·L)).
    BendingRigidity,
    /// EA (through S/P², S = EA·L/kT).
    StretchRigidity,
    /// The strain ratio of this index.
    StrainRatio(usize),
}

/// Where a filament of persistence ratio `p` = EI/(kT·L) and stretch ratio `s` = EA·L/kT
/// at the strain ratios ε/ε_c0 `strain_ratios` leaves the domain in which the exact
/// equilibrium theory is computed and tested: P in [`PERSISTENCE_RATIO_RANGE`], S/P² in
/// [`STRETCH_BEND_RATIO_RANGE`], each strain ratio in [[`MIN_STRAIN_RATIO`],
/// [`max_strain_ratio`]]. Outside, the quadrature runs for minutes, exhausts memory or
/// meets a known limit; so scenes and data are refused there, as `theory compression`
/// refuses its flags. The first input found outside, with the allowed range of that input
/// (the others held) in words; `None` inside.
pub fn domain_violation(p: f64, s: f64, strain_ratios: &[f64]) -> Option<(DomainInput, String)> {
    let (p_lo, p_hi) = PERSISTENCE_RATIO_RANGE;
    if !(p.is_finite() && (p_lo..=p_hi).contains(&p)) {
        let allowed = format!(
            "such that P = EI/(kT L) is in [{p_lo:e}, {p_hi:e}] (here {p:.3e}; the exact \
             compression theory's domain)"
        );
        return Some((DomainInput::BendingRigidity, allowed));
    }
    let (k_lo, k_hi) = STRETCH_BEND_RATIO_RANGE;
    let k = s / (p * p);
    if !(k.is_finite() && (k_lo..=k_hi).contains(&k)) {
        let allowed = format!(
            "such that S/P² = EA L³ kT/EI² is in [{k_lo:e}, {k_hi:e}] (here {k:.3e}; the exact \
             compression theory's domain: outside it runs for minutes or meets a known limit)"
        );
        return Some((DomainInput::StretchRigidity, allowed));
    }
    let max = max_strain_ratio(p, s);
    let i = strain_ratios
        .iter()
        .position(|r| !(r.is_finite() && (MIN_STRAIN_RATIO..=max).contains(r)))?;
    let allowed = format!(
        "in [{MIN_STRAIN_RATIO:e}, {max:e}] at P = {p:e}, S = {s:e} (at most {STRAIN_RATIO_SCALE}·√S/P: \
         the exact compression theory's domain)"
    );
    Some((DomainInput::StrainRatio(i), allowed))
}

/// Terms of the power series used for the small modes.
const SERIES_TERMS: usize = 30;
/// Modes with `b τ_max` at most this go into the power series.
const SERIES_RADIUS: f64 = 0.25;
/// Target of the bound on |χ(u)| at which the CDF's Fourier series is truncated.
const CDF_TOLERANCE: f64 = 1e-14;
/// Cap on the number of Fourier terms of a [`ForceDistribution`].
const MAX_FOURIER_TERMS: usize = 200_000;
/// Nodes per exponential in the Gaussian-kernel sums of a [`ForceDistribution`].
const KERNEL_ANCHOR: i64 = 8;
/// Extra exponent for the Gaussian range of the quadrature.
const RANGE_MARGIN: f64 = 10.0;
/// Cap on the work of one quadrature, trapezoid nodes times modes evaluated per node
/// ([`CompressionTheory::quadrature_work`]); about 10 s. Inside the ranges the CLI accepts
/// ([`STRETCH_BEND_RATIO_RANGE`], [`max_strain_ratio`]) the work stays below 10⁸.
pub const MAX_QUADRATURE_WORK: f64 = 2e9;
/// Cap on the trapezoid nodes a [`ForceDistribution`] stores (16 bytes each: 160 MB).
pub const MAX_DISTRIBUTION_NODES: f64 = 1e7;
/// Cap on the number of continuum tail modes summed one by one in one evaluation of the
/// exact tail at a real argument (`2c₁|η|` up to `(cap/4)²`); about 40 ms each.
const MAX_TAIL_MODES: usize = 4_000_000;
/// Cap on the Newton/bisection iterations of the saddle point (bisection alone halves a
/// bracket of 2¹⁰²⁴ to rounding in ≈ 1100 steps; Newton converges in ≈ 10).
const MAX_SADDLE_ITERATIONS: usize = 300;

fn numerical(routine: &str, detail: impl Into<String>) -> Error {
    Error::Numerical {
        routine: routine.into(),
        detail: detail.into(),
    }
}

/// Number of transverse directions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Dims {
    /// Planar filament: one deflection w; each mode contributes a χ²₁.
    Two,
    /// Filament in space: deflections w and v; each mode contributes a χ²₂.
    Three,
}

impl Dims {
    /// `2 → Two`, `3 → Three`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for any other value.
    pub fn from_u32(dims: u32) -> Result<Self> {
        match dims {
            2 => Ok(Dims::Two),
            3 => Ok(Dims::Three),
            _ => Err(Error::invalid("dims", dims, "2 or 3")),
        }
    }

    /// Number of transverse directions `d` (1 in 2D, 2 in 3D): the degrees of freedom of
    /// each mode's χ².
    pub fn copies(self) -> usize {
        match self {
            Dims::Two => 1,
            Dims::Three => 2,
        }
    }

    /// The spatial dimension, 2 or 3.
    pub fn as_u32(self) -> u32 {
        match self {
            Dims::Two => 2,
            Dims::Three => 3,
        }
    }
}

/// `Σ_{n>m} n^{−p}` for `p = 2` or `4`: the Euler–Maclaurin expansion at
/// `K = max(m, 1000)` (to `O(K^{−p−7})`, relative error below 10⁻²⁰), plus the explicit
/// terms `m < n ≤ K` summed from the smallest.
fn inverse_power_tail(p: u32, m: usize) -> f64 {
    let k = m.max(1000);
    let x = k as f64;
    let em = match p {
        2 => {
            1.0 / x - 1.0 / (2.0 * x * x) + 1.0 / (6.0 * x.powi(3)) - 1.0 / (30.0 * x.powi(5))
                + 1.0 / (42.0 * x.powi(7))
        }
        4 => {
            1.0 / (3.0 * x.powi(3)) - 1.0 / (2.0 * x.powi(4)) + 1.0 / (3.0 * x.powi(5))
                - 1.0 / (6.0 * x.powi(7))
                + 2.0 / (9.0 * x.powi(9))
        }
        _ => unreachable!("inverse_power_tail: p must be 2 or 4"),
    };
    (m + 1..=k)
        .rev()
        .fold(em, |acc, n| acc + (n as f64).powi(-(p as i32)))
}

/// `B_{2i}/(2i)!`, i = 1..=8: the Euler–Maclaurin coefficients.
const BERNOULLI_OVER_FACTORIAL: [f64; 8] = [
    1.0 / 12.0,
    -1.0 / 720.0,
    1.0 / 30_240.0,
    -1.0 / 1_209_600.0,
    1.0 / 47_900_160.0,
    -691.0 / 1_307_674_368_000.0,
    1.0 / 74_724_249_600.0,
    -3617.0 / 10_670_622_842_880_000.0,
];

/// Terms of the scaled-zeta table of an [`InverseSquareTail`] used by the contour (power
/// sums up to [`SERIES_TERMS`] need `k + j ≤ 64`, see [`ZetaSeries::power_sum`]).
const CONTOUR_ZETA_TERMS: usize = 64;
/// Terms of the scaled-zeta table for `L`, `Σ(n² − x)⁻¹` and `Σ(n² − x)⁻²` alone
/// (`|r| ≤ 1/16`: 16⁻¹⁸ < 10⁻²¹).
const LOG_SUM_TERMS: usize = 20;
/// The series in `r = z/N²` are used for `|z| ≤ N²/16`, i.e. base `N ≥ 4√|z|`.
const TAIL_BASE_FACTOR: f64 = 4.0;
/// Relative size of the last term kept in the tail series.
const TAIL_SERIES_TOLERANCE: f64 = 1e-18;

/// The scaled Hurwitz zeta values `ζ̃_{2j}(N) = N^{2j} ζ(2j, N) = Σ_{n≥N} (N/n)^{2j}`,
/// `j = 1..=count`: Euler–Maclaurin at `K_j = max(N, 3(j + 8))` with 8 Bernoulli terms
/// (the first omitted term bounds the error, `≤ 2((2j+16)/(2πK_j))^{18} ≤ 2·0.107^{18}
/// ≈ 7·10⁻¹⁸` relative), plus the explicit terms `N ≤ n < K_j`, smallest first.
fn scaled_even_zeta(base: usize, count: usize) -> Vec<f64> {
    let nb = base as f64;
    let start = |j: usize| base.max(3 * (j + 8));
    let mut z: Vec<f64> = (1..=count)
        .map(|j| {
            let s = 2.0 * j as f64;
            let k = start(j) as f64;
            let mut em = k / (s - 1.0) + 0.5;
            let mut rising = s;
            let mut k_pow = 1.0 / k;
            for (i, b) in BERNOULLI_OVER_FACTORIAL.iter().enumerate() {
                em += b * rising * k_pow;
                let i2 = 2.0 * i as f64;
                rising *= (s + i2 + 1.0) * (s + i2 + 2.0);
                k_pow /= k * k;
            }
            (nb / k).powi(2 * j as i32) * em
        })
        .collect();
    for n in (base..start(count)).rev() {
        let q = (nb / n as f64).powi(2);
        let mut p = q;
        for (j, zj) in z.iter_mut().enumerate() {
            if n < start(j + 1) {
                *zj += p;
            }
            p *= q;
        }
    }
    z
}

/// The series in `r = z/N²` of sums over `n ≥ N` (module docs, *The continuum*), from a
/// table of [`scaled_even_zeta`]; valid for `|r| ≤ 1/16`.
#[derive(Debug, Clone)]
struct ZetaSeries {
    base: usize,
    zeta: Vec<f64>,
}

impl ZetaSeries {
    fn new(base: usize, count: usize) -> Self {
        ZetaSeries {
            base,
            zeta: scaled_even_zeta(base, count),
        }
    }

    fn base_sq(&self) -> f64 {
        (self.base as f64).powi(2)
    }

    /// `L_N(z) = −Σ_{n≥N} ln(1 − z/n²) = Σ_{j≥1} r^j ζ̃_{2j}/j`.
    fn log_sum(&self, z: Complex<f64>) -> Complex<f64> {
        let r = z / self.base_sq();
        let mut acc = Complex::new(0.0, 0.0);
        let mut p = r;
        for (j, zj) in self.zeta.iter().enumerate() {
            let term = p * (zj / (j + 1) as f64);
            acc += term;
            if term.norm() <= TAIL_SERIES_TOLERANCE * acc.norm() {
                break;
            }
            p *= r;
        }
        acc
    }

    /// `L_N(x)` for real x.
    fn log_sum_real(&self, x: f64) -> f64 {
        let r = x / self.base_sq();
        let mut acc = 0.0;
        let mut p = r;
        for (j, zj) in self.zeta.iter().enumerate() {
            let term = p * zj / (j + 1) as f64;
            acc += term;
            if term.abs() <= TAIL_SERIES_TOLERANCE * acc.abs() {
                break;
            }
            p *= r;
        }
        acc
    }

    /// `Σ_{n≥N} (a/(n² − x))^k = (a/N²)^k Σ_{j≥0} C(k+j−1, j) r^j ζ̃_{2(k+j)}`, k ≥ 1.
    /// The terms first grow by the binomial, then fall by `≈ |r|`; for `k ≤ 30`,
    /// `|r| ≤ 1/16` the term `k + j = 64` is below 10⁻²³ of the sum.
    fn power_sum(&self, k: usize, a: f64, x: f64) -> f64 {
        let nn = self.base_sq();
        let r = x / nn;
        let mut acc = 0.0;
        let mut coef = 1.0;
        for j in 0..self.zeta.len().saturating_sub(k - 1) {
            let term = coef * self.zeta[k + j - 1];
            acc += term;
            if term.abs() <= TAIL_SERIES_TOLERANCE * acc.abs() {
                break;
            }
            coef *= r * (k + j) as f64 / (j + 1) as f64;
        }
        (a / nn).powi(k as i32) * acc
    }
}

/// The omitted modes `c_n = c₁/n²`, `n ≥ first` of [`Tail::InverseSquare`] with their
/// scaled-zeta table at `N = first`. Arguments `|z| > N²/16` move the series to the base
/// `⌈4√|z|⌉` (new table) and sum the modes in between explicitly.
#[derive(Debug, Clone)]
struct InverseSquareTail {
    c1: f64,
    series: ZetaSeries,
}

impl InverseSquareTail {
    fn new(c1: f64, first: usize, count: usize) -> Self {
        InverseSquareTail {
            c1,
            series: ZetaSeries::new(first, count),
        }
    }

    fn first(&self) -> usize {
        self.series.base
    }

    /// The base needed for `|z|` (at least `first`).
    fn base_for(&self, z_abs: f64) -> usize {
        let need = (TAIL_BASE_FACTOR * z_abs.sqrt()).ceil();
        if need <= self.first() as f64 {
            self.first()
        } else {
            need as usize
        }
    }

    /// The series at `base` (this table, or a new one of `count` terms).
    fn series_at(&self, base: usize, count: usize) -> std::borrow::Cow<'_, ZetaSeries> {
        if base == self.first() && count <= self.series.zeta.len() {
            std::borrow::Cow::Borrowed(&self.series)
        } else {
            std::borrow::Cow::Owned(ZetaSeries::new(base, count))
        }
    }

    /// `L(z) = −Σ_{n≥first} ln(1 − z/n²)` for complex z.
    fn log_sum(&self, z: Complex<f64>) -> Complex<f64> {
        let base = self.base_for(z.norm());
        let mut acc = self.series_at(base, LOG_SUM_TERMS).log_sum(z);
        for n in (self.first()..base).rev() {
            acc -= (1.0 - z / (n as f64).powi(2)).ln();
        }
        acc
    }

    /// `L(2c₁η)` for real η: the tail's `ψ/(d/2)`; `+∞` at or past the singularity of the
    /// first omitted mode.
    fn log_sum_real(&self, eta: f64) -> f64 {
        let x = 2.0 * self.c1 * eta;
        if x >= (self.first() as f64).powi(2) {
            return f64::INFINITY;
        }
        let base = self.base_for(x.abs());
        let mut acc = self.series_at(base, LOG_SUM_TERMS).log_sum_real(x);
        for n in (self.first()..base).rev() {
            acc -= (-x / (n as f64).powi(2)).ln_1p();
        }
        acc
    }

    /// `Σ_{n≥first} (2c₁/(n² − 2c₁η))^k = Σ b_n^k` (the tilted weights' power sums; k = 1, 2
    /// give the tail's ψ′ and ψ″ up to the factors d/2 and d).
    fn tilted_power_sum(&self, k: usize, eta: f64) -> f64 {
        let a = 2.0 * self.c1;
        let x = a * eta;
        let base = self.base_for(x.abs());
        let mut acc = self.series_at(base, LOG_SUM_TERMS + k).power_sum(k, a, x);
        for n in (self.first()..base).rev() {
            acc += (a / ((n as f64).powi(2) - x)).powi(k as i32);
        }
        acc
    }
}

/// How the modes that are not in [`StoredLengthLaw::weights`] enter the law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tail {
    /// No omitted modes (a discrete filament).
    None,
    /// The omitted modes replaced by a Gaussian `N(mean, variance)` with their exact mean
    /// `d Σ c_n` and variance `2d Σ c_n²` ([`StoredLengthLaw::continuum_gaussian_tail`]):
    /// an approximation, bounded by [`continuum_tail_log_char_bound`].
    Gaussian {
        /// Mean of the omitted modes.
        mean: f64,
        /// Variance of the omitted modes.
        variance: f64,
    },
    /// The omitted modes exactly: a χ²_d of weight `c_n = first_weight/n²` for every
    /// `n ≥ first_mode` (the continuum's modes beyond the explicit ones,
    /// [`StoredLengthLaw::continuum`]), summed by Hurwitz-zeta series (module docs,
    /// *The continuum*).
    InverseSquare {
        /// `c₁`: the weight the sequence `c₁/n²` would have at `n = 1`.
        first_weight: f64,
        /// The first omitted mode.
        first_mode: usize,
    },
}

/// The law of the stored length `s = (1/2L)∫|w'|² dx` under the bending-only Gaussian
/// ensemble: `s = Σ_i c_i χ²_{d,i} + S_T`, with `S_T` the omitted modes ([`Tail`]: none for
/// a discrete filament, exact for the continuum).
#[derive(Debug, Clone, PartialEq)]
pub struct StoredLengthLaw {
    /// Explicit mode weights `c_i = kT μ_i/(2L)`, descending.
    pub weights: Vec<f64>,
    /// Degrees of freedom `d` of each mode's χ² (1 in 2D, 2 in 3D).
    pub copies: usize,
    /// The omitted modes.
    pub tail: Tail,
}

impl StoredLengthLaw {
    /// The continuum filament, exactly: `c_n = kT L/(2 EI n²π²)` for `n = 1..=n_modes`
    /// explicitly, and every mode `n > n_modes` through the Hurwitz-zeta series of
    /// [`Tail::InverseSquare`]. The law does not depend on `n_modes` beyond rounding; it only
    /// splits the work ([`DEFAULT_CONTINUUM_MODES`]).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for invalid parameters or `n_modes = 0`.
    pub fn continuum(params: &FilamentParams, dims: Dims, n_modes: usize) -> Result<Self> {
        params.validate()?;
        if n_modes == 0 {
            return Err(Error::invalid("n_modes", n_modes, ">= 1"));
        }
        let c1 = continuum_first_weight(params);
        Ok(StoredLengthLaw {
            weights: (1..=n_modes).map(|n| c1 / (n as f64 * n as f64)).collect(),
            copies: dims.copies(),
            tail: Tail::InverseSquare {
                first_weight: c1,
                first_mode: n_modes + 1,
            },
        })
    }

    /// The continuum truncated to `n_modes` explicit modes, with the modes `n > n_modes`
    /// replaced by a Gaussian of their exact mean and variance ([`Tail::Gaussian`]). The
    /// brute-force reference for [`Self::continuum`] (cost `O(n_modes)` per evaluation; the
    /// error in `ln φ` is bounded by [`continuum_tail_log_char_bound`], below 10⁻¹⁶ for
    /// 10⁴ modes at the paper's parameters).
    ///
    /// # Errors
    /// As [`Self::continuum`].
    pub fn continuum_gaussian_tail(
        params: &FilamentParams,
        dims: Dims,
        n_modes: usize,
    ) -> Result<Self> {
        let mut law = Self::continuum(params, dims, n_modes)?;
        let c1 = continuum_first_weight(params);
        let d = dims.copies() as f64;
        law.tail = Tail::Gaussian {
            mean: d * c1 * inverse_power_tail(2, n_modes),
            variance: 2.0 * d * c1 * c1 * inverse_power_tail(4, n_modes),
        };
        Ok(law)
    }

    /// The filament discretized by `n_elements` uniform Hermite-cubic elements:
    /// `c_i = kT μ_i/(2L)`, `μ_i = 1/λ_i` with `λ_i` the generalized eigenvalues of
    /// `(K, G)` of [`BeamModel`] (the buckling loads of the mesh), from the closed form
    /// [`discrete_buckling_loads`]; no tail. The closed form equals the dense generalized
    /// eigenproblem ([`Self::discrete_dense`]) to rounding (≤ 10⁻¹² relative for N ≤ 32,
    /// `tests/compression_theory.rs`), but stays exact for large N, where the dense
    /// route loses accuracy in the largest μ as `≈ ε_mach·N⁴` (3·10⁻⁷ at N = 512) and costs
    /// `O(N³)`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for invalid parameters or `n_elements` outside
    /// `[1, MAX_DISCRETE_ELEMENTS]`.
    pub fn discrete(params: &FilamentParams, dims: Dims, n_elements: usize) -> Result<Self> {
        let loads = discrete_buckling_loads(params, n_elements)?;
        let f = params.kt / (2.0 * params.length);
        Ok(StoredLengthLaw {
            weights: loads.iter().map(|l| f / l).collect(),
            copies: dims.copies(),
            tail: Tail::None,
        })
    }

    /// As [`Self::discrete`], but from the dense generalized eigenproblem of the assembled
    /// [`BeamModel`] matrices: `K = LLᵀ` (banded Cholesky), `μ_i` the eigenvalues of
    /// `L⁻¹GL⁻ᵀ` (`O(N³)`). A cross-check of the closed form; inaccurate for large N (see
    /// [`Self::discrete`]).
    ///
    /// # Errors
    /// As [`Self::discrete`]; [`Error::Numerical`] if `K` is not positive definite or an
    /// eigenvalue is not positive.
    pub fn discrete_dense(params: &FilamentParams, dims: Dims, n_elements: usize) -> Result<Self> {
        let mu = discrete_compliances_dense(params, n_elements)?;
        let f = params.kt / (2.0 * params.length);
        Ok(StoredLengthLaw {
            weights: mu.iter().map(|m| f * m).collect(),
            copies: dims.copies(),
            tail: Tail::None,
        })
    }

    /// A law of explicit weights only (no tail): `s = Σ_i c_i χ²_{d,i}`, `d = copies`,
    /// weights sorted descending. Any object whose stored measure is a quadratic form
    /// `s = xᵀGx/(2X)` under a Gaussian `x ~ N(0, kT K⁻¹)` has such a law, with
    /// `c_i = kT μ_i/(2X)` and `μ_i` the generalized eigenvalues of `(G, K)` (module docs,
    /// *The stored-length law*); e.g. the membrane's stored area,
    /// [`crate::fem::plate_area`].
    ///
    /// # Errors
    /// As [`Self::validate`].
    pub fn from_weights(mut weights: Vec<f64>, copies: usize) -> Result<Self> {
        weights.sort_by(|a, b| b.total_cmp(a));
        let law = StoredLengthLaw {
            weights,
            copies,
            tail: Tail::None,
        };
        law.validate()?;
        Ok(law)
    }

    /// Checks the law is well formed: `copies ≥ 1`, weights finite and `≥ 0`, Gaussian tail
    /// cumulants finite and `≥ 0`, an inverse-square tail with a finite positive weight and
    /// `first_mode ≥ 1`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the offending field.
    pub fn validate(&self) -> Result<()> {
        if self.copies == 0 {
            return Err(Error::invalid("copies", self.copies, ">= 1"));
        }
        if let Some(c) = self.weights.iter().find(|c| !(c.is_finite() && **c >= 0.0)) {
            return Err(Error::invalid("weights", c, "finite and >= 0"));
        }
        match self.tail {
            Tail::None => {}
            Tail::Gaussian { mean, variance } => {
                if !(mean.is_finite() && mean >= 0.0) {
                    return Err(Error::invalid("tail mean", mean, "finite and >= 0"));
                }
                if !(variance.is_finite() && variance >= 0.0) {
                    return Err(Error::invalid("tail variance", variance, "finite and >= 0"));
                }
            }
            Tail::InverseSquare {
                first_weight,
                first_mode,
            } => {
                if !(first_weight.is_finite() && first_weight > 0.0) {
                    return Err(Error::invalid(
                        "tail first_weight",
                        first_weight,
                        "finite and > 0",
                    ));
                }
                if first_mode == 0 {
                    return Err(Error::invalid("tail first_mode", first_mode, ">= 1"));
                }
            }
        }
        Ok(())
    }

    /// Mean of the omitted modes: 0, the Gaussian's mean, or `d c₁ Σ_{n≥first} n⁻²`.
    pub fn tail_mean(&self) -> f64 {
        match self.tail {
            Tail::None => 0.0,
            Tail::Gaussian { mean, .. } => mean,
            Tail::InverseSquare {
                first_weight,
                first_mode,
            } => self.copies as f64 * first_weight * inverse_power_tail(2, first_mode - 1),
        }
    }

    /// Variance of the omitted modes: 0, the Gaussian's variance, or
    /// `2d c₁² Σ_{n≥first} n⁻⁴`.
    pub fn tail_variance(&self) -> f64 {
        match self.tail {
            Tail::None => 0.0,
            Tail::Gaussian { variance, .. } => variance,
            Tail::InverseSquare {
                first_weight,
                first_mode,
            } => {
                let d = self.copies as f64;
                2.0 * d * first_weight * first_weight * inverse_power_tail(4, first_mode - 1)
            }
        }
    }

    /// `E s = d Σ c_i + tail mean` (the stored length of the free filament, ⟨s⟩₀).
    pub fn mean(&self) -> f64 {
        let d = self.copies as f64;
        d * self.weights.iter().rev().sum::<f64>() + self.tail_mean()
    }

    /// `Var s = 2d Σ c_i² + tail variance`.
    pub fn variance(&self) -> f64 {
        let d = self.copies as f64;
        2.0 * d * self.weights.iter().rev().map(|c| c * c).sum::<f64>() + self.tail_variance()
    }

    /// The largest weight, omitted modes included (0 without modes).
    pub fn max_weight(&self) -> f64 {
        let explicit = self.weights.iter().fold(0.0_f64, |a, &c| a.max(c));
        match self.tail {
            Tail::InverseSquare {
                first_weight,
                first_mode,
            } => explicit.max(first_weight / (first_mode as f64).powi(2)),
            _ => explicit,
        }
    }

    /// The characteristic function `φ(t) = E e^{its} = Π(1 − 2ic_it)^{−d/2} · φ_T(t)`,
    /// evaluated as a sum of logarithms; `φ_T` is 1, `e^{it m_T − t² v_T/2}` (Gaussian tail)
    /// or `e^{(d/2) L(2ic₁t)}` (inverse-square tail, module docs).
    pub fn char_fn(&self, t: f64) -> Complex<f64> {
        let half_d = 0.5 * self.copies as f64;
        let (mut re, mut im) = (0.0, 0.0);
        for &c in self.weights.iter().rev() {
            let x = 2.0 * c * t;
            re -= 0.5 * half_d * (x * x).ln_1p();
            im += half_d * x.atan();
        }
        match self.tail {
            Tail::None => {}
            Tail::Gaussian { mean, variance } => {
                re -= 0.5 * variance * t * t;
                im += t * mean;
            }
            Tail::InverseSquare {
                first_weight,
                first_mode,
            } => {
                let l = InverseSquareTail::new(first_weight, first_mode, LOG_SUM_TERMS)
                    .log_sum(Complex::new(0.0, 2.0 * first_weight * t));
                re += half_d * l.re;
                im += half_d * l.im;
            }
        }
        Complex::from_polar(re.exp(), im)
    }

    /// The cumulant generating function `ψ(η) = ln E e^{ηs}`, finite for
    /// `η < 1/(2 max c_i)`; `+∞` beyond.
    pub fn cumulant_generating_fn(&self, eta: f64) -> f64 {
        let tail = match self.tail {
            Tail::InverseSquare {
                first_weight,
                first_mode,
            } => Some(InverseSquareTail::new(
                first_weight,
                first_mode,
                LOG_SUM_TERMS,
            )),
            _ => None,
        };
        cgf(&self.weights, self.copies, &self.tail, tail.as_ref(), eta)
    }
}

/// `ψ(η)` of explicit weights plus a tail (`+∞` past the first singularity); `exact` is the
/// prepared [`Tail::InverseSquare`], if any.
fn cgf(
    weights: &[f64],
    copies: usize,
    tail: &Tail,
    exact: Option<&InverseSquareTail>,
    eta: f64,
) -> f64 {
    let half_d = 0.5 * copies as f64;
    let mut acc = 0.0;
    for &c in weights.iter().rev() {
        let a = -2.0 * c * eta;
        if a <= -1.0 {
            return f64::INFINITY;
        }
        acc -= half_d * a.ln_1p();
    }
    match (tail, exact) {
        (Tail::Gaussian { mean, variance }, _) => acc + eta * mean + 0.5 * eta * eta * variance,
        (Tail::InverseSquare { .. }, Some(t)) => acc + half_d * t.log_sum_real(eta),
        _ => acc,
    }
}

/// `c₁ = kT L/(2EIπ²)` of the continuum.
fn continuum_first_weight(params: &FilamentParams) -> f64 {
    params.kt * params.length / (2.0 * params.bending_rigidity * PI * PI)
}

/// Rigorous bound on `|ln φ_exact(t) − ln φ_law(t)|` for
/// [`StoredLengthLaw::continuum_gaussian_tail`]`(params, dims, n_modes)`: the error of representing the
/// modes `n > n_modes` by a Gaussian with their exact mean and variance, at a complex
/// argument of modulus `t_abs`. `(d/2)(2|t|)³ p₃/(3(1 − 2c_{M+1}|t|))` with
/// `p₃ = Σ_{n>M} c_n³ ≤ c₁³/(5(M+½)⁵)` (midpoint bound of a convex sum); `+∞` if
/// `2c_{M+1}|t| ≥ 1`.
pub fn continuum_tail_log_char_bound(
    params: &FilamentParams,
    dims: Dims,
    n_modes: usize,
    t_abs: f64,
) -> f64 {
    let c1 = continuum_first_weight(params);
    let m1 = n_modes as f64 + 1.0;
    let r = 2.0 * c1 / (m1 * m1) * t_abs;
    if r >= 1.0 {
        return f64::INFINITY;
    }
    let p3 = c1.powi(3) / (5.0 * (n_modes as f64 + 0.5).powi(5));
    0.5 * dims.copies() as f64 * (2.0 * t_abs).powi(3) * p3 / (3.0 * (1.0 - r))
}

/// Lower-triangular banded forward substitution `L y = b` in place.
fn forward_solve(lband: &[f64], bw: usize, b: &mut [f64]) {
    let w = bw + 1;
    for i in 0..b.len() {
        let mut s = b[i];
        for k in i.saturating_sub(bw)..i {
            s -= lband[i * w + (i - k)] * b[k];
        }
        b[i] = s / lband[i * w];
    }
}

fn check_elements(n_elements: usize) -> Result<()> {
    if n_elements == 0 || n_elements > MAX_DISCRETE_ELEMENTS {
        return Err(Error::invalid(
            "n_elements",
            n_elements,
            format!("in [1, {MAX_DISCRETE_ELEMENTS}]"),
        ));
    }
    Ok(())
}

/// All `2N` buckling loads of the hinged filament discretized by `n_elements = N`
/// uniform Hermite-cubic elements — the generalized eigenvalues `λ` of `K v = λ G v` over
/// the free DOFs of [`BeamModel`] — ascending, in closed form.
///
/// **Derivation.** A hinge is a mirror for the element equations (w odd, θ = w' even),
/// so with `h = L/N` and `k = nπ/L` the vectors `w_i = W sin(kx_i)`, `θ_i = Θ cos(kx_i)`
/// span an invariant subspace of the pencil: the constrained `w_0 = w_N = 0` hold, and the
/// boundary rows of `θ_0`, `θ_N` are exactly half the interior rows. On it, summing the
/// element matrices over the two elements at a node (`σ = sin(kh/2)`):
///
/// ```text
/// K₂ = (EI/h³) [[48σ², −12h sin kh], [−12h sin kh, (12 − 8σ²)h²]],
/// G₂ = (1/30h) [[144σ², −6h sin kh], [−6h sin kh, (6 + 4σ²)h²]],
/// ```
///
/// with `det K₂ = 192 (EI)² σ⁴/h⁴` and `det G₂ = 0.8 σ²(1 + σ²)`. With `λ = x·EI/h²` the
/// characteristic equation is `(1 + σ²)x² − (60 − 16σ²)x + 240σ² = 0`: for
/// `n = 1..N−1` both roots (the acoustic root `x₋ = 480σ²/(b + √D)`, `b = 60 − 16σ²`,
/// `D = b² − 960σ²(1 + σ²) > 0`, computed without cancellation; `x₋ → (kh)²`, i.e.
/// `λ → EIk²`), plus the rotation-only modes `n = 0` (`x = 60`, θ constant) and `n = N`
/// (`x = 12`, θ alternating). The lowest load, `n = 1` acoustic, is
/// [`buckling_load_discrete`]; it converges to `F_c0` as `h⁴`.
///
/// # Errors
/// [`Error::InvalidParameter`] for invalid parameters or `n_elements` outside
/// `[1, MAX_DISCRETE_ELEMENTS]`.
pub fn discrete_buckling_loads(params: &FilamentParams, n_elements: usize) -> Result<Vec<f64>> {
    params.validate()?;
    check_elements(n_elements)?;
    let h = params.length / n_elements as f64;
    let scale = params.bending_rigidity / (h * h);
    let mut loads = Vec::with_capacity(2 * n_elements);
    loads.push(60.0 * scale);
    loads.push(12.0 * scale);
    for n in 1..n_elements {
        let sigma = (n as f64 * PI / (2.0 * n_elements as f64)).sin();
        let s2 = sigma * sigma;
        let b = 60.0 - 16.0 * s2;
        let root = (b * b - 960.0 * s2 * (1.0 + s2)).sqrt();
        loads.push(480.0 * s2 / (b + root) * scale);
        loads.push((b + root) / (2.0 * (1.0 + s2)) * scale);
    }
    loads.sort_by(|a, b| a.total_cmp(b));
    Ok(loads)
}

/// Eigenvalues μ of `K⁻¹G` (the compliances `1/buckling load` of the discrete modes),
/// descending, from the dense generalized eigenproblem.
fn discrete_compliances_dense(params: &FilamentParams, n_elements: usize) -> Result<Vec<f64>> {
    params.validate()?;
    check_elements(n_elements)?;
    let beam = BeamModel::new(*params, Mesh::uniform(params.length, n_elements)?)?;
    let chol = beam.stiffness().cholesky()?;
    let g = beam.geometric();
    let n = beam.n_dofs();
    let bw = chol.bandwidth();
    let mut lband = vec![0.0; n * (bw + 1)];
    for i in 0..n {
        for k in i.saturating_sub(bw)..=i {
            lband[i * (bw + 1) + (i - k)] = chol.get(i, k);
        }
    }
    // Z = L⁻¹ G (column by column), then B = L⁻¹ Zᵀ = L⁻¹ G L⁻ᵀ.
    let gb = g.bandwidth();
    let mut z = DMatrix::<f64>::zeros(n, n);
    for j in 0..n {
        let mut col = z.column_mut(j);
        let col = col.as_mut_slice();
        let rows = j.saturating_sub(gb)..(j + gb + 1).min(n);
        for (i, v) in rows.clone().zip(&mut col[rows]) {
            *v = g.get(i, j);
        }
        forward_solve(&lband, bw, col);
    }
    z.transpose_mut();
    for j in 0..n {
        let mut col = z.column_mut(j);
        forward_solve(&lband, bw, col.as_mut_slice());
    }
    let b = (&z + z.transpose()) * 0.5;
    drop(z);
    let mut mu: Vec<f64> = b.symmetric_eigenvalues().iter().copied().collect();
    if let Some(v) = mu.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
        return Err(numerical(
            "discrete stored-length weights",
            format!("eigenvalue {v:e} of K^-1 G, expected finite and > 0"),
        ));
    }
    mu.sort_by(|a, b| b.total_cmp(a));
    Ok(mu)
}

/// Euler buckling load of the filament discretized by `n_elements` uniform Hermite-cubic
/// elements: `1/μ_max`, the smallest generalized eigenvalue of `(K, G)` (closed form, see
/// [`discrete_buckling_loads`]). It converges to `F_c0 = π²EI/L²` from above as `h⁴`
/// (the discretization is stiffer).
///
/// # Errors
/// As [`StoredLengthLaw::discrete`].
pub fn buckling_load_discrete(params: &FilamentParams, n_elements: usize) -> Result<f64> {
    Ok(discrete_buckling_loads(params, n_elements)?[0])
}

/// Accuracy knobs of the quadrature (defaults: step scale 1, level 40).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuadratureOptions {
    /// Multiplies the trapezoid step chosen from the aliasing bound (`< 1` refines).
    pub step_scale: f64,
    /// The level T: tails, aliasing and range are cut at `e^{−T}`.
    pub decay_exponent: f64,
}

impl Default for QuadratureOptions {
    fn default() -> Self {
        QuadratureOptions {
            step_scale: 1.0,
            decay_exponent: 40.0,
        }
    }
}

/// The global constraint of the stored-length theory: a stiffness S that penalizes the
/// stored measure `s` against the imposed strain ε through the energy
/// `(S·X/2)(s − ε)²`, X the measure, and the reference scales that make the results
/// dimensionless (module docs, *Other constrained objects*).
///
/// | object | S | X | `F = S(ε − s)` | reference load | reference strain |
/// |---|---|---|---|---|---|
/// | filament | EA | L | compressive force | `F_c0 = π²EI/L²` | `ε_c0 = F_c0/EA` |
/// | membrane | K_A | A₀ | `−σ` (σ the tension) | `σ_c0 = κq²_min` | `ε_c0 = σ_c0/K_A` |
///
/// The theory uses `A = S·X/(2kT)` (the stretching Gaussian `e^{−A(s−ε)²}`) and the force
/// unit `kT/X`; every weight `c_i` of the [`StoredLengthLaw`] is `kT μ_i/(2X)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GlobalConstraint {
    /// The stiffness S of the constraint: EA (filament) or the area modulus K_A
    /// (membrane).
    pub stiffness: f64,
    /// The measure X: the length L (filament) or the true area A₀ (membrane).
    pub measure: f64,
    /// Thermal energy kT.
    pub kt: f64,
    /// The load that [`CompressionTheory::force_ratio`] divides by: F_c0 or σ_c0.
    pub reference_load: f64,
    /// The strain that [`CompressionTheory::force_ratio`]'s argument multiplies: ε_c0.
    pub reference_strain: f64,
}

impl GlobalConstraint {
    /// The filament's constraint: S = EA, X = L, kT, reference load
    /// [`FilamentParams::euler_load`] and strain [`FilamentParams::euler_strain`].
    ///
    /// # Errors
    /// As [`FilamentParams::validate`].
    pub fn filament(params: &FilamentParams) -> Result<Self> {
        params.validate()?;
        Ok(GlobalConstraint {
            stiffness: params.stretch_rigidity,
            measure: params.length,
            kt: params.kt,
            reference_load: params.euler_load(),
            reference_strain: params.euler_strain(),
        })
    }

    /// A membrane's constraint: S = K_A (`area_modulus`), X = A₀ (`area`), kT, reference
    /// load `reference_tension` (σ_c0 = κq²_min) and strain `σ_c0/K_A`.
    ///
    /// # Errors
    /// As [`Self::validate`].
    pub fn membrane(area_modulus: f64, area: f64, kt: f64, reference_tension: f64) -> Result<Self> {
        let c = GlobalConstraint {
            stiffness: area_modulus,
            measure: area,
            kt,
            reference_load: reference_tension,
            reference_strain: reference_tension / area_modulus,
        };
        c.validate()?;
        Ok(c)
    }

    /// Checks every field finite and `> 0`, and `S·X/kT` and `kT/X` finite and `> 0`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first offending field.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("stiffness", self.stiffness),
            ("measure", self.measure),
            ("kt", self.kt),
            ("reference_load", self.reference_load),
            ("reference_strain", self.reference_strain),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::invalid(name, v, "finite and > 0"));
            }
        }
        let a = self.stretch_exponent();
        if !(a.is_finite() && a > 0.0) {
            return Err(Error::invalid(
                "stiffness*measure/(2kt)",
                a,
                "finite and > 0",
            ));
        }
        let unit = self.force_unit();
        if !(unit.is_finite() && unit > 0.0) {
            return Err(Error::invalid("kt/measure", unit, "finite and > 0"));
        }
        Ok(())
    }

    /// `A = S·X/(2kT)`.
    pub fn stretch_exponent(&self) -> f64 {
        self.stiffness * self.measure / (2.0 * self.kt)
    }

    /// The force unit `kT/X`: the mean-field force is `(kT/X)η̂`.
    pub fn force_unit(&self) -> f64 {
        self.kt / self.measure
    }
}

/// The exact equilibrium force–strain theory for one filament, or any object with a
/// [`GlobalConstraint`] (global constraint + stored-length law). See the module
/// documentation for the method.
#[derive(Debug, Clone)]
pub struct CompressionTheory {
    constraint: GlobalConstraint,
    /// The filament's parameters, when built from a filament ([`Self::new`]).
    filament: Option<FilamentParams>,
    law: StoredLengthLaw,
    options: QuadratureOptions,
    /// Positive weights only, descending.
    weights: Vec<f64>,
    /// The prepared exact tail of a [`Tail::InverseSquare`] law.
    exact_tail: Option<InverseSquareTail>,
    /// The largest weight, tail included (0 without modes).
    max_weight: f64,
    /// ⟨s⟩₀ of the law.
    mean: f64,
    half_d: f64,
    /// A = EA·L/(2kT).
    a: f64,
    /// kT/L.
    force_unit: f64,
}

/// Contour parameters at one strain.
#[derive(Debug, Clone, Copy)]
struct Setup {
    eta: f64,
    m: f64,
    h: f64,
    tau_max: f64,
    level: f64,
}

/// The tilted characteristic function on a contour, split into explicit and series modes.
struct Contour {
    half_d: f64,
    m: f64,
    inv4a: f64,
    explicit: Vec<f64>,
    series: Vec<f64>,
    tail_lin: f64,
    tail_half_var: f64,
}

impl Contour {
    /// `ln φ_η(τ)`.
    /// The explicit modes in pairs: `ln((1 − ix)(1 − iy)) = ½ln(1 + x² + y² + x²y²)
    /// − i·atan2(x + y, 1 − xy)`, exact because x, y have the same sign (the two arguments
    /// add to less than π); half the logarithms and arctangents of one mode at a time.
    fn log_phi(&self, tau: f64) -> Complex<f64> {
        let (mut re, mut im) = (0.0, 0.0);
        let mut pairs = self.explicit.chunks_exact(2);
        for pair in &mut pairs {
            let (x, y) = (pair[0] * tau, pair[1] * tau);
            let (x2, y2) = (x * x, y * y);
            re -= 0.5 * self.half_d * (x2 + y2 + x2 * y2).ln_1p();
            im += self.half_d * (x + y).atan2(1.0 - x * y);
        }
        for &b in pairs.remainder() {
            let x = b * tau;
            re -= 0.5 * self.half_d * (x * x).ln_1p();
            im += self.half_d * x.atan();
        }
        let mut acc = Complex::new(0.0, 0.0);
        if !self.series.is_empty() {
            let z = Complex::new(0.0, tau);
            for &a in self.series.iter().rev() {
                acc = acc * z + a;
            }
            acc *= z;
        }
        Complex::new(
            re + acc.re - self.tail_half_var * tau * tau,
            im + acc.im + tau * self.tail_lin,
        )
    }

    /// Modes (explicit, plus the power-series terms) evaluated per node.
    fn modes_per_node(&self) -> usize {
        self.explicit.len() + self.series.len()
    }

    /// `φ_η(τ) e^{−iτm}`.
    fn shifted(&self, tau: f64) -> Complex<f64> {
        let l = self.log_phi(tau);
        Complex::from_polar(l.re.exp(), l.im - tau * self.m)
    }

    /// `f(τ) = φ_η(τ) e^{−iτm} e^{−τ²/(4A)}`.
    fn integrand(&self, tau: f64) -> Complex<f64> {
        let l = self.log_phi(tau);
        Complex::from_polar((l.re - tau * tau * self.inv4a).exp(), l.im - tau * self.m)
    }
}

/// Trapezoid sums `s0 = Σf`, `s1 = Σ τ f / i`, `s2 = Σ τ² f` over the full line.
#[derive(Debug, Clone, Copy)]
struct Moments {
    s0: f64,
    s1: f64,
    s2: f64,
}

impl CompressionTheory {
    /// Builds the theory for `params` (uses EA, kT, L) and a stored-length law computed
    /// for the same parameters.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for invalid parameters or an ill-formed law.
    pub fn new(params: &FilamentParams, law: StoredLengthLaw) -> Result<Self> {
        let mut theory = Self::with_constraint(GlobalConstraint::filament(params)?, law)?;
        theory.filament = Some(*params);
        Ok(theory)
    }

    /// Builds the theory for any [`GlobalConstraint`] (e.g. a membrane under imposed
    /// projected area, [`crate::fem::plate_area`]) and a stored-length law whose weights
    /// are `kT μ_i/(2X)` for the same constraint.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for an invalid constraint or an ill-formed law.
    pub fn with_constraint(constraint: GlobalConstraint, law: StoredLengthLaw) -> Result<Self> {
        constraint.validate()?;
        law.validate()?;
        let mut weights: Vec<f64> = law.weights.iter().copied().filter(|&c| c > 0.0).collect();
        weights.sort_by(|a, b| b.total_cmp(a));
        let exact_tail = match law.tail {
            Tail::InverseSquare {
                first_weight,
                first_mode,
            } => Some(InverseSquareTail::new(
                first_weight,
                first_mode,
                CONTOUR_ZETA_TERMS,
            )),
            _ => None,
        };
        Ok(CompressionTheory {
            constraint,
            filament: None,
            half_d: 0.5 * law.copies as f64,
            max_weight: law.max_weight(),
            mean: law.mean(),
            law,
            options: QuadratureOptions::default(),
            weights,
            exact_tail,
            a: constraint.stretch_exponent(),
            force_unit: constraint.force_unit(),
        })
    }

    /// The same theory with other quadrature settings.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless `0 < step_scale ≤ 1` and
    /// `10 ≤ decay_exponent ≤ 200`.
    pub fn with_options(mut self, options: QuadratureOptions) -> Result<Self> {
        if !(options.step_scale > 0.0 && options.step_scale <= 1.0) {
            return Err(Error::invalid(
                "step_scale",
                options.step_scale,
                "in (0, 1]",
            ));
        }
        if !(options.decay_exponent >= 10.0 && options.decay_exponent <= 200.0) {
            return Err(Error::invalid(
                "decay_exponent",
                options.decay_exponent,
                "in [10, 200]",
            ));
        }
        self.options = options;
        Ok(self)
    }

    /// The filament's physical parameters; `None` if the theory was built by
    /// [`Self::with_constraint`] (no filament: see [`Self::constraint`]).
    pub fn params(&self) -> Option<&FilamentParams> {
        self.filament.as_ref()
    }

    /// The global constraint (S, X, kT and the reference scales).
    pub fn constraint(&self) -> &GlobalConstraint {
        &self.constraint
    }

    /// The stored-length law.
    pub fn law(&self) -> &StoredLengthLaw {
        &self.law
    }

    /// The quadrature settings.
    pub fn options(&self) -> QuadratureOptions {
        self.options
    }

    /// `(kT/L)/(2 c_max)`: the buckling load of the law's stiffest-to-buckle mode (F_c0 for
    /// the continuum, [`buckling_load_discrete`] for a mesh); `+∞` without weights.
    pub fn buckling_load(&self) -> f64 {
        self.force_unit * self.eta_max()
    }

    fn eta_max(&self) -> f64 {
        if self.max_weight > 0.0 {
            1.0 / (2.0 * self.max_weight)
        } else {
            f64::INFINITY
        }
    }

    fn psi(&self, eta: f64) -> f64 {
        cgf(
            &self.weights,
            self.law.copies,
            &self.law.tail,
            self.exact_tail.as_ref(),
            eta,
        )
    }

    /// `ψ′(η)` (k = 1) or `ψ″(η)` (k = 2) of the Gaussian or exact tail.
    fn tail_derivative(&self, k: usize, eta: f64) -> f64 {
        match (&self.law.tail, &self.exact_tail) {
            (Tail::Gaussian { mean, variance }, _) => match k {
                1 => mean + eta * variance,
                _ => *variance,
            },
            (Tail::InverseSquare { .. }, Some(t)) => self.half_d * t.tilted_power_sum(k, eta),
            _ => 0.0,
        }
    }

    fn psi1(&self, eta: f64) -> f64 {
        let d = 2.0 * self.half_d;
        let mut acc = 0.0;
        for &c in self.weights.iter().rev() {
            acc += d * c / (1.0 - 2.0 * c * eta);
        }
        acc + self.tail_derivative(1, eta)
    }

    fn psi2(&self, eta: f64) -> f64 {
        let d = 2.0 * self.half_d;
        let mut acc = 0.0;
        for &c in self.weights.iter().rev() {
            let q = c / (1.0 - 2.0 * c * eta);
            acc += 2.0 * d * q * q;
        }
        acc + self.tail_derivative(2, eta)
    }

    /// The saddle point η̂: `ψ'(η) + η/(2A) = ε`, by safeguarded Newton on a bracket.
    fn saddle(&self, strain: f64) -> Result<f64> {
        let inv2a = 0.5 / self.a;
        let g = |eta: f64| self.psi1(eta) + eta * inv2a - strain;
        let mean = self.mean;
        let mut lo = (2.0 * self.a * (strain - mean)).min(0.0) - 1.0;
        // η̂ ≥ lo: the exact tail at η̂ sums at most this many modes one by one
        let tail_modes = self.tail_modes_at(lo);
        if tail_modes > MAX_TAIL_MODES {
            return Err(numerical(
                "compression saddle point",
                format!(
                    "strain {strain:e}: the saddle point may lie as far as eta = {lo:e}, where \
                     the exact continuum tail would sum {tail_modes} modes one by one (cap \
                     {MAX_TAIL_MODES}); {}",
                    match &self.filament {
                        Some(p) => format!(
                            "EA*L^3*kT/EI^2 = {:e} is too large",
                            p.stretch_rigidity * p.length.powi(3) * p.kt
                                / p.bending_rigidity.powi(2)
                        ),
                        None => "the constraint is too stiff for the weights".to_string(),
                    }
                ),
            ));
        }
        let emax = self.eta_max();
        let mut hi = if emax.is_finite() {
            let mut r = 0.5_f64;
            loop {
                let cand = emax * (1.0 - r);
                if cand > lo && g(cand) > 0.0 {
                    break cand;
                }
                r *= 0.25;
                if r < 1e-15 {
                    return Err(numerical(
                        "compression saddle point",
                        format!(
                            "strain {strain:e} too far beyond buckling for a double-precision \
                             contour (distance to the singularity below 1e-15 relative)"
                        ),
                    ));
                }
            }
        } else {
            (2.0 * self.a * strain).max(0.0) + 1.0
        };
        // g is increasing and convex: Newton from the right converges monotonically; the
        // bracket guards against rounding.
        let mut eta = hi;
        for _ in 0..MAX_SADDLE_ITERATIONS {
            let gv = g(eta);
            let g_scale = strain.abs() + mean + eta.abs() * inv2a;
            if gv.abs() <= 1e-15 * g_scale {
                return Ok(eta);
            }
            if gv > 0.0 {
                hi = eta;
            } else {
                lo = eta;
            }
            let slope = self.psi2(eta) + inv2a;
            let mut next = eta - gv / slope;
            if !(next > lo && next < hi) {
                next = 0.5 * (lo + hi);
            }
            if (next - eta).abs() <= 1e-15 * eta.abs() || hi - lo <= 1e-15 * hi.abs().max(lo.abs())
            {
                return Ok(next);
            }
            eta = next;
        }
        Err(numerical(
            "compression saddle point",
            format!(
                "no convergence at strain {strain:e} after {MAX_SADDLE_ITERATIONS} iterations \
                 (bracket [{lo:e}, {hi:e}], residual {:e})",
                g(eta)
            ),
        ))
    }

    /// Number of continuum tail modes the exact tail sums one by one at the real argument
    /// `2c₁η` (0 without an [`Tail::InverseSquare`] tail).
    fn tail_modes_at(&self, eta: f64) -> usize {
        match &self.exact_tail {
            Some(t) => {
                let need = TAIL_BASE_FACTOR * (2.0 * t.c1 * eta).abs().sqrt();
                if need.is_finite() {
                    (need.ceil() as usize).saturating_sub(t.first())
                } else {
                    usize::MAX
                }
            }
            None => 0,
        }
    }

    /// Chernoff bounds `P(s_η − m > x_R) ≤ e^{−level}`, `P(s_η − m < −x_L) ≤ e^{−level}`
    /// for the tilted law s_η (density ∝ p₀(s)e^{ηs}), minimized over a ladder of
    /// exponents θ (right: θ below the singularity distance δ).
    fn chernoff(&self, eta: f64, m: f64, level: f64) -> (f64, f64) {
        let var = self.psi2(eta);
        if var <= 0.0 {
            return (0.0, 0.0);
        }
        let p0 = self.psi(eta);
        let delta = self.eta_max() - eta;
        let theta0 = (2.0 * level / var).sqrt();
        let mut ladder: Vec<f64> = (-24..=24)
            .map(|k| theta0 * 2f64.powf(k as f64 / 2.0))
            .collect();
        let (mut x_l, mut x_r) = (f64::INFINITY, f64::INFINITY);
        // (far-left exponents whose exact tail would be too long only loosen the bound)
        for &th in ladder
            .iter()
            .filter(|&&th| self.tail_modes_at(eta - th) <= MAX_TAIL_MODES)
        {
            let v = (level + self.psi(eta - th) - p0 + th * m) / th;
            if v.is_finite() {
                x_l = x_l.min(v);
            }
        }
        if delta.is_finite() {
            ladder.retain(|&th| th < delta * 0.999);
            ladder.extend((1..=24).map(|k| delta * (1.0 - 2f64.powi(-k))));
        }
        for &th in &ladder {
            let v = (level + self.psi(eta + th) - p0 - th * m) / th;
            if v.is_finite() {
                x_r = x_r.min(v);
            }
        }
        (x_l.max(0.0), x_r.max(0.0))
    }

    fn setup(&self, strain: f64) -> Result<Setup> {
        if !strain.is_finite() {
            return Err(Error::invalid("strain", strain, "finite"));
        }
        let eta = self.saddle(strain)?;
        let m = strain - eta * 0.5 / self.a;
        let var_g = 0.5 / self.a;
        let sigma_y = (self.psi2(eta) + var_g).sqrt();
        let t = self.options.decay_exponent;
        let level = t + (sigma_y / var_g.sqrt()).ln().max(0.0) + 2.0;
        let (x_l, x_r) = self.chernoff(eta, m, level);
        let period = x_l.max(x_r) + (level / self.a).sqrt();
        let h = 2.0 * PI / period * self.options.step_scale;
        let tau_max = (4.0 * self.a * (level + RANGE_MARGIN)).sqrt();
        if !(h.is_finite() && h > 0.0 && tau_max.is_finite()) {
            return Err(numerical(
                "compression quadrature",
                format!("bad step {h:e} or range {tau_max:e} at strain {strain:e}"),
            ));
        }
        Ok(Setup {
            eta,
            m,
            h,
            tau_max,
            level,
        })
    }

    fn contour(&self, s: &Setup, tau_range: f64) -> Contour {
        let mut explicit = Vec::new();
        let mut power = vec![0.0; SERIES_TERMS];
        let mut add_mode = |b: f64| {
            if b * tau_range > SERIES_RADIUS {
                explicit.push(b);
            } else {
                let mut bk = b;
                for p in power.iter_mut() {
                    *p += bk;
                    bk *= b;
                    if bk == 0.0 {
                        break;
                    }
                }
            }
        };
        for &c in &self.weights {
            add_mode(2.0 * c / (1.0 - 2.0 * c * s.eta));
        }
        if let Some(t) = &self.exact_tail {
            // b_n = 2c₁/(n² − x): the modes below the base (b_n τ_range > SERIES_RADIUS or
            // |x| > n²/16) one by one, the rest by their power sums
            let a = 2.0 * t.c1;
            let x = a * s.eta;
            let radius = (x + a * tau_range / SERIES_RADIUS).max(0.0).sqrt().ceil();
            let base = t.base_for(x.abs()).max(radius as usize);
            for n in t.first()..base {
                add_mode(a / ((n as f64).powi(2) - x));
            }
            let series = t.series_at(base, CONTOUR_ZETA_TERMS);
            for (k, p) in power.iter_mut().enumerate() {
                *p += series.power_sum(k + 1, a, x);
            }
        }
        let (tail_lin, tail_var) = match self.law.tail {
            Tail::Gaussian { mean, variance } => (mean + s.eta * variance, variance),
            _ => (0.0, 0.0),
        };
        let series = if power[0] > 0.0 {
            power
                .iter()
                .enumerate()
                .map(|(k, p)| self.half_d * p / (k + 1) as f64)
                .collect()
        } else {
            Vec::new()
        };
        Contour {
            half_d: self.half_d,
            m: s.m,
            inv4a: 0.25 / self.a,
            explicit,
            series,
            tail_lin,
            tail_half_var: 0.5 * tail_var,
        }
    }

    /// `|φ_η(τ)|` over all modes (monotone decreasing in |τ|).
    fn abs_phi(&self, eta: f64, tau: f64) -> f64 {
        let mut re = 0.0;
        for &c in self.weights.iter().rev() {
            let x = 2.0 * c / (1.0 - 2.0 * c * eta) * tau;
            re -= 0.5 * self.half_d * (x * x).ln_1p();
        }
        match (&self.law.tail, &self.exact_tail) {
            (Tail::Gaussian { variance, .. }, _) => re -= 0.5 * variance * tau * tau,
            (Tail::InverseSquare { .. }, Some(t)) => {
                let x = 2.0 * t.c1 * eta;
                let y = 2.0 * t.c1 * tau;
                re += self.half_d
                    * (t.log_sum(Complex::new(x, y)).re - t.log_sum(Complex::new(x, 0.0)).re);
            }
            _ => {}
        }
        re.exp()
    }

    fn moments(&self, s: &Setup, c: &Contour) -> Moments {
        let (mut s0, mut s1, mut s2) = (1.0, 0.0, 0.0);
        let cutoff = (-s.level).exp();
        let weight_max = 1.0 + s.tau_max * s.tau_max;
        let mut j = 1usize;
        loop {
            let tau = j as f64 * s.h;
            if tau > s.tau_max {
                break;
            }
            let f = c.integrand(tau);
            s0 += 2.0 * f.re;
            s1 += 2.0 * tau * f.im;
            s2 += 2.0 * tau * tau * f.re;
            let remaining = (s.tau_max - tau) / s.h + 1.0;
            if f.norm() * weight_max * remaining < cutoff * s0.abs() {
                break;
            }
            j += 1;
        }
        Moments { s0, s1, s2 }
    }

    fn evaluate(&self, strain: f64) -> Result<(Setup, Moments)> {
        let s = self.setup(strain)?;
        let c = self.contour(&s, s.tau_max);
        let work = Self::work_of(&s, &c);
        if work > MAX_QUADRATURE_WORK {
            return Err(numerical(
                "compression quadrature",
                format!(
                    "strain {strain:e} would need {:.3e} trapezoid nodes times {} modes = \
                     {work:.3e} mode evaluations (cap {MAX_QUADRATURE_WORK:e}; the nodes grow \
                     as the strain times sqrt(EA*L/kT))",
                    s.tau_max / s.h,
                    c.modes_per_node()
                ),
            ));
        }
        let mo = self.moments(&s, &c);
        if !(mo.s0.is_finite() && mo.s0 > 0.0 && mo.s1.is_finite() && mo.s2.is_finite()) {
            return Err(numerical(
                "compression quadrature",
                format!(
                    "non-positive or non-finite normalization {:e} at strain {strain:e}",
                    mo.s0
                ),
            ));
        }
        Ok((s, mo))
    }

    /// Upper bound on the work of the quadrature: nodes up to `τ_max` times the modes
    /// evaluated per node.
    fn work_of(s: &Setup, c: &Contour) -> f64 {
        (s.tau_max / s.h + 1.0) * c.modes_per_node() as f64
    }

    /// The work of the quadrature for ⟨F⟩ at strain ε, as the number of mode evaluations
    /// (trapezoid nodes up to the range `τ_max`, an upper bound on those used, times the
    /// explicit modes plus the power-series terms evaluated at each node). A deterministic
    /// measure of the cost (≈ 10⁸ per second); above [`MAX_QUADRATURE_WORK`] the
    /// evaluation is refused.
    ///
    /// # Errors
    /// As [`Self::mean_force`], except for the cap itself.
    pub fn quadrature_work(&self, strain: f64) -> Result<f64> {
        let s = self.setup(strain)?;
        Ok(Self::work_of(&s, &self.contour(&s, s.tau_max)))
    }

    fn mean_from(&self, s: &Setup, mo: &Moments) -> f64 {
        self.force_unit * (s.eta - mo.s1 / mo.s0)
    }

    fn variance_from(&self, mo: &Moments) -> f64 {
        let r1 = mo.s1 / mo.s0;
        let ea = self.constraint.stiffness;
        (ea * self.force_unit - self.force_unit * self.force_unit * (mo.s2 / mo.s0 + r1 * r1))
            .max(0.0)
    }

    /// The exact equilibrium mean compressive force ⟨F⟩ at imposed nominal strain ε
    /// (physical units; negative = tension).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a non-finite strain; [`Error::Numerical`] if the
    /// quadrature fails (e.g. a strain so large that the contour cannot be resolved in
    /// double precision).
    pub fn mean_force(&self, strain: f64) -> Result<f64> {
        let (s, mo) = self.evaluate(strain)?;
        Ok(self.mean_from(&s, &mo))
    }

    /// `⟨F⟩/F_c0` at `ε = strain_ratio·ε_c0`, with the continuum `F_c0 = π²EI/L²` and
    /// `ε_c0 = π²EI/(EA·L²)` ([`FilamentParams::euler_load`], `euler_strain`), also for a
    /// discrete law; in general the [`GlobalConstraint`]'s reference load and strain (for a
    /// membrane `⟨F⟩/σ_c0 = −⟨σ⟩/σ_c0` at `ε = strain_ratio·ε_c0`).
    ///
    /// # Errors
    /// As [`Self::mean_force`].
    pub fn force_ratio(&self, strain_ratio: f64) -> Result<f64> {
        if !strain_ratio.is_finite() {
            return Err(Error::invalid("strain_ratio", strain_ratio, "finite"));
        }
        Ok(
            self.mean_force(strain_ratio * self.constraint.reference_strain)?
                / self.constraint.reference_load,
        )
    }

    /// The exact equilibrium variance of F at strain ε.
    ///
    /// # Errors
    /// As [`Self::mean_force`].
    pub fn force_variance(&self, strain: f64) -> Result<f64> {
        let (_, mo) = self.evaluate(strain)?;
        Ok(self.variance_from(&mo))
    }

    /// The Gaussian mean-field (saddle-point) force `(kT/L)η̂`: the tension that makes the
    /// mean stored length of the Gaussian ensemble under that tension, plus the elastic
    /// strain F/EA, equal to ε. Not exact; it never exceeds [`Self::buckling_load`]. For
    /// comparison only.
    ///
    /// # Errors
    /// As [`Self::mean_force`].
    pub fn mean_field_force(&self, strain: f64) -> Result<f64> {
        if !strain.is_finite() {
            return Err(Error::invalid("strain", strain, "finite"));
        }
        Ok(self.force_unit * self.saddle(strain)?)
    }

    /// The exact equilibrium distribution of `F = EA(ε − s)` at strain ε.
    ///
    /// # Errors
    /// As [`Self::mean_force`].
    pub fn force_distribution(&self, strain: f64) -> Result<ForceDistribution> {
        let (s, mo) = self.evaluate(strain)?;
        let mean = self.mean_from(&s, &mo);
        let std_dev = self.variance_from(&mo).sqrt();
        let (x0, period) = self.fourier_window(&s, &mo);
        let du = 2.0 * PI / period;
        let rho_exp = self.options.decay_exponent + RANGE_MARGIN;
        let rho = (4.0 * self.a * rho_exp).sqrt();
        let (k_cap, rigorous_bound) = self.fourier_cap(&s, &mo, du, rho, rho_exp);
        let contour = self.contour(&s, k_cap as f64 * du + rho);
        // Refused before anything is allocated: the nodes up to the last Fourier
        // frequency are stored, each costs the modes, and each coefficient sums the nodes
        // within rho of its frequency.
        let nodes = (k_cap as f64 * du + rho) / s.h + 1.0;
        let work = nodes * contour.modes_per_node() as f64 + k_cap as f64 * (2.0 * rho / s.h + 1.0);
        if nodes > MAX_DISTRIBUTION_NODES || work > MAX_QUADRATURE_WORK {
            return Err(numerical(
                "compression force distribution",
                format!(
                    "strain {strain:e} would need {nodes:.3e} kernel nodes (cap \
                     {MAX_DISTRIBUTION_NODES:e}) and {work:.3e} mode evaluations (cap \
                     {MAX_QUADRATURE_WORK:e}): the distribution of F is too narrow for its \
                     Fourier series at this stretch rigidity"
                ),
            ));
        }
        let mut sums = KernelSums {
            contour,
            h: s.h,
            rho,
            inv4a: 0.25 / self.a,
            vals: Vec::new(),
        };
        let norm = sums.at(0.0).re;
        if !(norm.is_finite() && norm > 0.0) {
            return Err(numerical(
                "compression force distribution",
                format!("non-positive normalization {norm:e} at strain {strain:e}"),
            ));
        }
        let (coeffs, truncation_bound) =
            fourier_coefficients(&mut sums, norm, du, k_cap, rigorous_bound);
        let mut dist = ForceDistribution {
            strain,
            ea: self.constraint.stiffness,
            mean_field_force: self.force_unit * s.eta,
            x0,
            period,
            du,
            coeffs,
            c0: 0.0,
            mean,
            std_dev,
            truncation_bound,
        };
        dist.c0 = dist.series_im(x0);
        Ok(dist)
    }

    /// The window `(x0, period)` of the Fourier series in X = s − m: the support where the
    /// tilted density exceeds e^{−level} (Chernoff bounds, capped by the Gaussian factor),
    /// widened by 2 % on each side.
    fn fourier_window(&self, s: &Setup, mo: &Moments) -> (f64, f64) {
        let a = self.a;
        // Z = E_q[e^{−A(s−m)²}] = √(π/A)/(2π) · h · s0
        let z = (PI / a).sqrt() / (2.0 * PI) * s.h * mo.s0;
        let level = self.options.decay_exponent + (-z.ln()).max(0.0);
        let w = (level / a).sqrt();
        let (x_l, x_r) = self.chernoff(s.eta, s.m, level);
        let lo = -(w.min(x_l));
        let hi = w.min(x_r);
        let width = (hi - lo).max(1e-300);
        let x0 = lo - 0.02 * width;
        let period = 1.04 * width;
        (x0, period)
    }

    /// The rigorous cap K on the number of Fourier terms and the bound on the CDF error at
    /// that cap: the smallest K with bound(KΔ) ≤ [`CDF_TOLERANCE`], at most
    /// [`MAX_FOURIER_TERMS`].
    fn fourier_cap(
        &self,
        s: &Setup,
        mo: &Moments,
        du: f64,
        rho: f64,
        rho_exp: f64,
    ) -> (usize, f64) {
        let a = self.a;
        let kernel_mass = (4.0 * PI * a).sqrt() / s.h + 1.0;
        let bound = |u: f64| {
            (self.abs_phi(s.eta, (u - rho).max(0.0)) * kernel_mass
                + (2.0 * u / s.h + 1.0) * (-rho_exp).exp())
                / mo.s0
        };
        // smallest K with bound(KΔ) ≤ tolerance (bound is monotone up to the tiny
        // linear term), capped
        let mut k_hi = 1usize;
        while bound(k_hi as f64 * du) > CDF_TOLERANCE && k_hi < MAX_FOURIER_TERMS {
            k_hi = (2 * k_hi).min(MAX_FOURIER_TERMS);
        }
        let mut k_lo = k_hi / 2;
        while k_hi - k_lo > 1 {
            let mid = (k_lo + k_hi) / 2;
            if bound(mid as f64 * du) > CDF_TOLERANCE {
                k_lo = mid;
            } else {
                k_hi = mid;
            }
        }
        let k_cap = k_hi;
        (k_cap, bound(k_cap as f64 * du))
    }
}

/// Gaussian-kernel sums Σ_j φ_η(τ_j) e^{−iτ_j m} e^{−(τ_j − u)²/(4A)} over the nodes
/// τ_j = j h within `rho` of u, with φ_η(τ_j) e^{−iτ_j m} for j ≥ 0 computed on demand and
/// kept (negative j by conjugation).
struct KernelSums {
    contour: Contour,
    h: f64,
    rho: f64,
    inv4a: f64,
    vals: Vec<Complex<f64>>,
}

impl KernelSums {
    fn at(&mut self, u: f64) -> Complex<f64> {
        let jlo = ((u - self.rho) / self.h).ceil() as i64;
        let jhi = ((u + self.rho) / self.h).floor() as i64;
        while (self.vals.len() as i64) <= jhi.max(-jlo) {
            let tau = self.vals.len() as f64 * self.h;
            self.vals.push(self.contour.shifted(tau));
        }
        let val = |j: i64| {
            if j >= 0 {
                self.vals[j as usize]
            } else {
                self.vals[(-j) as usize].conj()
            }
        };
        // The kernel w_j = e^{−d_j²/(4A)}, d_j = jh − u, by its exact recurrence
        // w_{j+1} = w_j g_j, g_{j+1} = g_j e^{−2h²/(4A)}, g_j = e^{−(2d_j h + h²)/(4A)}, restarted
        // from exponentials every KERNEL_ANCHOR nodes (rounding ≤ ≈ KERNEL_ANCHOR²ε/2
        // relative; two products per node instead of an exponential).
        let (h, c) = (self.h, self.inv4a);
        let q = (-2.0 * h * h * c).exp();
        let mut acc = Complex::new(0.0, 0.0);
        let mut j = jlo;
        while j <= jhi {
            let d = j as f64 * h - u;
            let mut w = (-d * d * c).exp();
            let mut g = (-(2.0 * d * h + h * h) * c).exp();
            let end = (j + KERNEL_ANCHOR - 1).min(jhi);
            acc += val(j) * w;
            for jj in j + 1..=end {
                w *= g;
                g *= q;
                acc += val(jj) * w;
            }
            j = end + 1;
        }
        acc
    }
}

/// The coefficients χ(kΔ)/k, k = 1..K, of the force distribution's series and its
/// truncation bound. Terms k = 1..K; stop at K = 2^j ≥ 16 once every |χ(kΔ)|,
/// K/2 < k ≤ K, is below the tolerance (observed decay; the bound is then that maximum),
/// or at the rigorous cap `k_cap` (bound `rigorous_bound`).
fn fourier_coefficients(
    sums: &mut KernelSums,
    norm: f64,
    du: f64,
    k_cap: usize,
    rigorous_bound: f64,
) -> (Vec<Complex<f64>>, f64) {
    let mut coeffs: Vec<Complex<f64>> = Vec::new();
    let mut block_max = 0.0_f64;
    let mut truncation_bound = rigorous_bound;
    for k in 1..=k_cap {
        let chi = sums.at(k as f64 * du) / norm;
        block_max = block_max.max(chi.norm());
        coeffs.push(chi / k as f64);
        if k.is_power_of_two() {
            if k >= 16 && block_max < CDF_TOLERANCE {
                truncation_bound = block_max;
                break;
            }
            block_max = 0.0;
        }
    }
    (coeffs, truncation_bound)
}

/// The exact equilibrium distribution of the compressive force `F = EA(ε − s)` at one
/// strain, from a Fourier series of the stored length's tilted law (module docs).
#[derive(Debug, Clone)]
pub struct ForceDistribution {
    strain: f64,
    ea: f64,
    mean_field_force: f64,
    /// Window start of X = s − m.
    x0: f64,
    period: f64,
    du: f64,
    /// χ(kΔ)/k, k = 1..
    coeffs: Vec<Complex<f64>>,
    c0: f64,
    mean: f64,
    std_dev: f64,
    truncation_bound: f64,
}

impl ForceDistribution {
    /// `Σ_k Im[χ(kΔ) e^{−ikΔx}]/k`.
    fn series_im(&self, x: f64) -> f64 {
        let mut acc = 0.0;
        let mut z = Complex::new(1.0, 0.0);
        let r = Complex::from_polar(1.0, -self.du * x);
        for (i, g) in self.coeffs.iter().enumerate() {
            let k = i + 1;
            if k % 64 == 0 {
                z = Complex::from_polar(1.0, -(k as f64) * self.du * x);
            } else {
                z *= r;
            }
            acc += (g * z).im;
        }
        acc
    }

    /// CDF of X = s − m.
    fn cdf_x(&self, x: f64) -> f64 {
        if x <= self.x0 {
            0.0
        } else if x >= self.x0 + self.period {
            1.0
        } else {
            ((x - self.x0) / self.period - (self.series_im(x) - self.c0) / PI).clamp(0.0, 1.0)
        }
    }

    /// `P(F ≤ f)`.
    pub fn cdf(&self, f: f64) -> f64 {
        if f.is_nan() {
            return f64::NAN;
        }
        1.0 - self.cdf_x((self.mean_field_force - f) / self.ea)
    }

    /// ⟨F⟩ (the same value as [`CompressionTheory::mean_force`]).
    pub fn mean(&self) -> f64 {
        self.mean
    }

    /// Standard deviation of F (square root of [`CompressionTheory::force_variance`]).
    pub fn std_dev(&self) -> f64 {
        self.std_dev
    }

    /// The imposed strain ε.
    pub fn strain(&self) -> f64 {
        self.strain
    }

    /// Interval of F outside which the CDF is 0 or 1 (it holds all but `≈ e^{−40}` of the
    /// probability).
    pub fn support(&self) -> (f64, f64) {
        (
            self.mean_field_force - self.ea * (self.x0 + self.period),
            self.mean_field_force - self.ea * self.x0,
        )
    }

    /// Number of Fourier terms of the series.
    pub fn fourier_terms(&self) -> usize {
        self.coeffs.len()
    }

    /// Size of the omitted Fourier coefficients: the largest |χ(kΔ)| over the last half of
    /// the retained terms when the series stopped on observed decay (below 10⁻¹⁴), else the
    /// rigorous bound on |χ| at the first omitted term (10⁻¹⁴, or larger if the cap of
    /// 2·10⁵ terms was reached).
    pub fn truncation_bound(&self) -> f64 {
        self.truncation_bound
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exact theory's domain, as `theory compression` bounds its flags: the paper's
    /// filament inside at every strain up to 100·√S/P, each input found outside at either
    /// side of its range (the bounds themselves inside), EI before EA before the strains.
    #[test]
    fn domain_violation_names_the_input_outside() {
        assert_eq!(
            domain_violation(100.0, 1e6, &[-8.0, 0.0, 6.0, 1000.0]),
            None
        );
        assert_eq!(domain_violation(1e-3, 1e-8, &[0.0]), None);
        assert_eq!(domain_violation(1e6, 1e24, &[0.0]), None);
        let input = |p, s, r: &[f64]| domain_violation(p, s, r).map(|(i, _)| i);
        assert_eq!(
            input(100.0, 1e6, &[0.0, 1000.5]),
            Some(DomainInput::StrainRatio(1))
        );
        assert_eq!(
            input(100.0, 1e6, &[-1.1e8]),
            Some(DomainInput::StrainRatio(0))
        );
        assert_eq!(
            input(100.0, 1e6, &[f64::NAN]),
            Some(DomainInput::StrainRatio(0))
        );
        assert_eq!(
            input(100.0, 50.0, &[0.0]),
            Some(DomainInput::StretchRigidity)
        );
        assert_eq!(
            input(100.0, 1.1e16, &[0.0]),
            Some(DomainInput::StretchRigidity)
        );
        assert_eq!(input(1e7, 1e6, &[0.0]), Some(DomainInput::BendingRigidity));
        assert_eq!(input(9e-4, 1e6, &[1e9]), Some(DomainInput::BendingRigidity));
        let (_, allowed) = domain_violation(100.0, 50.0, &[0.0]).unwrap();
        assert!(
            allowed.contains("[1e-2, 1e12]") && allowed.contains("5.000e-3"),
            "{allowed}"
        );
    }

    /// The exact law of F is refused, before anything is allocated, where its Fourier
    /// series would need more than [`MAX_DISTRIBUTION_NODES`] nodes (a small stretch
    /// rigidity: S/P² = 0.1 at 4 elements asks for 3·10⁷; before the cap, S/P² = 10⁻²
    /// aborted on a 4 GiB allocation); the paper's filament (S/P² = 100) is far inside.
    #[test]
    fn force_distribution_is_refused_beyond_its_node_cap() {
        let law = |ea: f64| {
            let p = FilamentParams {
                bending_rigidity: 100.0,
                stretch_rigidity: ea,
                ..FilamentParams::default()
            };
            let disc = StoredLengthLaw::discrete(&p, Dims::Two, 4).unwrap();
            let t = CompressionTheory::new(&p, disc).unwrap();
            let strain = 2.0 * t.constraint().reference_strain;
            t.force_distribution(strain)
        };
        for ea in [100.0, 1000.0] {
            match law(ea) {
                Err(Error::Numerical { detail, .. }) => {
                    assert!(detail.contains("kernel nodes (cap 1e7)"), "{detail}")
                }
                other => panic!("EA = {ea}: {other:?}"),
            }
        }
        assert!(law(1e6).is_ok());
    }

    #[test]
    fn inverse_power_tails_are_consistent() {
        let zeta = [PI * PI / 6.0, PI.powi(4) / 90.0];
        for (i, &p) in [2u32, 4].iter().enumerate() {
            assert!(
                (inverse_power_tail(p, 0) / zeta[i] - 1.0).abs() < 1e-15,
                "p = {p}"
            );
            let head: f64 = (1..=5).map(|n| (n as f64).powi(-(p as i32))).sum();
            let t5 = inverse_power_tail(p, 5);
            assert!(((t5 + head) / zeta[i] - 1.0).abs() < 1e-15, "p = {p}");
            // Euler–Maclaurin at 1000 against Euler–Maclaurin at 5000 plus explicit terms
            let partial: f64 = (1001..=5000)
                .rev()
                .map(|n| (n as f64).powi(-(p as i32)))
                .sum();
            let em = inverse_power_tail(p, 5000) + partial;
            assert!(
                (inverse_power_tail(p, 1000) / em - 1.0).abs() < 1e-14,
                "p = {p}"
            );
        }
    }

    #[test]
    fn scaled_even_zeta_matches_known_values() {
        // ζ(2j) at base 1: π²/6, π⁴/90, π⁶/945, π⁸/9450
        let z = scaled_even_zeta(1, CONTOUR_ZETA_TERMS);
        let exact = [
            PI.powi(2) / 6.0,
            PI.powi(4) / 90.0,
            PI.powi(6) / 945.0,
            PI.powi(8) / 9450.0,
        ];
        for (j, e) in exact.iter().enumerate() {
            assert!((z[j] / e - 1.0).abs() < 5e-16, "j = {}", j + 1);
        }
        // other bases against the explicit sums of inverse_power_tail (p = 2, 4) and a
        // direct sum over n < 40N (p = 2j ≥ 20: the rest is below 40^{−20})
        for base in [2usize, 7, 65, 300, 5000] {
            let nb = base as f64;
            let z = scaled_even_zeta(base, CONTOUR_ZETA_TERMS);
            for (j, p) in [(1usize, 2u32), (2, 4)] {
                let e = nb.powi(p as i32) * inverse_power_tail(p, base - 1);
                assert!((z[j - 1] / e - 1.0).abs() < 1e-15, "base {base}, p = {p}");
            }
            for j in [10usize, 30, 64] {
                let e: f64 = (base..40 * base)
                    .rev()
                    .map(|n| (nb / n as f64).powi(2 * j as i32))
                    .sum();
                assert!((z[j - 1] / e - 1.0).abs() < 1e-14, "base {base}, j = {j}");
            }
        }
    }

    #[test]
    fn char_fn_of_law_matches_cumulants() {
        let law = StoredLengthLaw {
            weights: vec![0.3, 0.1],
            copies: 2,
            tail: Tail::Gaussian {
                mean: 0.05,
                variance: 0.01,
            },
        };
        let t = 1e-4;
        let phi = law.char_fn(t);
        // ln φ ≈ i t κ1 − t² κ2/2
        let approx = Complex::new(-0.5 * t * t * law.variance(), t * law.mean()).exp();
        assert!((phi - approx).norm() < 1e-11);
        assert!((law.cumulant_generating_fn(1e-6) - 1e-6 * law.mean()).abs() < 1e-11);
    }
}
