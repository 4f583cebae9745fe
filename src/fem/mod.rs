//! (placeholder: filled in by the fem work.)
