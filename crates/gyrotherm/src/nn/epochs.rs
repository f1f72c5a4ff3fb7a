//! The training loop: epochs of Adam steps over whole runs or truncated-BPTT windows, with
//! validation, early stopping and best-parameter selection.

use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::adam::{clip_grad_norm, Adam};
use super::config::{Bptt, Sequence, StopReason, TrainConfig, TrainOutput, WindowStart};
use super::error::TrainError;
use super::eval::{flatten, unflatten};
use super::kernel::Kernel;
use super::lstm::{backward, forward, tape_stride, Layout, Real};
use super::params::init_params;

/// A truncated-BPTT window.
#[derive(Debug, Clone, Copy)]
struct Window {
    run: usize,
    start: usize,
    len: usize,
    /// First step (window-relative) counted in the loss.
    counted_from: usize,
}

pub(crate) struct Trainer<'r, 'a, T> {
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
    pub(crate) fn new(
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
            return Err(TrainError::DivergedAtStep {
                step: self.adam.steps(),
            });
        }
        Ok(())
    }

    pub(crate) fn run(
        mut self,
        progress: &mut dyn FnMut(usize, f64),
    ) -> Result<TrainOutput, TrainError> {
        let cfg = self.cfg;
        // Grown as the epochs run, not reserved for the number asked: a mistyped
        // `epochs` must not take memory before a single epoch is trained.
        let mut loss_history = Vec::new();
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
                return Err(TrainError::DivergedAtEpoch { epoch, loss });
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
