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
//! no allocation per step or per epoch once the buffers exist. The published size (I = 2 or 1,
//! H = 8) runs a const-generic kernel whose weights and state live in local arrays; other sizes
//! run the same equations over slices. σ and tanh are computed as `1/(1+e^-z)` and
//! `2σ(2z) - 1` with a branch-free polynomial `exp` ([`exp_f64`], [`exp_f32`]) so that the
//! 4H gates vectorise: tanh so computed has an absolute error of a few ulps (its relative
//! error grows near 0, which costs nothing here).

// The const-size kernels index fixed arrays in nested loops on purpose: the bounds are
// compile-time constants (no checks) and the loops vectorise.
#![allow(clippy::needless_range_loop)]

use core::ops::{Add, AddAssign, Div, Mul, Neg, Sub};

/// The float type the kernel runs in: f64 (exact enough for the PyTorch test vector) or f32
/// (twice the SIMD width).
pub(crate) trait Real:
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
        exp_f64(self)
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
        exp_f32(self)
    }
}

/// eˣ for f64, branch-free so that loops over gates vectorise: x clamped to [-708, 709];
/// x = n·ln2 + r with n = round(x/ln2) (Cody–Waite two-part ln2), |r| ≤ ln2/2; e^r by its
/// Taylor polynomial to degree 13 (truncation < 2e-17 relative); 2ⁿ built in the exponent
/// bits. Relative error a few ulps (checked against `f64::exp` in the tests).
#[inline(always)]
pub(crate) fn exp_f64(x: f64) -> f64 {
    const LOG2E: f64 = core::f64::consts::LOG2_E;
    // fdlibm's split: ln2_hi has 32 trailing zero bits, so n·LN2_HI is exact.
    const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
    const LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76);
    // 1.5·2^52: adding it rounds to an integer held in the low mantissa bits.
    const SHIFT: f64 = 6_755_399_441_055_744.0;
    let x = x.clamp(-708.0, 709.0);
    let t = x * LOG2E + SHIFT;
    let n = t - SHIFT;
    let r = (x - n * LN2_HI) - n * LN2_LO;
    let mut p = 1.0 / 6_227_020_800.0;
    for c in [
        1.0 / 479_001_600.0,
        1.0 / 39_916_800.0,
        1.0 / 3_628_800.0,
        1.0 / 362_880.0,
        1.0 / 40_320.0,
        1.0 / 5_040.0,
        1.0 / 720.0,
        1.0 / 120.0,
        1.0 / 24.0,
        1.0 / 6.0,
        0.5,
        1.0,
        1.0,
    ] {
        p = p * r + c;
    }
    let bits = t.to_bits().wrapping_sub(SHIFT.to_bits()).wrapping_add(1023) << 52;
    p * f64::from_bits(bits)
}

/// eˣ for f32: the flight crate's [`gyrotherm_core::lstm::exp`] (same polynomial, so training
/// and flight agree to the bit on the activations).
#[inline(always)]
pub(crate) fn exp_f32(x: f32) -> f32 {
    gyrotherm_core::lstm::exp(x)
}

#[inline(always)]
pub(crate) fn sigmoid<T: Real>(z: T) -> T {
    T::ONE / (T::ONE + (-z).exp())
}

#[inline(always)]
pub(crate) fn tanh<T: Real>(z: T) -> T {
    let two = T::ONE + T::ONE;
    two * sigmoid(two * z) - T::ONE
}

/// Number of parameters of an I-input, H-hidden network with a 1-output head.
pub(crate) fn param_count(input_size: usize, hidden_size: usize) -> usize {
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
    pub(crate) fn w_ih(&self) -> core::ops::Range<usize> {
        0..4 * self.h * self.i
    }
    pub(crate) fn w_hh(&self) -> core::ops::Range<usize> {
        let s = self.w_ih().end;
        s..s + 4 * self.h * self.h
    }
    pub(crate) fn b_ih(&self) -> core::ops::Range<usize> {
        let s = self.w_hh().end;
        s..s + 4 * self.h
    }
    pub(crate) fn b_hh(&self) -> core::ops::Range<usize> {
        let s = self.b_ih().end;
        s..s + 4 * self.h
    }
    pub(crate) fn w_out(&self) -> core::ops::Range<usize> {
        let s = self.b_hh().end;
        s..s + self.h
    }
    pub(crate) fn b_out(&self) -> usize {
        self.w_out().end
    }
    pub(crate) fn len(&self) -> usize {
        self.b_out() + 1
    }
}

/// Weights packed for the kernel, in T.
#[derive(Debug, Clone)]
pub(crate) struct Packed<T> {
    pub lay: Layout,
    /// `wx[k·4H + r]` = `w_ih[r][k]`.
    pub(crate) wx: Vec<T>,
    /// `wh[m·4H + r]` = `w_hh[r][m]`.
    pub(crate) wh: Vec<T>,
    /// `b_ih + b_hh`.
    pub(crate) b: Vec<T>,
    pub(crate) w_out: Vec<T>,
    pub(crate) b_out: T,
}

impl<T: Real> Packed<T> {
    pub(crate) fn new(lay: Layout) -> Self {
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
    pub(crate) fn load(&mut self, theta: &[f64]) {
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
        for ((b, bi), bh) in self
            .b
            .iter_mut()
            .zip(&theta[lay.b_ih()])
            .zip(&theta[lay.b_hh()])
        {
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
    /// Same layout as [`Packed`]'s.
    pub(crate) wx: Vec<T>,
    pub(crate) wh: Vec<T>,
    pub(crate) b: Vec<T>,
    pub(crate) w_out: Vec<T>,
    pub(crate) b_out: T,
}

impl<T: Real> Grads<T> {
    pub(crate) fn new(lay: Layout) -> Self {
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

    pub(crate) fn zero(&mut self) {
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
    pub(crate) fn add_to_flat(&self, grad: &mut [f64]) {
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
pub(crate) fn forward<T: Real>(
    p: &Packed<T>,
    x: &[T],
    h0: &[T],
    c0: &[T],
    tape: &mut [T],
    y: &mut [T],
) {
    // Constant sizes for the published network let the compiler unroll and vectorise.
    match (p.lay.i, p.lay.h) {
        (2, 8) => forward_const::<T, 2, 8>(p, x, h0, c0, tape, y),
        (1, 8) => forward_const::<T, 1, 8>(p, x, h0, c0, tape, y),
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
    let (b, wx, wh, w_out) = (
        &p.b[..g4],
        &p.wx[..g4 * ni],
        &p.wh[..g4 * nh],
        &p.w_out[..nh],
    );
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
        (2, 8) => backward_const::<T, 2, 8>(p, x, h0, c0, tape, dy, g),
        (1, 8) => backward_const::<T, 1, 8>(p, x, h0, c0, tape, dy, g),
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

/// `[[T; H]; 4]` gate blocks from a 4H slice.
#[inline(always)]
fn gates_from<T: Real, const H: usize>(v: &[T]) -> [[T; H]; 4] {
    let mut out = [[T::ZERO; H]; 4];
    for (o, s) in out.iter_mut().zip(v.chunks_exact(H)) {
        o.copy_from_slice(s);
    }
    out
}

#[inline(always)]
fn array_from<T: Real, const N: usize>(v: &[T]) -> [T; N] {
    let mut out = [T::ZERO; N];
    out.copy_from_slice(&v[..N]);
    out
}

/// Weights of a const-size network in local arrays.
struct ConstWeights<T, const I: usize, const H: usize> {
    /// `wx[k][g][j]` = `w_ih[gH+j][k]`.
    wx: [[[T; H]; 4]; I],
    /// `wh[m][g][j]` = `w_hh[gH+j][m]`.
    wh: [[[T; H]; 4]; H],
    b: [[T; H]; 4],
    w_out: [T; H],
}

impl<T: Real, const I: usize, const H: usize> ConstWeights<T, I, H> {
    #[inline(always)]
    fn new(p: &Packed<T>) -> Self {
        let g4 = 4 * H;
        let mut wx = [[[T::ZERO; H]; 4]; I];
        for (k, w) in wx.iter_mut().enumerate() {
            *w = gates_from(&p.wx[k * g4..(k + 1) * g4]);
        }
        let mut wh = [[[T::ZERO; H]; 4]; H];
        for (m, w) in wh.iter_mut().enumerate() {
            *w = gates_from(&p.wh[m * g4..(m + 1) * g4]);
        }
        ConstWeights {
            wx,
            wh,
            b: gates_from(&p.b),
            w_out: array_from(&p.w_out),
        }
    }
}

/// The activations of one step from the pre-activations z (in place: i, f, g, o), and the
/// new cell state, its tanh and the new hidden state.
#[inline(always)]
fn activate<T: Real, const H: usize>(z: &mut [[T; H]; 4], c: &mut [T; H]) -> ([T; H], [T; H]) {
    let two = T::ONE + T::ONE;
    // tanh(z_g) = 2σ(2 z_g) - 1: one uniform σ loop over all 4H gates.
    for v in z[2].iter_mut() {
        *v = two * *v;
    }
    for zg in z.iter_mut() {
        for v in zg.iter_mut() {
            *v = sigmoid(*v);
        }
    }
    for v in z[2].iter_mut() {
        *v = two * *v - T::ONE;
    }
    let mut tc = [T::ZERO; H];
    let mut h = [T::ZERO; H];
    for j in 0..H {
        c[j] = z[1][j] * c[j] + z[0][j] * z[2][j];
        tc[j] = two * c[j];
    }
    for v in tc.iter_mut() {
        *v = sigmoid(*v);
    }
    for j in 0..H {
        tc[j] = two * tc[j] - T::ONE;
        h[j] = z[3][j] * tc[j];
    }
    (tc, h)
}

/// [`forward`] for compile-time sizes: same equations and tape, local-array weights and state.
fn forward_const<T: Real, const I: usize, const H: usize>(
    p: &Packed<T>,
    x: &[T],
    h0: &[T],
    c0: &[T],
    tape: &mut [T],
    y: &mut [T],
) {
    let w = ConstWeights::<T, I, H>::new(p);
    let mut h: [T; H] = array_from(h0);
    let mut c: [T; H] = array_from(c0);
    let s = tape_stride(H);
    for ((slot, xt), yt) in tape
        .chunks_exact_mut(s)
        .zip(x.chunks_exact(I))
        .zip(y.iter_mut())
    {
        let xt: [T; I] = array_from(xt);
        let mut z = w.b;
        for k in 0..I {
            for g in 0..4 {
                for j in 0..H {
                    z[g][j] += w.wx[k][g][j] * xt[k];
                }
            }
        }
        for m in 0..H {
            for g in 0..4 {
                for j in 0..H {
                    z[g][j] += w.wh[m][g][j] * h[m];
                }
            }
        }
        let (tc, hn) = activate(&mut z, &mut c);
        h = hn;
        let mut out = p.b_out;
        for (wj, hj) in w.w_out.iter().zip(&h) {
            out += *wj * *hj;
        }
        *yt = out;
        let (zs, rest) = slot.split_at_mut(4 * H);
        for (d, v) in zs.chunks_exact_mut(H).zip(&z) {
            d.copy_from_slice(v);
        }
        let (cs, rest) = rest.split_at_mut(H);
        let (tcs, hs) = rest.split_at_mut(H);
        cs.copy_from_slice(&c);
        tcs.copy_from_slice(&tc);
        hs.copy_from_slice(&h);
    }
}

/// [`backward`] for compile-time sizes: same equations, local-array weights and accumulators.
#[allow(clippy::too_many_arguments)]
fn backward_const<T: Real, const I: usize, const H: usize>(
    p: &Packed<T>,
    x: &[T],
    h0: &[T],
    c0: &[T],
    tape: &mut [T],
    dy: &[T],
    g: &mut Grads<T>,
) {
    let s = tape_stride(H);
    let g4 = 4 * H;
    // Row-major W_hh as whr[g][j][m], so δh_{t-1} = Σ_{g,j} whr[g][j]·δz[g][j] runs over m.
    let mut whr = [[[T::ZERO; H]; H]; 4];
    for (m, col) in p.wh.chunks_exact(g4).enumerate() {
        for (r, v) in col.iter().enumerate() {
            whr[r / H][r % H][m] = *v;
        }
    }
    let w_out: [T; H] = array_from(&p.w_out);
    let mut gwx = [[[T::ZERO; H]; 4]; I];
    let mut gwh = [[[T::ZERO; H]; 4]; H];
    let mut gb = [[T::ZERO; H]; 4];
    let mut gw_out = [T::ZERO; H];
    let mut gb_out = T::ZERO;
    let mut dh = [T::ZERO; H];
    let mut dc = [T::ZERO; H];
    let h0: [T; H] = array_from(h0);
    let c0: [T; H] = array_from(c0);
    let steps = dy.len();
    for t in (0..steps).rev() {
        let cur = &tape[t * s..(t + 1) * s];
        let (h_prev, c_prev): ([T; H], [T; H]) = if t == 0 {
            (h0, c0)
        } else {
            let prev = &tape[(t - 1) * s..t * s];
            (array_from(&prev[6 * H..]), array_from(&prev[4 * H..]))
        };
        let a: [[T; H]; 4] = gates_from(&cur[..g4]);
        let tc: [T; H] = array_from(&cur[5 * H..]);
        let h: [T; H] = array_from(&cur[6 * H..]);
        let dyt = dy[t];
        gb_out += dyt;
        let mut dz = [[T::ZERO; H]; 4];
        for j in 0..H {
            gw_out[j] += dyt * h[j];
            let dhj = dh[j] + w_out[j] * dyt;
            let (i, f, gg, o) = (a[0][j], a[1][j], a[2][j], a[3][j]);
            let dcj = dc[j] + dhj * o * (T::ONE - tc[j] * tc[j]);
            dz[0][j] = dcj * gg * i * (T::ONE - i);
            dz[1][j] = dcj * c_prev[j] * f * (T::ONE - f);
            dz[2][j] = dcj * i * (T::ONE - gg * gg);
            dz[3][j] = dhj * tc[j] * o * (T::ONE - o);
            dc[j] = dcj * f;
        }
        for gg in 0..4 {
            for j in 0..H {
                gb[gg][j] += dz[gg][j];
            }
        }
        let xt: [T; I] = array_from(&x[t * I..(t + 1) * I]);
        for k in 0..I {
            for gg in 0..4 {
                for j in 0..H {
                    gwx[k][gg][j] += dz[gg][j] * xt[k];
                }
            }
        }
        for m in 0..H {
            for gg in 0..4 {
                for j in 0..H {
                    gwh[m][gg][j] += dz[gg][j] * h_prev[m];
                }
            }
        }
        // δh_{t-1}: one partial sum per gate block, then added.
        let mut acc = [[T::ZERO; H]; 4];
        for gg in 0..4 {
            for j in 0..H {
                for m in 0..H {
                    acc[gg][m] += whr[gg][j][m] * dz[gg][j];
                }
            }
        }
        for m in 0..H {
            dh[m] = (acc[0][m] + acc[1][m]) + (acc[2][m] + acc[3][m]);
        }
    }
    for (d, v) in g.wx.iter_mut().zip(gwx.iter().flatten().flatten()) {
        *d += *v;
    }
    for (d, v) in g.wh.iter_mut().zip(gwh.iter().flatten().flatten()) {
        *d += *v;
    }
    for (d, v) in g.b.iter_mut().zip(gb.iter().flatten()) {
        *d += *v;
    }
    for (d, v) in g.w_out.iter_mut().zip(&gw_out) {
        *d += *v;
    }
    g.b_out += gb_out;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The polynomial exp against std over [-750, 750] (beyond the clamp: the clamped result
    /// is compared to std at the clamp point) in steps of 1/64 and finely near 0.
    /// Tolerance: 4 ulps relative (4ε of the type).
    #[test]
    fn exp_matches_std() {
        let mut worst = (0.0f64, 0.0f64);
        for k in -48_000..=48_000 {
            let x = k as f64 / 64.0;
            let xc = x.clamp(-708.0, 709.0);
            let want = xc.exp();
            let rel = (exp_f64(x) - want).abs() / want;
            assert!(
                rel <= 4.0 * f64::EPSILON,
                "f64 x {x}: want {want}, got {}, rel {rel:e}",
                exp_f64(x)
            );
            if rel > worst.0 {
                worst = (rel, x);
            }
        }
        println!("exp_f64 worst rel err {:e} at {}", worst.0, worst.1);
        let mut worst = (0.0f64, 0.0f64);
        for k in -6_400..=6_400 {
            let x = k as f32 / 64.0;
            let want = (x.clamp(-87.0, 88.0) as f64).exp();
            let rel = (exp_f32(x) as f64 - want).abs() / want;
            assert!(
                rel <= 4.0 * f32::EPSILON as f64,
                "f32 x {x}: want {want}, got {}, rel {rel:e}",
                exp_f32(x)
            );
            if rel > worst.0 {
                worst = (rel, x as f64);
            }
        }
        println!("exp_f32 worst rel err {:e} at {}", worst.0, worst.1);
        assert!(exp_f64(f64::NAN).is_nan() && exp_f32(f32::NAN).is_nan());
    }
}
