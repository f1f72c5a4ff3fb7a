//! The training loop: epochs of Adam steps over whole runs or truncated-BPTT windows, with
//! validation, early stopping and best-parameter selection.

use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::adam::{clip_grad_norm, cosine_lr, Adam};
use super::batch::{ChunkWork, Gemm, WindowRef};
use super::config::{
    Bptt, LrSchedule, Sequence, StopReason, TrainConfig, TrainOutput, WindowStart,
};
use super::error::TrainError;
use super::kernel::Kernel;
use super::lstm::{backward, forward, tape_stride, Layout, Packed};
use super::params::{flatten, init_params, unflatten};

/// Batches drawn in a row with no counted step before sampled training gives up.
const MAX_EMPTY_DRAWS: usize = 1000;

/// Windows per chunk of a batch (one worker's matrix products): about an eighth of the batch,
/// so that up to eight cores share it, but at least 8 and at most 32 columns per product
/// (narrower products waste the matrix kernels, wider ones only add memory). Fixed by the
/// batch size alone, so the chunks, and hence the sums, are the same on every machine.
pub(crate) fn chunk_size(batch: usize) -> usize {
    batch.div_ceil(8).clamp(8, 32)
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

pub(crate) struct Trainer<'r, 'a, T> {
    runs: &'r [Sequence<'a>],
    /// Sampled windows: per run, the number of window starts it offers, cumulated.
    starts_cum: Vec<usize>,
    /// Sampled windows: one batch kernel per worker.
    work: Vec<ChunkWork<T>>,
    /// Adam steps the learning-rate schedule spans.
    planned_steps: usize,
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

impl<'r, 'a, T: Gemm> Trainer<'r, 'a, T> {
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
        let sampled = matches!(cfg.bptt, Bptt::Sampled { .. });
        Trainer {
            runs,
            starts_cum: Vec::new(),
            work: Vec::new(),
            planned_steps: cfg.epochs,
            validation,
            cfg,
            lay,
            kernel: if sampled {
                Kernel::inputs_only(lay, runs)
            } else {
                Kernel::new(lay, runs)
            },
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
        if self.cfg.lr_schedule == LrSchedule::Cosine {
            let k = usize::try_from(self.adam.steps()).unwrap_or(usize::MAX);
            self.adam.lr = cosine_lr(self.cfg.lr, k, self.planned_steps);
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
                window,
                burn_in,
                batch,
                ..
            } => {
                let w = self.windows(window, burn_in);
                self.planned_steps = cfg.epochs.saturating_mul(w.len().div_ceil(batch));
                w
            }
            Bptt::Sampled {
                window, burn_in, ..
            } => {
                self.starts_cum = self.window_starts(window, burn_in);
                Vec::new()
            }
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
                Bptt::Sampled {
                    window,
                    burn_in,
                    batch,
                } => {
                    let loss = self.sampled_step(window, burn_in, batch)?;
                    loss_history.push(loss);
                    progress(epoch, loss);
                    loss
                }
            };
            if !loss.is_finite() {
                return Err(TrainError::DivergedAtEpoch { epoch, loss });
            }
            if !matches!(cfg.bptt, Bptt::Full) && cfg.target_loss.is_some_and(|t| loss <= t) {
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

    /// Per run, how many window starts it offers (every start of a full window; one, the
    /// whole run, if shorter than a window; none if it has no step past the burn-in),
    /// cumulated.
    fn window_starts(&self, window: usize, burn_in: usize) -> Vec<usize> {
        let mut total = 0usize;
        self.runs
            .iter()
            .map(|r| {
                let n = r.steps();
                total += match n {
                    n if n <= burn_in => 0,
                    n if n <= window => 1,
                    n => n - window + 1,
                };
                total
            })
            .collect()
    }

    /// One window drawn uniformly over all starts: (run, start, steps).
    fn draw(&mut self, window: usize) -> (usize, usize, usize) {
        let total = self.starts_cum.last().copied().unwrap_or(0);
        let u = self.rng.gen_range(0..total.max(1));
        let run = self.starts_cum.partition_point(|&c| c <= u);
        let before = if run == 0 {
            0
        } else {
            self.starts_cum[run - 1]
        };
        let start = u - before;
        let steps = self.runs[run].steps();
        (run, start, window.min(steps - start))
    }

    /// One Adam step on `batch` windows drawn at random; returns the batch's MSE before it.
    fn sampled_step(
        &mut self,
        window: usize,
        burn_in: usize,
        batch: usize,
    ) -> Result<f64, TrainError> {
        let ni = self.lay.i;
        let mut empty = 0;
        let (drawn, n) = loop {
            let drawn: Vec<(usize, usize, usize)> = (0..batch).map(|_| self.draw(window)).collect();
            let n: usize = drawn
                .iter()
                .map(|&(run, start, len)| {
                    let r = &self.runs[run];
                    (burn_in..len).filter(|&t| r.counts(start + t)).count()
                })
                .sum();
            if n > 0 {
                break (drawn, n);
            }
            empty += 1;
            if empty >= MAX_EMPTY_DRAWS {
                return Err(TrainError::NoCountedWindow { tries: empty });
            }
        };
        self.kernel.packed.load(&self.theta);
        let xs = &self.kernel.xs;
        let wins: Vec<WindowRef<'_, T>> = drawn
            .iter()
            .map(|&(run, start, len)| {
                let r = &self.runs[run];
                WindowRef {
                    x: &xs[run][start * ni..(start + len) * ni],
                    target: &r.target[start..start + len],
                    counted_from: burn_in,
                    mask: r.loss_mask.map(|m| &m[start..start + len]),
                }
            })
            .collect();
        let sum = batch_grad(
            &self.kernel.packed,
            &wins,
            n,
            self.cfg.threads,
            &mut self.work,
            &mut self.grad,
        )?;
        drop(wins);
        self.adam_step()?;
        Ok(sum / n as f64)
    }
}

/// Gradient of the MSE over the `n` counted steps of `wins` into `grad` (overwritten, flat,
/// PyTorch order), chunk by chunk on up to `threads` workers (0: one per core); returns the
/// sum of squared errors. Chunks are summed in order, so the result does not depend on the
/// number of workers.
pub(crate) fn batch_grad<T: Gemm>(
    packed: &Packed<T>,
    wins: &[WindowRef<'_, T>],
    n: usize,
    threads: usize,
    work: &mut Vec<ChunkWork<T>>,
    grad: &mut [f64],
) -> Result<f64, TrainError> {
    let lay = packed.lay;
    let scale = 2.0 / n.max(1) as f64;
    let chunks: Vec<&[WindowRef<'_, T>]> = wins.chunks(chunk_size(wins.len())).collect();
    let cores = if threads == 0 {
        std::thread::available_parallelism().map_or(1, |c| c.get())
    } else {
        threads
    };
    let workers = cores.min(chunks.len()).max(1);
    while work.len() < workers {
        work.push(ChunkWork::new(lay));
    }
    let mut results: Vec<(f64, Vec<f64>)> = vec![(0.0, vec![0.0; lay.len()]); chunks.len()];
    if workers == 1 {
        for (c, r) in chunks.iter().zip(results.iter_mut()) {
            run_chunk(packed, scale, &mut work[0], c, r);
        }
    } else {
        let mut jobs: Vec<Vec<Job<'_, '_, T>>> = (0..workers).map(|_| Vec::new()).collect();
        for (k, (c, r)) in chunks.iter().zip(results.iter_mut()).enumerate() {
            jobs[k % workers].push((*c, r));
        }
        let ok = std::thread::scope(|sc| {
            let handles: Vec<_> = work
                .iter_mut()
                .zip(jobs)
                .map(|(w, js)| {
                    sc.spawn(move || {
                        for (c, r) in js {
                            run_chunk(packed, scale, w, c, r);
                        }
                    })
                })
                .collect();
            handles.into_iter().all(|h| h.join().is_ok())
        });
        if !ok {
            return Err(TrainError::ThreadPanicked);
        }
    }
    grad.fill(0.0);
    let mut sum = 0.0;
    for (s, g) in &results {
        sum += s;
        for (a, b) in grad.iter_mut().zip(g) {
            *a += b;
        }
    }
    Ok(sum)
}

/// A worker's job: a chunk of windows and where its result goes.
type Job<'c, 'w, T> = (&'c [WindowRef<'w, T>], &'c mut (f64, Vec<f64>));

/// One chunk's sum of squared errors and gradient (flat f64) into `out`.
fn run_chunk<T: Gemm>(
    packed: &Packed<T>,
    scale: f64,
    work: &mut ChunkWork<T>,
    wins: &[WindowRef<'_, T>],
    out: &mut (f64, Vec<f64>),
) {
    work.grads.zero();
    out.0 = work.run(packed, wins, scale);
    work.grads.add_to_flat(&mut out.1);
}
