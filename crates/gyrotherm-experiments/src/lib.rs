//! Experiment harnesses for gyrotherm: the held-out sweeps and the generalisation benchmark
//! whose records live in `docs/experiments/`. Not part of the library's face; not published.
