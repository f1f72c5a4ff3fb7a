//! LSTM + linear read-out parameters, f64, in PyTorch's `nn.LSTM` / `nn.Linear` layout.
//!
//! Gate order of the rows of `w_ih`, `w_hh`, `b_ih`, `b_hh`: i, f, g, o (H rows each), as in
//! PyTorch: i=σ(W_ii x+b_ii+W_hi h+b_hi), f=σ(…), g=tanh(…), o=σ(…), c'=f·c+i·g,
//! h'=o·tanh(c'), y = w_out·h' + b_out.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::lstm::{param_count, Layout};

/// Parameters of one LSTM layer with a one-output linear head. Row-major matrices.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LstmParams {
    /// Number of inputs per step, I.
    pub input_size: usize,
    /// Number of hidden units, H (8 in He et al. 2024).
    pub hidden_size: usize,
    /// Input weights, 4H × I, row-major, gate blocks i, f, g, o.
    pub w_ih: Vec<f64>,
    /// Recurrent weights, 4H × H, row-major, gate blocks i, f, g, o.
    pub w_hh: Vec<f64>,
    /// Input bias, 4H.
    pub b_ih: Vec<f64>,
    /// Recurrent bias, 4H.
    pub b_hh: Vec<f64>,
    /// Read-out weights, H.
    pub w_out: Vec<f64>,
    /// Read-out bias.
    pub b_out: f64,
}

impl LstmParams {
    /// All zeros with the given sizes.
    pub fn zeros(input_size: usize, hidden_size: usize) -> Self {
        let g = 4 * hidden_size;
        LstmParams {
            input_size,
            hidden_size,
            w_ih: vec![0.0; g * input_size],
            w_hh: vec![0.0; g * hidden_size],
            b_ih: vec![0.0; g],
            b_hh: vec![0.0; g],
            w_out: vec![0.0; hidden_size],
            b_out: 0.0,
        }
    }

    /// Check shapes and finiteness; the error names the tensor at fault.
    pub fn validate(&self) -> Result<(), ParamsError> {
        let (i, h) = (self.input_size, self.hidden_size);
        if i == 0 || h == 0 {
            return Err(ParamsError::ZeroSize {
                input_size: i,
                hidden_size: h,
            });
        }
        let shapes = [
            ("w_ih", self.w_ih.len(), 4 * h * i),
            ("w_hh", self.w_hh.len(), 4 * h * h),
            ("b_ih", self.b_ih.len(), 4 * h),
            ("b_hh", self.b_hh.len(), 4 * h),
            ("w_out", self.w_out.len(), h),
        ];
        for (tensor, got, want) in shapes {
            if got != want {
                return Err(ParamsError::Shape {
                    tensor,
                    got,
                    want,
                    input_size: i,
                    hidden_size: h,
                });
            }
        }
        let tensors: [(&'static str, &[f64]); 6] = [
            ("w_ih", &self.w_ih),
            ("w_hh", &self.w_hh),
            ("b_ih", &self.b_ih),
            ("b_hh", &self.b_hh),
            ("w_out", &self.w_out),
            ("b_out", core::slice::from_ref(&self.b_out)),
        ];
        for (tensor, t) in tensors {
            if let Some(index) = t.iter().position(|v| !v.is_finite()) {
                return Err(ParamsError::NonFinite {
                    tensor,
                    index,
                    value: t[index],
                });
            }
        }
        Ok(())
    }
}

/// LSTM parameters that cannot be used: the tensor and the value at fault.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum ParamsError {
    /// A size is zero.
    ZeroSize {
        input_size: usize,
        hidden_size: usize,
    },
    /// A tensor has the wrong number of values.
    Shape {
        tensor: &'static str,
        got: usize,
        want: usize,
        input_size: usize,
        hidden_size: usize,
    },
    /// A value is not finite.
    NonFinite {
        tensor: &'static str,
        index: usize,
        value: f64,
    },
    /// The flight network was built for other sizes.
    FlightSize {
        input_size: usize,
        hidden_size: usize,
        flight_input_size: usize,
        flight_hidden_size: usize,
    },
    /// The flight crate refused the f32 weights (a value beyond ±3.4e38).
    Flight(gyrotherm_core::lstm::WeightError),
}

impl std::fmt::Display for ParamsError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ParamsError::ZeroSize {
                input_size,
                hidden_size,
            } => write!(
                f,
                "input_size {input_size} and hidden_size {hidden_size} must both be at least 1"
            ),
            ParamsError::Shape {
                tensor,
                got,
                want,
                input_size,
                hidden_size,
            } => write!(
                f,
                "{tensor} has {got} values, expected {want} for input_size {input_size}, \
                 hidden_size {hidden_size}"
            ),
            ParamsError::NonFinite {
                tensor,
                index,
                value,
            } => write!(f, "{tensor}[{index}] is not finite ({value})"),
            ParamsError::FlightSize {
                input_size,
                hidden_size,
                flight_input_size,
                flight_hidden_size,
            } => write!(
                f,
                "model has input_size {input_size}, hidden_size {hidden_size}; the flight network \
                 was built for {flight_input_size}, {flight_hidden_size}"
            ),
            ParamsError::Flight(_) => f.write_str(
                "the weights do not convert to the flight network's f32 (a value beyond ±3.4e38)",
            ),
        }
    }
}

impl std::error::Error for ParamsError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ParamsError::Flight(e) => Some(e),
            _ => None,
        }
    }
}

impl LstmParams {
    /// Export to the flight crate's f32 weights (values rounded to nearest f32). Refuses
    /// sizes other than I × H, and values that are not finite or overflow f32.
    pub fn to_core<const I: usize, const H: usize>(
        &self,
    ) -> Result<gyrotherm_core::lstm::LstmWeights<I, H>, ParamsError> {
        if self.input_size != I || self.hidden_size != H {
            return Err(ParamsError::FlightSize {
                input_size: self.input_size,
                hidden_size: self.hidden_size,
                flight_input_size: I,
                flight_hidden_size: H,
            });
        }
        self.validate()?;
        let f = |v: &[f64]| v.iter().map(|x| *x as f32).collect::<Vec<f32>>();
        gyrotherm_core::lstm::LstmWeights::from_slices(
            &f(&self.w_ih),
            &f(&self.w_hh),
            &f(&self.b_ih),
            &f(&self.b_hh),
            &f(&self.w_out),
            self.b_out as f32,
        )
        .map_err(ParamsError::Flight)
    }
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
pub(crate) fn flatten(p: &LstmParams) -> Vec<f64> {
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
pub(crate) fn unflatten(theta: &[f64], input_size: usize, hidden_size: usize) -> LstmParams {
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
