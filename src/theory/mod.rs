//! Exact equilibrium theory beyond the linear beam.
//!
//! - [`compression`]: the mean compressive force ⟨F⟩(ε) of a hinged filament at an
//!   imposed end shortening (the paper's Fig. 2), its variance and its full equilibrium
//!   distribution, exactly (no mean-field approximation), for the continuum and for the
//!   Hermite-cubic discretization the simulator uses.

pub mod compression;

pub use compression::{
    CompressionTheory, DEFAULT_CONTINUUM_MODES, Dims, ForceDistribution, MAX_DISCRETE_ELEMENTS,
    QuadratureOptions, StoredLengthLaw, Tail, buckling_load_discrete,
    continuum_tail_log_char_bound, discrete_buckling_loads,
};
