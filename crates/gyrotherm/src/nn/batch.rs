//! The batched kernel of minibatch truncated BPTT: a batch of windows, each from zero state,
//! run side by side so that every time step's gate sums for all windows are one matrix
//! product, and the weight gradients are one matrix product over all steps and windows.
//!
//! The equations are those of [`super::lstm`]; only the order of the sums differs. Matrix
//! products go through nalgebra's `gemm`, which hands dynamic-size f32/f64 products to the
//! `matrixmultiply` crate (its kernels are chosen at run time: AVX-512, FMA, AVX or SSE2, so
//! a build for plain x86-64 still uses the machine's widest units). Shapes, all column-major
//! (one column per window and step):
//!
//! ```text
//! Z[t] (4H × B) = Wx (4H × I) · X[t] (I × B) + Wh (4H × H) · H[t-1] (H × B) + b
//! δH[t-1] (H × B) = Whᵀ · δZ[t]
//! ∂Wx += δZ (4H × T·B) · Xᵀ (T·B × I)      ∂Wh += δZ[1..] · H[..T-1]ᵀ
//! ```
//!
//! A batch is cut into chunks of windows; each chunk is one worker's product and gradient,
//! and the chunks' gradients are summed in chunk order, so the result does not depend on how
//! many threads ran them.

use nalgebra::{DMatrixView, DMatrixViewMut, Dyn};

use super::lstm::{sigmoid, tanh, tape_stride, Grads, Layout, Packed, Real};

/// A matrix in a slice: rows, columns, row stride, column stride (elements).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Shape {
    pub rows: usize,
    pub cols: usize,
    pub rs: usize,
    pub cs: usize,
}

impl Shape {
    /// A column-major matrix with columns `cs` apart.
    pub(crate) fn cols(rows: usize, cols: usize, cs: usize) -> Shape {
        Shape {
            rows,
            cols,
            rs: 1,
            cs,
        }
    }

    /// The transpose of the same elements.
    pub(crate) fn t(self) -> Shape {
        Shape {
            rows: self.cols,
            cols: self.rows,
            rs: self.cs,
            cs: self.rs,
        }
    }
}

/// Above this in every dimension nalgebra hands a product to matrixmultiply; at or below it
/// nalgebra runs its own fallback, which reads out of bounds for a transposed (row-strided)
/// view, so [`small_gemm`] takes those products instead.
const MATRIXMULTIPLY_MIN_DIM: usize = 6;

/// `c = a·b + beta·c` for f32 or f64 (the products matrixmultiply runs).
pub(crate) trait Gemm: Real {
    fn gemm(c: &mut [Self], cs: Shape, a: &[Self], ash: Shape, b: &[Self], bsh: Shape, beta: Self);
}

/// `c = a·b + beta·c` by plain loops (small products; `c` is not read when `beta` is 0).
fn small_gemm<T: Real>(c: &mut [T], csh: Shape, a: &[T], ash: Shape, b: &[T], bsh: Shape, beta: T) {
    for j in 0..csh.cols {
        for i in 0..csh.rows {
            let mut acc = T::ZERO;
            for p in 0..ash.cols {
                acc += a[i * ash.rs + p * ash.cs] * b[p * bsh.rs + j * bsh.cs];
            }
            let k = i * csh.rs + j * csh.cs;
            c[k] = if beta == T::ZERO {
                acc
            } else {
                acc + beta * c[k]
            };
        }
    }
}

macro_rules! impl_gemm {
    ($t:ty) => {
        impl Gemm for $t {
            #[inline]
            fn gemm(
                c: &mut [$t],
                csh: Shape,
                a: &[$t],
                ash: Shape,
                b: &[$t],
                bsh: Shape,
                beta: $t,
            ) {
                assert!(csh.rows == ash.rows && csh.cols == bsh.cols && ash.cols == bsh.rows);
                if csh.rows < MATRIXMULTIPLY_MIN_DIM
                    || csh.cols < MATRIXMULTIPLY_MIN_DIM
                    || ash.cols < MATRIXMULTIPLY_MIN_DIM
                {
                    small_gemm(c, csh, a, ash, b, bsh, beta);
                    return;
                }
                let a = DMatrixView::<$t, Dyn, Dyn>::from_slice_with_strides(
                    a, ash.rows, ash.cols, ash.rs, ash.cs,
                );
                let b = DMatrixView::<$t, Dyn, Dyn>::from_slice_with_strides(
                    b, bsh.rows, bsh.cols, bsh.rs, bsh.cs,
                );
                let mut c = DMatrixViewMut::<$t, Dyn, Dyn>::from_slice_with_strides_mut(
                    c, csh.rows, csh.cols, csh.rs, csh.cs,
                );
                c.gemm(1.0, &a, &b, beta);
            }
        }
    };
}
impl_gemm!(f32);
impl_gemm!(f64);

/// One window of a batch: inputs (steps × I, row-major), target, which steps count in the
/// loss; zero start state.
#[derive(Debug, Clone, Copy)]
pub(crate) struct WindowRef<'a, T> {
    pub x: &'a [T],
    pub target: &'a [f64],
    /// Step t counts if `t >= counted_from` and `mask` (when given) is true at t.
    pub counted_from: usize,
    pub mask: Option<&'a [bool]>,
}

impl<T> WindowRef<'_, T> {
    pub(crate) fn steps(&self) -> usize {
        self.target.len()
    }

    pub(crate) fn counts(&self, t: usize) -> bool {
        t >= self.counted_from && self.mask.is_none_or(|m| m[t])
    }

    pub(crate) fn counted(&self) -> usize {
        (0..self.steps()).filter(|&t| self.counts(t)).count()
    }
}

/// One worker's buffers for a chunk of windows, grown as needed and reused.
pub(crate) struct ChunkWork<T> {
    lay: Layout,
    /// Inputs, column (t, b) at `(t·nb + b)·ip`, zero beyond the I inputs (see `ip`).
    x: Vec<T>,
    /// `Wx` padded with zero columns to `ip` inputs.
    wx: Vec<T>,
    /// The gradient of the padded `Wx`.
    gwx: Vec<T>,
    /// Tape, column (t, b) at `(t·nb + b)·7H`: `[i f g o | c | tanh c | h]`; the gate part
    /// holds δz after the backward pass.
    tape: Vec<T>,
    y: Vec<T>,
    dy: Vec<T>,
    dh: Vec<T>,
    dc: Vec<T>,
    pub(crate) grads: Grads<T>,
}

impl<T: Gemm> ChunkWork<T> {
    pub(crate) fn new(lay: Layout) -> Self {
        ChunkWork {
            lay,
            x: Vec::new(),
            wx: Vec::new(),
            gwx: Vec::new(),
            tape: Vec::new(),
            y: Vec::new(),
            dy: Vec::new(),
            dh: Vec::new(),
            dc: Vec::new(),
            grads: Grads::new(lay),
        }
    }

    /// Forward and backward over `wins` from zero state; adds the gradient of
    /// `Σ counted (y - target)² · scale / 2` into `self.grads` (so `scale = 2/n` gives the
    /// gradient of the MSE over n counted steps) and returns the sum of squared errors.
    pub(crate) fn run(&mut self, p: &Packed<T>, wins: &[WindowRef<'_, T>], scale: f64) -> f64 {
        let Layout { i: ni, h: nh } = self.lay;
        // Inputs padded with zeros to at least MATRIXMULTIPLY_MIN_DIM, so that the input
        // products (over I) go to matrixmultiply too; the padding adds nothing.
        let ip = ni.max(MATRIXMULTIPLY_MIN_DIM);
        let (g4, s) = (4 * nh, tape_stride(nh));
        let nb = wins.len();
        let len = wins.iter().map(|w| w.steps()).max().unwrap_or(0);
        if nb == 0 || len == 0 {
            return 0.0;
        }
        let cols = len * nb;
        // Gather the inputs; steps past a shorter window's end are zero (padding: their dy is
        // zero and nothing flows back from beyond a window's end, so they add nothing).
        self.x.clear();
        self.x.resize(cols * ip, T::ZERO);
        for (b, w) in wins.iter().enumerate() {
            for t in 0..w.steps() {
                let dst = (t * nb + b) * ip;
                self.x[dst..dst + ni].copy_from_slice(&w.x[t * ni..(t + 1) * ni]);
            }
        }
        self.tape.resize(cols * s, T::ZERO);
        self.y.resize(cols, T::ZERO);
        self.dy.resize(cols, T::ZERO);
        self.dh.resize(nh * nb, T::ZERO);
        self.dc.resize(nh * nb, T::ZERO);

        // Forward. Input part of every step at once: Z = Wx · X.
        self.wx.clear();
        self.wx.extend_from_slice(&p.wx[..g4 * ni]);
        self.wx.resize(g4 * ip, T::ZERO);
        let wx = Shape::cols(g4, ip, g4);
        let wh = Shape::cols(g4, nh, g4);
        T::gemm(
            &mut self.tape,
            Shape::cols(g4, cols, s),
            &self.wx,
            wx,
            &self.x,
            Shape::cols(ip, cols, ip),
            T::ZERO,
        );
        let two = T::ONE + T::ONE;
        for t in 0..len {
            let (before, cur) = self.tape.split_at_mut(t * nb * s);
            let cur = &mut cur[..nb * s];
            if t > 0 {
                let prev = &before[(t - 1) * nb * s..];
                T::gemm(
                    cur,
                    Shape::cols(g4, nb, s),
                    &p.wh,
                    wh,
                    &prev[6 * nh..],
                    Shape::cols(nh, nb, s),
                    T::ONE,
                );
            }
            for b in 0..nb {
                let col = &mut cur[b * s..(b + 1) * s];
                let (z, rest) = col.split_at_mut(g4);
                for (zr, br) in z.iter_mut().zip(&p.b) {
                    *zr += *br;
                }
                for (r, zr) in z.iter_mut().enumerate() {
                    *zr = if r / nh == 2 { tanh(*zr) } else { sigmoid(*zr) };
                }
                let (c, rest) = rest.split_at_mut(nh);
                let (tc, h) = rest.split_at_mut(nh);
                let mut out = p.b_out;
                for j in 0..nh {
                    let c_prev = if t > 0 {
                        before[(t - 1) * nb * s + b * s + 4 * nh + j]
                    } else {
                        T::ZERO
                    };
                    let cj = z[nh + j] * c_prev + z[j] * z[2 * nh + j];
                    let tcj = two * sigmoid(two * cj) - T::ONE;
                    let hj = z[3 * nh + j] * tcj;
                    c[j] = cj;
                    tc[j] = tcj;
                    h[j] = hj;
                    out += p.w_out[j] * hj;
                }
                self.y[t * nb + b] = out;
            }
        }

        // Loss and δy.
        let mut sum = 0.0;
        for (b, w) in wins.iter().enumerate() {
            for t in 0..len {
                let k = t * nb + b;
                self.dy[k] = if t < w.steps() && w.counts(t) {
                    let e = self.y[k].to_f64() - w.target[t];
                    sum += e * e;
                    T::from_f64(scale * e)
                } else {
                    T::ZERO
                };
            }
        }

        // Backward through time: δz per step (into the tape's gate part), δh by Whᵀ·δZ.
        self.dh.fill(T::ZERO);
        self.dc.fill(T::ZERO);
        let g = &mut self.grads;
        for t in (0..len).rev() {
            let (before, cur) = self.tape.split_at_mut(t * nb * s);
            let cur = &mut cur[..nb * s];
            for b in 0..nb {
                let dyt = self.dy[t * nb + b];
                let col = &mut cur[b * s..(b + 1) * s];
                let (z, rest) = col.split_at_mut(g4);
                let tc = &rest[nh..2 * nh];
                let h = &rest[2 * nh..3 * nh];
                g.b_out += dyt;
                let dh = &self.dh[b * nh..(b + 1) * nh];
                let dc = &mut self.dc[b * nh..(b + 1) * nh];
                for j in 0..nh {
                    g.w_out[j] += dyt * h[j];
                    let c_prev = if t > 0 {
                        before[(t - 1) * nb * s + b * s + 4 * nh + j]
                    } else {
                        T::ZERO
                    };
                    let dhj = dh[j] + p.w_out[j] * dyt;
                    let (i, f, gg, o) = (z[j], z[nh + j], z[2 * nh + j], z[3 * nh + j]);
                    let dcj = dc[j] + dhj * o * (T::ONE - tc[j] * tc[j]);
                    z[j] = dcj * gg * i * (T::ONE - i);
                    z[nh + j] = dcj * c_prev * f * (T::ONE - f);
                    z[2 * nh + j] = dcj * i * (T::ONE - gg * gg);
                    z[3 * nh + j] = dhj * tc[j] * o * (T::ONE - o);
                    dc[j] = dcj * f;
                }
                for (a, d) in g.b.iter_mut().zip(&*z) {
                    *a += *d;
                }
            }
            if t > 0 {
                T::gemm(
                    &mut self.dh,
                    Shape::cols(nh, nb, nh),
                    &p.wh,
                    wh.t(),
                    cur,
                    Shape::cols(g4, nb, s),
                    T::ZERO,
                );
            }
        }
        // Weight gradients over all steps and windows: ∂Wx += δZ·Xᵀ, ∂Wh += δZ[1..]·H[..-1]ᵀ.
        self.gwx.clear();
        self.gwx.resize(g4 * ip, T::ZERO);
        T::gemm(
            &mut self.gwx,
            wx,
            &self.tape,
            Shape::cols(g4, cols, s),
            &self.x,
            Shape::cols(ip, cols, ip).t(),
            T::ZERO,
        );
        for (a, d) in g.wx.iter_mut().zip(&self.gwx) {
            *a += *d;
        }
        if len > 1 {
            let shifted = (len - 1) * nb;
            T::gemm(
                &mut g.wh,
                wh,
                &self.tape[nb * s..],
                Shape::cols(g4, shifted, s),
                &self.tape[6 * nh..],
                Shape::cols(nh, shifted, s).t(),
                T::ONE,
            );
        }
        sum
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// matrixmultiply's products (through nalgebra) against the plain loops on strided and
    /// transposed views of the shapes the kernel uses, in f64 and f32: within a few ulps of
    /// the sums' magnitude (the summation order differs).
    #[test]
    fn matrixmultiply_products_match_plain_loops() {
        fn check<T: Gemm>(tol: f64) {
            let (m, k, n, pad) = (24, 9, 13, 3);
            let val = |i: usize| T::from_f64(((i * 7919 % 113) as f64 - 56.0) / 37.0);
            // A stored transposed (row stride k + pad), B column-major with padding, C
            // column-major with padding: the kernel's three kinds of view.
            let a: Vec<T> = (0..m * (k + pad)).map(val).collect();
            let ash = Shape::cols(k, m, k + pad).t();
            let b: Vec<T> = (0..n * (k + pad)).map(|i| val(i + 5)).collect();
            let bsh = Shape::cols(k, n, k + pad);
            let csh = Shape::cols(m, n, m + pad);
            for beta in [T::ZERO, T::ONE] {
                let c0: Vec<T> = (0..n * (m + pad)).map(|i| val(i + 11)).collect();
                let (mut fast, mut slow) = (c0.clone(), c0);
                T::gemm(&mut fast, csh, &a, ash, &b, bsh, beta);
                small_gemm(&mut slow, csh, &a, ash, &b, bsh, beta);
                for (x, y) in fast.iter().zip(&slow) {
                    assert!((x.to_f64() - y.to_f64()).abs() <= tol, "{x:?} vs {y:?}");
                }
            }
        }
        check::<f64>(1e-12);
        check::<f32>(1e-4);
    }
}
