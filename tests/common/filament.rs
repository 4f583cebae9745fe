//! Filament parameter sets of the tests. Non-unit values are deliberate: a wrong power of
//! L, EI, ξ or kT cannot cancel.

use langevin_fem::FilamentParams;

/// The paper's Fig. 2: L = kT = 1, EI/(kT·L) = 100, EA·L/kT = 10⁶.
pub fn paper() -> FilamentParams {
    FilamentParams {
        length: 1.0,
        bending_rigidity: 100.0,
        stretch_rigidity: 1.0e6,
        drag: 1.0,
        kt: 1.0,
    }
}

/// The paper's dimensionless groups (P = 100, S = 10⁶) in non-unit units: L = 2,
/// kT = 1.3, ξ = 0.7.
pub fn paper_rescaled() -> FilamentParams {
    let (l, kt) = (2.0, 1.3);
    FilamentParams {
        length: l,
        bending_rigidity: 100.0 * kt * l,
        stretch_rigidity: 1.0e6 * kt / l,
        drag: 0.7,
        kt,
    }
}

/// A generic filament for the finite-element tests: L = 2, EI = 3, EA = 10⁶, ξ = 0.7,
/// kT = 1.3.
pub fn sample() -> FilamentParams {
    FilamentParams {
        length: 2.0,
        bending_rigidity: 3.0,
        stretch_rigidity: 1e6,
        drag: 0.7,
        kt: 1.3,
    }
}

/// The filament of the spectral-reference tests: L = 2.5, EI = 0.7, EA = 10⁶, ξ = 3,
/// kT = 0.4.
pub fn spectral_sample() -> FilamentParams {
    FilamentParams {
        length: 2.5,
        bending_rigidity: 0.7,
        stretch_rigidity: 1.0e6,
        drag: 3.0,
        kt: 0.4,
    }
}
