//! LSTM cell + linear read-out, f32 inference, one sample at a time.
//!
//! The published compensator (He et al. 2024, DOI 10.19452/j.issn1007-5453.2024.02.004, §2):
//! one LSTM layer, 2 inputs (temperature and its 20 s rate), 8 hidden units, one linear output.
//! Equations and gate order are PyTorch's `nn.LSTM` + `nn.Linear(H, 1)`:
//!
//! ```text
//! i  = σ(W_ii x + b_ii + W_hi h + b_hi)      f = σ(W_if x + b_if + W_hf h + b_hf)
//! g  = tanh(W_ig x + b_ig + W_hg h + b_hg)   o = σ(W_io x + b_io + W_ho h + b_ho)
//! c' = f·c + i·g     h' = o·tanh(c')     y = w_out·h' + b_out
//! ```
//!
//! Activations: σ(z) = 1 / (1 + e^-z) and tanh(z) = 2σ(2z) - 1, with e^x from [`exp`], a
//! branch-free polynomial (no `libm` call) so that the 4H gates of a step vectorise; `libm`'s
//! `expf`/`tanhf` cost ~300 ns a step on the development machine, [`exp`] meets the 100 ns
//! budget. Accuracy (swept against std in the tests): e^x and σ within 4 ulps relative,
//! tanh within 3e-7 absolute.
//!
//! Two types:
//! - [`LstmWeights`]: the parameters as plain arrays in PyTorch layout (row `gate·H + j` of
//!   `weight_ih` is `w_ih[gate][j]`), checked once for finiteness by its constructors; `const`,
//!   so a flight build can keep it in a `static`.
//! - [`Lstm`]: the weights repacked for the step loop plus the state (h, c). [`Lstm::step`]
//!   is panic-free and allocation-free for every input; a non-finite input is refused and the
//!   state is left untouched.

use core::fmt;

use crate::error::{Channel, InputError};

/// Gate blocks in PyTorch order.
const GATES: usize = 4;

/// Which parameter tensor, in PyTorch names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tensor {
    /// `weight_ih_l0`, 4H × I.
    WIh,
    /// `weight_hh_l0`, 4H × H.
    WHh,
    /// `bias_ih_l0`, 4H.
    BIh,
    /// `bias_hh_l0`, 4H.
    BHh,
    /// Read-out weight, H.
    WOut,
    /// Read-out bias, 1.
    BOut,
}

impl fmt::Display for Tensor {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Tensor::WIh => "w_ih",
            Tensor::WHh => "w_hh",
            Tensor::BIh => "b_ih",
            Tensor::BHh => "b_hh",
            Tensor::WOut => "w_out",
            Tensor::BOut => "b_out",
        })
    }
}

/// Weights the constructors refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum WeightError {
    /// A slice had the wrong number of values for the compile-time sizes.
    Shape {
        /// Which tensor.
        tensor: Tensor,
        /// Values given.
        got: usize,
        /// Values expected.
        want: usize,
    },
    /// A NaN or infinite value, at the flat row-major index in PyTorch layout.
    NonFinite {
        /// Which tensor.
        tensor: Tensor,
        /// Flat row-major index.
        index: usize,
    },
}

impl fmt::Display for WeightError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            WeightError::Shape { tensor, got, want } => {
                write!(f, "{tensor} has {got} values, expected {want}")
            }
            WeightError::NonFinite { tensor, index } => {
                write!(f, "{tensor}[{index}] is not finite")
            }
        }
    }
}

impl core::error::Error for WeightError {}

/// LSTM + linear read-out weights, f32, PyTorch layout; I inputs, H hidden units (8 as in
/// He et al. 2024, §2). Every value is finite (checked by [`LstmWeights::new`] and
/// [`LstmWeights::from_slices`], the only constructors).
#[derive(Debug, Clone, PartialEq)]
pub struct LstmWeights<const I: usize, const H: usize = 8> {
    w_ih: [[[f32; I]; H]; GATES],
    w_hh: [[[f32; H]; H]; GATES],
    b_ih: [[f32; H]; GATES],
    b_hh: [[f32; H]; GATES],
    w_out: [f32; H],
    b_out: f32,
}

/// First non-finite value of `v`, as its index. Slice patterns, not indexing: `const` and
/// panic-free.
const fn first_non_finite(v: &[f32]) -> Option<usize> {
    let mut rest = v;
    let mut k = 0;
    while let [head, tail @ ..] = rest {
        if !head.is_finite() {
            return Some(k);
        }
        rest = tail;
        k += 1;
    }
    None
}

impl<const I: usize, const H: usize> LstmWeights<I, H> {
    /// Checked constructor from arrays in PyTorch layout: `w_ih[gate][j][k]` is row
    /// `gate·H + j`, column k of `weight_ih_l0` (gates i, f, g, o), and so on. Refuses any
    /// non-finite value. `const`, so it can build a `static`:
    ///
    /// ```
    /// use gyrotherm_core::lstm::LstmWeights;
    /// static W: LstmWeights<1, 1> = match LstmWeights::new(
    ///     [[[0.5]], [[0.5]], [[0.5]], [[0.5]]],
    ///     [[[0.1]], [[0.1]], [[0.1]], [[0.1]]],
    ///     [[0.0]; 4],
    ///     [[0.0]; 4],
    ///     [1.0],
    ///     0.0,
    /// ) {
    ///     Ok(w) => w,
    ///     Err(_) => panic!("non-finite weight"),
    /// };
    /// ```
    pub const fn new(
        w_ih: [[[f32; I]; H]; GATES],
        w_hh: [[[f32; H]; H]; GATES],
        b_ih: [[f32; H]; GATES],
        b_hh: [[f32; H]; GATES],
        w_out: [f32; H],
        b_out: f32,
    ) -> Result<Self, WeightError> {
        // Gate by gate, row by row, walking the arrays as slices (no indexing in a const fn).
        let (mut gi, mut gh, mut gbi, mut gbh): (&[_], &[_], &[_], &[_]) =
            (&w_ih, &w_hh, &b_ih, &b_hh);
        let mut g = 0;
        while let ([wi, ti @ ..], [wh, th @ ..], [bi, tbi @ ..], [bh, tbh @ ..]) =
            (gi, gh, gbi, gbh)
        {
            let (mut ri, mut rh): (&[[f32; I]], &[[f32; H]]) = (wi, wh);
            let mut j = 0;
            while let ([row_i, tri @ ..], [row_h, trh @ ..]) = (ri, rh) {
                let row = g * H + j;
                if let Some(k) = first_non_finite(row_i) {
                    return Err(WeightError::NonFinite {
                        tensor: Tensor::WIh,
                        index: row * I + k,
                    });
                }
                if let Some(k) = first_non_finite(row_h) {
                    return Err(WeightError::NonFinite {
                        tensor: Tensor::WHh,
                        index: row * H + k,
                    });
                }
                (ri, rh) = (tri, trh);
                j += 1;
            }
            if let Some(j) = first_non_finite(bi) {
                return Err(WeightError::NonFinite {
                    tensor: Tensor::BIh,
                    index: g * H + j,
                });
            }
            if let Some(j) = first_non_finite(bh) {
                return Err(WeightError::NonFinite {
                    tensor: Tensor::BHh,
                    index: g * H + j,
                });
            }
            (gi, gh, gbi, gbh) = (ti, th, tbi, tbh);
            g += 1;
        }
        if let Some(j) = first_non_finite(&w_out) {
            return Err(WeightError::NonFinite {
                tensor: Tensor::WOut,
                index: j,
            });
        }
        if !b_out.is_finite() {
            return Err(WeightError::NonFinite {
                tensor: Tensor::BOut,
                index: 0,
            });
        }
        Ok(LstmWeights {
            w_ih,
            w_hh,
            b_ih,
            b_hh,
            w_out,
            b_out,
        })
    }

    /// Checked constructor from flat row-major slices in PyTorch layout (`w_ih`: 4H·I values,
    /// `w_hh`: 4H·H, `b_ih` and `b_hh`: 4H, `w_out`: H). Refuses wrong lengths and non-finite
    /// values, naming the tensor.
    pub fn from_slices(
        w_ih: &[f32],
        w_hh: &[f32],
        b_ih: &[f32],
        b_hh: &[f32],
        w_out: &[f32],
        b_out: f32,
    ) -> Result<Self, WeightError> {
        let shapes = [
            (Tensor::WIh, w_ih.len(), GATES * H * I),
            (Tensor::WHh, w_hh.len(), GATES * H * H),
            (Tensor::BIh, b_ih.len(), GATES * H),
            (Tensor::BHh, b_hh.len(), GATES * H),
            (Tensor::WOut, w_out.len(), H),
        ];
        for (tensor, got, want) in shapes {
            if got != want {
                return Err(WeightError::Shape { tensor, got, want });
            }
        }
        let mut a_ih = [[[0.0; I]; H]; GATES];
        let mut a_hh = [[[0.0; H]; H]; GATES];
        let mut a_bi = [[0.0; H]; GATES];
        let mut a_bh = [[0.0; H]; GATES];
        let mut a_out = [0.0; H];
        for (dst, src) in a_ih.iter_mut().flatten().flatten().zip(w_ih) {
            *dst = *src;
        }
        for (dst, src) in a_hh.iter_mut().flatten().flatten().zip(w_hh) {
            *dst = *src;
        }
        for (dst, src) in a_bi.iter_mut().flatten().zip(b_ih) {
            *dst = *src;
        }
        for (dst, src) in a_bh.iter_mut().flatten().zip(b_hh) {
            *dst = *src;
        }
        for (dst, src) in a_out.iter_mut().zip(w_out) {
            *dst = *src;
        }
        Self::new(a_ih, a_hh, a_bi, a_bh, a_out, b_out)
    }

    /// `weight_ih_l0` as `[gate][j][k]`.
    pub fn w_ih(&self) -> &[[[f32; I]; H]; GATES] {
        &self.w_ih
    }
    /// `weight_hh_l0` as `[gate][j][m]`.
    pub fn w_hh(&self) -> &[[[f32; H]; H]; GATES] {
        &self.w_hh
    }
    /// `bias_ih_l0` as `[gate][j]`.
    pub fn b_ih(&self) -> &[[f32; H]; GATES] {
        &self.b_ih
    }
    /// `bias_hh_l0` as `[gate][j]`.
    pub fn b_hh(&self) -> &[[f32; H]; GATES] {
        &self.b_hh
    }
    /// Read-out weight.
    pub fn w_out(&self) -> &[f32; H] {
        &self.w_out
    }
    /// Read-out bias.
    pub fn b_out(&self) -> f32 {
        self.b_out
    }
}

/// e^x in f32, branch-free: x clamped to [-87, 88] (so 2ⁿ stays a normal float; e^x is then
/// 1.6e-38 at the bottom, 1.65e38 at the top); x = n·ln2 + r with n = round(x/ln2) by the
/// 1.5·2²³ rounding trick and ln2 split in two (Cody–Waite), |r| ≤ ln2/2; e^r by its Taylor
/// polynomial to degree 7 (truncation < 1e-8 relative); 2ⁿ built in the exponent bits.
/// NaN in, NaN out.
#[inline(always)]
pub fn exp(x: f32) -> f32 {
    const LOG2E: f32 = core::f32::consts::LOG2_E;
    const LN2_HI: f32 = 0.693_145_75;
    const LN2_LO: f32 = 1.428_606_8e-6;
    const SHIFT: f32 = 12_582_912.0;
    let x = x.clamp(-87.0, 88.0);
    let t = x * LOG2E + SHIFT;
    let n = t - SHIFT;
    let r = (x - n * LN2_HI) - n * LN2_LO;
    let mut p = 1.0 / 5_040.0;
    for c in [
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
    let bits = t.to_bits().wrapping_sub(SHIFT.to_bits()).wrapping_add(127) << 23;
    p * f32::from_bits(bits)
}

/// Logistic sigmoid σ(z) = 1 / (1 + e^-z) with [`exp`]; in [0, 1] for every non-NaN z.
#[inline(always)]
pub fn sigmoid(z: f32) -> f32 {
    1.0 / (1.0 + exp(-z))
}

/// tanh(z) = 2σ(2z) - 1; in [-1, 1] for every non-NaN z, absolute error ≤ 3e-7.
#[inline(always)]
pub fn tanh(z: f32) -> f32 {
    2.0 * sigmoid(2.0 * z) - 1.0
}

/// A running LSTM: weights repacked for the step loop, plus the state (h, c), zero at start.
///
/// Size: 4H·(I + H + 1) + 3H + 1 floats (1.5 KiB for I = 2, H = 8), on 64-byte boundaries:
/// `repr(C)` keeps the field order, and every column of 4H floats is 16H bytes, so each
/// column starts 16-byte aligned and SIMD loads of the weights fold into the multiplies.
#[derive(Debug, Clone, PartialEq)]
#[repr(C, align(64))]
pub struct Lstm<const I: usize, const H: usize = 8> {
    /// `w_x[k][gate][j]` = `w_ih[gate][j][k]`: column-major, so the 4H gate sums are a sum of
    /// scaled columns, each column 4H contiguous floats (8 SSE vectors for H = 8).
    w_x: [[[f32; H]; GATES]; I],
    /// `w_h[m][gate][j]` = `w_hh[gate][j][m]`.
    w_h: [[[f32; H]; GATES]; H],
    /// `b_ih + b_hh`.
    b: [[f32; H]; GATES],
    h: [f32; H],
    c: [f32; H],
    w_out: [f32; H],
    b_out: f32,
}

impl<const I: usize, const H: usize> Lstm<I, H> {
    /// A network with zero state. The weights were checked by their constructor.
    pub fn new(weights: &LstmWeights<I, H>) -> Self {
        // Transpose [gate][j][k] into [k][gate][j]: column k of each row lands in w_x[k].
        let mut w_x = [[[0.0; H]; GATES]; I];
        for (k, col) in w_x.iter_mut().enumerate() {
            for (col_g, w_g) in col.iter_mut().zip(&weights.w_ih) {
                for (dst, row) in col_g.iter_mut().zip(w_g) {
                    *dst = row.get(k).copied().unwrap_or(0.0);
                }
            }
        }
        let mut w_h = [[[0.0; H]; GATES]; H];
        for (m, col) in w_h.iter_mut().enumerate() {
            for (col_g, w_g) in col.iter_mut().zip(&weights.w_hh) {
                for (dst, row) in col_g.iter_mut().zip(w_g) {
                    *dst = row.get(m).copied().unwrap_or(0.0);
                }
            }
        }
        let mut b = weights.b_ih;
        for (b_g, bh_g) in b.iter_mut().zip(&weights.b_hh) {
            for (bj, bh) in b_g.iter_mut().zip(bh_g) {
                *bj += bh;
            }
        }
        Lstm {
            w_x,
            w_h,
            b,
            w_out: weights.w_out,
            b_out: weights.b_out,
            h: [0.0; H],
            c: [0.0; H],
        }
    }

    /// One sample: feed `x`, advance the state, return the read-out y.
    ///
    /// Panic-free and allocation-free for every input (fixed-size arrays, iterator loops,
    /// no indexing that can fail). Errors, with the state left untouched:
    /// - `x[k]` NaN or ±∞: `InputError::NonFinite(Channel::Feature(k))`;
    /// - finite inputs so large (|x| ≳ 1e37) that the gate sums overflow to NaN:
    ///   `InputError::NonFinite(Channel::Feature(k))` with k the input of largest magnitude.
    ///
    /// With finite weights, the state stays finite: |h| ≤ 1 and |c| grows by at most 1 a step.
    ///
    /// Arithmetic, element by element (the order a C port must keep to match bit for bit;
    /// every operation rounds to f32, no FMA):
    /// `z = b; z += W_ih[:,k]·x[k] for k = 0..I; z += W_hh[:,m]·h[m] for m = 0..H`;
    /// `i, f, o = σ(z)`, `g' = σ(2·z_g)`; `c = f·c + i·(2g' - 1)`; `t = σ(2c)`;
    /// `h = o·(2t - 1)`; `y = b_out; y += w_out[j]·h[j] for j = 0..H`.
    /// Each loop runs across the 4H gates or the H units (SIMD lanes), never across the
    /// terms of one sum, so vectorising does not re-associate anything. The recurrence
    /// (h → gate sums → σ → c → σ → h) is a chain of about 75 dependent operations, two of
    /// them divisions: that chain, not the arithmetic, bounds the time of a step.
    #[inline]
    pub fn step(&mut self, x: &[f32; I]) -> Result<f32, InputError> {
        if let Some(k) = x.iter().position(|v| !v.is_finite()) {
            return Err(InputError::NonFinite(Channel::Feature(feature_index(k))));
        }
        // Gate pre-activations z = b + W_ih x + W_hh h, as a sum of scaled columns.
        let mut z = self.b;
        for (col, xk) in self.w_x.iter().zip(x) {
            for (zg, cg) in z.iter_mut().zip(col) {
                for (zj, w) in zg.iter_mut().zip(cg) {
                    *zj += w * xk;
                }
            }
        }
        for (col, hm) in self.w_h.iter().zip(&self.h) {
            for (zg, cg) in z.iter_mut().zip(col) {
                for (zj, w) in zg.iter_mut().zip(cg) {
                    *zj += w * hm;
                }
            }
        }
        // One uniform σ pass over all 4H gates (tanh z_g = 2σ(2 z_g) - 1), so it vectorises.
        for v in z[2].iter_mut() {
            *v *= 2.0;
        }
        for zg in z.iter_mut() {
            for v in zg.iter_mut() {
                *v = sigmoid(*v);
            }
        }
        let [zi, zf, zg, zo] = &z;
        // Lane j of each row; j < H always, so the fallback is never taken (and is compiled
        // out), but no index can panic.
        let lane = |row: &[f32; H], j: usize| row.get(j).copied().unwrap_or(0.0);
        let c: [f32; H] = core::array::from_fn(|j| {
            lane(zf, j) * lane(&self.c, j) + lane(zi, j) * (2.0 * lane(zg, j) - 1.0)
        });
        let mut tc: [f32; H] = core::array::from_fn(|j| 2.0 * lane(&c, j));
        for v in tc.iter_mut() {
            *v = sigmoid(*v);
        }
        let mut h = *zo;
        for (hj, tj) in h.iter_mut().zip(&tc) {
            *hj *= 2.0 * tj - 1.0;
        }
        let mut y = self.b_out;
        for (wj, hj) in self.w_out.iter().zip(&h) {
            y += wj * hj;
        }
        // A NaN anywhere in h (only from an overflowing gate sum) reaches y, since the
        // read-out weights are finite and 0·NaN is NaN; |h| ≤ 1 so y cannot overflow.
        if !y.is_finite() {
            let mut k_max = (0, 0.0f32);
            for (k, v) in x.iter().enumerate() {
                if v.abs() > k_max.1 {
                    k_max = (k, v.abs());
                }
            }
            return Err(InputError::NonFinite(Channel::Feature(feature_index(
                k_max.0,
            ))));
        }
        self.h = h;
        self.c = c;
        Ok(y)
    }

    /// Zero the state (h = c = 0), as at the start of a run.
    pub fn reset(&mut self) {
        self.h = [0.0; H];
        self.c = [0.0; H];
    }

    /// Hidden state h.
    pub fn hidden(&self) -> &[f32; H] {
        &self.h
    }

    /// Cell state c.
    pub fn cell(&self) -> &[f32; H] {
        &self.c
    }

    /// Set the state (h, c), e.g. to resume a run. Refuses non-finite values
    /// (`Channel::Feature(j)`, j the state index) and leaves the state untouched.
    pub fn set_state(&mut self, h: &[f32; H], c: &[f32; H]) -> Result<(), InputError> {
        if let Some(j) = h.iter().chain(c).position(|v| !v.is_finite()) {
            return Err(InputError::NonFinite(Channel::Feature(feature_index(
                j % H.max(1),
            ))));
        }
        self.h = *h;
        self.c = *c;
        Ok(())
    }
}

/// Feature index as the error's u8, saturating (inputs beyond 255 report 255).
fn feature_index(k: usize) -> u8 {
    u8::try_from(k).unwrap_or(u8::MAX)
}

#[cfg(test)]
#[allow(
    clippy::indexing_slicing,
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic
)]
mod tests {
    use super::*;

    impl<const I: usize, const H: usize> Lstm<I, H> {
        /// The step as first written (indexed loops over the units): the reference that
        /// [`Lstm::step`] must equal bit for bit.
        #[allow(clippy::needless_range_loop)]
        fn step_reference(&mut self, x: &[f32; I]) -> Result<f32, InputError> {
            if let Some(k) = x.iter().position(|v| !v.is_finite()) {
                return Err(InputError::NonFinite(Channel::Feature(feature_index(k))));
            }
            let mut z = self.b;
            for (col, xk) in self.w_x.iter().zip(x) {
                for (zg, cg) in z.iter_mut().zip(col) {
                    for (zj, w) in zg.iter_mut().zip(cg) {
                        *zj += w * xk;
                    }
                }
            }
            for (col, hm) in self.w_h.iter().zip(&self.h) {
                for (zg, cg) in z.iter_mut().zip(col) {
                    for (zj, w) in zg.iter_mut().zip(cg) {
                        *zj += w * hm;
                    }
                }
            }
            for v in z[2].iter_mut() {
                *v *= 2.0;
            }
            for zg in z.iter_mut() {
                for v in zg.iter_mut() {
                    *v = sigmoid(*v);
                }
            }
            let [zi, zf, zg, zo] = &z;
            let mut c = [0.0f32; H];
            let mut tc = [0.0f32; H];
            for j in 0..H {
                c[j] = zf[j] * self.c[j] + zi[j] * (2.0 * zg[j] - 1.0);
                tc[j] = 2.0 * c[j];
            }
            for v in tc.iter_mut() {
                *v = sigmoid(*v);
            }
            let mut h = [0.0f32; H];
            let mut y = self.b_out;
            for j in 0..H {
                h[j] = zo[j] * (2.0 * tc[j] - 1.0);
                y += self.w_out[j] * h[j];
            }
            if !y.is_finite() {
                let mut k_max = (0, 0.0f32);
                for (k, v) in x.iter().enumerate() {
                    if v.abs() > k_max.1 {
                        k_max = (k, v.abs());
                    }
                }
                return Err(InputError::NonFinite(Channel::Feature(feature_index(
                    k_max.0,
                ))));
            }
            self.h = h;
            self.c = c;
            Ok(y)
        }
    }

    /// xorshift64*: a deterministic stream for the equality sweep (no dependency).
    struct Rng(u64);
    impl Rng {
        fn next_u64(&mut self) -> u64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
        }
        /// Uniform in [-1, 1).
        fn unit(&mut self) -> f32 {
            (self.next_u64() >> 40) as f32 / (1u64 << 23) as f32 - 1.0
        }
        /// Uniform in [-scale, scale), with scale drawn from 1e-3 to 1e3 per call
        /// site when `wide`, so both saturated gates and tiny sums occur.
        fn value(&mut self, scale: f32) -> f32 {
            self.unit() * scale
        }
        fn scale(&mut self) -> f32 {
            let e = (self.next_u64() % 7) as i32 - 3;
            10f32.powi(e)
        }
    }

    /// Random weights, each tensor at its own scale (1e-3 … 1e3).
    fn random_weights<const I: usize, const H: usize>(rng: &mut Rng) -> LstmWeights<I, H> {
        let s = [
            rng.scale(),
            rng.scale(),
            rng.scale(),
            rng.scale(),
            rng.scale(),
        ];
        let w_ih: Vec<f32> = (0..GATES * H * I).map(|_| rng.value(s[0])).collect();
        let w_hh: Vec<f32> = (0..GATES * H * H).map(|_| rng.value(s[1])).collect();
        let b_ih: Vec<f32> = (0..GATES * H).map(|_| rng.value(s[2])).collect();
        let b_hh: Vec<f32> = (0..GATES * H).map(|_| rng.value(s[2])).collect();
        let w_out: Vec<f32> = (0..H).map(|_| rng.value(s[3])).collect();
        let b_out = rng.value(s[4]);
        LstmWeights::from_slices(&w_ih, &w_hh, &b_ih, &b_hh, &w_out, b_out).unwrap()
    }

    /// `Lstm::step` against `step_reference` over random weights, states and inputs: the
    /// outputs, errors and states must agree bit for bit (compared as bit patterns, so a
    /// differing NaN payload or signed zero would fail too). Inputs include values large
    /// enough to overflow the gate sums (the error path) and non-finite ones.
    fn step_equals_reference<const I: usize, const H: usize>(seed: u64, nets: usize, steps: usize) {
        let mut rng = Rng(seed);
        let (mut n_ok, mut n_err) = (0usize, 0usize);
        for _ in 0..nets {
            let w = random_weights::<I, H>(&mut rng);
            let mut fast = Lstm::new(&w);
            let (hs, cs) = (rng.scale().min(1.0), rng.scale() * 10.0);
            let h0: [f32; H] = core::array::from_fn(|_| rng.value(hs));
            let c0: [f32; H] = core::array::from_fn(|_| rng.value(cs));
            fast.set_state(&h0, &c0).unwrap();
            let mut slow = fast.clone();
            let xs = rng.scale();
            for _ in 0..steps {
                let mut x: [f32; I] = core::array::from_fn(|_| rng.value(xs));
                match rng.next_u64() % 64 {
                    0 => x[0] = f32::MAX * rng.unit(),
                    1 => x[I - 1] = f32::NAN,
                    2 => x[0] = 1e30 * rng.unit(),
                    _ => {}
                }
                let (a, b) = (fast.step(&x), slow.step_reference(&x));
                match (a, b) {
                    (Ok(a), Ok(b)) => {
                        assert_eq!(a.to_bits(), b.to_bits(), "y: {a} vs {b}, x {x:?}");
                        n_ok += 1;
                    }
                    (a, b) => {
                        assert_eq!(a, b, "x {x:?}");
                        n_err += 1;
                    }
                }
                let bits = |v: &[f32; H]| v.map(f32::to_bits);
                assert_eq!(bits(fast.hidden()), bits(slow.hidden()));
                assert_eq!(bits(fast.cell()), bits(slow.cell()));
            }
        }
        assert!(
            n_ok > nets * steps / 2 && n_err > 0,
            "{n_ok} ok, {n_err} errors"
        );
    }

    #[test]
    fn step_equals_reference_bit_for_bit() {
        step_equals_reference::<2, 8>(0x9e37_79b9_7f4a_7c15, 400, 250);
        step_equals_reference::<1, 1>(7, 200, 100);
        step_equals_reference::<3, 5>(11, 200, 100);
        step_equals_reference::<12, 8>(13, 100, 100);
        // The larger networks of the LSTM recipes (hidden size is a training setting).
        step_equals_reference::<12, 32>(17, 20, 100);
        step_equals_reference::<12, 64>(19, 8, 100);
    }

    /// Sweep e^x, σ and tanh against std f64 over [-30, 30] in steps of 1/1024 (e^x over
    /// [-87, 88]) plus extremes. Tolerances: e^x and σ 4 f32 ulps relative (4·2^-23 ≈ 4.8e-7;
    /// σ also passes with 1e-37 absolute deep in its lower tail, where exp is clamped); tanh
    /// 3e-7 absolute (2σ(2z) - 1 cancels near 0). The worst points are printed.
    #[test]
    fn activations_match_std() {
        const REL_TOL: f64 = 4.0 * f32::EPSILON as f64;
        const SIGMOID_ABS_TOL: f64 = 1e-37;
        const TANH_ABS_TOL: f64 = 3e-7;
        let (mut w_exp, mut w_sig, mut w_tanh) =
            ((0.0f64, 0.0f32), (0.0f64, 0.0f32), (0.0f64, 0.0f32));
        for k in -87 * 1024..=88 * 1024 {
            let x = k as f32 / 1024.0;
            let want = (x as f64).exp();
            let rel = (exp(x) as f64 - want).abs() / want;
            assert!(
                rel <= REL_TOL,
                "exp({x}): want {want}, got {}, rel {rel:e}",
                exp(x)
            );
            if rel > w_exp.0 {
                w_exp = (rel, x);
            }
        }
        let extremes = [-1e30f32, -100.0, -88.5, 88.5, 100.0, 1e30];
        let sweep = (-30 * 1024..=30 * 1024).map(|k| k as f32 / 1024.0);
        for x in sweep.chain(extremes) {
            let xd = x as f64;
            let want = 1.0 / (1.0 + (-xd).exp());
            let err = (sigmoid(x) as f64 - want).abs();
            let rel = err / want.max(f64::MIN_POSITIVE);
            assert!(
                rel <= REL_TOL || err <= SIGMOID_ABS_TOL,
                "sigmoid({x}): want {want}, got {}, rel err {rel:e}",
                sigmoid(x)
            );
            if err > SIGMOID_ABS_TOL && rel > w_sig.0 {
                w_sig = (rel, x);
            }
            let want = xd.tanh();
            let err = (tanh(x) as f64 - want).abs();
            assert!(
                err <= TANH_ABS_TOL,
                "tanh({x}): want {want}, got {}, err {err:e}",
                tanh(x)
            );
            if err > w_tanh.0 {
                w_tanh = (err, x);
            }
        }
        assert!(exp(f32::NAN).is_nan() && sigmoid(f32::NAN).is_nan());
        std::println!(
            "worst: exp rel {:e} at {}, sigmoid rel {:e} at {}, tanh abs {:e} at {}",
            w_exp.0,
            w_exp.1,
            w_sig.0,
            w_sig.1,
            w_tanh.0,
            w_tanh.1
        );
    }

    fn weights_1x1() -> LstmWeights<1, 1> {
        LstmWeights::new(
            [[[0.5]], [[-0.25]], [[0.75]], [[0.1]]],
            [[[0.2]], [[0.3]], [[-0.4]], [[0.6]]],
            [[0.1], [0.2], [0.3], [0.4]],
            [[-0.05], [0.05], [0.0], [0.1]],
            [1.5],
            -0.5,
        )
        .unwrap()
    }

    /// Hand-computed (f64) two-step run of a 1×1 cell from the equations in the module doc.
    #[test]
    fn step_matches_equations() {
        const TOL: f64 = 1e-6; // f32 arithmetic on O(1) values
        let mut net = Lstm::new(&weights_1x1());
        let (mut h, mut c) = (0.0f64, 0.0f64);
        let s = |z: f64| 1.0 / (1.0 + (-z).exp());
        for x in [0.8f64, -1.3] {
            let i = s(0.5 * x + 0.2 * h + 0.05);
            let f = s(-0.25 * x + 0.3 * h + 0.25);
            let g = (0.75 * x - 0.4 * h + 0.3).tanh();
            let o = s(0.1 * x + 0.6 * h + 0.5);
            c = f * c + i * g;
            h = o * c.tanh();
            let want = 1.5 * h - 0.5;
            let got = net.step(&[x as f32]).unwrap() as f64;
            assert!((got - want).abs() < TOL, "want {want}, got {got}");
            assert!((net.hidden()[0] as f64 - h).abs() < TOL);
            assert!((net.cell()[0] as f64 - c).abs() < TOL);
        }
        net.reset();
        assert_eq!((net.hidden()[0], net.cell()[0]), (0.0, 0.0));
    }

    #[test]
    fn non_finite_input_leaves_state() {
        let w: LstmWeights<2, 1> =
            LstmWeights::from_slices(&[0.1; 8], &[0.2; 4], &[0.0; 4], &[0.0; 4], &[1.0], 0.0)
                .unwrap();
        let mut net = Lstm::new(&w);
        net.step(&[1.0, 2.0]).unwrap();
        let before = net.clone();
        for bad in [
            [f32::NAN, 0.0],
            [0.0, f32::INFINITY],
            [0.0, f32::NEG_INFINITY],
        ] {
            let k = bad.iter().position(|v| !v.is_finite()).unwrap() as u8;
            assert_eq!(
                net.step(&bad),
                Err(InputError::NonFinite(Channel::Feature(k)))
            );
            assert_eq!(net, before);
        }
        // Finite inputs whose weighted sum overflows: 2·MAX - 2·MAX = inf - inf = NaN.
        let w: LstmWeights<2, 1> = LstmWeights::from_slices(
            &[2.0, -2.0].repeat(4),
            &[0.2; 4],
            &[0.0; 4],
            &[0.0; 4],
            &[1.0],
            0.0,
        )
        .unwrap();
        let mut net = Lstm::new(&w);
        net.step(&[1.0, 2.0]).unwrap();
        let before = net.clone();
        assert_eq!(
            net.step(&[f32::MAX, f32::MAX]),
            Err(InputError::NonFinite(Channel::Feature(0)))
        );
        assert_eq!(net, before);
        // Large but harmless inputs saturate the gates and are accepted.
        assert!(net.step(&[1e30, -1e30]).is_ok());
    }

    #[test]
    fn constructors_refuse_bad_weights() {
        let e = LstmWeights::<2, 1>::from_slices(
            &[0.1; 7],
            &[0.2; 4],
            &[0.0; 4],
            &[0.0; 4],
            &[1.0],
            0.0,
        );
        assert_eq!(
            e,
            Err(WeightError::Shape {
                tensor: Tensor::WIh,
                got: 7,
                want: 8
            })
        );
        let mut w_hh = [0.2; 4];
        w_hh[3] = f32::NAN;
        let e =
            LstmWeights::<2, 1>::from_slices(&[0.1; 8], &w_hh, &[0.0; 4], &[0.0; 4], &[1.0], 0.0);
        assert_eq!(
            e,
            Err(WeightError::NonFinite {
                tensor: Tensor::WHh,
                index: 3
            })
        );
        let e = LstmWeights::<2, 1>::from_slices(
            &[0.1; 8],
            &[0.2; 4],
            &[0.0; 4],
            &[0.0; 4],
            &[1.0],
            f32::INFINITY,
        );
        assert_eq!(
            e,
            Err(WeightError::NonFinite {
                tensor: Tensor::BOut,
                index: 0
            })
        );
    }

    #[test]
    fn set_state_refuses_non_finite() {
        let mut net = Lstm::new(&weights_1x1());
        assert!(net.set_state(&[0.5], &[f32::NAN]).is_err());
        assert_eq!(net.hidden(), &[0.0]);
        net.set_state(&[0.5], &[-0.25]).unwrap();
        assert_eq!((net.hidden(), net.cell()), (&[0.5], &[-0.25]));
    }
}
