//! (placeholder: filled in by the spectral work.)
