//! The fluid membrane under an imposed projected area: the exact equilibrium tension
//! ⟨σ⟩(ε), its variance and distribution, from the stored-area law of the continuum and of
//! the uniform Bogner–Fox–Schmit mesh ([`super::PlateModel`]).
//!
//! # The model
//!
//! A fluid membrane of true area `A₀ = a·b` (bending rigidity κ, area modulus K_A) in a
//! frame that imposes the projected area `A_p = (1 − ε)A₀`. In the Monge gauge the excess
//! area is `ΔA = ½∫|∇h|² d²r`; write `s = ΔA/A₀` (the stored area per area). The energy is
//! the quadratic Helfrich bending energy plus the global area constraint
//! (physics notes § 7),
//!
//! ```text
//! U(h) = ½ hᵀK_b h + (K_A·A₀/2)(s(h) − ε)²,   s(h) = hᵀG h/(2A₀),
//! σ = K_A (A_p + ΔA − A₀)/A₀ = K_A (s − ε)          (positive = tension),
//! ```
//!
//! with `K_b = κ∫(∇²φ)²` and `G = ∫∇φ·∇φ` over the FE basis (in the continuum, over the
//! modes). This is the filament's problem ([`crate::theory::compression`]) with
//! `EA ↔ K_A`, `L ↔ A₀` and `F = EA(ε − s) ↔ −σ`: [`GlobalConstraint::membrane`]. Under the
//! bending-only Gaussian ensemble `h ~ N(0, kT K_b⁻¹)` the stored area is
//! `s = Σ_i c_i χ²_{1,i}`, `c_i = kT μ_i/(2A₀)`, `μ_i` the generalized eigenvalues of
//! `(G, K_b)` (`1/μ_i` are the buckling tensions of the modes). The exact tension
//! `⟨σ⟩ = −⟨F⟩`, its variance and its distribution then follow from the same saddle-point
//! contour ([`CompressionTheory`]) without any mean-field approximation. Every mode enters
//! with `d = 1`: the periodic cosine and sine modes of one wavevector are two equal weights
//! (not paired into a χ²₂).
//!
//! **Reference scales.** The smallest buckling tension of the continuum,
//! `σ_c0 = κ q²_min` (simply supported `q²_min = π²(1/a² + 1/b²)`, periodic
//! `(2π/max(a, b))²`), and `ε_c0 = σ_c0/K_A`. At `ε = 0` the thermal excess area puts the
//! membrane under tension, `⟨σ⟩ ≈ K_A⟨s⟩₀ > 0`; beyond buckling `⟨σ⟩ → −σ_c` (the
//! buckling tension of the law's softest mode).
//!
//! # The continuum and its cutoff
//!
//! Simply supported, the mode `(m, n)`, `m, n ≥ 1`, `sin(mπx/a) sin(nπy/b)` has
//! `∫|∇φ|² = q²A₀/4` and `κ∫(∇²φ)² = κq⁴A₀/4`, so `μ = 1/(κq²)`, `q² = (mπ/a)² + (nπ/b)²`;
//! periodic, the cosine and the sine of each wavevector `q = 2π(m/a, n/b)` of the
//! half-lattice (`m > 0`, or `m = 0 < n`) have `μ = 1/(κq²)` each (the zero mode, a
//! translation, does not store area). The sum `⟨s⟩₀ = Σ kT/(2A₀κq²)` diverges
//! logarithmically, so the continuum needs a stated cutoff ([`AreaCutoff`]): by lattice
//! indices, the acoustic modes of an `nx × ny` mesh (simply supported `1 ≤ m < nx`,
//! `1 ≤ n < ny`; periodic `2|m| < nx`, `2|n| < ny`), or by wavenumber `|q| ≤ Q`.
//!
//! # The discrete law
//!
//! On the uniform mesh, the 1D waves of [`super::plate_modes`] block-diagonalize every
//! 1D matrix, so `K_b = κ(K4⊗M + 2K2⊗K2 + M⊗K4)` and `G = K2⊗M + M⊗K2` (the σ-coefficient
//! of [`super::plate`]'s stiffness) are block-diagonal with blocks of size
//! `s_x·s_y ≤ 4`, one per pair of waves. Each small pencil `G_b y = μ K_b y` is solved
//! exactly ([`discrete_compliances`]: Cholesky of `K_b`, symmetric eigensolver of
//! `L⁻¹G_bL⁻ᵀ`). The one singular block, the periodic `(cos 0) ⊗ (cos 0)` (the uniform
//! translation, `K_b = G_b = 0`), is left out; every other block has `K_b > 0`. A block
//! of two height-carrying waves of resolved wavenumbers (simply supported `1 ≤ k < N`,
//! periodic `2k < N`, not both 0) is *acoustic*: its largest μ converges to the
//! continuum's `1/(κq²)` of the same lattice indices (at `O(h⁴)`, tested), its others are
//! optical (`μ = O(h²/κ)`). [`dense_compliances`] solves the dense generalized
//! eigenproblem of the assembled matrices as a cross-check (`tests/area_theory.rs`).
//!
//! The total `⟨s⟩₀` of the mesh is not the continuum's at the mesh's cutoff: the acoustic
//! weights lie below the continuum's (by `O((qh)⁴)`, largest near the cutoff), and the
//! optical modes add weights of order `h²/κ` each, `O(1/κ)` in all (the filament's
//! "bubble" deficit has the opposite sign). `tests/area_theory.rs` bounds the difference.

use super::modal::symmetric_pencil;
use super::plate::PlateModel;
use super::plate::{Axis, stiffness_entry};
use super::plate_modes::{Wave, axis_waves};
use crate::error::{Error, Result, require_positive};
use crate::spectral::membrane::{Membrane, MembraneBoundary, MembraneParams};
use crate::theory::compression::{
    CompressionTheory, DomainInput, ForceDistribution, GlobalConstraint, QuadratureOptions,
    StoredLengthLaw,
};
use nalgebra::{DMatrix, SymmetricEigen};
use std::f64::consts::PI;

/// Most elements per side of [`discrete_compliances`]: `4·nx·ny ≤ 65 536` weights, whose
/// saddle point and Chernoff bounds cost `O(weights)` per evaluation (≈ 0.2 s per strain at
/// the cap; the blocks themselves ≈ 0.1 s).
pub const MAX_AREA_ELEMENTS: usize = 128;

/// Most lattice indices per side of an [`AreaCutoff::Lattice`]: at most 65 536 modes, as
/// [`MAX_AREA_ELEMENTS`].
pub const MAX_AREA_CUTOFF_INDEX: usize = 256;

/// Range of `κ/kT` accepted by `theory area` (as the filament's
/// [`crate::theory::PERSISTENCE_RATIO_RANGE`]): every weight `c_i = kT/(2A₀κq²)` scales as
/// `kT/κ` and `A = K_A·A₀/(2kT)`, so `⟨σ⟩/σ_c0` at `ε/ε_c0` depends on κ and
/// `S = K_A·A₀/kT` only through `S/(κ/kT)²` (substitute `s = s̃·kT/κ`), which the CLI keeps
/// in [`crate::theory::STRETCH_BEND_RATIO_RANGE`]; this range only keeps the intermediate
/// quantities far from overflow.
pub const AREA_BENDING_RANGE: (f64, f64) = (1e-3, 1e6);

/// The largest strain ratio ε/ε_c0 accepted by `theory area`: the filament's bound
/// [`crate::theory::max_strain_ratio`] at the persistence ratio with the same largest
/// weight, `P_eq = κ q²_min A₀/(π² kT)` (`c_max = kT/(2A₀κq²_min) = 1/(2π²P_eq)`), i.e.
/// `100·√S/P_eq`: the quadrature's nodes grow as `ε√A ∝ (ε/ε_c0)·P_eq/√S` as for the
/// filament (work bound tested in `tests/area_theory.rs`).
pub fn max_area_strain_ratio(params: &AreaParams) -> f64 {
    let p_eq =
        params.bending_rigidity * params.membrane_params().min_wavenumber_sq() * params.area()
            / (PI * PI * params.kt);
    let s = params.area_modulus * params.area() / params.kt;
    crate::theory::max_strain_ratio(p_eq, s)
}

/// Largest aspect ratio `max(a, b)/min(a, b)` accepted by [`AreaParams::validate`]: the
/// reference scale `q²_min` then stays within a factor 5 of that of the square.
pub const MAX_AREA_ASPECT_RATIO: f64 = 10.0;

/// Physical parameters of a membrane under imposed projected area (consistent units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AreaParams {
    /// Bending rigidity κ (energy).
    pub bending_rigidity: f64,
    /// Area modulus K_A (energy per area).
    pub area_modulus: f64,
    /// Thermal energy kT.
    pub kt: f64,
    /// Side a along x.
    pub width: f64,
    /// Side b along y.
    pub height: f64,
    /// Boundary conditions.
    pub boundary: MembraneBoundary,
}

impl Default for AreaParams {
    /// κ = 20 kT, K_A·A₀/kT = 10⁶, kT = a = b = 1, simply supported.
    fn default() -> Self {
        AreaParams {
            bending_rigidity: 20.0,
            area_modulus: 1e6,
            kt: 1.0,
            width: 1.0,
            height: 1.0,
            boundary: MembraneBoundary::SimplySupported,
        }
    }
}

impl AreaParams {
    /// Checks κ, K_A, kT, a, b finite and `> 0`, the aspect ratio at most
    /// [`MAX_AREA_ASPECT_RATIO`], and `K_A·A₀/kT`, `kT/A₀` finite.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first offending field.
    pub fn validate(&self) -> Result<()> {
        require_positive("bending_rigidity", self.bending_rigidity)?;
        require_positive("area_modulus", self.area_modulus)?;
        require_positive("kt", self.kt)?;
        require_positive("width", self.width)?;
        require_positive("height", self.height)?;
        let aspect = self.height / self.width;
        if !(aspect.is_finite()
            && (1.0 / MAX_AREA_ASPECT_RATIO..=MAX_AREA_ASPECT_RATIO).contains(&aspect))
        {
            return Err(Error::invalid(
                "height",
                self.height,
                format!(
                    "in [{:e}, {:e}] (height/width in [1/{MAX_AREA_ASPECT_RATIO}, \
                     {MAX_AREA_ASPECT_RATIO}] with width {:e})",
                    self.width / MAX_AREA_ASPECT_RATIO,
                    self.width * MAX_AREA_ASPECT_RATIO,
                    self.width
                ),
            ));
        }
        self.constraint().map(|_| ())
    }

    /// Where these parameters at the strain ratios `strain_ratios` leave the domain in
    /// which `theory area` computes the exact theory (as the filament's
    /// [`crate::theory::domain_violation`]): κ/kT in [`AREA_BENDING_RANGE`],
    /// S/(κ/kT)² (S = K_A·A₀/kT) in [`crate::theory::STRETCH_BEND_RATIO_RANGE`], each
    /// strain ratio in [[`crate::theory::MIN_STRAIN_RATIO`], [`max_area_strain_ratio`]].
    /// The first input outside ([`DomainInput::StretchRigidity`] stands for K_A) with its
    /// allowed range in words; `None` inside.
    pub fn domain_violation(&self, strain_ratios: &[f64]) -> Option<(DomainInput, String)> {
        let k = self.bending_rigidity / self.kt;
        let (k_lo, k_hi) = AREA_BENDING_RANGE;
        if !(k.is_finite() && (k_lo..=k_hi).contains(&k)) {
            let allowed = format!(
                "such that κ/kT is in [{k_lo:e}, {k_hi:e}] (here {k:.3e}; the exact theory's domain)"
            );
            return Some((DomainInput::BendingRigidity, allowed));
        }
        let (l_lo, l_hi) = crate::theory::STRETCH_BEND_RATIO_RANGE;
        let l = self.area_modulus * self.area() / self.kt / (k * k);
        if !(l.is_finite() && (l_lo..=l_hi).contains(&l)) {
            let allowed = format!(
                "such that S/(κ/kT)² = K_A A₀ kT/κ² is in [{l_lo:e}, {l_hi:e}] (here {l:.3e}; the \
                 exact theory's domain: outside it runs for minutes or meets a known limit)"
            );
            return Some((DomainInput::StretchRigidity, allowed));
        }
        let (min, max) = (crate::theory::MIN_STRAIN_RATIO, max_area_strain_ratio(self));
        let i = strain_ratios
            .iter()
            .position(|r| !(r.is_finite() && (min..=max).contains(r)))?;
        let allowed = format!("in [{min:e}, {max:e}] here (the exact theory's domain)");
        Some((DomainInput::StrainRatio(i), allowed))
    }

    /// The parameters of the membrane `params` (its tension ignored: under imposed
    /// projected area the tension is `K_A(s − ε)`) with area modulus `area_modulus`.
    pub fn from_membrane(params: &MembraneParams, area_modulus: f64) -> Self {
        AreaParams {
            bending_rigidity: params.bending_rigidity,
            area_modulus,
            kt: params.kt,
            width: params.width,
            height: params.height,
            boundary: params.boundary,
        }
    }

    /// True area `A₀ = a·b`.
    pub fn area(&self) -> f64 {
        self.width * self.height
    }

    /// The tensionless membrane of [`crate::spectral::membrane`] (ξ = 1) with this
    /// geometry and κ.
    pub fn membrane_params(&self) -> MembraneParams {
        MembraneParams {
            bending_rigidity: self.bending_rigidity,
            tension: 0.0,
            drag: 1.0,
            kt: self.kt,
            width: self.width,
            height: self.height,
            boundary: self.boundary,
        }
    }

    /// `σ_c0 = κ q²_min`, the continuum's smallest buckling tension (module docs).
    pub fn reference_tension(&self) -> f64 {
        self.bending_rigidity * self.membrane_params().min_wavenumber_sq()
    }

    /// `ε_c0 = σ_c0/K_A`.
    pub fn reference_strain(&self) -> f64 {
        self.reference_tension() / self.area_modulus
    }

    /// The global constraint `S = K_A`, `X = A₀`, reference load σ_c0
    /// ([`GlobalConstraint::membrane`]).
    ///
    /// # Errors
    /// As [`GlobalConstraint::validate`].
    pub fn constraint(&self) -> Result<GlobalConstraint> {
        GlobalConstraint::membrane(
            self.area_modulus,
            self.area(),
            self.kt,
            self.reference_tension(),
        )
    }
}

/// One generalized eigenvalue μ of the area pencil `(G, K_b)` (module docs): the
/// compliance `1/buckling tension` of a mode.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AreaCompliance {
    /// Lattice index (wavenumber) along x: `m` of the continuum mode, or the 1D wave
    /// number `k_x` of the mesh block.
    pub m: usize,
    /// Lattice index along y (`|n|` of a periodic mode).
    pub n: usize,
    /// Whether the mode converges to the continuum mode `(m, n)` (always, for the
    /// continuum; the largest μ of an acoustic block of the mesh).
    pub acoustic: bool,
    /// μ (`1/(κq²)` in the continuum).
    pub mu: f64,
}

/// The mode cutoff of the continuum (module docs, *The continuum and its cutoff*).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AreaCutoff {
    /// The acoustic modes of an `nx × ny` mesh: simply supported `1 ≤ m < nx`,
    /// `1 ≤ n < ny`; periodic `2|m| < nx`, `2|n| < ny` (cosine and sine, q ≠ 0).
    Lattice {
        /// `nx`.
        nx: usize,
        /// `ny`.
        ny: usize,
    },
    /// Every mode with `|q| ≤ Q` ([`Membrane::modes_within`]).
    Wavenumber(f64),
}

fn check_count(name: &str, value: usize, min: usize, max: usize) -> Result<()> {
    if (min..=max).contains(&value) {
        Ok(())
    } else {
        Err(Error::invalid(name, value, format!("in [{min}, {max}]")))
    }
}

/// The continuum's compliances `μ = 1/(κq²)` of the modes within `cutoff` (one entry per
/// real mode: the periodic cosine and sine separately), descending.
///
/// # Errors
/// [`Error::InvalidParameter`] for invalid parameters or a cutoff outside its range
/// (lattice indices in `[2, MAX_AREA_CUTOFF_INDEX]`, `[3, …]` periodic, so that the
/// lattice holds a mode; a wavenumber
/// holding at most [`crate::spectral::membrane::MAX_LISTED_MODES`] modes) or holding no
/// mode.
pub fn continuum_compliances(
    params: &AreaParams,
    cutoff: AreaCutoff,
) -> Result<Vec<AreaCompliance>> {
    params.validate()?;
    let kappa = params.bending_rigidity;
    let periodic = params.boundary == MembraneBoundary::Periodic;
    let f = if periodic { 2.0 } else { 1.0 };
    let (ua, ub) = (f * PI / params.width, f * PI / params.height);
    let mu = |m: i64, n: i64| {
        let (qx, qy) = (m as f64 * ua, n as f64 * ub);
        1.0 / (kappa * (qx * qx + qy * qy))
    };
    let mut out = Vec::new();
    match cutoff {
        AreaCutoff::Lattice { nx, ny } => {
            let min = if periodic { 3 } else { 2 };
            check_count("cutoff nx", nx, min, MAX_AREA_CUTOFF_INDEX)?;
            check_count("cutoff ny", ny, min, MAX_AREA_CUTOFF_INDEX)?;
            if periodic {
                let (mx, my) = (((nx - 1) / 2) as i64, ((ny - 1) / 2) as i64);
                for m in 0..=mx {
                    for n in -my..=my {
                        if m > 0 || n > 0 {
                            let c = AreaCompliance {
                                m: m as usize,
                                n: n.unsigned_abs() as usize,
                                acoustic: true,
                                mu: mu(m, n),
                            };
                            out.extend([c, c]);
                        }
                    }
                }
            } else {
                for m in 1..nx {
                    for n in 1..ny {
                        out.push(AreaCompliance {
                            m,
                            n,
                            acoustic: true,
                            mu: mu(m as i64, n as i64),
                        });
                    }
                }
            }
        }
        AreaCutoff::Wavenumber(q) => {
            let mb = Membrane::new(params.membrane_params())?;
            for mode in mb.modes_within(q)? {
                out.push(AreaCompliance {
                    m: mode.m.unsigned_abs() as usize,
                    n: mode.n.unsigned_abs() as usize,
                    acoustic: true,
                    mu: mu(mode.m, mode.n),
                });
            }
        }
    }
    if out.is_empty() {
        return Err(Error::invalid(
            "cutoff",
            format!("{cutoff:?}"),
            "a cutoff that keeps at least one mode",
        ));
    }
    out.sort_by(|a, b| b.mu.total_cmp(&a.mu));
    Ok(out)
}

/// The two axes of an `nx × ny` mesh of `params`.
fn mesh_axes(params: &AreaParams, nx: usize, ny: usize) -> Result<[Axis; 2]> {
    params.validate()?;
    let periodic = params.boundary == MembraneBoundary::Periodic;
    let min = if periodic { 2 } else { 1 };
    check_count("nx", nx, min, MAX_AREA_ELEMENTS)?;
    check_count("ny", ny, min, MAX_AREA_ELEMENTS)?;
    Ok([
        Axis {
            elements: nx,
            length: params.width,
            periodic,
        },
        Axis {
            elements: ny,
            length: params.height,
            periodic,
        },
    ])
}

/// Whether a wave carries height and has a wavenumber the mesh resolves (hinged
/// `1 ≤ k < N`, periodic `2k < N`).
fn resolved(axis: &Axis, wave: &Wave) -> bool {
    wave.has_height()
        && if axis.periodic {
            2 * wave.k < axis.elements
        } else {
            wave.k >= 1 && wave.k < axis.elements
        }
}

/// The μ of the pencil `G_b y = μ K_b y` of one block of waves, ascending (negative
/// round-off of a positive semidefinite `G_b` clamped to 0).
fn block_compliances(kappa: f64, x: &Wave, y: &Wave) -> Result<Vec<f64>> {
    let (sx, d) = (x.size(), x.size() * y.size());
    let mut kb = DMatrix::zeros(d, d);
    let mut gb = DMatrix::zeros(d, d);
    for i in 0..d {
        for j in 0..d {
            let (a, b, a2, b2) = (i % sx, i / sx, j % sx, j / sx);
            let ex = [x.mats[0][a][a2], x.mats[1][a][a2], x.mats[2][a][a2]];
            let ey = [y.mats[0][b][b2], y.mats[1][b][b2], y.mats[2][b][b2]];
            kb[(i, j)] = stiffness_entry(kappa, 0.0, ex, ey);
            gb[(i, j)] = stiffness_entry(0.0, 1.0, ex, ey);
        }
    }
    let (_, a) = symmetric_pencil(&gb, kb, "plate area block")?;
    let mut mu: Vec<f64> = SymmetricEigen::new(a).eigenvalues.iter().copied().collect();
    mu.sort_by(|p, q| p.total_cmp(q));
    let top = mu.last().copied().unwrap_or(0.0);
    for v in mu.iter_mut() {
        if *v < 0.0 && *v >= -1e-12 * top {
            *v = 0.0;
        }
    }
    if let Some(v) = mu.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
        return Err(Error::Numerical {
            routine: "plate area block".into(),
            detail: format!("compliance {v:e}, expected finite and >= 0"),
        });
    }
    Ok(mu)
}

/// Every compliance μ of the uniform `nx × ny` Bogner–Fox–Schmit mesh of `params`, from
/// its exact block form (module docs, *The discrete law*): `4·nx·ny` values (one fewer
/// periodic: the zero mode), descending, labelled by the wave numbers of their block; the
/// largest μ of each acoustic block is marked `acoustic`.
///
/// # Errors
/// [`Error::InvalidParameter`] for invalid parameters or `nx`, `ny` outside
/// `[1, MAX_AREA_ELEMENTS]` (`[2, …]` periodic); [`Error::Numerical`] if a block pencil
/// cannot be solved.
pub fn discrete_compliances(
    params: &AreaParams,
    nx: usize,
    ny: usize,
) -> Result<Vec<AreaCompliance>> {
    let axes = mesh_axes(params, nx, ny)?;
    let mats = [axes[0].assemble()?, axes[1].assemble()?];
    let waves = [
        axis_waves(&axes[0], &mats[0]),
        axis_waves(&axes[1], &mats[1]),
    ];
    let mut out = Vec::with_capacity(4 * nx * ny);
    for x in &waves[0] {
        for y in &waves[1] {
            let translation =
                axes[0].periodic && x.k == 0 && y.k == 0 && x.has_height() && y.has_height();
            if translation {
                continue;
            }
            let acoustic = resolved(&axes[0], x) && resolved(&axes[1], y);
            let mu = block_compliances(params.bending_rigidity, x, y)?;
            let last = mu.len() - 1;
            out.extend(mu.into_iter().enumerate().map(|(i, mu)| AreaCompliance {
                m: x.k,
                n: y.k,
                acoustic: acoustic && i == last,
                mu,
            }));
        }
    }
    out.sort_by(|a, b| b.mu.total_cmp(&a.mu));
    Ok(out)
}

/// The acoustic compliances of a mesh (`discrete`, from [`discrete_compliances`]) whose
/// modes lie within the lattice cutoff `nx × ny` ([`AreaCutoff::Lattice`]): the mesh's
/// approximations of exactly the continuum modes of that cutoff, one for one (same count
/// and labels as [`continuum_compliances`]), so that a theory of these converges to the
/// continuum's at a fixed cutoff as the mesh is refined, at the O(h⁴) of the modes.
pub fn within_lattice(
    params: &AreaParams,
    discrete: &[AreaCompliance],
    nx: usize,
    ny: usize,
) -> Vec<AreaCompliance> {
    let periodic = params.boundary == MembraneBoundary::Periodic;
    discrete
        .iter()
        .filter(|c| {
            c.acoustic
                && if periodic {
                    2 * c.m < nx && 2 * c.n < ny && (c.m > 0 || c.n > 0)
                } else {
                    (1..nx).contains(&c.m) && (1..ny).contains(&c.n)
                }
        })
        .copied()
        .collect()
}

/// One mesh of [`mesh_convergence`].
#[derive(Debug, Clone, PartialEq)]
pub struct MeshConvergenceRow {
    /// Elements per side.
    pub elements: usize,
    /// Modes of the mesh.
    pub modes: usize,
    /// `⟨ΔA⟩/A₀` of the free membrane on the whole mesh.
    pub free_excess_area_ratio: f64,
    /// ⟨σ⟩/σ_c0 of the whole mesh, per strain ratio.
    pub tension_ratio: Vec<f64>,
    /// ⟨σ⟩/σ_c0 of the continuum at the mesh's own lattice cutoff, per strain ratio.
    pub continuum_at_mesh: Vec<f64>,
    /// ⟨σ⟩/σ_c0 of the mesh's modes within the fixed cutoff ([`within_lattice`]).
    pub fixed_cutoff: Vec<f64>,
    /// `fixed_cutoff` minus the continuum at the fixed cutoff: the discretization error.
    pub fixed_error: Vec<f64>,
    /// `log₂` of the ratio of the previous (coarser) mesh's `|fixed_error|` to this one's,
    /// divided by `log₂` of the ratio of element counts: the observed order (`None` on the
    /// first mesh).
    pub fixed_order: Vec<Option<f64>>,
}

/// The tension–strain curve of the membrane under imposed area over meshes of
/// `elements × elements` (ascending, each ≥ the fixed cutoff), at `strain_ratios`
/// (issue #28): the whole mesh's curve, which drifts with the mesh because the thermal
/// excess area grows as the log of the mode cutoff (Helfrich–Servuss: physics, each mesh
/// a different membrane), the continuum at the mesh's own cutoff beside it, and the
/// discretization error separated from that drift: the mesh's modes within a fixed cutoff
/// (the lattice of the first mesh, [`within_lattice`]) against the continuum at that
/// cutoff, with its observed order (4 for the Bogner–Fox–Schmit element's eigenvalues).
/// Returns the continuum at the fixed cutoff and one row per mesh.
///
/// # Errors
/// As [`AreaTheory::discrete`], [`AreaTheory::continuum`] and their tension; invalid
/// parameters for an empty or unsorted mesh list.
pub fn mesh_convergence(
    params: &AreaParams,
    elements: &[usize],
    strain_ratios: &[f64],
) -> Result<(Vec<f64>, Vec<MeshConvergenceRow>)> {
    let Some(&fixed) = elements.first() else {
        return Err(Error::invalid("elements", "[]", "at least one mesh"));
    };
    if elements.windows(2).any(|w| w[1] <= w[0]) {
        return Err(Error::invalid(
            "elements",
            format!("{elements:?}"),
            "strictly ascending",
        ));
    }
    let curve = |theory: &AreaTheory| -> Result<Vec<f64>> {
        strain_ratios
            .iter()
            .map(|&r| theory.tension_ratio(r))
            .collect()
    };
    let cutoff = AreaCutoff::Lattice {
        nx: fixed,
        ny: fixed,
    };
    let continuum_fixed = curve(&AreaTheory::continuum(params, cutoff)?)?;
    let mut rows: Vec<MeshConvergenceRow> = Vec::with_capacity(elements.len());
    for &n in elements {
        let all = discrete_compliances(params, n, n)?;
        let whole = AreaTheory::new(params, area_law(params, &all)?)?;
        let restricted = within_lattice(params, &all, fixed, fixed);
        let fixed_theory = AreaTheory::new(params, area_law(params, &restricted)?)?;
        let continuum_at_mesh = curve(&AreaTheory::continuum(
            params,
            AreaCutoff::Lattice { nx: n, ny: n },
        )?)?;
        let fixed_cutoff = curve(&fixed_theory)?;
        let fixed_error: Vec<f64> = fixed_cutoff
            .iter()
            .zip(&continuum_fixed)
            .map(|(d, c)| d - c)
            .collect();
        let fixed_order = match rows.last() {
            Some(prev) => prev
                .fixed_error
                .iter()
                .zip(&fixed_error)
                .map(|(e0, e1)| {
                    let order =
                        (e0.abs() / e1.abs()).log2() / (n as f64 / prev.elements as f64).log2();
                    order.is_finite().then_some(order)
                })
                .collect(),
            None => vec![None; strain_ratios.len()],
        };
        rows.push(MeshConvergenceRow {
            elements: n,
            modes: all.len(),
            free_excess_area_ratio: whole.free_excess_area_ratio(),
            tension_ratio: curve(&whole)?,
            continuum_at_mesh,
            fixed_cutoff,
            fixed_error,
            fixed_order,
        });
    }
    Ok((continuum_fixed, rows))
}

/// The compliances of the assembled `nx × ny` [`PlateModel`] from the dense generalized
/// eigenproblem: `K_b` the stiffness at σ = 0, `G` the stiffness at κ = 10⁻³⁰⁰, σ = 1
/// (the bending part underflows against G's entries), `K_b` made definite by `z zᵀ` with
/// `z` the periodic zero mode (`Gz = K_bz = 0`, so the spectrum gains one 0, removed);
/// descending. `O(n³)`: a cross-check of [`discrete_compliances`] for small meshes.
///
/// # Errors
/// As [`PlateModel::new`]; [`Error::Numerical`] if the pencil cannot be solved.
pub fn dense_compliances(params: &AreaParams, nx: usize, ny: usize) -> Result<Vec<f64>> {
    params.validate()?;
    let mp = params.membrane_params();
    let bending = PlateModel::new(mp, nx, ny)?;
    let area = PlateModel::new(
        MembraneParams {
            bending_rigidity: 1e-300,
            tension: 1.0,
            ..mp
        },
        nx,
        ny,
    )?;
    let mut kb = bending.stiffness().to_dense();
    let g = area.stiffness().to_dense();
    let zero = bending.zero_mode();
    if let Some(z) = &zero {
        for i in 0..z.len() {
            for j in 0..z.len() {
                kb[(i, j)] += z[i] * z[j];
            }
        }
    }
    let (_, a) = symmetric_pencil(&g, kb, "dense plate area")?;
    let mut mu: Vec<f64> = SymmetricEigen::new(a).eigenvalues.iter().copied().collect();
    mu.sort_by(|p, q| q.total_cmp(p));
    if zero.is_some() {
        // the smallest (the zero mode's 0, to round-off)
        mu.pop();
    }
    Ok(mu)
}

/// The stored-area law of compliances: `c_i = kT μ_i/(2A₀)`, `d = 1`, no tail.
///
/// # Errors
/// As [`StoredLengthLaw::from_weights`].
pub fn area_law(params: &AreaParams, compliances: &[AreaCompliance]) -> Result<StoredLengthLaw> {
    let f = params.kt / (2.0 * params.area());
    StoredLengthLaw::from_weights(compliances.iter().map(|c| f * c.mu).collect(), 1)
}

/// The exact equilibrium tension of a membrane under imposed projected area: a
/// [`CompressionTheory`] of the membrane's [`GlobalConstraint`] and stored-area law,
/// with the membrane's sign (`σ = −F`, positive = tension).
#[derive(Debug, Clone)]
pub struct AreaTheory {
    params: AreaParams,
    theory: CompressionTheory,
}

impl AreaTheory {
    /// The theory of `params` and a stored-area law computed for them ([`area_law`]).
    ///
    /// # Errors
    /// As [`AreaParams::validate`] and [`CompressionTheory::with_constraint`].
    pub fn new(params: &AreaParams, law: StoredLengthLaw) -> Result<Self> {
        params.validate()?;
        Ok(AreaTheory {
            params: *params,
            theory: CompressionTheory::with_constraint(params.constraint()?, law)?,
        })
    }

    /// The exact discrete theory of the uniform `nx × ny` mesh ([`discrete_compliances`]).
    ///
    /// # Errors
    /// As [`discrete_compliances`].
    pub fn discrete(params: &AreaParams, nx: usize, ny: usize) -> Result<Self> {
        Self::new(
            params,
            area_law(params, &discrete_compliances(params, nx, ny)?)?,
        )
    }

    /// The continuum within `cutoff` ([`continuum_compliances`]).
    ///
    /// # Errors
    /// As [`continuum_compliances`].
    pub fn continuum(params: &AreaParams, cutoff: AreaCutoff) -> Result<Self> {
        Self::new(
            params,
            area_law(params, &continuum_compliances(params, cutoff)?)?,
        )
    }

    /// The same theory with other quadrature settings.
    ///
    /// # Errors
    /// As [`CompressionTheory::with_options`].
    pub fn with_options(mut self, options: QuadratureOptions) -> Result<Self> {
        self.theory = self.theory.with_options(options)?;
        Ok(self)
    }

    /// The parameters.
    pub fn params(&self) -> &AreaParams {
        &self.params
    }

    /// The underlying theory (its forces are `F = −σ`).
    pub fn theory(&self) -> &CompressionTheory {
        &self.theory
    }

    /// The law's `⟨s⟩₀ = ⟨ΔA⟩₀/A₀` of the free (bending-only) membrane.
    pub fn free_excess_area_ratio(&self) -> f64 {
        self.theory.law().mean()
    }

    /// The exact mean tension `⟨σ⟩ = K_A(⟨s⟩_ε − ε) = −⟨F⟩` at imposed strain
    /// `ε = 1 − A_p/A₀`.
    ///
    /// # Errors
    /// As [`CompressionTheory::mean_force`].
    pub fn mean_tension(&self, strain: f64) -> Result<f64> {
        Ok(-self.theory.mean_force(strain)?)
    }

    /// `⟨σ⟩/σ_c0` at `ε = strain_ratio·ε_c0`.
    ///
    /// # Errors
    /// As [`CompressionTheory::force_ratio`].
    pub fn tension_ratio(&self, strain_ratio: f64) -> Result<f64> {
        Ok(-self.theory.force_ratio(strain_ratio)?)
    }

    /// The Gaussian mean-field tension `−(kT/A₀)η̂` (for comparison only; never below the
    /// law's buckling tension `−1/μ_max`).
    ///
    /// # Errors
    /// As [`CompressionTheory::mean_field_force`].
    pub fn mean_field_tension(&self, strain: f64) -> Result<f64> {
        Ok(-self.theory.mean_field_force(strain)?)
    }

    /// The exact variance of σ (that of F).
    ///
    /// # Errors
    /// As [`CompressionTheory::force_variance`].
    pub fn tension_variance(&self, strain: f64) -> Result<f64> {
        self.theory.force_variance(strain)
    }

    /// The exact distribution of `F = −σ` at strain ε: `P(σ ≤ x) = 1 − cdf(−x)`.
    ///
    /// # Errors
    /// As [`CompressionTheory::force_distribution`].
    pub fn force_distribution(&self, strain: f64) -> Result<ForceDistribution> {
        self.theory.force_distribution(strain)
    }
}
