//! The forward/backward kernel over whole runs: buffers allocated once, per-run inputs
//! converted to the kernel's float type.

use super::config::Sequence;
use super::lstm::{backward, forward, tape_stride, Grads, Layout, Packed, Real};

/// Buffers and per-run inputs converted to T; no allocation after construction.
pub(crate) struct Kernel<T> {
    pub(crate) lay: Layout,
    pub(crate) packed: Packed<T>,
    pub(crate) grads: Grads<T>,
    /// Inputs of each run in T.
    pub(crate) xs: Vec<Vec<T>>,
    pub(crate) tape: Vec<T>,
    pub(crate) y: Vec<T>,
    pub(crate) dy: Vec<T>,
    pub(crate) dh: Vec<T>,
    pub(crate) dc: Vec<T>,
    pub(crate) zeros: Vec<T>,
}

impl<T: Real> Kernel<T> {
    pub(crate) fn new(lay: Layout, runs: &[Sequence<'_>]) -> Self {
        let longest = runs.iter().map(|r| r.steps()).max().unwrap_or(0);
        Self::with_tape(lay, runs, longest)
    }

    /// The runs' inputs in T and the packed weights, without the whole-run tape (for
    /// training on sampled windows, whose tapes are the batch kernel's).
    pub(crate) fn inputs_only(lay: Layout, runs: &[Sequence<'_>]) -> Self {
        Self::with_tape(lay, runs, 0)
    }

    fn with_tape(lay: Layout, runs: &[Sequence<'_>], longest: usize) -> Self {
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
    pub(crate) fn mse(&mut self, theta: &[f64], runs: &[Sequence<'_>]) -> f64 {
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
    pub(crate) fn full_grad(
        &mut self,
        theta: &[f64],
        runs: &[Sequence<'_>],
        grad: &mut [f64],
    ) -> f64 {
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
