//! Training entry points: one network, two on two threads, or with the z-scores fitted.
//!
//! Determinism: one training runs on the calling thread, in a fixed order; the same seed and
//! data give bit-identical parameters. [`train_pair`] runs two trainings (bias and scale
//! factor) on two threads, each as deterministic as on its own.

use super::checks::check_problem;
use super::config::{Precision, Sequence, TrainConfig, TrainOutput};
use super::epochs::Trainer;
use super::error::TrainError;
use super::zscore::ZScore;

/// Train one network on `runs` (already normalised), with optional `validation` runs for
/// early stopping and best-parameter selection. `progress(epoch, loss)` is called after each
/// epoch's loss is known (epoch counted from 0).
pub fn train_lstm(
    runs: &[Sequence<'_>],
    validation: &[Sequence<'_>],
    input_size: usize,
    cfg: &TrainConfig,
    progress: &mut dyn FnMut(usize, f64),
) -> Result<TrainOutput, TrainError> {
    check_problem(runs, validation, input_size, cfg)?;
    match cfg.precision {
        Precision::F64 => Trainer::<f64>::new(runs, validation, input_size, cfg).run(progress),
        Precision::F32 => Trainer::<f32>::new(runs, validation, input_size, cfg).run(progress),
    }
}

/// Train two networks (e.g. bias and scale factor, He et al. 2024 §2) on two threads. Each is
/// as deterministic as [`train_lstm`] alone.
#[allow(clippy::type_complexity)]
pub fn train_pair(
    a: (
        &[Sequence<'_>],
        &[Sequence<'_>],
        &mut (dyn FnMut(usize, f64) + Send),
    ),
    b: (
        &[Sequence<'_>],
        &[Sequence<'_>],
        &mut (dyn FnMut(usize, f64) + Send),
    ),
    input_size: usize,
    cfg: &TrainConfig,
) -> (
    Result<TrainOutput, TrainError>,
    Result<TrainOutput, TrainError>,
) {
    std::thread::scope(|s| {
        let (runs_b, val_b, prog_b) = b;
        let hb = s.spawn(move || train_lstm(runs_b, val_b, input_size, cfg, prog_b));
        let (runs_a, val_a, prog_a) = a;
        let ra = train_lstm(runs_a, val_a, input_size, cfg, prog_a);
        let rb = hb.join().unwrap_or(Err(TrainError::ThreadPanicked));
        (ra, rb)
    })
}

/// A trained network with the z-scores it was trained under.
#[derive(Debug, Clone, PartialEq)]
pub struct NormalisedFit {
    /// Parameters and loss histories (losses in normalised units).
    pub output: TrainOutput,
    /// Per-input z-score, fitted over all training runs.
    pub input_z: ZScore,
    /// Target z-score (one channel), fitted over the counted (unmasked) training steps.
    pub target_z: ZScore,
}

/// Convenience: fit z-scores on raw training inputs and targets, normalise training and
/// validation runs with them, and train. The network's output y maps back to the target's
/// units as `target_z.invert(0, y)`.
pub fn train_normalised(
    runs: &[Sequence<'_>],
    validation: &[Sequence<'_>],
    input_size: usize,
    cfg: &TrainConfig,
    progress: &mut dyn FnMut(usize, f64),
) -> Result<NormalisedFit, TrainError> {
    check_problem(runs, validation, input_size, cfg)?;
    let all_x: Vec<f64> = runs.iter().flat_map(|r| r.inputs.iter().copied()).collect();
    let input_z = ZScore::fit(&all_x, input_size);
    let all_y: Vec<f64> = runs
        .iter()
        .flat_map(|r| (0..r.steps()).filter(|&t| r.counts(t)).map(|t| r.target[t]))
        .collect();
    let target_z = ZScore::fit(&all_y, 1);
    let norm = |rs: &[Sequence<'_>]| -> Vec<(Vec<f64>, Vec<f64>)> {
        rs.iter()
            .map(|r| {
                let x = r
                    .inputs
                    .iter()
                    .enumerate()
                    .map(|(k, v)| input_z.apply(k % input_size, *v))
                    .collect();
                let y = r.target.iter().map(|v| target_z.apply(0, *v)).collect();
                (x, y)
            })
            .collect()
    };
    let (tr, va) = (norm(runs), norm(validation));
    let (tr_s, va_s) = (with_data(runs, &tr), with_data(validation, &va));
    let output = train_lstm(&tr_s, &va_s, input_size, cfg, progress)?;
    Ok(NormalisedFit {
        output,
        input_z,
        target_z,
    })
}

/// The runs of `raw` (for their masks) with inputs and targets from `data`.
fn with_data<'d>(raw: &[Sequence<'d>], data: &'d [(Vec<f64>, Vec<f64>)]) -> Vec<Sequence<'d>> {
    raw.iter()
        .zip(data)
        .map(|(r, (x, y))| Sequence {
            inputs: x,
            target: y,
            loss_mask: r.loss_mask,
        })
        .collect()
}
