//! The oracle of a membrane scene's references (issue #27): closed forms from the
//! membrane's parameters alone, with the tolerance of a known error bound, as for the
//! filament ([module docs](super)).
//!
//! - **Eigenvalues** of the Bogner–Fox–Schmit plate (uniform nx × ny mesh, simply
//!   supported or periodic): the discrete problem separates by wavevector into blocks of
//!   at most four unknowns, and the block of mode (m, n) holds the tensor product φ⊗ψ of
//!   the 1D Hermite-cubic Ritz modes of wavenumbers q_x and q_y. Hence, with
//!   δ = λ₁ᴰ/λ − 1 ∈ [0, (qh)⁴/720] the 1D (beam) eigenvalue error of the filament's oracle
//!   (×2 beyond qh = 2.5) and μ = ∫ψ′²/∫ψ² ∈ [q², q²√(1 + δ)] (Ritz from above for −d²/dx²;
//!   Cauchy–Schwarz ∫ψ′² = −∫ψψ″ ≤ (∫ψ²∫ψ″²)^½),
//!   `c_q ≤ ξλₕ ≤ κ[q_x⁴(1+δ_x) + 2q_x²q_y²√((1+δ_x)(1+δ_y)) + q_y⁴(1+δ_y)] + σ[μ_x + μ_y]`
//!   (the upper end of μ for σ ≥ 0, q² for σ < 0): Rayleigh–Ritz from above on the
//!   conforming space, and the Rayleigh quotient of φ⊗ψ. A 2 % error of κ in the shared
//!   plate leaves this band.
//! - **Integrator factors and multipliers**: the closed forms of the filament's oracle at
//!   `a = λₕΔt`; the stationary variance is checked with consistent noise (factor 1). The
//!   element-uniform load of a plate has no closed-form noise factor with a rigorous bound
//!   (its modes are not exact tensor products), so with it only the multiplier is checked.
//! - **Profile** ⟨h²(x, b/2)⟩ with consistent noise and an exact-variance integrator: the
//!   discrete field is the energy projection of the continuum field, independent of its
//!   error (a Gaussian field with precision K/kT), so its variance is at most the
//!   continuum's; the gap (about h² for a membrane) has no rigorous bound here, so the
//!   check is one-sided.
//! - **Spectral model**: per mode the variance kT/(c_q‖φ‖²) (‖φ‖² = A/4 simply supported,
//!   A/2 periodic) and the multiplier e^{−c_qΔt/ξ}, to round-off; the profile of the modes
//!   of the index rectangle below the continuum by at most the rigorous tail bound of the
//!   modes beyond the largest wavenumber the rectangle holds in every direction.

use super::{ASYMPTOTIC_KH, EIGEN_ROUNDOFF, EXACT, Oracle, integrator_closed_form, oracle_check};
use crate::dynamics::IntegratorKind;
use crate::fem::noise::NoiseModel;
use crate::scene::linear::LinearRun;
use crate::scene::{ModelKind, Scene};
use crate::spectral::membrane::{Membrane, MembraneBoundary, MembraneMode, MembraneParams};
use std::f64::consts::PI;

/// The membrane's checked modes and their wavevectors, from the parameters alone.
struct Lattice {
    params: MembraneParams,
    modes: Vec<MembraneMode>,
}

impl Lattice {
    /// Lattice spacing along x and y: π/a, π/b (simply supported) or 2π/a, 2π/b.
    fn spacing(&self) -> (f64, f64) {
        let f = match self.params.boundary {
            MembraneBoundary::SimplySupported => PI,
            MembraneBoundary::Periodic => 2.0 * PI,
        };
        (f / self.params.width, f / self.params.height)
    }

    /// (q_x, q_y) of `mode`.
    fn q(&self, mode: MembraneMode) -> (f64, f64) {
        let (kx, ky) = self.spacing();
        (kx * mode.m as f64, ky * mode.n as f64)
    }

    /// c_q = κq⁴ + σq².
    fn c(&self, mode: MembraneMode) -> f64 {
        let (qx, qy) = self.q(mode);
        let q2 = qx * qx + qy * qy;
        self.params.bending_rigidity * q2 * q2 + self.params.tension * q2
    }

    /// ‖φ‖² of a real mode: A/4 simply supported, A/2 periodic.
    fn norm_sq(&self) -> f64 {
        match self.params.boundary {
            MembraneBoundary::SimplySupported => self.params.area() / 4.0,
            MembraneBoundary::Periodic => self.params.area() / 2.0,
        }
    }
}

/// The 1D Hermite-cubic eigenvalue error bound at `kh`: (kh)⁴/720, twice that beyond
/// [`ASYMPTOTIC_KH`] (the filament's oracle).
fn beam_bound(kh: f64) -> f64 {
    let factor = if kh <= ASYMPTOTIC_KH { 1.0 } else { 2.0 };
    factor * kh.powi(4) / 720.0
}

/// The oracle of a membrane run (see the [module docs](self)).
pub(super) fn membrane_oracle(
    scene: &Scene,
    params: MembraneParams,
    run: &LinearRun,
    o: &mut Oracle,
) {
    let modes = Membrane::new(params).and_then(|mb| mb.modes(run.reference.modes.len()));
    let modes = match modes {
        Ok(m) => m,
        Err(e) => {
            o.notes.push(format!(
                "run {}: the membrane's modes could not be listed ({e}), so its references are not checked against the continuum",
                run.spec.name
            ));
            return;
        }
    };
    let lattice = Lattice { params, modes };
    match scene.model {
        ModelKind::Fem => plate_oracle(scene, &lattice, run, o),
        ModelKind::Spectral => spectral_oracle(scene, &lattice, run, o),
        ModelKind::Compression => {}
    }
}

/// The plate's references: eigenvalue band, integrator factor (consistent noise) and
/// multiplier per mode, the one-sided profile.
fn plate_oracle(scene: &Scene, lattice: &Lattice, run: &LinearRun, o: &mut Oracle) {
    let p = &lattice.params;
    let r = &run.reference;
    let name = &run.spec.name;
    let hx = p.width / scene.mesh.elements as f64;
    let hy = p.height / scene.mesh.elements_along_y() as f64;
    for (mr, &mode) in r.modes.iter().zip(&lattice.modes) {
        let (qx, qy) = lattice.q(mode);
        let (dx, dy) = (beam_bound(qx * hx), beam_bound(qy * hy));
        let rate = lattice.c(mode) / p.drag;
        let mu = |q: f64, d: f64| {
            if p.tension >= 0.0 {
                q * q * (1.0 + d).sqrt()
            } else {
                q * q
            }
        };
        let upper = (p.bending_rigidity
            * (qx.powi(4) * (1.0 + dx)
                + 2.0 * qx * qx * qy * qy * ((1.0 + dx) * (1.0 + dy)).sqrt()
                + qy.powi(4) * (1.0 + dy))
            + p.tension * (mu(qx, dx) + mu(qy, dy)))
            / p.drag;
        let rate_h = p.kt / mr.variance_equipartition;
        let roundoff = EIGEN_ROUNDOFF * r.max_rate / rate_h.min(rate);
        let label = format!("({}, {})", mode.m, mode.n);
        o.checks.push(oracle_check(
            format!("{name}/oracle-eigenvalue/n={}", mr.n),
            rate_h / rate - 1.0,
            0.0,
            (-roundoff, upper / rate - 1.0 + roundoff),
            format!(
                "lambda_h/lambda - 1 of plate mode {label} (q_x h_x = {:.3}, q_y h_y = {:.3}) against Rayleigh-Ritz from above and the Rayleigh quotient of the product of the 1D Hermite modes, whose errors are at most (qh)^4/720",
                qx * hx,
                qy * hy
            ),
        ));
        let (integ, m_closed) = integrator_closed_form(run.spec.integrator, rate_h * r.dt);
        if run.spec.noise == NoiseModel::Consistent {
            let tol = (EXACT + roundoff) * integ;
            o.checks.push(oracle_check(
                format!("{name}/oracle-variance/n={}", mr.n),
                mr.variance_discrete / mr.variance_equipartition,
                integ,
                (-tol, tol),
                format!(
                    "stationary variance / (kT/lambda_h) of plate mode {label} against the {} factor {integ:.6} with consistent noise (lambda_h dt = {:.4e})",
                    run.spec.integrator,
                    rate_h * r.dt
                ),
            ));
        }
        o.checks.push(oracle_check(
            format!("{name}/oracle-multiplier/n={}", mr.n),
            mr.multiplier,
            m_closed,
            (-EXACT, EXACT),
            format!(
                "one-step multiplier of plate mode {label} against the closed form of {} at lambda_h dt = {:.4e}",
                run.spec.integrator,
                rate_h * r.dt
            ),
        ));
    }
    if run.spec.noise != NoiseModel::Consistent {
        o.notes.push(format!(
            "run {name}: the element-uniform load of a plate has no closed-form noise factor with a rigorous bound, so its mode variances are checked against the discrete reference only (eigenvalues and multipliers are checked here)"
        ));
    }
    let exact_variance = matches!(
        run.spec.integrator,
        IntegratorKind::CrankNicolson | IntegratorKind::ExactModal
    );
    if run.spec.noise == NoiseModel::Consistent && exact_variance {
        for (j, &x) in r.profile_x.iter().enumerate() {
            let cont = r.profile_continuum[j];
            let tol = EXACT * cont + EIGEN_ROUNDOFF * r.max_rate / r.modes[0].rate_continuum * cont;
            o.checks.push(oracle_check(
                format!("{name}/oracle-profile/x={x:.4}"),
                r.profile_discrete[j],
                cont,
                (-cont, tol),
                format!(
                    "<h^2(x, b/2)> of the plate at most the continuum {cont:.6e} (the discrete field is the energy projection of the continuum's, independent of its error; one-sided, the gap {:.3e} has no rigorous bound)",
                    cont - r.profile_discrete[j]
                ),
            ));
        }
    } else if !r.profile_x.is_empty() {
        o.notes.push(format!(
            "run {name}: the plate's profile is bounded by the continuum only with consistent noise and an exact-variance integrator; its modes are checked instead"
        ));
    }
}

/// The membrane's exact modal simulator: per mode the variance and multiplier against the
/// closed forms; the profile of the index rectangle against the continuum within the
/// rigorous tail bound.
fn spectral_oracle(scene: &Scene, lattice: &Lattice, run: &LinearRun, o: &mut Oracle) {
    let p = &lattice.params;
    let r = &run.reference;
    let name = &run.spec.name;
    for (mr, &mode) in r.modes.iter().zip(&lattice.modes) {
        let c = lattice.c(mode);
        let var = p.kt / (c * lattice.norm_sq());
        let label = format!("({}, {})", mode.m, mode.n);
        o.checks.push(oracle_check(
            format!("{name}/oracle-variance/n={}", mr.n),
            mr.variance_discrete,
            var,
            (-EXACT * var, EXACT * var),
            format!(
                "stationary variance of mode {label} against kT/(c_q |phi|^2), c_q = kappa q^4 + sigma q^2 (M3)"
            ),
        ));
        let m = (-c / p.drag * r.dt).exp();
        o.checks.push(oracle_check(
            format!("{name}/oracle-multiplier/n={}", mr.n),
            mr.multiplier,
            m,
            (-EXACT, EXACT),
            format!("one-step multiplier of mode {label} against exp(-c_q dt/xi)"),
        ));
    }
    // Every mode outside the index rectangle has |q| above the largest wavenumber the
    // rectangle holds along both axes.
    let (kx, ky) = lattice.spacing();
    let held = (kx * scene.mesh.elements as f64).min(ky * scene.mesh.elements_along_y() as f64);
    let tail = Membrane::new(*p).map_or(f64::INFINITY, |mb| mb.variance_tail(held));
    for (j, &x) in r.profile_x.iter().enumerate() {
        let cont = r.profile_continuum[j];
        o.checks.push(oracle_check(
            format!("{name}/oracle-profile/x={x:.4}"),
            r.profile_discrete[j],
            cont,
            (-tail - EXACT * cont, EXACT * cont),
            format!(
                "<h^2(x, b/2)> of the simulated modes against the continuum (M5); the modes beyond |q| = {held:.4e} add between 0 and {tail:.3e} (rigorous lattice tail bound)"
            ),
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fault::{Fault, FaultKind};
    use crate::scene::load_scene;

    /// The built-in membrane scene `name` with an `n × n` mesh (or `n × n` modes).
    fn scene(name: &str, n: usize) -> Scene {
        let mut s = load_scene(name, None).expect("built-in scene");
        s.mesh.elements = n;
        s.mesh.elements_y = Some(n);
        s.sampling.modes = 6;
        s
    }

    /// The oracle accepts the plate's references for both boundaries, with and without
    /// tension, for every integrator of the scenes, on coarse to fine meshes, and checks
    /// the eigenvalue and multiplier of every mode; and the spectral simulator's.
    #[test]
    fn accepts_the_references_over_meshes() {
        for name in ["membrane-hinged", "membrane-periodic", "membrane-bilayer"] {
            for n in [4, 8, 12] {
                let sc = scene(name, n);
                for spec in &sc.runs {
                    let run = LinearRun::prepare(&sc, spec).expect("prepares");
                    let o = crate::verify::oracle::linear_oracle(&sc, &run);
                    let failed: Vec<_> = o.checks.iter().filter(|c| !c.passed).collect();
                    assert!(
                        failed.is_empty(),
                        "{name} {n}x{n} {}: {failed:#?}",
                        spec.name
                    );
                    assert!(o.checks.len() >= 2 * run.reference.modes.len());
                }
            }
        }
        let sc = scene("membrane-spectral", 8);
        let run = LinearRun::prepare(&sc, &sc.runs[0]).unwrap();
        let o = crate::verify::oracle::linear_oracle(&sc, &run);
        assert!(o.passed(), "{:#?}", o.checks);
        assert_eq!(o.checks.len(), 2 * 6 + sc.sampling.profile_points.len());
    }

    /// A 2 % error of κ in the shared plate fails the eigenvalue check of every mode,
    /// stiffer or softer (Rayleigh–Ritz: the plate cannot be softer than the continuum;
    /// 2 % is far above the (qh)⁴/720 band at 8 × 8); the spectral references with a
    /// 1e-6 error of a variance fail.
    #[test]
    fn rejects_a_wrong_shared_plate() {
        for name in ["membrane-hinged", "membrane-periodic"] {
            let sc = scene(name, 8);
            let spec = &sc.runs[0];
            for s in [0.02, -0.02] {
                let bad = sc
                    .clone()
                    .with_fault(Fault::new(FaultKind::SharedStiffness, s).unwrap());
                let run = LinearRun::prepare(&bad, spec).unwrap();
                let o = crate::verify::oracle::linear_oracle(&bad, &run);
                let eig: Vec<bool> = o
                    .checks
                    .iter()
                    .filter(|c| c.name.contains("oracle-eigenvalue"))
                    .map(|c| c.passed)
                    .collect();
                assert_eq!(eig, vec![false; 6], "{name} kappa x {}", 1.0 + s);
            }
        }
        let sc = scene("membrane-spectral", 8);
        let mut run = LinearRun::prepare(&sc, &sc.runs[0]).unwrap();
        run.reference.modes[2].variance_discrete *= 1.0 + 1e-6;
        assert!(!crate::verify::oracle::linear_oracle(&sc, &run).passed());
    }
}
