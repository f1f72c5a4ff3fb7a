//! Evaluating a network outside training: forward passes, MSE, loss and gradient (for
//! gradient checks and comparison with other frameworks).

use super::batch::{Gemm, WindowRef};
use super::checks::check_runs;
use super::config::{Precision, Sequence};
use super::epochs::batch_grad;
use super::error::TrainError;
use super::kernel::Kernel;
use super::lstm::{forward, tape_stride, Layout, Packed};
use super::params::{flatten, unflatten, LstmParams};

/// Forward-only MSE of `params` over `runs` (mean over counted steps), in the given kernel
/// precision; for validation and checks.
pub fn evaluate_mse(
    params: &LstmParams,
    runs: &[Sequence<'_>],
    precision: Precision,
) -> Result<f64, TrainError> {
    params.validate()?;
    check_runs("evaluation", runs, params.input_size)?;
    let theta = flatten(params);
    let lay = Layout {
        i: params.input_size,
        h: params.hidden_size,
    };
    Ok(match precision {
        Precision::F64 => Kernel::<f64>::new(lay, runs).mse(&theta, runs),
        Precision::F32 => Kernel::<f32>::new(lay, runs).mse(&theta, runs),
    })
}

/// Forward pass of `params` over one run from zero state, in f64: the outputs y_t. The
/// reference the exported f32 core network is checked against.
pub fn predict(params: &LstmParams, inputs: &[f64]) -> Result<Vec<f64>, TrainError> {
    let zeros = vec![0.0; params.hidden_size];
    Ok(predict_with_state(params, inputs, &zeros, &zeros)?.y)
}

/// Outputs and final state of a forward pass.
#[derive(Debug, Clone, PartialEq)]
pub struct RunOutput {
    /// y_t per step.
    pub y: Vec<f64>,
    /// Final hidden state h_n.
    pub h_n: Vec<f64>,
    /// Final cell state c_n.
    pub c_n: Vec<f64>,
}

/// Forward pass of `params` over one run (`inputs`: steps·I, row-major) from state (h0, c0),
/// in f64.
pub fn predict_with_state(
    params: &LstmParams,
    inputs: &[f64],
    h0: &[f64],
    c0: &[f64],
) -> Result<RunOutput, TrainError> {
    params.validate()?;
    let (ni, nh) = (params.input_size, params.hidden_size);
    if inputs.len() % ni != 0 || inputs.is_empty() {
        return Err(TrainError::PredictInput {
            values: inputs.len(),
            input_size: ni,
        });
    }
    if h0.len() != nh || c0.len() != nh {
        return Err(TrainError::InitialState {
            h: h0.len(),
            c: c0.len(),
            hidden_size: nh,
        });
    }
    if let Some(k) = inputs
        .iter()
        .chain(h0)
        .chain(c0)
        .position(|v| !v.is_finite())
    {
        return Err(TrainError::NonFiniteState { index: k });
    }
    let steps = inputs.len() / ni;
    let lay = Layout { i: ni, h: nh };
    let mut p = Packed::<f64>::new(lay);
    p.load(&flatten(params));
    let s = tape_stride(nh);
    let mut tape = vec![0.0; steps * s];
    let mut y = vec![0.0; steps];
    forward(&p, inputs, h0, c0, &mut tape, &mut y);
    let last = &tape[(steps - 1) * s..];
    Ok(RunOutput {
        y,
        h_n: last[6 * nh..7 * nh].to_vec(),
        c_n: last[4 * nh..5 * nh].to_vec(),
    })
}

/// Forward, loss and gradient of `params` over `runs` with full BPTT, in f64: (MSE, gradient
/// as an `LstmParams`). For gradient checks and comparison with other frameworks.
pub fn loss_and_grad(
    params: &LstmParams,
    runs: &[Sequence<'_>],
) -> Result<(f64, LstmParams), TrainError> {
    loss_and_grad_in(params, runs, Precision::F64)
}

/// [`loss_and_grad`] with the kernel in the given precision (what training uses per epoch).
pub(crate) fn loss_and_grad_in(
    params: &LstmParams,
    runs: &[Sequence<'_>],
    precision: Precision,
) -> Result<(f64, LstmParams), TrainError> {
    params.validate()?;
    check_runs("training", runs, params.input_size)?;
    let lay = Layout {
        i: params.input_size,
        h: params.hidden_size,
    };
    let theta = flatten(params);
    let mut grad = vec![0.0; lay.len()];
    let loss = match precision {
        Precision::F64 => Kernel::<f64>::new(lay, runs).full_grad(&theta, runs, &mut grad),
        Precision::F32 => Kernel::<f32>::new(lay, runs).full_grad(&theta, runs, &mut grad),
    };
    Ok((loss, unflatten(&grad, lay.i, lay.h)))
}

/// Loss and gradient of `params` over a batch of windows, as one step of minibatch truncated
/// BPTT ([`Bptt::Sampled`](super::Bptt::Sampled)) computes them: every window from zero state,
/// its first `burn_in` steps (and its masked steps) out of the loss, the MSE over the counted
/// steps of all windows together; batched matrix products on up to `threads` workers (0: one
/// per core). Returns (MSE, gradient as an `LstmParams`). Windows may differ in length.
pub fn batch_loss_and_grad(
    params: &LstmParams,
    windows: &[Sequence<'_>],
    burn_in: usize,
    precision: Precision,
    threads: usize,
) -> Result<(f64, LstmParams), TrainError> {
    params.validate()?;
    check_runs("training", windows, params.input_size)?;
    let lay = Layout {
        i: params.input_size,
        h: params.hidden_size,
    };
    let theta = flatten(params);
    let mut grad = vec![0.0; lay.len()];
    let loss = match precision {
        Precision::F64 => batch_in::<f64>(lay, &theta, windows, burn_in, threads, &mut grad),
        Precision::F32 => batch_in::<f32>(lay, &theta, windows, burn_in, threads, &mut grad),
    }?;
    Ok((loss, unflatten(&grad, lay.i, lay.h)))
}

fn batch_in<T: Gemm>(
    lay: Layout,
    theta: &[f64],
    windows: &[Sequence<'_>],
    burn_in: usize,
    threads: usize,
    grad: &mut [f64],
) -> Result<f64, TrainError> {
    let mut packed = Packed::<T>::new(lay);
    packed.load(theta);
    let xs: Vec<Vec<T>> = windows
        .iter()
        .map(|w| w.inputs.iter().map(|v| T::from_f64(*v)).collect())
        .collect();
    let wins: Vec<WindowRef<'_, T>> = windows
        .iter()
        .zip(&xs)
        .map(|(w, x)| WindowRef {
            x,
            target: w.target,
            counted_from: burn_in,
            mask: w.loss_mask,
        })
        .collect();
    let n: usize = wins.iter().map(|w| w.counted()).sum();
    if n == 0 {
        return Err(TrainError::AllMasked { set: "training" });
    }
    let sum = batch_grad(&packed, &wins, n, threads, &mut Vec::new(), grad)?;
    Ok(sum / n as f64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nn::{init_params, ZScore};

    /// The f32 kernel (the training default) against the f64 one, whose gradient is checked
    /// by finite differences and against PyTorch (`tests/lstm_gradcheck.rs`,
    /// `tests/lstm_reference.rs`): loss and every gradient within 1e-4 of the largest gradient
    /// magnitude. f32 rounding (ε = 6e-8) summed over T = 3000 steps: √T·ε ≈ 3e-6 if the
    /// errors are random, T·ε ≈ 2e-4 if they all add up; a wrong term would be off by O(1).
    #[test]
    fn f32_kernel_gradient_matches_f64() {
        const REL_TOL: f64 = 1e-4;
        // A chamber-like cycle, its 20 s rate, and a bias lagging it by 150 s.
        let temp: Vec<f64> = (0..3000)
            .map(|t| 10.0 + 50.0 * (t as f64 * std::f64::consts::TAU / 3000.0).sin())
            .collect();
        let raw: Vec<f64> = temp
            .iter()
            .enumerate()
            .flat_map(|(t, v)| [*v, (v - temp[t.saturating_sub(20)]) / 20.0])
            .collect();
        let z = ZScore::fit(&raw, 2);
        let x: Vec<f64> = raw
            .iter()
            .enumerate()
            .map(|(k, v)| z.apply(k % 2, *v))
            .collect();
        let mut coil = temp[0];
        let y: Vec<f64> = temp
            .iter()
            .map(|v| {
                let prev = coil;
                coil += (v - coil) / 150.0;
                5.0 * (0.002 * (coil - 20.0) + 0.5 * (coil - prev))
            })
            .collect();
        for (i, h) in [(2, 8), (2, 5)] {
            let p = init_params(i, h, 11);
            let runs = [Sequence::new(&x, &y)];
            let (l64, g64) = loss_and_grad_in(&p, &runs, Precision::F64).unwrap();
            let (l32, g32) = loss_and_grad_in(&p, &runs, Precision::F32).unwrap();
            assert!(
                (l32 - l64).abs() <= REL_TOL * l64,
                "H={h} loss f64 {l64}, f32 {l32}"
            );
            let (g64, g32) = (flatten(&g64), flatten(&g32));
            let scale = g64.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let worst = g64
                .iter()
                .zip(&g32)
                .map(|(a, b)| (a - b).abs() / scale)
                .fold(0.0, f64::max);
            assert!(
                worst <= REL_TOL,
                "H={h}: f32 gradient off by {worst:e} of max |g|"
            );
        }
    }
}
