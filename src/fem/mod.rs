//! Finite-element model of the filament (the semi-discrete form of eq. 2) and of the membrane
//! (Bogner–Fox–Schmit plates): Hermite-cubic beam elements,
//! banded assembly over the free DOFs of a hinged beam, the paper's element-uniform noise
//! (eq. 5) and consistent noise, generalized modes of `(K, C)` and the exact stationary
//! covariances of the discrete system.
//!
//! - [`mesh`]: node coordinates on `[0, L]` (uniform, graded, explicit).
//! - [`hermite`]: shape functions and element matrices `C_e`, `K_e`, `G_e`, `b_e`.
//! - [`banded`]: symmetric banded matrices, banded Cholesky, inertia counts.
//! - [`system`]: the [`LinearSystem`] `C ẋ = −Kx + F` every object assembles to, with the
//!   element loads of eq. (5).
//! - [`beam`]: the assembled linear beam [`BeamModel`] and its stiffest rate `λ_max`.
//! - [`chain`]: the filament as a chain of nodes ([`ChainModel`]): the 5-point
//!   finite-difference filament and the linearized bead-spring chain (issue #31).
//! - [`plate`]: the Helfrich membrane `ξ ∂h/∂t = −κ∇⁴h + σ∇²h + f` on Bogner–Fox–Schmit
//!   rectangles ([`PlateModel`]), simply supported or periodic, and its `λ_max`.
//! - [`plate_modes`]: the separable modes of the uniform plate ([`PlateModes`]): `K`, `C`
//!   block-diagonal with blocks of at most 4×4 per pair of 1D waves, labelled by the
//!   continuum modes.
//! - [`plate_area`]: the membrane under imposed projected area ([`plate_area::AreaTheory`]):
//!   the stored-area law of the continuum and of the uniform plate (exact per block), and
//!   the exact equilibrium tension through [`crate::theory::CompressionTheory`].
//! - [`noise`]: [`NoiseModel`] and [`NoiseGenerator`] (`F = sqrt(2kT/Δt)·ζ`).
//! - [`modal`]: [`GeneralizedModes`] and exact stationary covariances.
//! - [`paired`]: the paired modal form of a uniform hinged beam ([`PairedModes`]): `K`,
//!   `C`, `G` block-diagonal with 2×2 blocks per wavenumber.
//! - [`area`]: the membrane under imposed projected area ([`area::AreaMembrane`]), the
//!   filament's global constraint on the plate.
//! - [`vonkarman`]: the finite-deflection filament under imposed end-shortening
//!   ([`vonkarman::CompressedFilament`]): energy, internal force, axial solve.

pub mod area;
pub mod banded;
pub mod beam;
pub mod chain;
pub mod hermite;
pub mod mesh;
pub mod modal;
pub mod noise;
pub mod paired;
pub mod plate;
pub mod plate_area;
pub mod plate_modes;
pub mod system;
pub mod vonkarman;

pub use area::AreaMembrane;
pub use banded::{BandedCholesky, SymBanded};
pub use beam::{BeamModel, UNIFORM_RATE_FACTOR};
pub use chain::ChainModel;
pub use mesh::Mesh;
pub use modal::{
    GeneralizedModes, continuous_stationary_covariance, discrete_stationary_covariance,
    generalized_modes, modal_noise_covariance, nodal_covariance,
};
pub use noise::{NoiseGenerator, NoiseModel};
pub use paired::{ModeBlock, PairedModes};
pub use plate::{
    MAX_BAND_ENTRIES, MAX_PLATE_DOFS, NodeDof, PLATE_RATE_FACTOR, PlateElementMatrix, PlateModel,
    SLOPE_RATE_FACTOR,
};
pub use plate_modes::{
    GeometricBlock, MAX_DENSE_MODE_DOFS, MAX_PLATE_MODE_DOFS, PlateMode, PlateModeLabel, PlateModes,
};
pub use system::{ElementLoad, LinearSystem};
