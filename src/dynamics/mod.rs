//! (placeholder: filled in by the dynamics work.)
