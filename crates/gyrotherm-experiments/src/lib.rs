//! Experiment harnesses for gyrotherm: the held-out sweeps and the generalisation benchmark
//! whose records live in `docs/experiments/`. Not part of the library's face; not published.

/// The value after `--key` in `args` (the harnesses' whole argument syntax).
pub fn arg_value(args: &[String], key: &str) -> Option<String> {
    args.iter()
        .position(|a| a == key)
        .and_then(|i| args.get(i + 1))
        .cloned()
}
