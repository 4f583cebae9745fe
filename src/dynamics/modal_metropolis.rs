//! `metropolis-crank-nicolson` for the von Kármán filament on a uniform hinged mesh, in
//! the paired modal form ([`PairedModes`]): the same Markov chain as the banded
//! [`super::nonlinear::NonlinearIntegrator`] in modal coordinates, at O(n) per step with
//! 2×2 solves instead of a banded factorization. The same chain serves the membrane under
//! imposed projected area ([`AreaMembrane`], issue #28) in the separated modes of the
//! uniform plate ([`PlateModes`]), whose area matrix couples at most 4 modes
//! ([`PlateModes::geometric_blocks`]): the energy has the same form ([`GlobalStrain`]:
//! `EA → K_A`, `L → A₀`, `F = −σ`), and the blocks are solved by a k × k Cholesky
//! factorization, k ≤ 4.
//!
//! With `w = Φ a` (`ΦᵀCΦ = I`, `ΦᵀKΦ = Λ`, `B = ΦᵀGΦ` block-diagonal), the energy of
//! [`CompressedFilament`] is `U(a) = ½ Σ λ_i a_i² + (EA·L/2)(s − ε)²`, `s = Σ_c a_cᵀB a_c/(2L)`,
//! `F = EA(ε − s)`, and the nodal proposal `(C + ½ΔtH_w) w' = (C − ½ΔtH_w) w +
//! sqrt(2kTΔt) ζ`, `ζ ~ N(0, C)`, `H_w = K − F(w) G`, becomes per component
//!
//! ```text
//! A_a a' = (2I − A_a) a + sqrt(2kTΔt) z,   A_a = I + ½Δt(Λ − F(a) B),   z = Φᵀζ ~ N(0, I),
//! ```
//!
//! block by block. It is accepted with probability `min(1, α)`,
//! `ln α = −(U(a') − U(a))/kT + d (ln det A_{a'} − ln det A_a) − ½|z_r|² + ½|z|²`
//! (d transverse components, `z_r = (A_{a'} a − (2I − A_{a'}) a')/sqrt(2kTΔt)` the noise of
//! the reverse move): the Jacobian of `w = Φ a` cancels in the ratio, so this is exactly
//! the acceptance of the nodal scheme and the chain is exact at any Δt. Proposals from or
//! into a state whose `A_a` is not positive definite are rejected.

mod drift;
mod independence;
mod lanes;

use super::driver::Trajectory;
use crate::error::{Error, Result};
use crate::fem::area::AreaMembrane;
use crate::fem::beam::BeamModel;
use crate::fem::paired::PairedModes;
use crate::fem::plate_modes::PlateModes;
use crate::fem::vonkarman::{CompressedFilament, GlobalStrain};
use crate::rng::TrajectoryRng;
use rand::RngExt;
use rand_distr::StandardNormal;

/// The block determinants are multiplied, and the logarithm of the running product taken
/// only when it leaves this range (a block determinant is at most `(1 + ½Δtλ_max)²`, far
/// below 1e58 for any accepted filament and step, so the product never overflows): one
/// logarithm per evaluation instead of one per block.
const PRODUCT_RANGE: (f64, f64) = (1e-250, 1e250);

/// One evaluated state of the chain: the modal coordinates (component-major), `B a`, the
/// energy, the compressive force and the inverse blocks of `A_a` with `ln det A_a`
/// (`None` if `A_a` is not positive definite).
#[derive(Debug, Clone)]
struct Evaluation {
    a: Vec<f64>,
    g: Vec<f64>,
    energy: f64,
    force: f64,
    /// `aᵀΛa` (all components): the bending part of `2U`.
    bend: f64,
    /// `aᵀBa = 2ℓs` (all components).
    two_l_s: f64,
    /// The force the proposal kernel uses: `force` (× the injected fault's factor,
    /// [`ModalMetropolis::with_proposal_force_factor`]).
    kernel_force: f64,
    /// `[inv00, inv01, inv11]` of each 2×2 block of `A_a`, then `[1/a, 0, 0]` per 1×1 block.
    inverse: Vec<[f64; 3]>,
    /// The inverse of each general block of `A_a` (row-major, stride 4).
    group_inverse: Vec<[f64; 16]>,
    /// The determinant of each general block of `A_a`, NaN unless positive definite
    /// ([`Proposal::CrankNicolson`]).
    group_det: Vec<f64>,
    /// `d · ln det A_a`, `None` if `A_a` is not positive definite. For
    /// [`Proposal::OrnsteinUhlenbeck`], `−½ ln det Σ_a` of the proposal covariance `Σ_a`
    /// (the same role in the Hastings ratio: `ln q(a → ·)` is this minus `½|noise|²`).
    log_det: Option<f64>,
    /// [`Proposal::Newton`]: `D_a⁻¹ g` (`D_a` the block part of `A_a`, `g = B a`).
    dg: Vec<f64>,
    /// [`Proposal::Newton`]: `1 + c gᵀD_a⁻¹g`, `c = ½Δt S/ℓ` (the Sherman–Morrison
    /// denominator).
    sm_denominator: f64,
    /// [`Proposal::OrnsteinUhlenbeck`]: the orthonormal eigenvectors of each group's
    /// `H = Λ_b − F B_b` (column `j` of row-major stride 4 is eigenvector `j`).
    vectors: Vec<[f64; 16]>,
    /// [`Proposal::OrnsteinUhlenbeck`]: `e^{−Δt h_j}` per coordinate (eigenvalue `h_j` of
    /// its group's `H`, in the group's eigenvector order).
    decay: Vec<f64>,
    /// [`Proposal::OrnsteinUhlenbeck`]: the standard deviation
    /// `sqrt(kT (1 − e^{−2Δt h_j})/h_j)` per coordinate.
    spread: Vec<f64>,
}

/// The proposal of a [`ModalMetropolis`] chain; every one is accepted with its exact
/// Metropolis–Hastings ratio, so the chain samples the same law at any Δt and the
/// proposal changes only the cost (acceptance and autocorrelation).
///
/// With `U(a) = ½ aᵀΛa + (Sℓ/2)(s − ε)²`, `s = aᵀBa/(2ℓ)`, `F = S(ε − s)`, `g = B a`:
/// `∇U = (Λ − F B) a` and the Hessian `∇²U = Λ − F B + (S/ℓ) g gᵀ` (from `∇F = −S g/ℓ`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Proposal {
    /// `A_a a' = (2I − A_a) a + sqrt(2kTΔt) z`, `A_a = I + ½Δt(Λ − F B)`: the block part of
    /// the Hessian only (see the module docs). The default, and the filament's.
    #[default]
    CrankNicolson,
    /// Newton-preconditioned Crank–Nicolson with the whole Hessian, rank-one term included:
    /// `A_a a' = A_a a − Δt ∇U(a) + sqrt(2kTΔt) z`, `A_a = D_a + c g gᵀ`,
    /// `D_a = I + ½Δt(Λ − F B)`, `c = ½Δt S/ℓ`, solved by Sherman–Morrison on the block
    /// inverses. The proposal is `N(a − Δt A_a⁻¹∇U, 2kTΔt A_a⁻²)`, so
    /// `ln q(a → a') = ln det A_a − ½|z|² + const`, and the reverse noise is
    /// `z_r = (A_{a'}(a − a') + Δt ∇U(a'))/sqrt(2kTΔt)`; without the rank-one term this is
    /// [`Proposal::CrankNicolson`]. `A_a` may be positive definite where `D_a` is not (one
    /// negative eigenvalue of `D_a` lifted by the rank-one term). Membrane chains only.
    Newton,
    /// The exact Ornstein–Uhlenbeck step of the linearization at the current force, block
    /// by block: with `H = Λ − F(a) B` (so `∇U(a) = H a` exactly),
    /// `a' = e^{−ΔtH} a + ξ`, `ξ ~ N(0, kT H⁻¹(I − e^{−2ΔtH}))`, from the eigenvectors of
    /// each group's `H` (Jacobi, k ≤ 4). Defined for indefinite `H` too (the variance
    /// `kT(1 − e^{−2Δt h})/h` is positive for every real `h`). Membrane chains only.
    OrnsteinUhlenbeck,
}

/// A general block of `k ≤ 4` modal coordinates coupled by `B`.
#[derive(Debug, Clone)]
struct Group {
    k: usize,
    rates: [f64; 4],
    /// `B` row-major, stride 4.
    b: [f64; 16],
}

impl Group {
    /// `Λ_b − F B_b` (row-major, stride 4): the block's Hessian of the linearization at
    /// the force `f`.
    fn linearized(&self, f: f64) -> [f64; 16] {
        let k = self.k;
        let mut h = [0.0; 16];
        for r in 0..k {
            for col in 0..k {
                h[4 * r + col] = -f * self.b[4 * r + col];
            }
            h[5 * r] += self.rates[r];
        }
        h
    }

    /// `A_b = I + h(Λ_b − F B_b)` at the kernel force `f`, `h = ½Δt` (row-major, stride
    /// 4): the block of the Crank–Nicolson and Newton proposals' matrix `A_a`.
    fn proposal_block(&self, f: f64, h: f64) -> [f64; 16] {
        let mut a = [0.0; 16];
        for r in 0..self.k {
            for c in 0..self.k {
                a[4 * r + c] = -h * f * self.b[4 * r + c];
            }
            a[5 * r] += 1.0 + h * self.rates[r];
        }
        a
    }
}

/// What the modal coordinates are coordinates of (for the nodal state).
#[derive(Debug, Clone)]
enum Basis<'m> {
    /// The filament's paired modes (coordinates in their order).
    Beam(&'m BeamModel, &'m PairedModes),
    /// The plate's modes: the mode index of each coordinate.
    Plate(&'m PlateModes, Vec<usize>),
}

/// The Metropolis-adjusted Crank–Nicolson chain of one trajectory in modal coordinates
/// (see the module docs); it owns its state.
#[derive(Debug, Clone)]
pub struct ModalMetropolis<'m> {
    constraint: GlobalStrain,
    basis: Basis<'m>,
    /// Per 2×2 block: `[λ0, λ1, b00, b01, b11]`.
    pairs: Vec<[f64; 5]>,
    /// Per 1×1 block: `[λ, b]`.
    singles: Vec<[f64; 2]>,
    /// General blocks (the plate), after the pairs and singles.
    groups: Vec<Group>,
    /// The indices of the general blocks of each size `k = 1 … 4` (entry `k − 1`), in
    /// order: inverted [`lanes::BLOCK_LANES`] at a time.
    groups_by_size: [Vec<usize>; 4],
    /// The rates in modal-coordinate order.
    rates: Vec<f64>,
    components: usize,
    half_dt: f64,
    scale: f64,
    kt: f64,
    current: Evaluation,
    proposal: Evaluation,
    z: Vec<f64>,
    /// `Some(θ)`: the θ-scheme with the constraint force explicit instead of the
    /// Metropolis chain ([`Self::with_theta`]).
    theta: Option<f64>,
    /// The factor on the force the proposal kernel uses (1; an injected fault otherwise,
    /// [`Self::with_proposal_force_factor`]).
    proposal_force_factor: f64,
    /// Proposals made.
    pub proposed: u64,
    /// Accepted proposals.
    pub accepted: u64,
    /// The proposal ([`Self::with_proposal`]).
    kind: Proposal,
    /// [`Proposal::Newton`]: per coordinate, whether its part of `g` enters the rank-one
    /// term ([`Self::with_rank_one_limit`]; empty: all do).
    rank_one: Vec<bool>,
    /// Whether every step is followed by a radial move ([`Self::with_radial_moves`]).
    radial: bool,
    /// Radial moves accepted.
    pub radial_accepted: u64,
    /// `Some`: every step an independence move instead ([`Self::with_independence_moves`]).
    independence: Option<independence::Independence>,
    /// Test hook: the log-determinant term of the new proposals' Hastings ratio dropped
    /// (a deliberately wrong chain, which the exactness test must catch); for the radial
    /// move, its Jacobian term.
    #[cfg(test)]
    drop_log_det: bool,
}

impl<'m> ModalMetropolis<'m> {
    /// The chain for `model` (whose beam `modes` was built from) with step `dt`, started at
    /// an exact sample of the free bending equilibrium, `a_i ~ N(0, kT/λ_i)` per component
    /// (drawn from `rng`, component by component).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a non-positive or non-finite `dt`, or if `modes` does
    /// not have the model's number of DOFs.
    pub fn new(
        model: &'m CompressedFilament,
        modes: &'m PairedModes,
        dt: f64,
        rng: &mut TrajectoryRng,
    ) -> Result<Self> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::invalid("dt", dt, "finite and > 0"));
        }
        let n = modes.n_modes();
        if n != model.beam().n_dofs() {
            return Err(Error::invalid(
                "paired modes",
                n,
                format!("the model's {} DOFs", model.beam().n_dofs()),
            ));
        }
        let nc = model.components();
        let pairs: Vec<[f64; 5]> = modes
            .pairs()
            .iter()
            .map(|b| {
                [
                    b.rates[0],
                    b.rates[1],
                    b.geometric[0],
                    b.geometric[1],
                    b.geometric[2],
                ]
            })
            .collect();
        let singles: Vec<[f64; 2]> = modes
            .singles()
            .iter()
            .map(|b| [b.rates[0], b.geometric[0]])
            .collect();
        let basis = Basis::Beam(model.beam(), modes);
        let parts = (pairs, singles, Vec::new(), modes.rates());
        Self::start(model.global_strain(), basis, parts, nc, dt, rng)
    }

    /// The chain for the membrane `model` under imposed projected area, in the modes
    /// `modes` of its plate (built from `model.plate()`), with step `dt`, started at an
    /// exact sample of the free bending equilibrium `a_i ~ N(0, kT/λ_i)` (the periodic zero
    /// mode left out). The coordinates are grouped by [`PlateModes::geometric_blocks`].
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a non-positive or non-finite `dt`, or if `modes` does
    /// not have the plate's number of DOFs.
    pub fn for_membrane(
        model: &AreaMembrane,
        modes: &'m PlateModes,
        dt: f64,
        rng: &mut TrajectoryRng,
    ) -> Result<Self> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::invalid("dt", dt, "finite and > 0"));
        }
        if modes.n_modes() != model.plate().n_dofs() {
            return Err(Error::invalid(
                "plate modes",
                modes.n_modes(),
                format!("the plate's {} DOFs", model.plate().n_dofs()),
            ));
        }
        let zero = modes.zero_mode();
        let (mut order, mut groups, mut rates) = (Vec::new(), Vec::new(), Vec::new());
        for block in modes.geometric_blocks() {
            // the zero mode (no rate, no area; its group's other modes are uncoupled from it)
            let kb = block.modes.len();
            let kept: Vec<usize> = (0..kb).filter(|&r| Some(block.modes[r]) != zero).collect();
            if kept.is_empty() {
                continue;
            }
            let mut g = Group {
                k: kept.len(),
                rates: [0.0; 4],
                b: [0.0; 16],
            };
            for (r, &br) in kept.iter().enumerate() {
                let i = block.modes[br];
                g.rates[r] = modes.modes()[i].rate;
                rates.push(g.rates[r]);
                order.push(i);
                for (c, &bc) in kept.iter().enumerate() {
                    g.b[4 * r + c] = model.area_scale() * block.matrix[br * kb + bc];
                }
            }
            groups.push(g);
        }
        let basis = Basis::Plate(modes, order);
        let parts = (Vec::new(), Vec::new(), groups, rates);
        Self::start(model.global_strain(), basis, parts, 1, dt, rng)
    }

    /// The chain from its blocks (pairs, singles, groups, the rates in coordinate order),
    /// started at an exact sample of the free bending equilibrium (component by
    /// component), moved onto the buckled branch above the buckling load.
    #[allow(clippy::type_complexity)]
    fn start(
        constraint: GlobalStrain,
        basis: Basis<'m>,
        (pairs, singles, groups, rates): (Vec<[f64; 5]>, Vec<[f64; 2]>, Vec<Group>, Vec<f64>),
        nc: usize,
        dt: f64,
        rng: &mut TrajectoryRng,
    ) -> Result<Self> {
        let kt = constraint.constraint.kt;
        let n = rates.len();
        let a: Vec<f64> = (0..nc)
            .flat_map(|_| rates.iter())
            .map(|&lam| (kt / lam).sqrt() * rng.sample::<f64, _>(StandardNormal))
            .collect();
        let blocks = pairs.len() + singles.len();
        let empty = Evaluation {
            a: vec![0.0; nc * n],
            g: vec![0.0; nc * n],
            energy: 0.0,
            force: 0.0,
            bend: 0.0,
            two_l_s: 0.0,
            kernel_force: 0.0,
            inverse: vec![[0.0; 3]; blocks],
            group_inverse: vec![[0.0; 16]; groups.len()],
            group_det: vec![0.0; groups.len()],
            log_det: None,
            dg: Vec::new(),
            sm_denominator: 1.0,
            vectors: Vec::new(),
            decay: Vec::new(),
            spread: Vec::new(),
        };
        let mut chain = ModalMetropolis {
            constraint,
            basis,
            pairs,
            singles,
            groups_by_size: std::array::from_fn(|s| {
                (0..groups.len())
                    .filter(|&g| groups[g].k == s + 1)
                    .collect()
            }),
            groups,
            rates,
            components: nc,
            half_dt: 0.5 * dt,
            scale: (2.0 * kt * dt).sqrt(),
            kt,
            current: Evaluation { a, ..empty.clone() },
            proposal: empty,
            z: vec![0.0; nc * n],
            theta: None,
            proposal_force_factor: 1.0,
            proposed: 0,
            accepted: 0,
            kind: Proposal::CrankNicolson,
            rank_one: Vec::new(),
            radial: false,
            radial_accepted: 0,
            independence: None,
            #[cfg(test)]
            drop_log_det: false,
        };
        let mut cur = std::mem::take(&mut chain.current);
        chain.evaluate(&mut cur);
        if cur.force > constraint.constraint.reference_load
            && !(chain.pairs.is_empty() && chain.groups.is_empty())
        {
            chain.start_buckled(&mut cur);
            chain.evaluate(&mut cur);
        }
        chain.current = cur;
        Ok(chain)
    }

    /// Above the Euler strain, moves the start onto the buckled branch: the first
    /// coordinate of the k = 1 block (the lowest mode, of component 0) is enlarged so that
    /// the stored length reaches `ε − F_c0/EA`, i.e. `F ≈ F_c0` (only that coordinate
    /// changes; the burn-in equilibrates the rest).
    ///
    /// Why: from the free bending equilibrium, `F ≈ EA·ε` can exceed the buckling loads
    /// of several modes by far, and then `A_a = I + ½Δt(Λ − F B)` is not positive definite
    /// at a large Δt: no proposal could be made and the chain would never move. In
    /// equilibrium F stays near F_c0 above the Euler strain.
    ///
    /// The membrane's chain does the same with the first coordinate of its slowest block
    /// (`b01 x1` then stands for `Σ_{j>0} b0j x_j` over the block).
    fn start_buckled(&self, e: &mut Evaluation) {
        let (p, strain) = (&self.constraint.constraint, self.constraint.strain);
        let target_two_l_s = 2.0 * p.measure * (strain - p.reference_load / p.stiffness);
        let two_l_s = 2.0 * p.measure * (strain - e.force / p.stiffness);
        let (i0, b00, b01, x1) = match self.pairs.first() {
            Some(&[_, _, b00, b01, _]) => (0, b00, b01, e.a[1]),
            None => {
                // the slowest block: groups follow the (empty) pairs and singles
                let i0 = self.singles.len();
                let g = &self.groups[0];
                let cross: f64 = (1..g.k).map(|j| g.b[j] * e.a[i0 + j]).sum();
                (i0, g.b[0], 1.0, cross)
            }
        };
        let x0 = e.a[i0];
        // two_l_s(x0') − two_l_s(x0) = b00 (x0'² − x0²) + 2 b01 x1 (x0' − x0): solve for x0'.
        let c = two_l_s - b00 * x0 * x0 - 2.0 * b01 * x1 * x0 - target_two_l_s;
        let disc = (b01 * x1).powi(2) - b00 * c;
        if b00 > 0.0 && disc > 0.0 {
            let root = disc.sqrt();
            let (r1, r2) = ((-b01 * x1 + root) / b00, (-b01 * x1 - root) / b00);
            e.a[i0] = if x0 >= 0.0 { r1.max(r2) } else { r1.min(r2) };
        }
    }

    /// Changes the time step to `dt` (the chain's state is kept: its law is exact at any
    /// Δt, so a burn-in at a small step may precede sampling at a large one).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for a non-positive or non-finite `dt`.
    pub fn set_dt(&mut self, dt: f64) -> Result<()> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::invalid("dt", dt, "finite and > 0"));
        }
        self.half_dt = 0.5 * dt;
        self.scale = (2.0 * self.kt * dt).sqrt();
        let mut cur = std::mem::take(&mut self.current);
        self.evaluate(&mut cur);
        self.current = cur;
        Ok(())
    }

    /// An injected fault ([`crate::fault`]): the proposal kernel (and a θ-scheme's explicit
    /// force) uses the constraint force × `factor`, the energy and the acceptance the true
    /// one. The Metropolis chain stays exact (the Hastings ratio uses the same kernel), so
    /// only its dynamics are wrong: what [`Self::drift_residual`] sees (issue #30).
    #[cfg(any(test, feature = "faults"))]
    pub fn with_proposal_force_factor(mut self, factor: f64) -> Self {
        self.proposal_force_factor = factor;
        let mut cur = std::mem::take(&mut self.current);
        self.evaluate(&mut cur);
        self.current = cur;
        self
    }

    /// The same state stepped by the θ-scheme with the constraint force explicit,
    ///
    /// ```text
    /// (I + θΔtΛ) a' = (I − (1−θ)ΔtΛ) a + Δt F(a) B a + sqrt(2kTΔt) z,
    /// ```
    ///
    /// the nodal scheme `(C + θΔtK) x' = (C − (1−θ)ΔtK) x + Δt F(x) G x + sqrt(2kTΔt) ζ`
    /// of [`super::nonlinear`] in modal coordinates (θ = 0 is the paper's explicit scheme).
    /// Not exact: its stationary law is biased by O(Δt) through the explicit force, and
    /// θ = 0 is unstable above `Δt = 2/λ_max`. Every step counts as accepted.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless `0 ≤ θ ≤ 1`.
    pub fn with_theta(mut self, theta: f64) -> Result<Self> {
        if !(0.0..=1.0).contains(&theta) {
            return Err(Error::invalid("theta", theta, "in [0, 1]"));
        }
        self.theta = Some(theta);
        Ok(self)
    }

    /// The same chain with proposal `kind` ([`Proposal`]); the current state is kept (and
    /// re-evaluated for the new proposal).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] for [`Proposal::Newton`] or
    /// [`Proposal::OrnsteinUhlenbeck`] on a filament chain (membrane chains only: one
    /// component, general blocks).
    pub fn with_proposal(mut self, kind: Proposal) -> Result<Self> {
        let membrane = self.pairs.is_empty() && self.singles.is_empty() && self.components == 1;
        if kind != Proposal::CrankNicolson && !membrane {
            return Err(Error::invalid(
                "proposal",
                format!("{kind:?}"),
                "CrankNicolson for a filament chain (the others are for the membrane)",
            ));
        }
        self.kind = kind;
        let n = self.n();
        for e in [&mut self.current, &mut self.proposal] {
            e.dg = vec![0.0; n];
            e.decay = vec![0.0; n];
            e.spread = vec![0.0; n];
            e.vectors = vec![[0.0; 16]; self.groups.len()];
        }
        let mut cur = std::mem::take(&mut self.current);
        self.evaluate(&mut cur);
        self.current = cur;
        Ok(self)
    }

    /// [`Proposal::Newton`] with the rank-one term restricted to the slow blocks: `g` is
    /// replaced in `A_a = D_a + c g gᵀ` by its part on the groups whose slowest rate is at
    /// most `max_rate`. Any positive definite `A_a` gives an exact chain with the same
    /// Hastings ratio (`∇U` stays the whole gradient); this one leaves the fast modes'
    /// proposal as Crank–Nicolson's, whose many entropic contributions to `gᵀ∇U` the full
    /// rank-one term turns into a systematic pull on the excess area (acceptance ≈ 0 on a
    /// 16 × 16 mesh). The current state is re-evaluated.
    pub fn with_rank_one_limit(mut self, max_rate: f64) -> Self {
        self.rank_one = self
            .groups
            .iter()
            .flat_map(|grp| {
                let slowest = grp.rates[..grp.k]
                    .iter()
                    .copied()
                    .fold(f64::INFINITY, f64::min);
                std::iter::repeat_n(slowest <= max_rate, grp.k)
            })
            .collect();
        let mut cur = std::mem::take(&mut self.current);
        self.evaluate(&mut cur);
        self.current = cur;
        self
    }

    /// Every step followed by a radial move: a Metropolis-within-Gibbs update of the
    /// squared radius `t = |a|²` at fixed direction `u = a/|a|` (all N coordinates of all
    /// components), the one direction in which the global constraint acts (`s ∝ t`). In
    /// polar coordinates the target's conditional law of `x = ln t` given `u` is
    /// `p(x) ∝ e^{(N/2)x − U(e^x u)/kT}` (the Jacobian `t^{N/2−1}` and `dt = t dx`), with
    /// `U(τa) = ½τ aᵀΛa + (Sℓ/2)(τs − ε)²` for a scale `τ` of `|a|²` — a Gamma law in `τ`
    /// times a Gaussian, log-concave in `x`. The proposal is its Laplace approximation
    /// `N(x*, 1/(N/2 + Aτ*²))` (mode `x* = ln τ*`, `Aτ*² + Bτ* − N/2 = 0`,
    /// `A = Sℓs²/kT`, `B = (½aᵀΛa − Sℓsε)/kT`), which depends on `u` only, so the move is an
    /// exact independence Metropolis–Hastings update of `x` given `u` (accepted with
    /// `p(x')q(x)/(p(x)q(x'))`), and the chain keeps the same law. A move into a state
    /// whose `A_a` is not positive definite is rejected, as the step's proposals are.
    /// It refreshes most of the variance of the tension in one move: at N ≈ 10³ the Gamma
    /// factor alone spreads `s` by `√(2/N)` ≈ 4 %. Draws one normal and one uniform per
    /// step after the step's own.
    pub fn with_radial_moves(mut self) -> Self {
        self.radial = true;
        self
    }

    /// The radial move of [`Self::with_radial_moves`] from `self.current`.
    fn radial_move(&mut self, rng: &mut TrajectoryRng) {
        let z: f64 = rng.sample(StandardNormal);
        let uniform: f64 = rng.random();
        let cur = &self.current;
        let half_n = self.half_dimension();
        let (q, two_l_s, kt) = (cur.bend, cur.two_l_s, self.kt);
        if !(q > 0.0 && two_l_s.is_finite() && cur.energy.is_finite()) {
            return;
        }
        let p = &self.constraint;
        let s = p.excess(two_l_s);
        let Some((x_star, var)) = self.radial_laplace(q, two_l_s) else {
            return;
        };
        #[cfg(test)]
        let jacobian = if self.drop_log_det { 0.0 } else { half_n };
        #[cfg(not(test))]
        let jacobian = half_n;
        let log_target = |x: f64| {
            let tau = x.exp();
            jacobian * x - (0.5 * tau * q + p.energy(tau * s)) / kt
        };
        let log_q = |x: f64| -0.5 * (x - x_star) * (x - x_star) / var;
        let x_new = x_star + var.sqrt() * z;
        let log_alpha = log_target(x_new) - log_target(0.0) + log_q(0.0) - log_q(x_new);
        if !(log_alpha >= 0.0 || uniform < log_alpha.exp()) {
            return;
        }
        let factor = (0.5 * x_new).exp();
        let mut prop = std::mem::take(&mut self.proposal);
        prop.a.clear();
        prop.a.extend(self.current.a.iter().map(|v| v * factor));
        self.evaluate(&mut prop);
        if prop.log_det.is_some() && prop.energy.is_finite() {
            std::mem::swap(&mut self.current, &mut prop);
            self.radial_accepted += 1;
        }
        self.proposal = prop;
    }

    /// The chain's proposal.
    pub fn proposal_kind(&self) -> Proposal {
        self.kind
    }

    /// One θ-step (see [`Self::with_theta`]) from `self.current` with noise `self.z`.
    fn theta_step(&mut self, theta: f64) {
        let dt = 2.0 * self.half_dt;
        let cur = &self.current;
        let f = cur.kernel_force;
        let n = self.n();
        let next = &mut self.proposal.a;
        for (c, out) in next.chunks_exact_mut(n).enumerate() {
            let (a, g, z) = (
                &cur.a[c * n..][..n],
                &cur.g[c * n..][..n],
                &self.z[c * n..][..n],
            );
            for (i, o) in out.iter_mut().enumerate() {
                let lam = self.rates[i];
                *o = ((1.0 - (1.0 - theta) * dt * lam) * a[i] + dt * f * g[i] + self.scale * z[i])
                    / (1.0 + theta * dt * lam);
            }
        }
        let mut prop = std::mem::take(&mut self.proposal);
        self.evaluate(&mut prop);
        self.proposal = prop;
        std::mem::swap(&mut self.current, &mut self.proposal);
        self.accepted += 1;
    }

    /// Number of modal coordinates per component.
    fn n(&self) -> usize {
        self.rates.len()
    }

    /// Evaluates `e.a` into `e` (see [`Evaluation`]): the state, then the factorization
    /// the chain's [`Proposal`] needs.
    fn evaluate(&self, e: &mut Evaluation) {
        self.evaluate_state(e);
        match self.kind {
            Proposal::CrankNicolson => self.factor_crank_nicolson(e),
            Proposal::Newton => self.factor_newton(e),
            Proposal::OrnsteinUhlenbeck => self.factor_ornstein_uhlenbeck(e),
        }
    }

    /// `B a`, the energy and the force of `e.a` into `e`.
    fn evaluate_state(&self, e: &mut Evaluation) {
        let n = self.n();
        let np = 2 * self.pairs.len();
        let (mut two_l_s, mut bend) = (0.0, 0.0);
        for (a, g) in e.a.chunks_exact(n).zip(e.g.chunks_exact_mut(n)) {
            let (ap, as_) = a.split_at(np);
            let (gp, gs) = g.split_at_mut(np);
            for ((x, y), blk) in ap
                .chunks_exact(2)
                .zip(gp.chunks_exact_mut(2))
                .zip(&self.pairs)
            {
                let [l0, l1, b00, b01, b11] = *blk;
                let (g0, g1) = (b00 * x[0] + b01 * x[1], b01 * x[0] + b11 * x[1]);
                y[0] = g0;
                y[1] = g1;
                two_l_s += x[0] * g0 + x[1] * g1;
                bend += l0 * x[0] * x[0] + l1 * x[1] * x[1];
            }
            let ns = self.singles.len();
            for ((x, y), blk) in as_.iter().zip(gs.iter_mut()).zip(&self.singles) {
                let g0 = blk[1] * x;
                *y = g0;
                two_l_s += x * g0;
                bend += blk[0] * x * x;
            }
            let (mut xg, mut yg) = (&as_[ns..], &mut gs[ns..]);
            for grp in &self.groups {
                let k = grp.k;
                let (x, xr) = xg.split_at(k);
                let (y, yr) = std::mem::take(&mut yg).split_at_mut(k);
                for r in 0..k {
                    let row = &grp.b[4 * r..4 * r + k];
                    y[r] = row.iter().zip(x).map(|(b, v)| b * v).sum();
                    two_l_s += x[r] * y[r];
                    bend += grp.rates[r] * x[r] * x[r];
                }
                (xg, yg) = (xr, yr);
            }
        }
        let p = &self.constraint;
        let s = p.excess(two_l_s);
        let f = p.force(s);
        e.force = f;
        e.kernel_force = f * self.proposal_force_factor;
        e.energy = 0.5 * bend + p.energy(s);
        e.bend = bend;
        e.two_l_s = two_l_s;
    }

    /// The inverse blocks of `A_a = I + ½Δt(Λ − F B)` and `d · ln det A_a` into `e`
    /// (`log_det` `None` unless positive definite).
    fn factor_crank_nicolson(&self, e: &mut Evaluation) {
        let f = e.kernel_force;
        let h = self.half_dt;
        let (mut ok, mut log_det, mut prod) = (true, 0.0, 1.0);
        let (ip, is) = e.inverse.split_at_mut(self.pairs.len());
        for (inv, blk) in ip.iter_mut().zip(&self.pairs) {
            let [l0, l1, b00, b01, b11] = *blk;
            let a00 = 1.0 + h * (l0 - f * b00);
            let a01 = -h * f * b01;
            let a11 = 1.0 + h * (l1 - f * b11);
            let det = a00 * a11 - a01 * a01;
            ok &= a00 > 0.0 && det > 0.0;
            let r = 1.0 / det;
            *inv = [a11 * r, -a01 * r, a00 * r];
            prod *= det;
            if !(PRODUCT_RANGE.0..PRODUCT_RANGE.1).contains(&prod) {
                log_det += prod.ln();
                prod = 1.0;
            }
        }
        for (inv, blk) in is.iter_mut().zip(&self.singles) {
            let a = 1.0 + h * (blk[0] - f * blk[1]);
            ok &= a > 0.0;
            *inv = [1.0 / a, 0.0, 0.0];
            prod *= a;
        }
        self.invert_groups(e, f, h);
        for &det in &e.group_det {
            if det.is_nan() {
                ok = false;
                continue;
            }
            prod *= det;
            if !(PRODUCT_RANGE.0..PRODUCT_RANGE.1).contains(&prod) {
                log_det += prod.ln();
                prod = 1.0;
            }
        }
        log_det += prod.ln();
        e.log_det = (ok && log_det.is_finite()).then_some(self.components as f64 * log_det);
    }

    /// The inverse and determinant of each general block of `A_a = I + ½Δt(Λ − F B)`
    /// (`f` the kernel force, `h = ½Δt`) into `e.group_inverse` and `e.group_det` (NaN
    /// unless positive definite), [`lanes::BLOCK_LANES`] blocks of one size at a time
    /// (the lanes left over hold the identity): per block the operations of
    /// [`spd_inverse`], so the same bits.
    fn invert_groups(&self, e: &mut Evaluation, f: f64, h: f64) {
        use lanes::{BLOCK_LANES, spd_inverse_lanes};
        for (s, indices) in self.groups_by_size.iter().enumerate() {
            let k = s + 1;
            for chunk in indices.chunks(BLOCK_LANES) {
                let mut a = [[0.0; 16]; BLOCK_LANES];
                for (q, m) in a.iter_mut().enumerate() {
                    match chunk.get(q) {
                        Some(&g) => *m = self.groups[g].proposal_block(f, h),
                        None => (0..k).for_each(|r| m[5 * r] = 1.0),
                    }
                }
                let (inv, det) = match k {
                    1 => spd_inverse_lanes::<1>(&a),
                    2 => spd_inverse_lanes::<2>(&a),
                    3 => spd_inverse_lanes::<3>(&a),
                    _ => spd_inverse_lanes::<4>(&a),
                };
                for (q, &g) in chunk.iter().enumerate() {
                    e.group_inverse[g] = inv[q];
                    e.group_det[g] = det[q];
                }
            }
        }
    }

    /// The proposal from `self.current` with noise `self.z` into `self.proposal.a`;
    /// `false` if `A_a` is not positive definite.
    fn propose(&mut self) -> bool {
        match self.kind {
            Proposal::CrankNicolson => self.propose_crank_nicolson(),
            Proposal::Newton => self.propose_newton(),
            Proposal::OrnsteinUhlenbeck => self.propose_ornstein_uhlenbeck(),
        }
    }

    /// `ln α` of the move `current → proposal` (both evaluated) made with noise `self.z`.
    fn log_acceptance(&self) -> f64 {
        match self.kind {
            Proposal::CrankNicolson => self.log_acceptance_crank_nicolson(),
            Proposal::Newton => self.log_acceptance_newton(),
            Proposal::OrnsteinUhlenbeck => self.log_acceptance_ornstein_uhlenbeck(),
        }
    }

    /// [`Self::propose`] for [`Proposal::CrankNicolson`].
    fn propose_crank_nicolson(&mut self) -> bool {
        let cur = &self.current;
        if cur.log_det.is_none() {
            return false;
        }
        let (n, np, h, f, sc) = (
            self.n(),
            2 * self.pairs.len(),
            self.half_dt,
            cur.kernel_force,
            self.scale,
        );
        let chunks = cur
            .a
            .chunks_exact(n)
            .zip(cur.g.chunks_exact(n))
            .zip(self.z.chunks_exact(n))
            .zip(self.proposal.a.chunks_exact_mut(n));
        for (((a, g), z), out) in chunks {
            for ((((x, gx), zx), o), (blk, inv)) in a[..np]
                .chunks_exact(2)
                .zip(g[..np].chunks_exact(2))
                .zip(z[..np].chunks_exact(2))
                .zip(out[..np].chunks_exact_mut(2))
                .zip(self.pairs.iter().zip(&cur.inverse))
            {
                // (2I − A_a) a + sqrt(2kTΔt) z, then A_a⁻¹.
                let r0 = x[0] - h * (blk[0] * x[0] - f * gx[0]) + sc * zx[0];
                let r1 = x[1] - h * (blk[1] * x[1] - f * gx[1]) + sc * zx[1];
                o[0] = inv[0] * r0 + inv[1] * r1;
                o[1] = inv[1] * r0 + inv[2] * r1;
            }
            let singles = self.singles.iter().zip(&cur.inverse[self.pairs.len()..]);
            for ((((x, gx), zx), o), (blk, inv)) in a[np..]
                .iter()
                .zip(&g[np..])
                .zip(&z[np..])
                .zip(out[np..].iter_mut())
                .zip(singles)
            {
                *o = inv[0] * (x - h * (blk[0] * x - f * gx) + sc * zx);
            }
            let mut at = np + self.singles.len();
            for (grp, inv) in self.groups.iter().zip(&cur.group_inverse) {
                let k = grp.k;
                let mut r = [0.0; 4];
                for (i, ri) in r.iter_mut().enumerate().take(k) {
                    let j = at + i;
                    *ri = a[j] - h * (grp.rates[i] * a[j] - f * g[j]) + sc * z[j];
                }
                for i in 0..k {
                    out[at + i] = (0..k).map(|c| inv[4 * i + c] * r[c]).sum();
                }
                at += k;
            }
        }
        // A non-finite proposal needs no separate pass: its energy, force or ln det A
        // comes out non-finite, so it is rejected (ln α = −∞ or NaN).
        true
    }

    /// [`Self::log_acceptance`] for [`Proposal::CrankNicolson`].
    fn log_acceptance_crank_nicolson(&self) -> f64 {
        let (cur, prop) = (&self.current, &self.proposal);
        let (Some(ld), Some(ld_p)) = (cur.log_det, prop.log_det) else {
            return f64::NEG_INFINITY;
        };
        let (n, h, fp) = (self.n(), self.half_dt, prop.kernel_force);
        let forward: f64 = self.z.iter().map(|z| z * z).sum();
        let mut backward = 0.0;
        let states = cur
            .a
            .chunks_exact(n)
            .zip(prop.a.chunks_exact(n))
            .zip(cur.g.chunks_exact(n))
            .zip(prop.g.chunks_exact(n));
        for (((a, ap), g), gp) in states {
            let terms = a.iter().zip(ap).zip(g).zip(gp).zip(&self.rates);
            for ((((a, ap), g), gp), lam) in terms {
                // A_{a'} a − (2I − A_{a'}) a' = (a − a') + ½Δt(Λ(a + a') − F'B(a + a')).
                let zr = (a - ap) + h * (lam * (a + ap) - fp * (g + gp));
                backward += zr * zr;
            }
        }
        -(prop.energy - cur.energy) / self.kt + (ld_p - ld)
            - 0.5 * backward / (self.scale * self.scale)
            + 0.5 * forward
    }

    /// The compressive force `F` of the current state.
    pub fn force(&self) -> f64 {
        self.current.force
    }

    /// The current modal coordinates, component-major (`n` per component, in the order of
    /// [`PairedModes`]).
    pub fn modal_state(&self) -> &[f64] {
        &self.current.a
    }

    /// The current nodal state, one vector of free DOFs per component (O(n²)); the
    /// membrane's heights are measured from their spatial mean (no zero-mode part).
    pub fn nodal_state(&self) -> Vec<Vec<f64>> {
        let n = self.n();
        self.current
            .a
            .chunks_exact(n)
            .map(|a| match &self.basis {
                Basis::Beam(beam, modes) => {
                    let mut w = vec![0.0; n];
                    modes.to_nodal(beam, a, &mut w);
                    w
                }
                Basis::Plate(modes, order) => {
                    let mut h = vec![0.0; modes.n_modes()];
                    for (&i, &ai) in order.iter().zip(a) {
                        for (hv, p) in h.iter_mut().zip(modes.mode_vector(i)) {
                            *hv += ai * p;
                        }
                    }
                    h
                }
            })
            .collect()
    }

    /// The index in [`PlateModes::modes`] of each modal coordinate of a membrane chain
    /// (`None` for the filament, whose coordinates are in [`PairedModes`] order).
    pub fn plate_order(&self) -> Option<&[usize]> {
        match &self.basis {
            Basis::Plate(_, order) => Some(order),
            Basis::Beam(..) => None,
        }
    }

    /// Adds the current state's squared rotation amplitude of every wavenumber block,
    /// `(β_0 a_0 + β_1 a_1)²` summed over components, to `acc` (one entry per block, in
    /// the order of [`PairedModes`]): O(n). [`PairedModes::add_rotation_squares`] turns
    /// sums of these into sums of nodal θ², leaving out the cross terms between
    /// wavenumbers, whose mean is zero (the energy is even in each block's coordinates): an
    /// unbiased estimate of the same mean squares as the nodal sums.
    ///
    /// # Panics
    /// If `acc` does not have one entry per block, or for a membrane chain.
    pub fn add_block_rotation_squares(&self, acc: &mut [f64]) {
        let Basis::Beam(_, modes) = &self.basis else {
            panic!("rotation squares of a filament chain only");
        };
        let n = self.n();
        let np = 2 * self.pairs.len();
        assert_eq!(
            acc.len(),
            self.pairs.len() + self.singles.len(),
            "one entry per block"
        );
        let (acc_pairs, acc_singles) = acc.split_at_mut(self.pairs.len());
        for a in self.current.a.chunks_exact(n) {
            let (ap, as_) = a.split_at(np);
            for ((out, b), x) in acc_pairs
                .iter_mut()
                .zip(modes.pairs())
                .zip(ap.chunks_exact(2))
            {
                let u = b.rotation[0] * x[0] + b.rotation[1] * x[1];
                *out += u * u;
            }
            for ((out, b), x) in acc_singles.iter_mut().zip(modes.singles()).zip(as_) {
                let u = b.rotation[0] * x;
                *out += u * u;
            }
        }
    }

    /// Fraction of accepted proposals (1 before the first).
    pub fn acceptance(&self) -> f64 {
        if self.proposed == 0 {
            1.0
        } else {
            self.accepted as f64 / self.proposed as f64
        }
    }
}

/// The membrane's proposals beyond Crank–Nicolson ([`Proposal::Newton`],
/// [`Proposal::OrnsteinUhlenbeck`]): one component, general blocks only
/// ([`ModalMetropolis::with_proposal`] refuses the others).
impl ModalMetropolis<'_> {
    /// `c = ½Δt S/ℓ`, the weight of the rank-one term `c g gᵀ` of `A_a` (`½Δt` times the
    /// Hessian's `(S/ℓ) g gᵀ`).
    fn rank_one_weight(&self) -> f64 {
        let p = &self.constraint.constraint;
        self.half_dt * p.stiffness / p.measure
    }

    /// Whether coordinate `j`'s part of `g` enters the rank-one term.
    fn in_rank_one(&self, j: usize) -> bool {
        self.rank_one.get(j).copied().unwrap_or(true)
    }

    /// The log-determinant difference as the Hastings ratio uses it (zero with the test
    /// hook `drop_log_det`).
    fn log_det_term(&self, difference: f64) -> f64 {
        #[cfg(test)]
        if self.drop_log_det {
            return 0.0;
        }
        difference
    }

    /// [`Proposal::Newton`]: the inverse blocks of `D_a = I + ½Δt(Λ − F B)` (LDLᵀ, any
    /// inertia), `D_a⁻¹ g`, the Sherman–Morrison denominator `w = 1 + c gᵀD_a⁻¹g` and
    /// `ln det A_a = ln |det D_a| + ln |w|` (matrix determinant lemma), `None` unless
    /// `A_a = D_a + c g gᵀ` is positive definite. By Cauchy interlacing a positive
    /// rank-one update raises each eigenvalue at most to the next one's place: `A_a` is
    /// positive definite iff `D_a` is (then `w ≥ 1`), or `D_a` has exactly one negative
    /// eigenvalue (no zero one) and `det A_a > 0`, i.e. `w < 0`.
    fn factor_newton(&self, e: &mut Evaluation) {
        let (f, h) = (e.kernel_force, self.half_dt);
        let c = self.rank_one_weight();
        let (mut ok, mut log_det, mut prod, mut negatives) = (true, 0.0, 1.0_f64, 0_usize);
        let mut at = 0;
        for (inv, grp) in e.group_inverse.iter_mut().zip(&self.groups) {
            let k = grp.k;
            match sym_inverse(&grp.proposal_block(f, h), k) {
                Some((ainv, det, neg)) => {
                    *inv = ainv;
                    negatives += neg;
                    prod *= det.abs();
                    if !(PRODUCT_RANGE.0..PRODUCT_RANGE.1).contains(&prod) {
                        log_det += prod.ln();
                        prod = 1.0;
                    }
                }
                None => ok = false,
            }
            for i in 0..k {
                e.dg[at + i] = if self.in_rank_one(at) {
                    (0..k).map(|col| inv[4 * i + col] * e.g[at + col]).sum()
                } else {
                    0.0
                };
            }
            at += k;
        }
        // dg is zero outside the rank-one coordinates
        let gdg: f64 = e.g.iter().zip(&e.dg).map(|(g, d)| g * d).sum();
        let w = 1.0 + c * gdg;
        e.sm_denominator = w;
        ok &= negatives == 0 || (negatives == 1 && w < 0.0);
        log_det += prod.ln() + w.abs().ln();
        e.log_det = (ok && log_det.is_finite()).then_some(log_det);
    }

    /// [`Proposal::Newton`]: `a' = a + A_a⁻¹u`, `u = −Δt∇U(a) + sqrt(2kTΔt) z`,
    /// `∇U = (Λ − F B) a = Λa − F g`, with Sherman–Morrison
    /// `A_a⁻¹u = D_a⁻¹u − c D_a⁻¹g (gᵀD_a⁻¹u)/(1 + c gᵀD_a⁻¹g)`.
    fn propose_newton(&mut self) -> bool {
        let cur = &self.current;
        if cur.log_det.is_none() {
            return false;
        }
        let (h, f, sc) = (self.half_dt, cur.kernel_force, self.scale);
        let c = self.rank_one_weight();
        let out = &mut self.proposal.a;
        let (mut at, mut g_dinv_u) = (0, 0.0);
        for (grp, inv) in self.groups.iter().zip(&cur.group_inverse) {
            let k = grp.k;
            let mut u = [0.0; 4];
            for (i, ui) in u.iter_mut().enumerate().take(k) {
                let j = at + i;
                *ui = -2.0 * h * (grp.rates[i] * cur.a[j] - f * cur.g[j]) + sc * self.z[j];
            }
            let in_rank_one = self.rank_one.get(at).copied().unwrap_or(true);
            for i in 0..k {
                let v: f64 = (0..k).map(|col| inv[4 * i + col] * u[col]).sum();
                out[at + i] = v;
                if in_rank_one {
                    g_dinv_u += cur.g[at + i] * v;
                }
            }
            at += k;
        }
        let t = c * g_dinv_u / cur.sm_denominator;
        for ((o, a), dg) in out.iter_mut().zip(&cur.a).zip(&cur.dg) {
            *o = a + *o - t * dg;
        }
        true
    }

    /// [`Proposal::Newton`]: `ln α = −ΔU/kT + ln det A_{a'} − ln det A_a − ½|z_r|² + ½|z|²`
    /// with `sqrt(2kTΔt) z_r = A_{a'}(a − a') + Δt∇U(a')
    /// = (a − a') + ½Δt(Λ(a + a') − F'(g + g')) + c g'(g'ᵀ(a − a'))` (`B(a − a') = g − g'`;
    /// without the last term, [`Self::log_acceptance_crank_nicolson`]'s `z_r`).
    fn log_acceptance_newton(&self) -> f64 {
        let (cur, prop) = (&self.current, &self.proposal);
        let (Some(ld), Some(ld_p)) = (cur.log_det, prop.log_det) else {
            return f64::NEG_INFINITY;
        };
        let (h, fp) = (self.half_dt, prop.kernel_force);
        let c = self.rank_one_weight();
        let forward: f64 = self.z.iter().map(|z| z * z).sum();
        let gd: f64 = cur
            .a
            .iter()
            .zip(&prop.a)
            .zip(&prop.g)
            .enumerate()
            .filter(|&(j, _)| self.in_rank_one(j))
            .map(|(_, ((a, ap), gp))| gp * (a - ap))
            .sum();
        let cgd = c * gd;
        let terms = cur
            .a
            .iter()
            .zip(&prop.a)
            .zip(cur.g.iter().zip(&prop.g))
            .zip(&self.rates)
            .enumerate();
        let backward: f64 = terms
            .map(|(j, (((a, ap), (g, gp)), lam))| {
                let rank_one = if self.in_rank_one(j) { cgd * gp } else { 0.0 };
                let zr = (a - ap) + h * (lam * (a + ap) - fp * (g + gp)) + rank_one;
                zr * zr
            })
            .sum();
        -(prop.energy - cur.energy) / self.kt + self.log_det_term(ld_p - ld)
            - 0.5 * backward / (self.scale * self.scale)
            + 0.5 * forward
    }

    /// [`Proposal::OrnsteinUhlenbeck`]: per group the eigenpairs `(h_j, v_j)` of
    /// `H = Λ_b − F B_b` (Jacobi), the decay `e^{−Δt h_j}`, the standard deviation
    /// `sqrt(kT (1 − e^{−2Δt h_j})/h_j)` (`sqrt(2kTΔt)` at `h_j = 0`) and
    /// `log_det = −Σ_j ln sd_j = −½ ln det Σ_a`.
    fn factor_ornstein_uhlenbeck(&self, e: &mut Evaluation) {
        let (f, dt, kt) = (e.kernel_force, 2.0 * self.half_dt, self.kt);
        let (mut log_var, mut prod, mut at) = (0.0, 1.0_f64, 0);
        for (vectors, grp) in e.vectors.iter_mut().zip(&self.groups) {
            let k = grp.k;
            let (values, v) = jacobi_eigen(&grp.linearized(f), k);
            *vectors = v;
            for (j, &hj) in values.iter().enumerate().take(k) {
                let x = -dt * hj;
                let decay = x.exp();
                // 1 − e^{−2Δt h}: expm1 where the difference would cancel
                let one_minus = if x.abs() < 0.5 {
                    -(2.0 * x).exp_m1()
                } else {
                    1.0 - decay * decay
                };
                let var = if hj == 0.0 {
                    2.0 * kt * dt
                } else {
                    kt * one_minus / hj
                };
                e.decay[at + j] = decay;
                e.spread[at + j] = var.sqrt();
                prod *= var;
                if !(PRODUCT_RANGE.0..PRODUCT_RANGE.1).contains(&prod) {
                    log_var += prod.ln();
                    prod = 1.0;
                }
            }
            at += k;
        }
        log_var += prod.ln();
        let log_det = -0.5 * log_var;
        e.log_det = log_det.is_finite().then_some(log_det);
    }

    /// [`Proposal::OrnsteinUhlenbeck`]: per group, `y = Vᵀa`, `y'_j = e^{−Δt h_j} y_j +
    /// sd_j z_j`, `a' = V y'` (`V` orthogonal: `a' ~ N(e^{−ΔtH}a, V diag(sd²) Vᵀ)`).
    fn propose_ornstein_uhlenbeck(&mut self) -> bool {
        let cur = &self.current;
        if cur.log_det.is_none() {
            return false;
        }
        let out = &mut self.proposal.a;
        let mut at = 0;
        for (grp, v) in self.groups.iter().zip(&cur.vectors) {
            let k = grp.k;
            let mut y = [0.0; 4];
            for (j, yj) in y.iter_mut().enumerate().take(k) {
                let proj: f64 = (0..k).map(|r| v[4 * r + j] * cur.a[at + r]).sum();
                *yj = cur.decay[at + j] * proj + cur.spread[at + j] * self.z[at + j];
            }
            for r in 0..k {
                out[at + r] = (0..k).map(|j| v[4 * r + j] * y[j]).sum();
            }
            at += k;
        }
        true
    }

    /// [`Proposal::OrnsteinUhlenbeck`]: `ln α = −ΔU/kT + ln q(a'→a) − ln q(a→a')`,
    /// `ln q(a→a') = −½ ln det Σ_a − ½|z|²`, the reverse noise
    /// `z_r,j = ((V'ᵀa)_j − e^{−Δt h'_j}(V'ᵀa')_j)/sd'_j` in the eigenvectors of `a'`.
    fn log_acceptance_ornstein_uhlenbeck(&self) -> f64 {
        let (cur, prop) = (&self.current, &self.proposal);
        let (Some(ld), Some(ld_p)) = (cur.log_det, prop.log_det) else {
            return f64::NEG_INFINITY;
        };
        let forward: f64 = self.z.iter().map(|z| z * z).sum();
        let (mut backward, mut at) = (0.0, 0);
        for (grp, v) in self.groups.iter().zip(&prop.vectors) {
            let k = grp.k;
            for j in 0..k {
                let (mut y, mut yp) = (0.0, 0.0);
                for r in 0..k {
                    y += v[4 * r + j] * cur.a[at + r];
                    yp += v[4 * r + j] * prop.a[at + r];
                }
                let zr = (y - prop.decay[at + j] * yp) / prop.spread[at + j];
                backward += zr * zr;
            }
            at += k;
        }
        -(prop.energy - cur.energy) / self.kt + self.log_det_term(ld_p - ld) - 0.5 * backward
            + 0.5 * forward
    }
}

impl Trajectory for ModalMetropolis<'_> {
    /// One Metropolis-adjusted step: the normals (all components), then one uniform, as the
    /// banded scheme draws them. Allocation-free.
    fn step(&mut self, rng: &mut TrajectoryRng) {
        if self.independence.is_some() {
            self.independence_move(rng);
            return;
        }
        for z in &mut self.z {
            *z = rng.sample(StandardNormal);
        }
        self.proposed += 1;
        if let Some(theta) = self.theta {
            self.theta_step(theta);
            return;
        }
        let u: f64 = rng.random();
        if self.propose() {
            let mut prop = std::mem::take(&mut self.proposal);
            self.evaluate(&mut prop);
            self.proposal = prop;
            let log_alpha = self.log_acceptance();
            if log_alpha >= 0.0 || u < log_alpha.exp() {
                std::mem::swap(&mut self.current, &mut self.proposal);
                self.accepted += 1;
            }
        }
        if self.radial {
            self.radial_move(rng);
        }
    }

    fn is_finite(&self) -> bool {
        self.current.energy.is_finite()
    }
}

impl Default for Evaluation {
    fn default() -> Self {
        Evaluation {
            a: Vec::new(),
            g: Vec::new(),
            energy: 0.0,
            force: 0.0,
            bend: 0.0,
            two_l_s: 0.0,
            kernel_force: 0.0,
            inverse: Vec::new(),
            group_inverse: Vec::new(),
            group_det: Vec::new(),
            log_det: None,
            dg: Vec::new(),
            sm_denominator: 1.0,
            vectors: Vec::new(),
            decay: Vec::new(),
            spread: Vec::new(),
        }
    }
}

/// The lower Cholesky factor `L` and the determinant of the symmetric `k × k` matrix `a`
/// (row-major, stride 4, `k ≤ 4`); `None` unless positive definite.
fn cholesky(a: &[f64; 16], k: usize) -> Option<([f64; 16], f64)> {
    match k {
        1 => cholesky_k::<1>(a),
        2 => cholesky_k::<2>(a),
        3 => cholesky_k::<3>(a),
        4 => cholesky_k::<4>(a),
        _ => None,
    }
}

/// [`cholesky`] at a block size `K` known at compile time, so that the loops unroll (the
/// same operations in the same order as for any `k`).
fn cholesky_k<const K: usize>(a: &[f64; 16]) -> Option<([f64; 16], f64)> {
    let mut l = [0.0; 16];
    let mut det = 1.0;
    for j in 0..K {
        let d = a[5 * j] - (0..j).map(|p| l[4 * j + p] * l[4 * j + p]).sum::<f64>();
        if d.is_nan() || d <= 0.0 {
            return None;
        }
        let ljj = d.sqrt();
        l[5 * j] = ljj;
        det *= d;
        for i in j + 1..K {
            let s = a[4 * i + j] - (0..j).map(|p| l[4 * i + p] * l[4 * j + p]).sum::<f64>();
            l[4 * i + j] = s / ljj;
        }
    }
    Some((l, det))
}

/// The inverse and determinant of the symmetric `k × k` matrix `a` (row-major, stride 4,
/// `k ≤ 4`) by Cholesky; `None` unless positive definite.
fn spd_inverse(a: &[f64; 16], k: usize) -> Option<([f64; 16], f64)> {
    match k {
        1 => spd_inverse_k::<1>(a),
        2 => spd_inverse_k::<2>(a),
        3 => spd_inverse_k::<3>(a),
        4 => spd_inverse_k::<4>(a),
        _ => None,
    }
}

/// [`spd_inverse`] at a block size known at compile time (the same operations in the
/// same order as for any `k`).
fn spd_inverse_k<const K: usize>(a: &[f64; 16]) -> Option<([f64; 16], f64)> {
    let (l, det) = cholesky_k::<K>(a)?;
    // columns of L⁻¹ by forward substitution, then A⁻¹ = L⁻ᵀ L⁻¹
    let mut li = [0.0; 16];
    for c in 0..K {
        for i in c..K {
            let rhs = if i == c { 1.0 } else { 0.0 };
            let s = rhs - (c..i).map(|p| l[4 * i + p] * li[4 * p + c]).sum::<f64>();
            li[4 * i + c] = s / l[5 * i];
        }
    }
    let mut inv = [0.0; 16];
    for r in 0..K {
        for c in 0..K {
            inv[4 * r + c] = (r.max(c)..K).map(|p| li[4 * p + r] * li[4 * p + c]).sum();
        }
    }
    Some((inv, det))
}

/// The inverse, determinant and number of negative eigenvalues of the symmetric `k × k`
/// matrix `a` (row-major, stride 4, `k ≤ 4`) by `LDLᵀ` without pivoting (Sylvester: the
/// signs of `D` are the inertia); `None` at a zero or non-finite pivot.
fn sym_inverse(a: &[f64; 16], k: usize) -> Option<([f64; 16], f64, usize)> {
    let (mut l, mut d) = ([0.0; 16], [0.0; 4]);
    for j in 0..k {
        let dj = a[5 * j]
            - (0..j)
                .map(|p| l[4 * j + p] * l[4 * j + p] * d[p])
                .sum::<f64>();
        if !dj.is_finite() || dj == 0.0 {
            return None;
        }
        d[j] = dj;
        l[5 * j] = 1.0;
        for i in j + 1..k {
            let s = a[4 * i + j]
                - (0..j)
                    .map(|p| l[4 * i + p] * l[4 * j + p] * d[p])
                    .sum::<f64>();
            l[4 * i + j] = s / dj;
        }
    }
    // L⁻¹ (unit lower triangular) by forward substitution, then A⁻¹ = L⁻ᵀ D⁻¹ L⁻¹
    let mut li = [0.0; 16];
    for c in 0..k {
        li[5 * c] = 1.0;
        for i in c + 1..k {
            li[4 * i + c] = -(c..i).map(|p| l[4 * i + p] * li[4 * p + c]).sum::<f64>();
        }
    }
    let mut inv = [0.0; 16];
    for r in 0..k {
        for c in 0..k {
            inv[4 * r + c] = (r.max(c)..k)
                .map(|p| li[4 * p + r] * li[4 * p + c] / d[p])
                .sum();
        }
    }
    let det = d[..k].iter().product();
    let negatives = d[..k].iter().filter(|&&x| x < 0.0).count();
    Some((inv, det, negatives))
}

/// Eigenvalues and orthonormal eigenvectors (columns of the row-major stride-4 result) of
/// the symmetric `k × k` matrix `a` (`k ≤ 4`) by cyclic Jacobi rotations (Golub & Van
/// Loan, Matrix Computations, §8.5: `t = sgn θ/(|θ| + sqrt(θ² + 1))`,
/// `θ = (a_qq − a_pp)/(2a_pq)`), until the off-diagonal part is below 1e-16 of the
/// diagonal (quadratic convergence: a few sweeps). The vectors are a product of
/// rotations, orthogonal to round-off, which is what the proposal's density relies on.
fn jacobi_eigen(a: &[f64; 16], k: usize) -> ([f64; 4], [f64; 16]) {
    let (mut m, mut v) = (*a, [0.0; 16]);
    for i in 0..k {
        v[5 * i] = 1.0;
    }
    for _sweep in 0..30 {
        let mut off = 0.0;
        let mut diag = 0.0;
        for p in 0..k {
            diag += m[5 * p] * m[5 * p];
            for q in p + 1..k {
                off += m[4 * p + q] * m[4 * p + q];
            }
        }
        if off <= 1e-32 * diag {
            break;
        }
        for p in 0..k {
            for q in p + 1..k {
                let apq = m[4 * p + q];
                if apq == 0.0 {
                    continue;
                }
                let theta = (m[5 * q] - m[5 * p]) / (2.0 * apq);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for r in 0..k {
                    let (mrp, mrq) = (m[4 * r + p], m[4 * r + q]);
                    m[4 * r + p] = c * mrp - s * mrq;
                    m[4 * r + q] = s * mrp + c * mrq;
                }
                for r in 0..k {
                    let (mpr, mqr) = (m[4 * p + r], m[4 * q + r]);
                    m[4 * p + r] = c * mpr - s * mqr;
                    m[4 * q + r] = s * mpr + c * mqr;
                }
                for r in 0..k {
                    let (vrp, vrq) = (v[4 * r + p], v[4 * r + q]);
                    v[4 * r + p] = c * vrp - s * vrq;
                    v[4 * r + q] = s * vrp + c * vrq;
                }
            }
        }
    }
    let mut values = [0.0; 4];
    for (i, x) in values.iter_mut().enumerate().take(k) {
        *x = m[5 * i];
    }
    (values, v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::FilamentParams;
    use crate::fem::beam::BeamModel;
    use crate::fem::mesh::Mesh;
    use crate::rng::trajectory_rng;
    use nalgebra::{DMatrix, DVector};

    pub(super) fn model(dims: usize, ne: usize, strain_ratio: f64) -> CompressedFilament {
        let p = FilamentParams {
            bending_rigidity: 100.0,
            stretch_rigidity: 1e6,
            ..FilamentParams::default()
        };
        let beam = BeamModel::new(p, Mesh::uniform(1.0, ne).unwrap()).unwrap();
        CompressedFilament::new(beam, dims, strain_ratio * p.euler_strain()).unwrap()
    }

    /// Φ as a dense matrix (columns: the nodal vectors of unit modal coordinates).
    fn phi(m: &CompressedFilament, modes: &PairedModes) -> DMatrix<f64> {
        let n = modes.n_modes();
        let mut out = DMatrix::zeros(n, n);
        let mut col = vec![0.0; n];
        for i in 0..n {
            let mut e = vec![0.0; n];
            e[i] = 1.0;
            modes.to_nodal(m.beam(), &e, &mut col);
            out.set_column(i, &DVector::from_column_slice(&col));
        }
        out
    }

    /// One proposal and its acceptance against an independent nodal oracle from dense
    /// matrices: with `w = Φa` and `ζ = CΦz` (so `ζ ~ N(0, C)`), the modal proposal is the
    /// nodal Crank–Nicolson proposal `(C + ½ΔtH_w) w' = (C − ½ΔtH_w) w + sqrt(2kTΔt) ζ`,
    /// and ln α equals `−ΔU/kT + ln q(w'→w) − ln q(w→w')` computed with dense `K, C, G`
    /// (the constant Jacobian of `w = Φa` cancels). 2D and 3D, in tension, near the Euler
    /// strain and buckled, at a large Δt (0.3 τ1) where F changes `A` noticeably.
    #[test]
    fn modal_step_is_the_nodal_crank_nicolson_metropolis_step() {
        for dims in [2, 3] {
            for ratio in [0.0, 1.0, 6.0] {
                let m = model(dims, 7, ratio);
                let modes = PairedModes::new(m.beam()).unwrap();
                let dt = 0.3 * m.beam().params().tau1();
                let mut rng = trajectory_rng(7, dims as u64);
                let mut chain = ModalMetropolis::new(&m, &modes, dt, &mut rng).unwrap();
                for z in &mut chain.z {
                    *z = rng.sample(StandardNormal);
                }
                let ok = chain.propose();
                assert!(
                    ok,
                    "log_det {:?} force {} a {:?}",
                    chain.current.log_det,
                    chain.current.force,
                    &chain.current.a[..4]
                );
                let mut prop = std::mem::take(&mut chain.proposal);
                chain.evaluate(&mut prop);
                chain.proposal = prop;
                let ln_alpha = chain.log_acceptance();
                assert!(
                    ln_alpha.is_finite() && ln_alpha != 0.0,
                    "ln alpha {ln_alpha}"
                );

                let n = modes.n_modes();
                let ph = phi(&m, &modes);
                let beam = m.beam();
                let (k, c, g) = (
                    beam.stiffness().to_dense(),
                    beam.damping().to_dense(),
                    beam.geometric().to_dense(),
                );
                let nodal = |a: &[f64]| -> Vec<Vec<f64>> {
                    a.chunks_exact(n)
                        .map(|x| (&ph * DVector::from_column_slice(x)).as_slice().to_vec())
                        .collect()
                };
                let w = nodal(&chain.current.a);
                let wp = nodal(&chain.proposal.a);
                let kt = beam.params().kt;
                let f = m.compressive_force(m.stored_length(&w));
                assert!((f - chain.current.force).abs() < 1e-9 * (1.0 + f.abs()));
                let h = &k - &g * f;
                let (am, bm) = (&c + &h * (0.5 * dt), &c - &h * (0.5 * dt));
                for (cidx, (wc, wpc)) in w.iter().zip(&wp).enumerate() {
                    let zeta = &c * &ph * DVector::from_column_slice(&chain.z[cidx * n..][..n]);
                    let lhs = &am * DVector::from_column_slice(wpc);
                    let rhs = &bm * DVector::from_column_slice(wc) + zeta * (2.0 * kt * dt).sqrt();
                    assert!(
                        (&lhs - &rhs).amax() < 1e-9 * rhs.amax(),
                        "dims {dims} ratio {ratio}: proposal residual {}",
                        (&lhs - &rhs).amax()
                    );
                }
                let oracle = crate::dynamics::nonlinear::tests::dense_log_alpha(&m, dt, &w, &wp);
                assert!(
                    (ln_alpha - oracle).abs() < 1e-6 * (1.0 + oracle.abs()),
                    "dims {dims} ratio {ratio}: ln alpha {ln_alpha} vs dense oracle {oracle}"
                );
                assert!(
                    (chain.proposal.energy - m.energy(&wp)).abs() < 1e-9 * (1.0 + m.energy(&wp))
                );
            }
        }
    }

    /// The equilibrium start has the bending-equilibrium variances `kT/λ_i`, and the chain
    /// keeps a finite state with a high acceptance at a moderate Δt.
    #[test]
    fn start_and_acceptance() {
        let m = model(2, 10, 0.0);
        let modes = PairedModes::new(m.beam()).unwrap();
        let rates = modes.rates();
        let mut sums = vec![0.0; rates.len()];
        let reps = 4000;
        for j in 0..reps {
            let chain = ModalMetropolis::new(&m, &modes, 1e-6, &mut trajectory_rng(3, j)).unwrap();
            for (s, a) in sums.iter_mut().zip(chain.modal_state()) {
                *s += a * a;
            }
        }
        for (s, lam) in sums.iter().zip(&rates) {
            let ratio = s / reps as f64 * lam;
            // chi2 with 4000 dof: relative s.d. sqrt(2/4000) = 0.022; 5 s.d.
            assert!((ratio - 1.0).abs() < 0.11, "variance ratio {ratio}");
        }
        let dt = 0.1 * m.beam().params().tau1();
        let mut rng = trajectory_rng(4, 0);
        let mut chain = ModalMetropolis::new(&m, &modes, dt, &mut rng).unwrap();
        for _ in 0..2000 {
            chain.step(&mut rng);
        }
        assert!(chain.is_finite());
        assert!(
            chain.acceptance() > 0.9,
            "acceptance {}",
            chain.acceptance()
        );
    }

    /// What: the membrane's chain (general blocks of up to 4 coordinates) makes the nodal
    /// Crank–Nicolson proposal and accepts with the exact Metropolis–Hastings ratio.
    /// Reference: dense `K_b`, `C` and `G = K(σ = 1) − K(σ = 0)` of the assembled plate,
    /// the nodal proposal `(C + ½ΔtH)h' = (C − ½ΔtH)h + sqrt(2kTΔt)ζ`, `H = K_b − F G`,
    /// `ζ = CΦz`, and `ln α = −ΔU/kT + ln q(h'→h) − ln q(h→h')` with dense determinants,
    /// `U = ½hᵀK_b h + (K_A A₀/2)(hᵀGh/(2A₀) − ε)²`. Set-up: simply supported 3 × 3 and
    /// periodic 4 × 4 (zero mode left out of the chain; it cancels in the nodal ratio),
    /// κ = 20 kT, in tension (ε = −ε_c0), near and beyond buckling (ε = ε_c0, 4 ε_c0), at a
    /// large Δt (0.3 τ1). Tolerance: round-off (1e-9 relative).
    #[test]
    fn membrane_step_is_the_nodal_crank_nicolson_metropolis_step() {
        use crate::fem::plate::PlateModel;
        use crate::spectral::membrane::{MembraneBoundary, MembraneParams};
        for boundary in [
            MembraneBoundary::SimplySupported,
            MembraneBoundary::Periodic,
        ] {
            for ratio in [-1.0, 1.0, 4.0] {
                let n_el = if boundary == MembraneBoundary::Periodic {
                    4
                } else {
                    3
                };
                let p = MembraneParams {
                    bending_rigidity: 20.0,
                    width: 1.2,
                    boundary,
                    ..MembraneParams::default()
                };
                let k_a = 2e4;
                let sigma_c0 = p.bending_rigidity * p.min_wavenumber_sq();
                let m = AreaMembrane::new(p, n_el, n_el, k_a, ratio * sigma_c0 / k_a).unwrap();
                let modes = PlateModes::new(m.plate()).unwrap();
                let tau1 = p.drag / (p.bending_rigidity * p.min_wavenumber_sq().powi(2));
                let dt = 0.3 * tau1;
                let mut rng = trajectory_rng(11, ratio.to_bits());
                let mut chain = ModalMetropolis::for_membrane(&m, &modes, dt, &mut rng).unwrap();
                for z in &mut chain.z {
                    *z = rng.sample(StandardNormal);
                }
                assert!(chain.propose(), "{boundary:?} {ratio}: no proposal");
                let mut prop = std::mem::take(&mut chain.proposal);
                chain.evaluate(&mut prop);
                chain.proposal = prop;
                let ln_alpha = chain.log_acceptance();
                assert!(
                    ln_alpha.is_finite() && ln_alpha != 0.0,
                    "ln alpha {ln_alpha}"
                );

                let g_plate =
                    PlateModel::new(MembraneParams { tension: 1.0, ..p }, n_el, n_el).unwrap();
                let k = m.plate().stiffness().to_dense();
                let c = m.plate().damping().to_dense();
                let g = g_plate.stiffness().to_dense() - &k;
                let c_inv = c.clone().try_inverse().unwrap();
                let order = chain.plate_order().unwrap().to_vec();
                let nd = modes.n_modes();
                let mut ph = DMatrix::zeros(nd, order.len());
                for (col, &i) in order.iter().enumerate() {
                    ph.column_mut(col).copy_from_slice(&modes.mode_vector(i));
                }
                let h = &ph * DVector::from_column_slice(&chain.current.a);
                let hp = &ph * DVector::from_column_slice(&chain.proposal.a);
                let area = p.area();
                let excess = |x: &DVector<f64>| (x.transpose() * &g * x)[(0, 0)] / (2.0 * area);
                let energy = |x: &DVector<f64>| {
                    let d = excess(x) - m.strain();
                    0.5 * (x.transpose() * &k * x)[(0, 0)] + 0.5 * k_a * area * d * d
                };
                let force = |x: &DVector<f64>| k_a * (m.strain() - excess(x));
                let f = force(&h);
                assert!((f - chain.current.force).abs() < 1e-9 * (1.0 + f.abs()));
                let a_of = |x: &DVector<f64>| {
                    let hm = &k - &g * force(x);
                    (&c + &hm * (0.5 * dt), &c - &hm * (0.5 * dt))
                };
                let (am, bm) = a_of(&h);
                let zeta = &c * &ph * DVector::from_column_slice(&chain.z);
                let rhs = &bm * &h + zeta * (2.0 * p.kt * dt).sqrt();
                let res = (&am * &hp - &rhs).amax();
                assert!(
                    res < 1e-9 * rhs.amax(),
                    "{boundary:?} {ratio}: residual {res:e}"
                );
                let log_q = |from: &DVector<f64>, to: &DVector<f64>| {
                    let (am, bm) = a_of(from);
                    let r = &am * to - &bm * from;
                    am.determinant().ln()
                        - 0.5 * (r.transpose() * &c_inv * &r)[(0, 0)] / (2.0 * p.kt * dt)
                };
                let oracle = -(energy(&hp) - energy(&h)) / p.kt + log_q(&hp, &h) - log_q(&h, &hp);
                assert!(
                    (ln_alpha - oracle).abs() < 1e-6 * (1.0 + oracle.abs()),
                    "{boundary:?} {ratio}: ln alpha {ln_alpha} vs dense oracle {oracle}"
                );
            }
        }
    }

    /// What: the membrane's θ-step (explicit constraint force) is the nodal θ-scheme.
    /// Reference: dense `(C + θΔtK_b)h' = (C − (1−θ)ΔtK_b)h + ΔtF(h)Gh + sqrt(2kTΔt)CΦz`.
    /// Set-up: periodic 4 × 4 in tension and simply supported 3 × 3 buckled, θ = 0, ½, 1.
    /// Tolerance: round-off (1e-9 relative).
    #[test]
    fn membrane_theta_step_is_the_nodal_theta_step() {
        use crate::fem::plate::PlateModel;
        use crate::spectral::membrane::{MembraneBoundary, MembraneParams};
        for (boundary, n_el, ratio) in [
            (MembraneBoundary::Periodic, 4, -2.0),
            (MembraneBoundary::SimplySupported, 3, 3.0),
        ] {
            for theta in [0.0_f64, 0.5, 1.0] {
                let p = MembraneParams {
                    bending_rigidity: 20.0,
                    height: 0.8,
                    boundary,
                    ..MembraneParams::default()
                };
                let k_a = 5e3;
                let sigma_c0 = p.bending_rigidity * p.min_wavenumber_sq();
                let m = AreaMembrane::new(p, n_el, n_el, k_a, ratio * sigma_c0 / k_a).unwrap();
                let modes = PlateModes::new(m.plate()).unwrap();
                let dt = 1e-5;
                let mut rng = trajectory_rng(12, theta.to_bits());
                let mut chain = ModalMetropolis::for_membrane(&m, &modes, dt, &mut rng)
                    .unwrap()
                    .with_theta(theta)
                    .unwrap();
                let order = chain.plate_order().unwrap().to_vec();
                let nd = modes.n_modes();
                let mut ph = DMatrix::zeros(nd, order.len());
                for (col, &i) in order.iter().enumerate() {
                    ph.column_mut(col).copy_from_slice(&modes.mode_vector(i));
                }
                let h = &ph * DVector::from_column_slice(&chain.current.a);
                let f = chain.current.force;
                chain.step(&mut rng);
                let hp = &ph * DVector::from_column_slice(&chain.current.a);
                let g_plate =
                    PlateModel::new(MembraneParams { tension: 1.0, ..p }, n_el, n_el).unwrap();
                let k = m.plate().stiffness().to_dense();
                let c = m.plate().damping().to_dense();
                let g = g_plate.stiffness().to_dense() - &k;
                let zeta = &c * &ph * DVector::from_column_slice(&chain.z);
                let lhs = (&c + &k * (theta * dt)) * &hp;
                let rhs = (&c - &k * ((1.0 - theta) * dt)) * &h
                    + &g * &h * (dt * f)
                    + zeta * (2.0 * p.kt * dt).sqrt();
                let res = (&lhs - &rhs).amax();
                assert!(
                    res < 1e-9 * rhs.amax(),
                    "{boundary:?} theta {theta}: {res:e}"
                );
            }
        }
    }

    /// A tiny membrane under imposed area for the exactness tests of the new proposals:
    /// `n_el × n_el` elements, κ = 20 kT, `K_A`, ε = `ratio`·ε_c0, on a 1.2 × 1 patch (no
    /// tied modes on the simply supported one).
    pub(super) fn tiny_membrane(
        boundary: crate::spectral::membrane::MembraneBoundary,
        n_el: usize,
        k_a: f64,
        ratio: f64,
    ) -> (AreaMembrane, PlateModes) {
        use crate::spectral::membrane::MembraneParams;
        let p = MembraneParams {
            bending_rigidity: 20.0,
            width: 1.2,
            boundary,
            ..MembraneParams::default()
        };
        let sigma_c0 = p.bending_rigidity * p.min_wavenumber_sq();
        let m = AreaMembrane::new(p, n_el, n_el, k_a, ratio * sigma_c0 / k_a).unwrap();
        let modes = PlateModes::new(m.plate()).unwrap();
        (m, modes)
    }

    /// `τ1 = ξ/(κ q⁴_min)` of the membrane.
    pub(super) fn membrane_tau1(m: &AreaMembrane) -> f64 {
        let p = m.plate().params();
        p.drag / (p.bending_rigidity * p.min_wavenumber_sq().powi(2))
    }

    /// The chain's energy and proposals as dense matrices in its modal coordinates, built
    /// from the assembled plate alone (`Λ = ΦᵀKΦ`, `B = ΦᵀGΦ`, `G = K(σ = 1) − K(σ = 0)`,
    /// `Φ` the mode vectors in the chain's order): the oracle of the proposal densities.
    struct DenseChain {
        lam: DMatrix<f64>,
        b: DMatrix<f64>,
        stiffness: f64,
        area: f64,
        kt: f64,
        strain: f64,
        dt: f64,
        /// Newton: the coordinates whose part of `g` enters the rank-one term.
        rank_one: Vec<bool>,
    }

    impl DenseChain {
        fn new(m: &AreaMembrane, modes: &PlateModes, order: &[usize], dt: f64) -> Self {
            use crate::fem::plate::PlateModel;
            use crate::spectral::membrane::MembraneParams;
            let p = *m.plate().params();
            let (nx, ny) = (m.plate().elements().0, m.plate().elements().1);
            let g_plate = PlateModel::new(MembraneParams { tension: 1.0, ..p }, nx, ny).unwrap();
            let k = m.plate().stiffness().to_dense();
            let g = g_plate.stiffness().to_dense() - &k;
            let mut ph = DMatrix::zeros(modes.n_modes(), order.len());
            for (col, &i) in order.iter().enumerate() {
                ph.column_mut(col).copy_from_slice(&modes.mode_vector(i));
            }
            DenseChain {
                lam: ph.transpose() * &k * &ph,
                b: ph.transpose() * &g * &ph,
                stiffness: m.area_modulus(),
                area: p.area(),
                kt: p.kt,
                strain: m.strain(),
                dt,
                rank_one: vec![true; order.len()],
            }
        }

        fn force(&self, a: &DVector<f64>) -> f64 {
            let s = (a.transpose() * &self.b * a)[(0, 0)] / (2.0 * self.area);
            self.stiffness * (self.strain - s)
        }

        fn energy(&self, a: &DVector<f64>) -> f64 {
            let s = (a.transpose() * &self.b * a)[(0, 0)] / (2.0 * self.area);
            let d = s - self.strain;
            0.5 * (a.transpose() * &self.lam * a)[(0, 0)] + 0.5 * self.stiffness * self.area * d * d
        }

        /// `Λ − F(a) B`.
        fn block_hessian(&self, a: &DVector<f64>) -> DMatrix<f64> {
            &self.lam - &self.b * self.force(a)
        }

        /// Mean and covariance of the proposal from `a`.
        fn proposal(&self, kind: Proposal, a: &DVector<f64>) -> (DVector<f64>, DMatrix<f64>) {
            let n = a.len();
            let hd = self.block_hessian(a);
            match kind {
                Proposal::Newton | Proposal::CrankNicolson => {
                    let mut g = &self.b * a;
                    for (gi, &keep) in g.iter_mut().zip(&self.rank_one) {
                        if !keep {
                            *gi = 0.0;
                        }
                    }
                    let mut h = hd.clone();
                    if kind == Proposal::Newton {
                        h += &g * g.transpose() * (self.stiffness / self.area);
                    }
                    let am = DMatrix::identity(n, n) + h * (0.5 * self.dt);
                    let ainv = am.try_inverse().unwrap();
                    let mean = a - &ainv * (&hd * a) * self.dt;
                    let cov = &ainv * &ainv * (2.0 * self.kt * self.dt);
                    (mean, cov)
                }
                Proposal::OrnsteinUhlenbeck => {
                    let eig = hd.symmetric_eigen();
                    let v = &eig.eigenvectors;
                    let decay = eig.eigenvalues.map(|h| (-self.dt * h).exp());
                    let var = eig
                        .eigenvalues
                        .map(|h| self.kt * (1.0 - (-2.0 * self.dt * h).exp()) / h);
                    let mean = v * DMatrix::from_diagonal(&decay) * v.transpose() * a;
                    let cov = v * DMatrix::from_diagonal(&var) * v.transpose();
                    (mean, cov)
                }
            }
        }

        /// `(x − μ)ᵀΣ⁻¹(x − μ)` and `ln N(x; μ, Σ)` of the proposal `from → to`.
        fn log_q(&self, kind: Proposal, from: &DVector<f64>, to: &DVector<f64>) -> (f64, f64) {
            let (mean, cov) = self.proposal(kind, from);
            let d = to - mean;
            let chol = cov.clone().cholesky().unwrap();
            let maha = (d.transpose() * chol.solve(&d))[(0, 0)];
            let log_det = 2.0 * chol.l().diagonal().map(f64::ln).sum();
            let n = to.len() as f64;
            let ln2pi = (2.0 * std::f64::consts::PI).ln();
            (maha, -0.5 * maha - 0.5 * log_det - 0.5 * n * ln2pi)
        }
    }

    /// `ln α` of the chain for the move `from → to`, with a noise vector of squared norm
    /// `noise_sq` (the only way the forward noise enters; `z` is set to
    /// `(sqrt(noise_sq), 0, …)`).
    fn chain_log_alpha(
        chain: &mut ModalMetropolis<'_>,
        from: &[f64],
        to: &[f64],
        noise_sq: f64,
    ) -> f64 {
        chain.current.a.copy_from_slice(from);
        let mut cur = std::mem::take(&mut chain.current);
        chain.evaluate(&mut cur);
        chain.current = cur;
        chain.proposal.a.copy_from_slice(to);
        let mut prop = std::mem::take(&mut chain.proposal);
        chain.evaluate(&mut prop);
        chain.proposal = prop;
        chain.z.iter_mut().for_each(|z| *z = 0.0);
        chain.z[0] = noise_sq.sqrt();
        chain.log_acceptance()
    }

    /// What: the new proposals (Newton with the rank-one term, exact OU per block) draw
    /// what their Hastings ratio assumes, and the ratio is exact.
    /// (i) The drawn `a'` has Mahalanobis distance `|z|²` under the dense Gaussian proposal
    /// (mean and covariance built with nalgebra from `Λ`, `B`, `g`: for Newton
    /// `N(a − Δt A⁻¹∇U, 2kTΔt A⁻²)`, `A = I + ½Δt(Λ − F B + (S/ℓ) g gᵀ)`; for OU
    /// `N(e^{−ΔtH} a, kT H⁻¹(I − e^{−2ΔtH}))`, `H = Λ − F B`), for several random `z`: a
    /// noise matrix `L` with `LLᵀ ≠ Σ` fails this; and the chain's `ln α` equals
    /// `−ΔU/kT + ln q(a'→a) − ln q(a→a')` of the dense densities.
    /// (ii) Detailed balance: `p(a) q(a→a') min(1, α(a→a')) = p(a') q(a'→a) min(1, α(a'→a))`
    /// with the dense `q` and the chain's `α` both ways, for random pairs.
    /// Newton also with the rank-one term on the slow groups only (rates ≤ 20 λ_1,
    /// [`ModalMetropolis::with_rank_one_limit`]; the oracle zeroes `g` beyond them).
    /// Set-up: simply supported 3 × 3 and periodic 4 × 4, in tension, near and beyond
    /// buckling, Δt = 1 τ1 (Newton, OU) and 0.3 τ1. Tolerance: (i) 1e-9 relative,
    /// (ii) 1e-10 of the terms' size.
    #[test]
    fn new_proposals_are_exact_against_dense_gaussians() {
        use crate::spectral::membrane::MembraneBoundary;
        let mut counts = [0_usize; 2];
        // (proposal, rank-one term on the groups with rates ≤ this × λ_1 only)
        let cases = [
            (Proposal::Newton, None),
            (Proposal::Newton, Some(20.0)),
            (Proposal::OrnsteinUhlenbeck, None),
        ];
        for (kind, limit) in cases {
            for (boundary, n_el) in [
                (MembraneBoundary::SimplySupported, 3),
                (MembraneBoundary::Periodic, 4),
            ] {
                for ratio in [-1.0, 1.0, 4.0] {
                    for dt_tau1 in [0.3, 1.0] {
                        let (m, modes) = tiny_membrane(boundary, n_el, 2e4, ratio);
                        let dt = dt_tau1 * membrane_tau1(&m);
                        let mut rng = trajectory_rng(21, ratio.to_bits() ^ dt_tau1.to_bits());
                        let mut chain = ModalMetropolis::for_membrane(&m, &modes, dt, &mut rng)
                            .unwrap()
                            .with_proposal(kind)
                            .unwrap();
                        if let Some(l) = limit {
                            chain = chain.with_rank_one_limit(l / membrane_tau1(&m));
                            let len = chain.rank_one.iter().filter(|&&r| r).count();
                            assert!(len > 0 && len < chain.n(), "{len} of {}", chain.n());
                        }
                        // into equilibrium first (a typical state, not the start)
                        for _ in 0..200 {
                            chain.step(&mut rng);
                        }
                        let mut dense =
                            DenseChain::new(&m, &modes, chain.plate_order().unwrap(), dt);
                        if limit.is_some() {
                            dense.rank_one.clone_from(&chain.rank_one);
                        }
                        let label = format!("{kind:?} {limit:?} {boundary:?} {ratio} {dt_tau1}");
                        for _ in 0..4 {
                            let a = DVector::from_column_slice(&chain.current.a);
                            assert!(
                                (dense.force(&a) - chain.current.force).abs()
                                    < 1e-9 * (1.0 + chain.current.force.abs()),
                                "{label}: force"
                            );
                            for z in &mut chain.z {
                                *z = rng.sample(StandardNormal);
                            }
                            let z_sq: f64 = chain.z.iter().map(|z| z * z).sum();
                            assert!(chain.propose(), "{label}: no proposal");
                            let mut prop = std::mem::take(&mut chain.proposal);
                            chain.evaluate(&mut prop);
                            chain.proposal = prop;
                            let ln_alpha = chain.log_acceptance();
                            let ap = DVector::from_column_slice(&chain.proposal.a);
                            // (i) the draw and the densities
                            let (maha, lq_f) = dense.log_q(kind, &a, &ap);
                            assert!(
                                (maha - z_sq).abs() < 1e-9 * z_sq,
                                "{label}: Mahalanobis {maha} vs |z|^2 {z_sq}"
                            );
                            let (maha_r, lq_r) = dense.log_q(kind, &ap, &a);
                            let oracle =
                                -(dense.energy(&ap) - dense.energy(&a)) / dense.kt + lq_r - lq_f;
                            assert!(
                                (ln_alpha - oracle).abs() < 1e-9 * (1.0 + oracle.abs()),
                                "{label}: ln alpha {ln_alpha} vs dense {oracle}"
                            );
                            // (ii) detailed balance, the chain's α both ways
                            let (av, apv) = (a.as_slice().to_vec(), ap.as_slice().to_vec());
                            let fwd = chain_log_alpha(&mut chain, &av, &apv, maha);
                            let rev = chain_log_alpha(&mut chain, &apv, &av, maha_r);
                            let left = -dense.energy(&a) / dense.kt + lq_f + fwd.min(0.0);
                            let right = -dense.energy(&ap) / dense.kt + lq_r + rev.min(0.0);
                            let size = 1.0 + left.abs().max(right.abs());
                            assert!(
                                (left - right).abs() < 1e-10 * size,
                                "{label}: detailed balance {left} vs {right}"
                            );
                            counts[usize::from(fwd < 0.0)] += 1;
                            // move on: accept the proposal or keep the state
                            chain
                                .current
                                .a
                                .copy_from_slice(if fwd >= 0.0 { &apv } else { &av });
                            let mut cur = std::mem::take(&mut chain.current);
                            chain.evaluate(&mut cur);
                            chain.current = cur;
                        }
                    }
                }
            }
        }
        // both branches of min(1, α) were exercised
        assert!(
            counts[0] > 5 && counts[1] > 5,
            "accepted/rejected {counts:?}"
        );
    }

    /// `(⟨F⟩ − exact)/s.e.` of a long chain with proposal `kind` at Δt = 1 τ1 on the
    /// simply supported 3 × 3 membrane of [`tiny_membrane`] (`K_A` = 2e4, ε = `ratio`·ε_c0),
    /// against the exact discrete theory of the same mesh ([`AreaTheory::discrete`]);
    /// `drop_log_det` makes the Hastings ratio wrong.
    fn long_chain_force_z(kind: Proposal, ratio: f64, drop_log_det: bool, steps: usize) -> f64 {
        long_chain_force_z_with(kind, false, ratio, drop_log_det, steps)
    }

    /// [`long_chain_force_z`], with radial moves after every step if `radial`
    /// (`drop_log_det` then drops the radial move's Jacobian instead).
    fn long_chain_force_z_with(
        kind: Proposal,
        radial: bool,
        ratio: f64,
        drop_log_det: bool,
        steps: usize,
    ) -> f64 {
        use crate::fem::plate_area::{AreaParams, AreaTheory};
        use crate::spectral::membrane::MembraneBoundary;
        let k_a = 2e4;
        let (m, modes) = tiny_membrane(MembraneBoundary::SimplySupported, 3, k_a, ratio);
        let tau1 = membrane_tau1(&m);
        let mut rng = trajectory_rng(31, ratio.to_bits() ^ u64::from(drop_log_det));
        // burn-in with the default chain at the scenes' step, then the proposal under test
        let mut chain = ModalMetropolis::for_membrane(&m, &modes, 0.02 * tau1, &mut rng).unwrap();
        for _ in 0..500 {
            chain.step(&mut rng);
        }
        let mut chain = chain.with_proposal(kind).unwrap();
        if radial {
            chain = chain.with_radial_moves();
        }
        chain.drop_log_det = drop_log_det;
        chain.set_dt(tau1).unwrap();
        for _ in 0..2000 {
            chain.step(&mut rng);
        }
        let forces: Vec<f64> = (0..steps)
            .map(|_| {
                chain.step(&mut rng);
                chain.force()
            })
            .collect();
        let est = crate::stats::mean_with_error(&forces).unwrap();
        let params = AreaParams::from_membrane(m.plate().params(), k_a);
        let exact = -AreaTheory::discrete(&params, 3, 3)
            .unwrap()
            .mean_tension(m.strain())
            .unwrap();
        eprintln!(
            "{kind:?} radial {radial} ratio {ratio} drop {drop_log_det}: <F> {} exact {exact} se {} tau {} acc {}",
            est.mean,
            est.std_error,
            est.tau_int,
            chain.acceptance()
        );
        (est.mean - exact) / est.std_error
    }

    /// What: the new proposals' chains are exact at a large step: a long chain at Δt = 1 τ1
    /// reproduces the exact ⟨F⟩ of the discrete theory of the same mesh within 4
    /// standard errors (autocorrelation-aware), and the same test catches a wrong Hastings
    /// ratio (the log-determinant term dropped: `|z|` far above 4). Set-up: simply
    /// supported 3 × 3, κ = 20 kT, `K_A` = 2e4, near buckling (ε = ε_c0), 200 000 steps.
    #[test]
    fn new_proposals_reproduce_the_exact_mean_force_at_a_large_step() {
        for kind in [Proposal::Newton, Proposal::OrnsteinUhlenbeck] {
            let z = long_chain_force_z(kind, 1.0, false, 200_000);
            assert!(z.abs() < 4.0, "{kind:?}: z = {z}");
            let z_wrong = long_chain_force_z(kind, 1.0, true, 200_000);
            assert!(
                z_wrong.abs() > 4.0,
                "{kind:?} without the log-det term: z = {z_wrong}"
            );
        }
    }

    /// What: the radial move keeps the chain exact: with it after every Crank–Nicolson
    /// step at Δt = 1 τ1 a long chain reproduces the exact ⟨F⟩ of the discrete theory
    /// within 4 standard errors, in tension, at buckling and buckled, and the same test
    /// catches the move without its Jacobian `t^{N/2}` (|z| far above 4). Set-up as
    /// [`new_proposals_reproduce_the_exact_mean_force_at_a_large_step`].
    #[test]
    fn radial_moves_keep_the_exact_mean_force() {
        for ratio in [-2.0, 1.0, 4.0] {
            let z = long_chain_force_z_with(Proposal::CrankNicolson, true, ratio, false, 100_000);
            assert!(z.abs() < 4.0, "ratio {ratio}: z = {z}");
        }
        let z_wrong = long_chain_force_z_with(Proposal::CrankNicolson, true, 1.0, true, 100_000);
        assert!(z_wrong.abs() > 4.0, "without the Jacobian: z = {z_wrong}");
    }
}
