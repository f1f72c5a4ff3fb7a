//! LSTM forward pass and backpropagation through time, by hand, generic over f32/f64.
//!
//! Equations (PyTorch `nn.LSTM`, gate order i, f, g, o; He et al. 2024, §2):
//!
//! ```text
//! z  = W_ih x_t + b_ih + W_hh h_{t-1} + b_hh          (4H pre-activations)
//! i, f, o = σ(z_i), σ(z_f), σ(z_o)    g = tanh(z_g)
//! c_t = f·c_{t-1} + i·g    h_t = o·tanh(c_t)    y_t = w_out·h_t + b_out
//! ```
//!
//! Backward, with δy_t = ∂L/∂y_t and δh, δc carried from step t+1:
//!
//! ```text
//! δh   = δh_{t+1} + w_out δy_t              δc = δc_{t+1} + δh·o·(1 - tanh²c_t)
//! δz_o = δh·tanh(c_t)·o(1-o)   δz_i = δc·g·i(1-i)   δz_g = δc·i·(1-g²)   δz_f = δc·c_{t-1}·f(1-f)
//! δc_t-1 = δc·f    δh_{t-1} = W_hhᵀ δz    ∂W_ih += δz x_tᵀ    ∂W_hh += δz h_{t-1}ᵀ    ∂b += δz
//! ```
//!
//! Layout: a per-step tape `[i f g o | c | tanh c | h]` (7H values), weights packed
//! column-major (`w[k][r]`) so that a step is a sum of scaled columns the compiler vectorises;
//! no allocation per step or per epoch once the buffers exist. σ and tanh are computed as
//! `1/(1+e^-z)` and `2σ(2z) - 1` with the standard library's `exp`: tanh so computed has an
//! absolute error of a few ulps (its relative error grows near 0, which costs nothing here).

use core::ops::{Add, AddAssign, Div, Mul, Neg, Sub};

/// The float type the kernel runs in: f64 (exact enough for the PyTorch test vector) or f32
/// (twice the SIMD width).
pub trait Real:
    Copy
    + Default
    + PartialOrd
    + Send
    + Sync
    + 'static
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + core::fmt::Debug
{
    /// 0.
    const ZERO: Self;
    /// 1.
    const ONE: Self;
    /// Convert (rounding for f32).
    fn from_f64(v: f64) -> Self;
    /// Convert (exact).
    fn to_f64(self) -> f64;
    /// eˣ.
    fn exp(self) -> Self;
}

impl Real for f64 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    #[inline(always)]
    fn from_f64(v: f64) -> Self {
        v
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self
    }
    #[inline(always)]
    fn exp(self) -> Self {
        f64::exp(self)
    }
}

impl Real for f32 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    #[inline(always)]
    fn from_f64(v: f64) -> Self {
        v as f32
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self as f64
    }
    #[inline(always)]
    fn exp(self) -> Self {
        f32::exp(self)
    }
}

#[inline(always)]
fn sigmoid<T: Real>(z: T) -> T {
    T::ONE / (T::ONE + (-z).exp())
}

#[inline(always)]
fn tanh<T: Real>(z: T) -> T {
    let two = T::ONE + T::ONE;
    two * sigmoid(two * z) - T::ONE
}

/// Number of parameters of an I-input, H-hidden network with a 1-output head.
pub fn param_count(input_size: usize, hidden_size: usize) -> usize {
    4 * hidden_size * (input_size + hidden_size + 2) + hidden_size + 1
}

/// Offsets of the tensors in the flat parameter vector (PyTorch order: w_ih, w_hh, b_ih, b_hh,
/// w_out, b_out).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Layout {
    pub i: usize,
    pub h: usize,
}

impl Layout {
    pub fn w_ih(&self) -> core::ops::Range<usize> {
        0..4 * self.h * self.i
    }
    pub fn w_hh(&self) -> core::ops::Range<usize> {
        let s = self.w_ih().end;
        s..s + 4 * self.h * self.h
    }
    pub fn b_ih(&self) -> core::ops::Range<usize> {
        let s = self.w_hh().end;
        s..s + 4 * self.h
    }
    pub fn b_hh(&self) -> core::ops::Range<usize> {
        let s = self.b_ih().end;
        s..s + 4 * self.h
    }
    pub fn w_out(&self) -> core::ops::Range<usize> {
        let s = self.b_hh().end;
        s..s + self.h
    }
    pub fn b_out(&self) -> usize {
        self.w_out().end
    }
    pub fn len(&self) -> usize {
        self.b_out() + 1
    }
}

/// Weights packed for the kernel, in T.
#[derive(Debug, Clone)]
pub(crate) struct Packed<T> {
    pub lay: Layout,
    /// `wx[k·4H + r]` = `w_ih[r][k]`.
    wx: Vec<T>,
    /// `wh[m·4H + r]` = `w_hh[r][m]`.
    wh: Vec<T>,
    /// `b_ih + b_hh`.
    b: Vec<T>,
    w_out: Vec<T>,
    b_out: T,
}

impl<T: Real> Packed<T> {
    pub fn new(lay: Layout) -> Self {
        let g4 = 4 * lay.h;
        Packed {
            lay,
            wx: vec![T::ZERO; g4 * lay.i],
            wh: vec![T::ZERO; g4 * lay.h],
            b: vec![T::ZERO; g4],
            w_out: vec![T::ZERO; lay.h],
            b_out: T::ZERO,
        }
    }

    /// Repack from the flat f64 parameter vector (no allocation).
    pub fn load(&mut self, theta: &[f64]) {
        let lay = self.lay;
        let (ni, nh, g4) = (lay.i, lay.h, 4 * lay.h);
        let w_ih = &theta[lay.w_ih()];
        let w_hh = &theta[lay.w_hh()];
        for r in 0..g4 {
            for k in 0..ni {
                self.wx[k * g4 + r] = T::from_f64(w_ih[r * ni + k]);
            }
            for m in 0..nh {
                self.wh[m * g4 + r] = T::from_f64(w_hh[r * nh + m]);
            }
        }
        for ((b, bi), bh) in self.b.iter_mut().zip(&theta[lay.b_ih()]).zip(&theta[lay.b_hh()]) {
            *b = T::from_f64(bi + bh);
        }
        for (w, v) in self.w_out.iter_mut().zip(&theta[lay.w_out()]) {
            *w = T::from_f64(*v);
        }
        self.b_out = T::from_f64(theta[lay.b_out()]);
    }
}

/// Gradient accumulators in the kernel's layout, in T.
#[derive(Debug, Clone)]
pub(crate) struct Grads<T> {
    lay: Layout,
    wx: Vec<T>,
    wh: Vec<T>,
    b: Vec<T>,
    w_out: Vec<T>,
    b_out: T,
}

impl<T: Real> Grads<T> {
    pub fn new(lay: Layout) -> Self {
        let g4 = 4 * lay.h;
        Grads {
            lay,
            wx: vec![T::ZERO; g4 * lay.i],
            wh: vec![T::ZERO; g4 * lay.h],
            b: vec![T::ZERO; g4],
            w_out: vec![T::ZERO; lay.h],
            b_out: T::ZERO,
        }
    }

    pub fn zero(&mut self) {
        for v in self
            .wx
            .iter_mut()
            .chain(&mut self.wh)
            .chain(&mut self.b)
            .chain(&mut self.w_out)
        {
            *v = T::ZERO;
        }
        self.b_out = T::ZERO;
    }

    /// Add into the flat f64 gradient in PyTorch order.
    pub fn add_to_flat(&self, grad: &mut [f64]) {
        let lay = self.lay;
        let (ni, nh, g4) = (lay.i, lay.h, 4 * lay.h);
        let (wi, wh, bi, bh, wo, bo) = (
            lay.w_ih().start,
            lay.w_hh().start,
            lay.b_ih().start,
            lay.b_hh().start,
            lay.w_out().start,
            lay.b_out(),
        );
        for r in 0..g4 {
            for k in 0..ni {
                grad[wi + r * ni + k] += self.wx[k * g4 + r].to_f64();
            }
            for m in 0..nh {
                grad[wh + r * nh + m] += self.wh[m * g4 + r].to_f64();
            }
            // ∂L/∂b_ih = ∂L/∂b_hh = Σ δz.
            grad[bi + r] += self.b[r].to_f64();
            grad[bh + r] += self.b[r].to_f64();
        }
        for j in 0..nh {
            grad[wo + j] += self.w_out[j].to_f64();
        }
        grad[bo] += self.b_out.to_f64();
    }
}

/// Values per step on the tape.
pub(crate) fn tape_stride(h: usize) -> usize {
    7 * h
}

/// Forward over `y.len()` steps from state (h0, c0); writes the tape (7H per step) and y.
/// `x` holds `y.len()·I` inputs, row-major.
pub(crate) fn forward<T: Real>(p: &Packed<T>, x: &[T], h0: &[T], c0: &[T], tape: &mut [T], y: &mut [T]) {
    // Constant sizes for the published network let the compiler unroll and vectorise.
    match (p.lay.i, p.lay.h) {
        (2, 8) => forward_impl(p, 2, 8, x, h0, c0, tape, y),
        (1, 8) => forward_impl(p, 1, 8, x, h0, c0, tape, y),
        (ni, nh) => forward_impl(p, ni, nh, x, h0, c0, tape, y),
    }
}

#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn forward_impl<T: Real>(
    p: &Packed<T>,
    ni: usize,
    nh: usize,
    x: &[T],
    h0: &[T],
    c0: &[T],
    tape: &mut [T],
    y: &mut [T],
) {
    let g4 = 4 * nh;
    let s = tape_stride(nh);
    let (b, wx, wh, w_out) = (&p.b[..g4], &p.wx[..g4 * ni], &p.wh[..g4 * nh], &p.w_out[..nh]);
    let steps = y.len();
    for t in 0..steps {
        let (before, rest) = tape.split_at_mut(t * s);
        let cur = &mut rest[..s];
        let (h_prev, c_prev) = if t == 0 {
            (&h0[..nh], &c0[..nh])
        } else {
            let prev = &before[(t - 1) * s..];
            (&prev[6 * nh..7 * nh], &prev[4 * nh..5 * nh])
        };
        let (z, rest) = cur.split_at_mut(g4);
        z.copy_from_slice(b);
        let xt = &x[t * ni..(t + 1) * ni];
        for (k, xk) in xt.iter().enumerate() {
            for (zr, w) in z.iter_mut().zip(&wx[k * g4..(k + 1) * g4]) {
                *zr += *w * *xk;
            }
        }
        for (m, hm) in h_prev.iter().enumerate() {
            for (zr, w) in z.iter_mut().zip(&wh[m * g4..(m + 1) * g4]) {
                *zr += *w * *hm;
            }
        }
        for (r, zr) in z.iter_mut().enumerate() {
            *zr = if r / nh == 2 { tanh(*zr) } else { sigmoid(*zr) };
        }
        let (c, rest) = rest.split_at_mut(nh);
        let (tc, h) = rest.split_at_mut(nh);
        let mut out = p.b_out;
        for j in 0..nh {
            let cj = z[nh + j] * c_prev[j] + z[j] * z[2 * nh + j];
            let tcj = tanh(cj);
            let hj = z[3 * nh + j] * tcj;
            c[j] = cj;
            tc[j] = tcj;
            h[j] = hj;
            out += w_out[j] * hj;
        }
        y[t] = out;
    }
}

/// Backward over the steps of a tape written by [`forward`] with the same x, h0, c0; `dy[t]` is
/// ∂L/∂y_t. Accumulates into `g`; no gradient flows into (h0, c0). Overwrites the gate part of
/// the tape with δz. `dh`, `dc` are H-long scratch buffers.
#[allow(clippy::too_many_arguments)]
pub(crate) fn backward<T: Real>(
    p: &Packed<T>,
    x: &[T],
    h0: &[T],
    c0: &[T],
    tape: &mut [T],
    dy: &[T],
    g: &mut Grads<T>,
    dh: &mut [T],
    dc: &mut [T],
) {
    match (p.lay.i, p.lay.h) {
        (2, 8) => backward_impl(p, 2, 8, x, h0, c0, tape, dy, g, dh, dc),
        (1, 8) => backward_impl(p, 1, 8, x, h0, c0, tape, dy, g, dh, dc),
        (ni, nh) => backward_impl(p, ni, nh, x, h0, c0, tape, dy, g, dh, dc),
    }
}

#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn backward_impl<T: Real>(
    p: &Packed<T>,
    ni: usize,
    nh: usize,
    x: &[T],
    h0: &[T],
    c0: &[T],
    tape: &mut [T],
    dy: &[T],
    g: &mut Grads<T>,
    dh: &mut [T],
    dc: &mut [T],
) {
    let g4 = 4 * nh;
    let s = tape_stride(nh);
    let (wh, w_out) = (&p.wh[..g4 * nh], &p.w_out[..nh]);
    let (gwx, gwh, gb, gw_out) = (
        &mut g.wx[..g4 * ni],
        &mut g.wh[..g4 * nh],
        &mut g.b[..g4],
        &mut g.w_out[..nh],
    );
    let (dh, dc) = (&mut dh[..nh], &mut dc[..nh]);
    dh.fill(T::ZERO);
    dc.fill(T::ZERO);
    let mut gb_out = T::ZERO;
    for t in (0..dy.len()).rev() {
        let (before, rest) = tape.split_at_mut(t * s);
        let cur = &mut rest[..s];
        let (h_prev, c_prev) = if t == 0 {
            (&h0[..nh], &c0[..nh])
        } else {
            let prev = &before[(t - 1) * s..];
            (&prev[6 * nh..7 * nh], &prev[4 * nh..5 * nh])
        };
        let (z, rest) = cur.split_at_mut(g4);
        let tc = &rest[nh..2 * nh];
        let h = &rest[2 * nh..3 * nh];
        let dyt = dy[t];
        gb_out += dyt;
        for j in 0..nh {
            gw_out[j] += dyt * h[j];
            let dhj = dh[j] + w_out[j] * dyt;
            let (i, f, gg, o) = (z[j], z[nh + j], z[2 * nh + j], z[3 * nh + j]);
            let dcj = dc[j] + dhj * o * (T::ONE - tc[j] * tc[j]);
            z[j] = dcj * gg * i * (T::ONE - i);
            z[nh + j] = dcj * c_prev[j] * f * (T::ONE - f);
            z[2 * nh + j] = dcj * i * (T::ONE - gg * gg);
            z[3 * nh + j] = dhj * tc[j] * o * (T::ONE - o);
            dc[j] = dcj * f;
        }
        let dz = &*z;
        for (a, d) in gb.iter_mut().zip(dz) {
            *a += *d;
        }
        let xt = &x[t * ni..(t + 1) * ni];
        for (k, xk) in xt.iter().enumerate() {
            for (a, d) in gwx[k * g4..(k + 1) * g4].iter_mut().zip(dz) {
                *a += *d * *xk;
            }
        }
        for (m, hm) in h_prev.iter().enumerate() {
            for (a, d) in gwh[m * g4..(m + 1) * g4].iter_mut().zip(dz) {
                *a += *d * *hm;
            }
            // δh_{t-1}[m] = Σ_r W_hh[r][m] δz[r], four partial sums for a shorter chain.
            let col = &wh[m * g4..(m + 1) * g4];
            let mut acc = [T::ZERO; 4];
            for (wc, dcc) in col.chunks_exact(4).zip(dz.chunks_exact(4)) {
                for l in 0..4 {
                    acc[l] += wc[l] * dcc[l];
                }
            }
            dh[m] = (acc[0] + acc[1]) + (acc[2] + acc[3]);
        }
    }
    g.b_out += gb_out;
}
