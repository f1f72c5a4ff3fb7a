//! Training an LSTM compensator: MSE, Adam, full or truncated BPTT, over one or more runs.
//!
//! Defaults are the published recipe (He et al. 2024, DOI 10.19452/j.issn1007-5453.2024.02.004,
//! §2–3): hidden 8, Adam lr 0.01, 1000 iterations, MSE; one Adam step per epoch over whole
//! runs (full BPTT). Inputs and targets must already be normalised (see [`ZScore`]), or use
//! [`train_normalised`], which fits the z-scores and returns them with the parameters.
//!
//! Determinism: one training runs on the calling thread, in a fixed order; the same seed and
//! data give bit-identical parameters. [`train_pair`] runs two trainings (bias and scale
//! factor) on two threads, each as deterministic as on its own.

use std::fmt;

use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::adam::{clip_grad_norm, Adam};
use super::lstm::{backward, forward, param_count, tape_stride, Grads, Layout, Packed, Real};
use super::params::LstmParams;
use super::zscore::ZScore;

/// One run: inputs (steps × I, row-major), target (steps) and an optional loss mask.
#[derive(Debug, Clone, Copy)]
pub struct Sequence<'a> {
    /// Normalised inputs, `steps·I` values, row-major (step t is `inputs[t·I..(t+1)·I]`).
    pub inputs: &'a [f64],
    /// Normalised target, one per step.
    pub target: &'a [f64],
    /// `Some(m)`: only steps with `m[t] == true` count in the loss (a masked target may be NaN).
    pub loss_mask: Option<&'a [bool]>,
}

impl<'a> Sequence<'a> {
    /// A run with every step in the loss.
    pub fn new(inputs: &'a [f64], target: &'a [f64]) -> Self {
        Sequence {
            inputs,
            target,
            loss_mask: None,
        }
    }

    /// The same run with a loss mask (`true`: the step counts).
    pub fn with_mask(self, loss_mask: &'a [bool]) -> Self {
        Sequence {
            loss_mask: Some(loss_mask),
            ..self
        }
    }

    fn steps(&self) -> usize {
        self.target.len()
    }

    fn counts(&self, t: usize) -> bool {
        self.loss_mask.is_none_or(|m| m[t])
    }
}

/// How gradients flow through time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Bptt {
    /// Full BPTT over each whole run; one Adam step per epoch (the published recipe).
    Full,
    /// Truncated BPTT over windows of `window` steps, `batch` windows per Adam step.
    ///
    /// Windows start every `window - burn_in` steps, so the counted parts tile each run. The
    /// first `burn_in` steps of a window are left out of the loss, except in a run's first
    /// window, whose start state (zero) is exact. Window start states: see [`WindowStart`].
    /// No gradient flows into a window's start state. Windows are shuffled each epoch with
    /// the seeded rng. An epoch is one pass over all windows.
    Truncated {
        /// Steps per window (> burn_in).
        window: usize,
        /// Leading steps of each window left out of the loss.
        burn_in: usize,
        /// Windows per Adam step (≥ 1).
        batch: usize,
        /// Where window start states come from.
        start: WindowStart,
    },
}

/// Start state of a truncated-BPTT window.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WindowStart {
    /// Carried: at the start of each epoch the network runs forward over each whole run with
    /// the current parameters and the states at the window starts are kept for that epoch
    /// (so they lag the Adam steps within the epoch by at most one epoch).
    Carried,
    /// Zero state at every window start; `burn_in` then lets the state settle.
    Zero,
}

/// Float type of the forward/backward kernel. Parameters, Adam state and gradient sums over
/// runs are f64 in both cases.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Precision {
    /// f64 throughout (matches PyTorch float64 to ~1e-12).
    F64,
    /// f32 forward/backward (twice the SIMD width; like PyTorch's default).
    F32,
}

/// Training settings. `Default` is the published recipe.
#[derive(Debug, Clone, PartialEq)]
pub struct TrainConfig {
    /// Hidden units H. Default 8 (He et al. 2024, §2).
    pub hidden_size: usize,
    /// Epochs (maximum). Default 1000 (He et al. 2024, §3).
    pub epochs: usize,
    /// Adam learning rate. Default 0.01 (He et al. 2024, §3).
    pub lr: f64,
    /// Adam β1. Default 0.9.
    pub beta1: f64,
    /// Adam β2. Default 0.999.
    pub beta2: f64,
    /// Adam ε. Default 1e-8.
    pub eps: f64,
    /// Seed of the ChaCha8 rng for the initial weights (and window shuffling). Default 0.
    pub seed: u64,
    /// Clip the gradient to this Euclidean norm before each Adam step. Default None.
    pub clip_grad_norm: Option<f64>,
    /// Stop as soon as an epoch's training loss is at or below this. Default None.
    pub target_loss: Option<f64>,
    /// Full or truncated BPTT. Default [`Bptt::Full`].
    pub bptt: Bptt,
    /// Kernel float type. Default [`Precision::F32`].
    pub precision: Precision,
    /// With validation runs: stop after this many epochs without a new best validation loss.
    /// Default None (run all epochs, still return the best parameters).
    pub patience: Option<usize>,
    /// Start the output layer (`w_out`, `b_out`) at zero, so the untrained network predicts
    /// the target mean: for a residual network, epoch 0 is then "no correction", and early
    /// stopping on validation can choose it. Default false (PyTorch init throughout).
    pub zero_output_init: bool,
}

impl Default for TrainConfig {
    fn default() -> Self {
        TrainConfig {
            hidden_size: 8,
            epochs: 1000,
            lr: 0.01,
            beta1: 0.9,
            beta2: 0.999,
            eps: 1e-8,
            seed: 0,
            clip_grad_norm: None,
            target_loss: None,
            bptt: Bptt::Full,
            precision: Precision::F32,
            patience: None,
            zero_output_init: false,
        }
    }
}

/// Why training stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StopReason {
    /// All epochs done.
    Epochs,
    /// Training loss reached `target_loss`.
    TargetLoss,
    /// No validation improvement for `patience` epochs.
    Patience,
}

/// What training returns.
#[derive(Debug, Clone, PartialEq)]
pub struct TrainOutput {
    /// The trained parameters: the best by validation loss when validation runs were given,
    /// else the last.
    pub params: LstmParams,
    /// Training MSE per epoch (full BPTT: of the parameters before that epoch's Adam step;
    /// truncated: mean over the epoch's batches).
    pub loss_history: Vec<f64>,
    /// Validation MSE per epoch (of the parameters before that epoch's step); empty without
    /// validation runs.
    pub val_loss_history: Vec<f64>,
    /// Epoch (0-based) whose parameters were returned, when chosen by validation.
    pub best_epoch: Option<usize>,
    /// Why it stopped.
    pub stop: StopReason,
}

/// Training refused its input.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TrainError(pub String);

impl fmt::Display for TrainError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for TrainError {}

fn err<T>(msg: String) -> Result<T, TrainError> {
    Err(TrainError(msg))
}

/// PyTorch-style initial parameters: every value U(-1/√H, 1/√H) (as `nn.LSTM`, and as
/// `nn.Linear(H, 1)`'s default init whose fan-in is H), drawn in the order w_ih, w_hh, b_ih,
/// b_hh, w_out, b_out from `ChaCha8Rng::seed_from_u64(seed)`.
pub fn init_params(input_size: usize, hidden_size: usize, seed: u64) -> LstmParams {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let k = 1.0 / (hidden_size.max(1) as f64).sqrt();
    let mut p = LstmParams::zeros(input_size, hidden_size);
    for v in p
        .w_ih
        .iter_mut()
        .chain(&mut p.w_hh)
        .chain(&mut p.b_ih)
        .chain(&mut p.b_hh)
        .chain(&mut p.w_out)
        .chain(std::iter::once(&mut p.b_out))
    {
        *v = rng.gen_range(-k..k);
    }
    p
}

/// Flat parameter vector in PyTorch order (w_ih, w_hh, b_ih, b_hh, w_out, b_out).
pub fn flatten(p: &LstmParams) -> Vec<f64> {
    let mut v = Vec::with_capacity(param_count(p.input_size, p.hidden_size));
    v.extend_from_slice(&p.w_ih);
    v.extend_from_slice(&p.w_hh);
    v.extend_from_slice(&p.b_ih);
    v.extend_from_slice(&p.b_hh);
    v.extend_from_slice(&p.w_out);
    v.push(p.b_out);
    v
}

/// Inverse of [`flatten`]; `theta` must hold `param_count(I, H)` values.
pub fn unflatten(theta: &[f64], input_size: usize, hidden_size: usize) -> LstmParams {
    let lay = Layout {
        i: input_size,
        h: hidden_size,
    };
    LstmParams {
        input_size,
        hidden_size,
        w_ih: theta[lay.w_ih()].to_vec(),
        w_hh: theta[lay.w_hh()].to_vec(),
        b_ih: theta[lay.b_ih()].to_vec(),
        b_hh: theta[lay.b_hh()].to_vec(),
        w_out: theta[lay.w_out()].to_vec(),
        b_out: theta[lay.b_out()],
    }
}

/// Check shapes and finiteness of runs; returns I.
fn check_runs(what: &str, runs: &[Sequence<'_>], input_size: usize) -> Result<(), TrainError> {
    for (n, r) in runs.iter().enumerate() {
        let steps = r.steps();
        if steps == 0 {
            return err(format!("{what} run {n} has no steps"));
        }
        if r.inputs.len() != steps * input_size {
            return err(format!(
                "{what} run {n}: {} input values for {steps} steps of {input_size} inputs \
                 (expected {})",
                r.inputs.len(),
                steps * input_size
            ));
        }
        if let Some(m) = r.loss_mask {
            if m.len() != steps {
                return err(format!(
                    "{what} run {n}: loss mask has {} entries for {steps} steps",
                    m.len()
                ));
            }
        }
        if let Some(k) = r.inputs.iter().position(|v| !v.is_finite()) {
            return err(format!(
                "{what} run {n}: input {} at step {} is not finite ({}); drop or fill the sample",
                k % input_size,
                k / input_size,
                r.inputs[k]
            ));
        }
        if let Some(t) = (0..steps).find(|&t| r.counts(t) && !r.target[t].is_finite()) {
            return err(format!(
                "{what} run {n}: target at step {t} is not finite ({}); mask it out",
                r.target[t]
            ));
        }
    }
    Ok(())
}

/// Validated sizes of a training problem.
fn check_problem(
    runs: &[Sequence<'_>],
    validation: &[Sequence<'_>],
    input_size: usize,
    cfg: &TrainConfig,
) -> Result<(), TrainError> {
    if runs.is_empty() {
        return err("no training runs given".into());
    }
    if input_size == 0 || cfg.hidden_size == 0 {
        return err(format!(
            "input size {input_size} and hidden size {} must both be at least 1",
            cfg.hidden_size
        ));
    }
    check_runs("training", runs, input_size)?;
    check_runs("validation", validation, input_size)?;
    let counted = |rs: &[Sequence<'_>]| {
        rs.iter()
            .map(|r| (0..r.steps()).filter(|&t| r.counts(t)).count())
            .sum::<usize>()
    };
    if counted(runs) == 0 {
        return err("every training step is masked out: nothing to fit".into());
    }
    if !validation.is_empty() && counted(validation) == 0 {
        return err("every validation step is masked out".into());
    }
    let pos = |v: f64| v.is_finite() && v > 0.0;
    if !pos(cfg.lr)
        || !pos(cfg.eps)
        || !(0.0..1.0).contains(&cfg.beta1)
        || !(0.0..1.0).contains(&cfg.beta2)
    {
        return err(format!(
            "Adam settings out of range: lr {} and eps {} must be > 0, beta1 {} and beta2 {} in [0, 1)",
            cfg.lr, cfg.eps, cfg.beta1, cfg.beta2
        ));
    }
    if let Some(c) = cfg.clip_grad_norm {
        if !pos(c) {
            return err(format!("clip_grad_norm {c} must be > 0"));
        }
    }
    if let Bptt::Truncated {
        window,
        burn_in,
        batch,
        ..
    } = cfg.bptt
    {
        if window <= burn_in || batch == 0 {
            return err(format!(
                "truncated BPTT needs window > burn_in and batch ≥ 1 (window {window}, \
                 burn_in {burn_in}, batch {batch})"
            ));
        }
    }
    Ok(())
}

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
        let rb = hb
            .join()
            .unwrap_or_else(|_| err("training thread panicked".into()));
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

/// Forward-only MSE of `params` over `runs` (mean over counted steps), in the given kernel
/// precision; for validation and checks.
pub fn evaluate_mse(
    params: &LstmParams,
    runs: &[Sequence<'_>],
    precision: Precision,
) -> Result<f64, TrainError> {
    params.validate().map_err(TrainError)?;
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
    params.validate().map_err(TrainError)?;
    let (ni, nh) = (params.input_size, params.hidden_size);
    if inputs.len() % ni != 0 || inputs.is_empty() {
        return err(format!(
            "{} input values is not a whole, non-zero number of steps of {ni}",
            inputs.len()
        ));
    }
    if h0.len() != nh || c0.len() != nh {
        return err(format!(
            "initial state has {} h and {} c values, expected {nh}",
            h0.len(),
            c0.len()
        ));
    }
    if let Some(k) = inputs
        .iter()
        .chain(h0)
        .chain(c0)
        .position(|v| !v.is_finite())
    {
        return err(format!("input or initial state value {k} is not finite"));
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
pub fn loss_and_grad_in(
    params: &LstmParams,
    runs: &[Sequence<'_>],
    precision: Precision,
) -> Result<(f64, LstmParams), TrainError> {
    params.validate().map_err(TrainError)?;
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

/// Buffers and per-run inputs converted to T; no allocation after construction.
struct Kernel<T> {
    lay: Layout,
    packed: Packed<T>,
    grads: Grads<T>,
    /// Inputs of each run in T.
    xs: Vec<Vec<T>>,
    tape: Vec<T>,
    y: Vec<T>,
    dy: Vec<T>,
    dh: Vec<T>,
    dc: Vec<T>,
    zeros: Vec<T>,
}

impl<T: Real> Kernel<T> {
    fn new(lay: Layout, runs: &[Sequence<'_>]) -> Self {
        let longest = runs.iter().map(|r| r.steps()).max().unwrap_or(0);
        Kernel {
            lay,
            packed: Packed::new(lay),
            grads: Grads::new(lay),
            xs: runs
                .iter()
                .map(|r| r.inputs.iter().map(|v| T::from_f64(*v)).collect())
                .collect(),
            tape: vec![T::ZERO; longest * tape_stride(lay.h)],
            y: vec![T::ZERO; longest],
            dy: vec![T::ZERO; longest],
            dh: vec![T::ZERO; lay.h],
            dc: vec![T::ZERO; lay.h],
            zeros: vec![T::ZERO; lay.h],
        }
    }

    /// Forward-only MSE over counted steps (f64 accumulation).
    fn mse(&mut self, theta: &[f64], runs: &[Sequence<'_>]) -> f64 {
        self.packed.load(theta);
        let (mut sum, mut n) = (0.0, 0usize);
        for (r, x) in runs.iter().zip(&self.xs) {
            let steps = r.steps();
            let s = steps * tape_stride(self.lay.h);
            forward(
                &self.packed,
                x,
                &self.zeros,
                &self.zeros,
                &mut self.tape[..s],
                &mut self.y[..steps],
            );
            for t in (0..steps).filter(|&t| r.counts(t)) {
                let e = self.y[t].to_f64() - r.target[t];
                sum += e * e;
                n += 1;
            }
        }
        sum / n.max(1) as f64
    }

    /// Full BPTT over all runs: returns the MSE and adds its gradient into `grad` (flat,
    /// PyTorch order; caller zeroes it).
    fn full_grad(&mut self, theta: &[f64], runs: &[Sequence<'_>], grad: &mut [f64]) -> f64 {
        self.packed.load(theta);
        let n: usize = runs
            .iter()
            .map(|r| (0..r.steps()).filter(|&t| r.counts(t)).count())
            .sum();
        let scale = 2.0 / n.max(1) as f64;
        let mut sum = 0.0;
        self.grads.zero();
        for (r, x) in runs.iter().zip(&self.xs) {
            let steps = r.steps();
            let s = steps * tape_stride(self.lay.h);
            let tape = &mut self.tape[..s];
            forward(
                &self.packed,
                x,
                &self.zeros,
                &self.zeros,
                tape,
                &mut self.y[..steps],
            );
            for t in 0..steps {
                self.dy[t] = if r.counts(t) {
                    let e = self.y[t].to_f64() - r.target[t];
                    sum += e * e;
                    T::from_f64(scale * e)
                } else {
                    T::ZERO
                };
            }
            backward(
                &self.packed,
                x,
                &self.zeros,
                &self.zeros,
                tape,
                &self.dy[..steps],
                &mut self.grads,
                &mut self.dh,
                &mut self.dc,
            );
        }
        self.grads.add_to_flat(grad);
        sum / n.max(1) as f64
    }
}

/// A truncated-BPTT window.
#[derive(Debug, Clone, Copy)]
struct Window {
    run: usize,
    start: usize,
    len: usize,
    /// First step (window-relative) counted in the loss.
    counted_from: usize,
}

struct Trainer<'r, 'a, T> {
    runs: &'r [Sequence<'a>],
    validation: &'r [Sequence<'a>],
    cfg: &'r TrainConfig,
    lay: Layout,
    kernel: Kernel<T>,
    val_kernel: Kernel<T>,
    theta: Vec<f64>,
    grad: Vec<f64>,
    adam: Adam,
    rng: ChaCha8Rng,
}

impl<'r, 'a, T: Real> Trainer<'r, 'a, T> {
    fn new(
        runs: &'r [Sequence<'a>],
        validation: &'r [Sequence<'a>],
        input_size: usize,
        cfg: &'r TrainConfig,
    ) -> Self {
        let lay = Layout {
            i: input_size,
            h: cfg.hidden_size,
        };
        let mut init = init_params(input_size, cfg.hidden_size, cfg.seed);
        if cfg.zero_output_init {
            init.w_out.fill(0.0);
            init.b_out = 0.0;
        }
        // The window-shuffling rng continues the init stream's seed on another stream.
        let mut rng = ChaCha8Rng::seed_from_u64(cfg.seed);
        rng.set_stream(1);
        Trainer {
            runs,
            validation,
            cfg,
            lay,
            kernel: Kernel::new(lay, runs),
            val_kernel: Kernel::new(lay, validation),
            theta: flatten(&init),
            grad: vec![0.0; lay.len()],
            adam: Adam::new(lay.len(), cfg.lr, cfg.beta1, cfg.beta2, cfg.eps),
            rng,
        }
    }

    fn adam_step(&mut self) -> Result<(), TrainError> {
        if let Some(max) = self.cfg.clip_grad_norm {
            clip_grad_norm(&mut self.grad, max);
        }
        self.adam.step(&mut self.theta, &self.grad);
        if self.theta.iter().any(|v| !v.is_finite()) {
            return err(format!(
                "training diverged at Adam step {} (non-finite parameters); lower the \
                 learning rate or set clip_grad_norm",
                self.adam.steps()
            ));
        }
        Ok(())
    }

    fn run(mut self, progress: &mut dyn FnMut(usize, f64)) -> Result<TrainOutput, TrainError> {
        let cfg = self.cfg;
        let mut loss_history = Vec::with_capacity(cfg.epochs);
        let mut val_loss_history = Vec::new();
        let mut best: Option<(f64, usize, Vec<f64>)> = None;
        let mut stop = StopReason::Epochs;
        let windows = match cfg.bptt {
            Bptt::Full => Vec::new(),
            Bptt::Truncated {
                window, burn_in, ..
            } => self.windows(window, burn_in),
        };
        for epoch in 0..cfg.epochs {
            if !self.validation.is_empty() {
                let v = self.val_kernel.mse(&self.theta, self.validation);
                val_loss_history.push(v);
                if best.as_ref().is_none_or(|(b, _, _)| v < *b) {
                    best = Some((v, epoch, self.theta.clone()));
                }
            }
            let loss = match cfg.bptt {
                Bptt::Full => {
                    self.grad.fill(0.0);
                    let loss = self
                        .kernel
                        .full_grad(&self.theta, self.runs, &mut self.grad);
                    loss_history.push(loss);
                    progress(epoch, loss);
                    if cfg.target_loss.is_some_and(|t| loss <= t) {
                        stop = StopReason::TargetLoss;
                        break;
                    }
                    self.adam_step()?;
                    loss
                }
                Bptt::Truncated { batch, start, .. } => {
                    let loss = self.truncated_epoch(&windows, batch, start)?;
                    loss_history.push(loss);
                    progress(epoch, loss);
                    loss
                }
            };
            if !loss.is_finite() {
                return err(format!(
                    "training diverged at epoch {epoch} (loss {loss}); lower the learning rate \
                     or set clip_grad_norm"
                ));
            }
            if matches!(cfg.bptt, Bptt::Truncated { .. })
                && cfg.target_loss.is_some_and(|t| loss <= t)
            {
                stop = StopReason::TargetLoss;
                break;
            }
            if let (Some(p), Some((_, b, _))) = (cfg.patience, &best) {
                if epoch >= b + p {
                    stop = StopReason::Patience;
                    break;
                }
            }
        }
        let (theta, best_epoch) = match best {
            Some((_, e, th)) => (th, Some(e)),
            None => (self.theta, None),
        };
        Ok(TrainOutput {
            params: unflatten(&theta, self.lay.i, self.lay.h),
            loss_history,
            val_loss_history,
            best_epoch,
            stop,
        })
    }

    fn windows(&self, window: usize, burn_in: usize) -> Vec<Window> {
        let stride = window - burn_in;
        let mut out = Vec::new();
        for (run, r) in self.runs.iter().enumerate() {
            let steps = r.steps();
            let mut start = 0;
            loop {
                let len = window.min(steps - start);
                let counted_from = if start == 0 { 0 } else { burn_in.min(len) };
                out.push(Window {
                    run,
                    start,
                    len,
                    counted_from,
                });
                if start + len >= steps {
                    break;
                }
                start += stride;
            }
        }
        out
    }

    /// One pass over all windows; returns the mean squared error over the counted steps.
    fn truncated_epoch(
        &mut self,
        windows: &[Window],
        batch: usize,
        start: WindowStart,
    ) -> Result<f64, TrainError> {
        let nh = self.lay.h;
        let ni = self.lay.i;
        let s = tape_stride(nh);
        // Start states (h, c) of every window, per WindowStart.
        let mut states = vec![T::ZERO; windows.len() * 2 * nh];
        if start == WindowStart::Carried {
            let k = &mut self.kernel;
            k.packed.load(&self.theta);
            for (n, r) in self.runs.iter().enumerate() {
                let steps = r.steps();
                forward(
                    &k.packed,
                    &k.xs[n],
                    &k.zeros,
                    &k.zeros,
                    &mut k.tape[..steps * s],
                    &mut k.y[..steps],
                );
                for (w, st) in windows.iter().zip(states.chunks_exact_mut(2 * nh)) {
                    if w.run == n && w.start > 0 {
                        let slot = &k.tape[(w.start - 1) * s..w.start * s];
                        st[..nh].copy_from_slice(&slot[6 * nh..7 * nh]);
                        st[nh..].copy_from_slice(&slot[4 * nh..5 * nh]);
                    }
                }
            }
        }
        let mut order: Vec<usize> = (0..windows.len()).collect();
        order.shuffle(&mut self.rng);
        let (mut total, mut total_n) = (0.0, 0usize);
        for chunk in order.chunks(batch) {
            let n: usize = chunk
                .iter()
                .map(|&w| {
                    let w = windows[w];
                    (w.counted_from..w.len)
                        .filter(|&t| self.runs[w.run].counts(w.start + t))
                        .count()
                })
                .sum();
            if n == 0 {
                continue;
            }
            let scale = 2.0 / n as f64;
            let k = &mut self.kernel;
            k.packed.load(&self.theta);
            k.grads.zero();
            for &wi in chunk {
                let w = windows[wi];
                let r = &self.runs[w.run];
                let st = &states[wi * 2 * nh..(wi + 1) * 2 * nh];
                let (h0, c0) = st.split_at(nh);
                let x = &k.xs[w.run][w.start * ni..(w.start + w.len) * ni];
                let tape = &mut k.tape[..w.len * s];
                forward(&k.packed, x, h0, c0, tape, &mut k.y[..w.len]);
                for t in 0..w.len {
                    k.dy[t] = if t >= w.counted_from && r.counts(w.start + t) {
                        let e = k.y[t].to_f64() - r.target[w.start + t];
                        total += e * e;
                        T::from_f64(scale * e)
                    } else {
                        T::ZERO
                    };
                }
                backward(
                    &k.packed,
                    x,
                    h0,
                    c0,
                    tape,
                    &k.dy[..w.len],
                    &mut k.grads,
                    &mut k.dh,
                    &mut k.dc,
                );
            }
            total_n += n;
            self.grad.fill(0.0);
            self.kernel.grads.add_to_flat(&mut self.grad);
            self.adam_step()?;
        }
        Ok(total / total_n.max(1) as f64)
    }
}
