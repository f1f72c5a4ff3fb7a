//! TODO: ground-side feature extraction over a whole log (runs the core pipeline).
