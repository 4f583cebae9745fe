//! The stored-length law a *linear scheme* samples, and the ⟨F⟩(ε) it predicts: how far
//! the paper's explicit scheme with its element-uniform noise (eq. 5) is expected to sit
//! from the exact equilibrium theory of Fig. 2.
//!
//! The exact theory ([`super::compression`]) tilts the law of the stored length
//! `s = wᵀGw/(2L)` under the bending Gaussian `w ~ N(0, kT K⁻¹)` by the stretching energy.
//! A scheme that is not fluctuation–dissipation exact samples, for the bending part, a
//! different Gaussian: its exact discrete stationary covariance
//! `Σ_w = Φ S Φᵀ` ([`DiscreteLaw`]: the element-uniform load's per-mode deficit, about
//! `(iπh/L)²/12` below equipartition, and the explicit step's `1/(1 − λΔt/2)` included).
//! Replacing `kT K⁻¹` by `Σ_w` gives the weights `c_i`, the eigenvalues of
//! `L_Σᵀ G L_Σ/(2L)` (`Σ_w = L_Σ L_Σᵀ`), and, tilted in the same way, the *linear-response
//! prediction* of the scheme's ⟨F⟩.
//!
//! It is a prediction, not an exact law: with noise that is not fluctuation–dissipation
//! exact the stationary density of the nonlinear dynamics is not the Boltzmann weight of
//! the stretching energy times that Gaussian. It is exact for the bending part (the modes
//! the stretching hardly couples: those whose buckling load is far above ⟨F⟩, which carry
//! most of the deficit) and is used to bound the systematic deviation the scenes
//! `fig2-paper-2d` and `fig2-paper-3d` must tolerate, not as their reference.

use super::compression::{CompressionTheory, Dims, StoredLengthLaw};
use crate::dynamics::{DiscreteLaw, Family, IntegratorKind};
use crate::error::{Error, Result};
use crate::fem::area::AreaMembrane;
use crate::fem::beam::BeamModel;
use crate::fem::mesh::Mesh;
use crate::fem::modal::generalized_modes;
use crate::fem::noise::NoiseModel;
use crate::fem::plate_area::{AreaParams, AreaTheory};
use crate::fem::plate_modes::PlateModes;
use crate::params::FilamentParams;
use nalgebra::DMatrix;

/// The stored-length law of the Gaussian a linear `integrator` with `noise` at step `dt`
/// samples for the bending part of a uniform mesh of `n_elements` (see the module docs):
/// weights the eigenvalues of `L_Σᵀ G L_Σ/(2L)`, one copy per transverse component.
///
/// # Errors
/// Invalid parameters or mesh; an unstable step (a mode with `|m| ≥ 1`);
/// a weight that is not finite.
pub fn scheme_stored_length_law(
    params: &FilamentParams,
    dims: Dims,
    n_elements: usize,
    integrator: IntegratorKind,
    noise: NoiseModel,
    dt: f64,
) -> Result<StoredLengthLaw> {
    let beam = BeamModel::new(*params, Mesh::uniform(params.length, n_elements)?)?;
    let modes = generalized_modes(&beam)?;
    let law = DiscreteLaw::new(&beam, &modes, integrator, noise, dt)?;
    // In modal coordinates w = Φq, q ~ N(0, S): s = qᵀ(ΦᵀGΦ)q/(2L), whose weights are the
    // eigenvalues of S^{1/2} ΦᵀGΦ S^{1/2}/(2L) (S^{1/2} from S's symmetric eigensystem: the
    // element-uniform load has rank n_elements, so S is poorly conditioned for Cholesky).
    let s = (&law.stationary + law.stationary.transpose()) * 0.5;
    let eig = s.symmetric_eigen();
    let root = &eig.eigenvectors
        * DMatrix::from_diagonal(&eig.eigenvalues.map(|v| v.max(0.0).sqrt()))
        * eig.eigenvectors.transpose();
    let phi = &modes.vectors;
    let g = phi.transpose() * beam.geometric().to_dense() * phi;
    let m = &root * g * &root / (2.0 * params.length);
    let m = (&m + m.transpose()) * 0.5;
    let weights: Vec<f64> = m
        .symmetric_eigenvalues()
        .iter()
        .map(|v| v.max(0.0))
        .collect();
    StoredLengthLaw::from_weights(weights, dims.copies())
}

/// The linear-response prediction of ⟨F⟩/F_c0 at each `strain_ratios` entry (ε/ε_c0) for a
/// scheme (see the module docs), with the exact discrete theory beside it: pairs
/// `(prediction, exact)`.
///
/// # Errors
/// As [`scheme_stored_length_law`] and [`CompressionTheory::force_ratio`].
pub fn scheme_force_ratios(
    params: &FilamentParams,
    dims: Dims,
    n_elements: usize,
    integrator: IntegratorKind,
    noise: NoiseModel,
    dt: f64,
    strain_ratios: &[f64],
) -> Result<Vec<(f64, f64)>> {
    let scheme = CompressionTheory::new(
        params,
        scheme_stored_length_law(params, dims, n_elements, integrator, noise, dt)?,
    )?;
    let exact =
        CompressionTheory::new(params, StoredLengthLaw::discrete(params, dims, n_elements)?)?;
    strain_ratios
        .iter()
        .map(|&r| Ok((scheme.force_ratio(r)?, exact.force_ratio(r)?)))
        .collect()
}

/// The stored-area law a θ-scheme with consistent noise at step `dt` samples for the
/// bending part of the membrane `model` under imposed area (issue #28: the paper's
/// explicit scheme, θ = 0, as the membrane's analogue of Fig. 2's), in the plate's
/// separated modes `modes`: per mode the variance `kT/(λ(1 + (θ − ½)λΔt))` (the θ-scheme's
/// exact stationary variance of `ȧ = −λa + noise`; `1/(1 − λΔt/2)` for the explicit step),
/// and the weights the eigenvalues of `Σ_b^{½} B_b Σ_b^{½}/(2A₀)` per geometric block
/// (`B_b` the true area matrix: a reference). At a vanishing step this is
/// [`crate::fem::plate_area::area_law`] of the mesh.
///
/// # Errors
/// Invalid parameters for a non-θ integrator or an unstable step (a mode with
/// `1 + (θ − ½)λΔt ≤ 0`); a weight that is not finite.
pub fn scheme_area_law(
    model: &AreaMembrane,
    modes: &PlateModes,
    integrator: IntegratorKind,
    dt: f64,
) -> Result<StoredLengthLaw> {
    let Family::Theta(theta) = integrator.family() else {
        return Err(Error::invalid(
            "integrator",
            integrator,
            "a theta-scheme (euler-maruyama, backward-euler, crank-nicolson)",
        ));
    };
    let p = model.plate().params();
    let (kt, two_area) = (p.kt, 2.0 * p.area());
    let zero = modes.zero_mode();
    let mut weights = Vec::with_capacity(modes.n_modes());
    for block in modes.geometric_blocks() {
        let kept: Vec<usize> = (0..block.modes.len())
            .filter(|&r| Some(block.modes[r]) != zero)
            .collect();
        let kb = block.modes.len();
        let root: Vec<f64> = kept
            .iter()
            .map(|&r| {
                let lam = modes.modes()[block.modes[r]].rate;
                let factor = 1.0 + (theta - 0.5) * lam * dt;
                if factor > 0.0 {
                    Ok((kt / (lam * factor)).sqrt())
                } else {
                    Err(Error::invalid(
                        "dt",
                        dt,
                        format!("below the stability limit {:e} of the step", 2.0 / lam),
                    ))
                }
            })
            .collect::<Result<_>>()?;
        let k = kept.len();
        let m = DMatrix::from_fn(k, k, |i, j| {
            root[i] * block.matrix[kept[i] * kb + kept[j]] * root[j] / two_area
        });
        let m = (&m + m.transpose()) * 0.5;
        weights.extend(m.symmetric_eigenvalues().iter().map(|v| v.max(0.0)));
    }
    StoredLengthLaw::from_weights(weights, 1)
}

/// The linear-response prediction of ⟨F⟩/σ_c0 = −⟨σ⟩/σ_c0 at each `strain_ratios` entry
/// (ε/ε_c0) for a θ-scheme on the membrane under imposed area ([`scheme_area_law`]), with
/// the exact discrete theory of the mesh beside it: pairs `(prediction, exact)`.
///
/// # Errors
/// As [`scheme_area_law`] and the theories' tension.
pub fn scheme_area_force_ratios(
    model: &AreaMembrane,
    modes: &PlateModes,
    integrator: IntegratorKind,
    dt: f64,
    strain_ratios: &[f64],
) -> Result<Vec<(f64, f64)>> {
    let params = AreaParams::from_membrane(model.plate().params(), model.area_modulus());
    let (nx, ny) = model.plate().elements();
    let scheme = AreaTheory::new(&params, scheme_area_law(model, modes, integrator, dt)?)?;
    let exact = AreaTheory::discrete(&params, nx, ny)?;
    strain_ratios
        .iter()
        .map(|&r| Ok((-scheme.tension_ratio(r)?, -exact.tension_ratio(r)?)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Fig. 2 filament: EI/(kT L) = 100, EA L/kT = 1e6, L = kT = ξ = 1.
    fn fig2() -> FilamentParams {
        FilamentParams {
            length: 1.0,
            bending_rigidity: 100.0,
            stretch_rigidity: 1e6,
            drag: 1.0,
            kt: 1.0,
        }
    }

    /// The oracle first: a fluctuation–dissipation-exact scheme (consistent noise) at a
    /// vanishing step samples kT K⁻¹, so its law's weights and its ⟨F⟩ are the exact
    /// discrete theory's (to the eigen-solver's rounding).
    #[test]
    fn consistent_noise_at_small_step_gives_the_exact_discrete_theory() {
        let p = fig2();
        let dt = 1e-9 * p.tau1();
        for dims in [Dims::Two, Dims::Three] {
            let law = scheme_stored_length_law(
                &p,
                dims,
                10,
                IntegratorKind::CrankNicolson,
                NoiseModel::Consistent,
                dt,
            )
            .unwrap();
            let exact = StoredLengthLaw::discrete(&p, dims, 10).unwrap();
            assert!(
                (law.mean() - exact.mean()).abs() < 1e-7 * exact.mean(),
                "{} vs {}",
                law.mean(),
                exact.mean()
            );
            let f = scheme_force_ratios(
                &p,
                dims,
                10,
                IntegratorKind::CrankNicolson,
                NoiseModel::Consistent,
                dt,
                &[0.0, 2.0, 6.0],
            )
            .unwrap();
            for (a, b) in f {
                assert!((a - b).abs() < 1e-6, "{dims:?}: {a} vs {b}");
            }
        }
    }

    /// The element-uniform load stores less length than equipartition (each mode below
    /// kT/λ): the paper's scheme's predicted ⟨s⟩ lies below the exact one, by the
    /// per-mode deficits (≈ 0.8 % for mode 1 alone, more for higher modes).
    #[test]
    fn element_uniform_noise_stores_less_length() {
        let p = fig2();
        let dt = 0.5 * p.tau1() * 7.7e-6;
        let law = scheme_stored_length_law(
            &p,
            Dims::Two,
            10,
            IntegratorKind::EulerMaruyama,
            NoiseModel::ElementUniform,
            dt,
        )
        .unwrap();
        let exact = StoredLengthLaw::discrete(&p, Dims::Two, 10).unwrap();
        let ratio = law.mean() / exact.mean();
        assert!(ratio < 0.995 && ratio > 0.9, "ratio {ratio}");
    }

    /// The predicted deviations of the paper's scheme on the scenes' strains, as the
    /// documentation quotes them (`docs/src/reference/statistics.md`): with the
    /// element-uniform noise ⟨F⟩ lies above the exact theory (less stored length, less
    /// tension), by 0.037 F_c0 at ε = 0 in 2D and 0.068 in 3D, falling to < 0.01 deep in
    /// the buckled branch; with consistent noise only the explicit step's stiff-mode
    /// variance is left, −0.017 (2D) and −0.032 (3D) at ε = 0 at 7e-6 τ1, −0.003 and −0.006
    /// at half that step (the top mode's 1/(1 − λΔt/2) is far from linear near the limit).
    /// Run with `--nocapture` to see the table.
    #[test]
    fn predicted_deviations_of_the_papers_scheme() {
        let p = fig2();
        let strains = [0.0, 2.0, 6.0];
        let mut table = Vec::new();
        for dims in [Dims::Two, Dims::Three] {
            for dt_tau1 in [7.0e-6, 3.5e-6] {
                for noise in [NoiseModel::ElementUniform, NoiseModel::Consistent] {
                    let f = scheme_force_ratios(
                        &p,
                        dims,
                        10,
                        IntegratorKind::EulerMaruyama,
                        noise,
                        dt_tau1 * p.tau1(),
                        &strains,
                    )
                    .unwrap();
                    let d: Vec<f64> = f.iter().map(|(a, b)| a - b).collect();
                    println!("{dims:?} dt {dt_tau1:e} tau1 {noise}: {d:+.4?}");
                    table.push((dims, dt_tau1, noise, d));
                }
            }
        }
        let at = |dims, dt, noise| {
            table
                .iter()
                .find(|(d, t, n, _)| *d == dims && *t == dt && *n == noise)
                .map(|r| r.3.clone())
                .unwrap()
        };
        let eu2 = at(Dims::Two, 7.0e-6, NoiseModel::ElementUniform);
        let eu3 = at(Dims::Three, 7.0e-6, NoiseModel::ElementUniform);
        assert!((eu2[0] - 0.037).abs() < 0.002 && (eu3[0] - 0.068).abs() < 0.002);
        assert!(eu2.iter().chain(&eu3).all(|d| *d > 0.0 && *d < 0.07));
        let c2 = at(Dims::Two, 7.0e-6, NoiseModel::Consistent);
        let c2h = at(Dims::Two, 3.5e-6, NoiseModel::Consistent);
        assert!((c2[0] + 0.017).abs() < 0.002 && (c2h[0] + 0.0033).abs() < 0.001);
    }

    /// The membrane's oracle: consistent noise at a vanishing explicit step samples
    /// `kT K_b⁻¹`, so the scheme's area law and tension are the exact discrete theory's;
    /// at a finite explicit step the stiff modes' excess variance raises the excess area,
    /// so the predicted tension rises (⟨F⟩ falls) by an amount that halves with the step.
    #[test]
    fn membrane_scheme_law_is_the_exact_theory_at_a_vanishing_step() {
        use crate::spectral::membrane::{MembraneBoundary, MembraneParams};
        for boundary in [
            MembraneBoundary::SimplySupported,
            MembraneBoundary::Periodic,
        ] {
            let mp = MembraneParams {
                bending_rigidity: 20.0,
                width: 1.1,
                boundary,
                ..MembraneParams::default()
            };
            let model = AreaMembrane::new(mp, 4, 4, 1e5, 0.0).unwrap();
            let modes = PlateModes::new(model.plate()).unwrap();
            let lam_max = modes.modes().iter().map(|m| m.rate).fold(0.0, f64::max);
            let law = scheme_area_law(
                &model,
                &modes,
                IntegratorKind::EulerMaruyama,
                1e-12 / lam_max,
            )
            .unwrap();
            let params = AreaParams::from_membrane(&mp, 1e5);
            let exact = crate::fem::plate_area::area_law(
                &params,
                &crate::fem::plate_area::discrete_compliances(&params, 4, 4).unwrap(),
            )
            .unwrap();
            assert!(
                (law.mean() / exact.mean() - 1.0).abs() < 1e-9,
                "{boundary:?}: {} vs {}",
                law.mean(),
                exact.mean()
            );
            let shift = |dt: f64| {
                let [(pred, exact)] = scheme_area_force_ratios(
                    &model,
                    &modes,
                    IntegratorKind::EulerMaruyama,
                    dt,
                    &[0.5],
                )
                .unwrap()[..] else {
                    unreachable!()
                };
                pred - exact
            };
            let (coarse, fine) = (shift(0.4 / lam_max), shift(0.2 / lam_max));
            assert!(coarse < 0.0 && fine < 0.0, "{boundary:?}: {coarse}, {fine}");
            assert!(
                (coarse / fine - 2.0).abs() < 0.3,
                "{boundary:?}: first order in dt: {coarse} / {fine}"
            );
            assert!(
                scheme_area_law(&model, &modes, IntegratorKind::EulerMaruyama, 2.1 / lam_max)
                    .is_err()
            );
        }
    }
}
