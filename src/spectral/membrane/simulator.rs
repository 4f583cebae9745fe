//! Exact modal simulator of the membrane (M1): the membrane's spectral reference, the
//! analogue of [`crate::spectral::simulator::ModalSimulator`] for the filament.
//!
//! The height is truncated to a list of real modes, h(r, t) = Σ_φ a_φ(t) φ(r), and each
//! amplitude is advanced by its exact Ornstein–Uhlenbeck transition (M2)
//!
//! a ← a e^{−λΔt} + σ_φ √(1 − e^{−2λΔt}) Z,  Z ~ N(0, 1) independent, σ_φ² = ⟨a²⟩ (M3),
//!
//! so the law of the amplitudes on the time grid is exact at any Δt. The only approximation
//! is the truncation, and the simulator gives the exact references *of the truncated
//! field* as finite sums over its own modes ([`MembraneSimulator::covariance`],
//! [`MembraneSimulator::correlation_from_rest`]); [`Membrane::point_variance`] and
//! [`Membrane::correlation`] give the untruncated ones with their bounds.

use super::sums::Kernel;
use super::{Membrane, MembraneBoundary, MembraneMode, ModeShape};
use crate::error::{Error, Result, require_positive};
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};

/// The most modes a simulator carries.
pub const MAX_SIMULATED_MODES: usize = 1 << 20;

/// Exact modal solution of (M1) over a fixed list of real modes, on a fixed time grid.
///
/// Random numbers: [`MembraneSimulator::step`] and [`MembraneSimulator::set_equilibrium`]
/// draw exactly one standard normal per mode (`rand_distr::StandardNormal`) in the order of
/// [`MembraneSimulator::modes`].
#[derive(Debug, Clone)]
pub struct MembraneSimulator {
    membrane: Membrane,
    modes: Vec<MembraneMode>,
    dt: f64,
    amplitudes: Vec<f64>,
    /// ⟨a²⟩ per mode (M3).
    variance: Vec<f64>,
    /// λ per mode.
    rate: Vec<f64>,
    /// e^{−λΔt}.
    decay: Vec<f64>,
    /// σ √(1 − e^{−2λΔt}).
    noise_sd: Vec<f64>,
}

impl MembraneSimulator {
    /// A simulator of `modes` (each a real mode of `membrane`, no repeats) with step `dt`,
    /// at rest.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if `modes` is empty, longer than
    /// [`MAX_SIMULATED_MODES`], holds a mode twice or a lattice point that is not a mode of
    /// this geometry (naming it), or `dt` is not finite and > 0.
    pub fn new(membrane: Membrane, modes: Vec<MembraneMode>, dt: f64) -> Result<Self> {
        require_positive("dt", dt)?;
        if modes.is_empty() || modes.len() > MAX_SIMULATED_MODES {
            return Err(Error::invalid(
                "number of modes",
                modes.len(),
                format!("in [1, {MAX_SIMULATED_MODES}]"),
            ));
        }
        let mut seen = std::collections::HashSet::with_capacity(modes.len());
        for mode in &modes {
            if !membrane.is_mode(*mode) || !seen.insert(*mode) {
                return Err(Error::invalid(
                    "mode",
                    format!("{mode:?}"),
                    format!(
                        "a real mode of this {} membrane, listed once",
                        membrane.params.boundary.name()
                    ),
                ));
            }
        }
        let variance: Vec<f64> = modes.iter().map(|m| membrane.mode_variance(*m)).collect();
        let rate: Vec<f64> = modes.iter().map(|m| membrane.mode_rate(*m)).collect();
        let decay = rate.iter().map(|r| (-r * dt).exp()).collect();
        let noise_sd = variance
            .iter()
            .zip(&rate)
            .map(|(v, r)| v.sqrt() * (-(-2.0 * r * dt).exp_m1()).sqrt())
            .collect();
        Ok(MembraneSimulator {
            membrane,
            amplitudes: vec![0.0; modes.len()],
            modes,
            dt,
            variance,
            rate,
            decay,
            noise_sd,
        })
    }

    /// The modes of the index rectangle: simply supported, 1 ≤ m ≤ `mx`, 1 ≤ n ≤ `my`;
    /// periodic, the half-lattice points with |m| ≤ `mx`, |n| ≤ `my` (both shapes), in
    /// the order of [`Membrane::modes_within`] (slowest first).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `mx` or `my` if it is 0 (or, with the other,
    /// would give more than [`MAX_SIMULATED_MODES`] modes).
    pub fn index_rectangle(membrane: &Membrane, mx: usize, my: usize) -> Result<Vec<MembraneMode>> {
        for (key, v) in [("mx", mx), ("my", my)] {
            if v == 0 || v > MAX_SIMULATED_MODES {
                return Err(Error::invalid(
                    key,
                    v,
                    format!("in [1, {MAX_SIMULATED_MODES}]"),
                ));
            }
        }
        let (ix, iy) = (mx as i64, my as i64);
        let count = match membrane.params.boundary {
            MembraneBoundary::SimplySupported => mx as u128 * my as u128,
            MembraneBoundary::Periodic => (2 * mx as u128 + 1) * (2 * my as u128 + 1) - 1,
        };
        if count > MAX_SIMULATED_MODES as u128 {
            return Err(Error::invalid(
                "mx",
                mx,
                format!("with my = {my}, at most {MAX_SIMULATED_MODES} modes (got {count})"),
            ));
        }
        let mut list: Vec<(f64, MembraneMode)> = Vec::new();
        match membrane.params.boundary {
            MembraneBoundary::SimplySupported => {
                for m in 1..=ix {
                    for n in 1..=iy {
                        let mode = MembraneMode {
                            m,
                            n,
                            shape: ModeShape::SineSine,
                        };
                        list.push((membrane.wavenumber_sq(mode), mode));
                    }
                }
            }
            MembraneBoundary::Periodic => {
                for m in 0..=ix {
                    for n in -iy..=iy {
                        for shape in [ModeShape::Cosine, ModeShape::Sine] {
                            let mode = MembraneMode { m, n, shape };
                            if membrane.is_mode(mode) {
                                list.push((membrane.wavenumber_sq(mode), mode));
                            }
                        }
                    }
                }
            }
        }
        list.sort_by(|(qa, a), (qb, b)| {
            qa.total_cmp(qb)
                .then((a.m, a.n, a.shape).cmp(&(b.m, b.n, b.shape)))
        });
        Ok(list.into_iter().map(|(_, m)| m).collect())
    }

    /// Every amplitude 0 (h(r, 0) = 0, the initial condition of (M4)).
    pub fn set_rest(&mut self) {
        self.amplitudes.fill(0.0);
    }

    /// Amplitudes drawn from the stationary law (M3), in mode order.
    pub fn set_equilibrium<R: Rng + ?Sized>(&mut self, rng: &mut R) {
        for (a, v) in self.amplitudes.iter_mut().zip(&self.variance) {
            let z: f64 = StandardNormal.sample(rng);
            *a = v.sqrt() * z;
        }
    }

    /// One exact OU transition of every mode, in mode order.
    pub fn step<R: Rng + ?Sized>(&mut self, rng: &mut R) {
        for ((a, rho), s) in self
            .amplitudes
            .iter_mut()
            .zip(&self.decay)
            .zip(&self.noise_sd)
        {
            let z: f64 = StandardNormal.sample(rng);
            *a = *a * rho + s * z;
        }
    }

    /// The modes, in the order of the amplitudes.
    pub fn modes(&self) -> &[MembraneMode] {
        &self.modes
    }

    /// The amplitudes a_φ.
    pub fn amplitudes(&self) -> &[f64] {
        &self.amplitudes
    }

    /// The time step.
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// The membrane.
    pub fn membrane(&self) -> &Membrane {
        &self.membrane
    }

    /// The height h(x, y) = Σ a_φ φ(x, y) (NaN outside the rectangle).
    pub fn height(&self, x: f64, y: f64) -> f64 {
        self.modes
            .iter()
            .zip(&self.amplitudes)
            .map(|(m, a)| a * self.membrane.mode_shape(*m, x, y))
            .sum()
    }

    /// The exact stationary covariance ⟨h(r) h(r′)⟩ = Σ ⟨a²⟩ φ(r) φ(r′) of the truncated
    /// field (NaN outside the rectangle).
    pub fn covariance(&self, r: (f64, f64), r2: (f64, f64)) -> f64 {
        self.mode_sum(r, r2, |_| 1.0)
    }

    /// The exact ⟨h(r, t) h(r′, η)⟩ from rest (t ≤ η) of the truncated field, (M4) over
    /// the simulated modes: Σ ⟨a²⟩ φ(r) φ(r′) (e^{−λ(η−t)} − e^{−λ(η+t)}).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] if t < 0, η < t or a time is not finite.
    pub fn correlation_from_rest(
        &self,
        r: (f64, f64),
        r2: (f64, f64),
        t: f64,
        eta: f64,
    ) -> Result<f64> {
        crate::spectral::check_two_times(t, eta, "(M4)")?;
        let kernel = Kernel::FromRest { t, eta };
        Ok(self.mode_sum(r, r2, |rate| kernel.factor(rate)))
    }

    /// The terms `(⟨a²⟩φ(r)², e^{−λΔt})` of the height's autocovariance at `r` after `k`
    /// steps, `⟨h(r, t) h(r, t + kΔt)⟩ = Σ ⟨a²⟩φ(r)² e^{−λkΔt}` (the modes are independent
    /// AR(1) sequences): their weights sum to [`Self::covariance`] at `(r, r)`.
    pub fn point_terms(&self, r: (f64, f64)) -> Vec<(f64, f64)> {
        let mb = &self.membrane;
        self.modes
            .iter()
            .zip(self.variance.iter().zip(&self.decay))
            .map(|(m, (v, d))| (v * mb.mode_shape(*m, r.0, r.1).powi(2), *d))
            .collect()
    }

    fn mode_sum(&self, r: (f64, f64), r2: (f64, f64), factor: impl Fn(f64) -> f64) -> f64 {
        let mb = &self.membrane;
        self.modes
            .iter()
            .zip(self.variance.iter().zip(&self.rate))
            .map(|(m, (v, rate))| {
                v * mb.mode_shape(*m, r.0, r.1) * mb.mode_shape(*m, r2.0, r2.1) * factor(*rate)
            })
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::trajectory_rng;

    const SEED: u64 = 0x3E3B_0001;

    fn membrane(boundary: MembraneBoundary, tension: f64) -> Membrane {
        super::super::test_membrane(boundary, tension)
    }

    // What: the update is a ← a e^{−λΔt} + σ√(1 − e^{−2λΔt}) Z in mode order, and the
    // equilibrium draw σZ. Reference: the formula evaluated with a clone of the generator.
    // Tolerance: bit-exact (the same operations).
    #[test]
    fn update_formula_and_draw_order() {
        let mb = membrane(MembraneBoundary::SimplySupported, 2.0);
        let modes = MembraneSimulator::index_rectangle(&mb, 3, 2).unwrap();
        let mut s = MembraneSimulator::new(mb, modes.clone(), 0.01).unwrap();
        let mut rng = trajectory_rng(SEED, 0);
        let mut twin = rng.clone();
        s.set_equilibrium(&mut rng);
        let mut expect: Vec<f64> = modes
            .iter()
            .map(|m| {
                let z: f64 = StandardNormal.sample(&mut twin);
                mb.mode_variance(*m).sqrt() * z
            })
            .collect();
        assert_eq!(s.amplitudes(), &expect[..]);
        s.step(&mut rng);
        for (a, m) in expect.iter_mut().zip(&modes) {
            let x = mb.mode_rate(*m) * 0.01;
            let z: f64 = StandardNormal.sample(&mut twin);
            *a = *a * (-x).exp() + mb.mode_variance(*m).sqrt() * (-(-2.0 * x).exp_m1()).sqrt() * z;
        }
        assert_eq!(s.amplitudes(), &expect[..]);
        let (x, y) = (0.3, 0.2);
        let direct: f64 = modes
            .iter()
            .zip(&expect)
            .map(|(m, a)| a * mb.mode_shape(*m, x, y))
            .sum();
        assert!((s.height(x, y) - direct).abs() <= 1e-14 * direct.abs().max(1e-3));
        assert_eq!(s.height(0.0, y), 0.0);
    }

    // What: the index rectangle holds mx·my simply supported modes and
    // (2mx+1)(2my+1) − 1 periodic ones, every one a mode, slowest first; bad input refused.
    #[test]
    fn index_rectangle_counts_and_order() {
        let ss = membrane(MembraneBoundary::SimplySupported, 0.0);
        let l = MembraneSimulator::index_rectangle(&ss, 4, 3).unwrap();
        assert_eq!(l.len(), 12);
        let per = membrane(MembraneBoundary::Periodic, 0.0);
        let p = MembraneSimulator::index_rectangle(&per, 2, 3).unwrap();
        assert_eq!(p.len(), 5 * 7 - 1);
        for (mb, list) in [(ss, &l), (per, &p)] {
            assert!(list.iter().all(|m| mb.is_mode(*m)));
            assert!(
                list.windows(2)
                    .all(|w| mb.wavenumber_sq(w[0]) <= mb.wavenumber_sq(w[1]))
            );
        }
        assert!(MembraneSimulator::index_rectangle(&ss, 0, 3).is_err());
        let dup = vec![l[0], l[0]];
        assert!(MembraneSimulator::new(ss, dup, 0.1).is_err());
        assert!(MembraneSimulator::new(ss, l.clone(), 0.0).is_err());
        assert!(MembraneSimulator::new(ss, p.clone(), 0.1).is_err());
    }

    // What: the truncated covariance and correlation converge to the untruncated (M4)
    // and point variance as the index rectangle grows. Reference:
    // Membrane::point_variance and Membrane::correlation (rigorous bounds 1e-12 of the
    // scale). Tolerance: the truncation error of a 160 × 160 rectangle; the 4 × 4
    // rectangle is far off (the test would notice a wrong sum).
    #[test]
    fn truncated_sums_converge_to_the_continuum() {
        for (boundary, tension) in [
            (MembraneBoundary::SimplySupported, 0.0),
            (MembraneBoundary::Periodic, 5.0),
        ] {
            let mb = membrane(boundary, tension);
            let r = (0.4, 0.35);
            let exact = mb.point_variance(r.0, r.1, 1e-12).unwrap().value;
            let big = MembraneSimulator::index_rectangle(&mb, 160, 160).unwrap();
            let s = MembraneSimulator::new(mb, big, 0.1).unwrap();
            let rel = (s.covariance(r, r) - exact).abs() / exact;
            assert!(rel < 2e-4, "{boundary:?}: {rel:e}");
            let small = MembraneSimulator::index_rectangle(&mb, 1, 1).unwrap();
            let s1 = MembraneSimulator::new(mb, small, 0.1).unwrap();
            assert!((s1.covariance(r, r) - exact).abs() / exact > 1e-2);
            let (t, eta) = (0.002, 0.005);
            let c = mb.correlation(r, (0.6, 0.35), t, eta, 1e-12).unwrap().value;
            let cs = s.correlation_from_rest(r, (0.6, 0.35), t, eta).unwrap();
            assert!((cs - c).abs() <= 1e-3 * exact, "{boundary:?}: {cs} vs {c}");
            assert!(s.correlation_from_rest(r, r, 0.3, 0.2).is_err());
        }
    }

    // What: the simulated field has the covariance the simulator claims: from rest, the
    // two-time product ⟨h(r, t) h(r′, η)⟩ over 4000 independent trajectories, and at
    // equilibrium ⟨h(r)²⟩ over 4000 draws. Reference: the exact truncated sums. Test: z
    // = (mean − exact)/s.e. with the sample standard error of independent products,
    // |z| < 4.5 (two tests, fixed seed; a 10 % error in the variances gives |z| ≈ 5–10).
    #[test]
    fn monte_carlo_matches_the_truncated_sums() {
        let mb = membrane(MembraneBoundary::SimplySupported, 1.0);
        let modes = MembraneSimulator::index_rectangle(&mb, 6, 6).unwrap();
        let dt = 0.002;
        let (r, r2) = ((0.5, 0.35), (0.3, 0.35));
        let (ts, es) = (3u32, 7u32);
        let n = 4000;
        let mut prod = Vec::with_capacity(n);
        let mut sq = Vec::with_capacity(n);
        let mut s = MembraneSimulator::new(mb, modes, dt).unwrap();
        for j in 0..n as u64 {
            let mut rng = trajectory_rng(SEED, 100 + j);
            s.set_rest();
            let mut at_t = 0.0;
            for k in 1..=es {
                s.step(&mut rng);
                if k == ts {
                    at_t = s.height(r.0, r.1);
                }
            }
            prod.push(at_t * s.height(r2.0, r2.1));
            s.set_equilibrium(&mut rng);
            sq.push(s.height(r.0, r.1).powi(2));
        }
        let z = |v: &[f64], exact: f64| {
            let m = v.iter().sum::<f64>() / v.len() as f64;
            let var = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (v.len() - 1) as f64;
            (m - exact) / (var / v.len() as f64).sqrt()
        };
        let exact_tt = s
            .correlation_from_rest(r, r2, ts as f64 * dt, es as f64 * dt)
            .unwrap();
        let z_tt = z(&prod, exact_tt);
        assert!(z_tt.abs() < 4.5, "two-time z = {z_tt}");
        let exact_sq = s.covariance(r, r);
        let z_sq = z(&sq, exact_sq);
        assert!(z_sq.abs() < 4.5, "variance z = {z_sq}");
        // A known wrong answer is rejected: the variance 10 % too large.
        assert!(z(&sq, 1.1 * exact_sq).abs() > 4.5);
    }
}
