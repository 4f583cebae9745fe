//! Exact equilibrium theory beyond the linear beam.
//!
//! - [`compression`]: the mean compressive force ⟨F⟩(ε) of a hinged filament at an
//!   imposed end shortening (the paper's Fig. 2), its variance and its full equilibrium
//!   distribution, exactly (no mean-field approximation), for the continuum and for the
//!   Hermite-cubic discretization the simulator uses.
//!   Its [`GlobalConstraint`] also serves the filament in tension and the membrane under
//!   imposed projected area ([`crate::fem::plate_area`]).
//! - [`scheme_law`]: the linear-response prediction of ⟨F⟩(ε) for a scheme that is not
//!   fluctuation–dissipation exact (the paper's explicit scheme with its element-uniform
//!   noise, eq. 5): how far it is expected to sit from the exact theory.

pub mod compression;
pub mod scheme_law;

pub use compression::{
    CompressionTheory, DEFAULT_CONTINUUM_MODES, Dims, DomainInput, ForceDistribution,
    GlobalConstraint, MAX_DISCRETE_ELEMENTS, MAX_QUADRATURE_WORK, MIN_STRAIN_RATIO,
    PERSISTENCE_RATIO_RANGE, QuadratureOptions, STRAIN_RATIO_SCALE, STRETCH_BEND_RATIO_RANGE,
    StoredLengthLaw, Tail, buckling_load_discrete, continuum_tail_log_char_bound,
    discrete_buckling_loads, domain_violation, max_strain_ratio,
};
