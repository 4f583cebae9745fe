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
    /// `[inv00, inv01, inv11]` of each 2×2 block of `A_a`, then `[1/a, 0, 0]` per 1×1 block.
    inverse: Vec<[f64; 3]>,
    /// The inverse of each general block of `A_a` (row-major, stride 4).
    group_inverse: Vec<[f64; 16]>,
    /// `d · ln det A_a`, `None` if `A_a` is not positive definite.
    log_det: Option<f64>,
}

/// A general block of `k ≤ 4` modal coordinates coupled by `B`.
#[derive(Debug, Clone)]
struct Group {
    k: usize,
    rates: [f64; 4],
    /// `B` row-major, stride 4.
    b: [f64; 16],
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
    /// Proposals made.
    pub proposed: u64,
    /// Accepted proposals.
    pub accepted: u64,
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
            inverse: vec![[0.0; 3]; blocks],
            group_inverse: vec![[0.0; 16]; groups.len()],
            log_det: None,
        };
        let mut chain = ModalMetropolis {
            constraint,
            basis,
            pairs,
            singles,
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
            proposed: 0,
            accepted: 0,
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

    /// One θ-step (see [`Self::with_theta`]) from `self.current` with noise `self.z`.
    fn theta_step(&mut self, theta: f64) {
        let dt = 2.0 * self.half_dt;
        let cur = &self.current;
        let f = cur.force;
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

    /// Evaluates `e.a` into `e` (see [`Evaluation`]).
    fn evaluate(&self, e: &mut Evaluation) {
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
        e.energy = 0.5 * bend + p.energy(s);
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
        for (inv, grp) in e.group_inverse.iter_mut().zip(&self.groups) {
            let mut a = [0.0; 16];
            for r in 0..grp.k {
                for c in 0..grp.k {
                    a[4 * r + c] = -h * f * grp.b[4 * r + c];
                }
                a[5 * r] += 1.0 + h * grp.rates[r];
            }
            match spd_inverse(&a, grp.k) {
                Some((ainv, det)) => {
                    *inv = ainv;
                    prod *= det;
                    if !(PRODUCT_RANGE.0..PRODUCT_RANGE.1).contains(&prod) {
                        log_det += prod.ln();
                        prod = 1.0;
                    }
                }
                None => ok = false,
            }
        }
        log_det += prod.ln();
        e.log_det = (ok && log_det.is_finite()).then_some(self.components as f64 * log_det);
    }

    /// The proposal from `self.current` with noise `self.z` into `self.proposal.a`;
    /// `false` if `A_a` is not positive definite.
    fn propose(&mut self) -> bool {
        let cur = &self.current;
        if cur.log_det.is_none() {
            return false;
        }
        let (n, np, h, f, sc) = (
            self.n(),
            2 * self.pairs.len(),
            self.half_dt,
            cur.force,
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

    /// `ln α` of the move `current → proposal` (both evaluated) made with noise `self.z`.
    fn log_acceptance(&self) -> f64 {
        let (cur, prop) = (&self.current, &self.proposal);
        let (Some(ld), Some(ld_p)) = (cur.log_det, prop.log_det) else {
            return f64::NEG_INFINITY;
        };
        let (n, h, fp) = (self.n(), self.half_dt, prop.force);
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

impl Trajectory for ModalMetropolis<'_> {
    /// One Metropolis-adjusted step: the normals (all components), then one uniform, as the
    /// banded scheme draws them. Allocation-free.
    fn step(&mut self, rng: &mut TrajectoryRng) {
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
            inverse: Vec::new(),
            group_inverse: Vec::new(),
            log_det: None,
        }
    }
}

/// The inverse and determinant of the symmetric `k × k` matrix `a` (row-major, stride 4,
/// `k ≤ 4`) by Cholesky; `None` unless positive definite.
fn spd_inverse(a: &[f64; 16], k: usize) -> Option<([f64; 16], f64)> {
    let mut l = [0.0; 16];
    let mut det = 1.0;
    for j in 0..k {
        let d = a[5 * j] - (0..j).map(|p| l[4 * j + p] * l[4 * j + p]).sum::<f64>();
        if d.is_nan() || d <= 0.0 {
            return None;
        }
        let ljj = d.sqrt();
        l[5 * j] = ljj;
        det *= d;
        for i in j + 1..k {
            let s = a[4 * i + j] - (0..j).map(|p| l[4 * i + p] * l[4 * j + p]).sum::<f64>();
            l[4 * i + j] = s / ljj;
        }
    }
    // columns of L⁻¹ by forward substitution, then A⁻¹ = L⁻ᵀ L⁻¹
    let mut li = [0.0; 16];
    for c in 0..k {
        for i in c..k {
            let rhs = if i == c { 1.0 } else { 0.0 };
            let s = rhs - (c..i).map(|p| l[4 * i + p] * li[4 * p + c]).sum::<f64>();
            li[4 * i + c] = s / l[5 * i];
        }
    }
    let mut inv = [0.0; 16];
    for r in 0..k {
        for c in 0..k {
            inv[4 * r + c] = (r.max(c)..k).map(|p| li[4 * p + r] * li[4 * p + c]).sum();
        }
    }
    Some((inv, det))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::FilamentParams;
    use crate::fem::beam::BeamModel;
    use crate::fem::mesh::Mesh;
    use crate::rng::trajectory_rng;
    use nalgebra::{DMatrix, DVector};

    fn model(dims: usize, ne: usize, strain_ratio: f64) -> CompressedFilament {
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
}
