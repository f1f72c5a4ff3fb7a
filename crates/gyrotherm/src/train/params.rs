//! LSTM + linear read-out parameters, f64, in PyTorch's `nn.LSTM` / `nn.Linear` layout.
//!
//! Gate order of the rows of `w_ih`, `w_hh`, `b_ih`, `b_hh`: i, f, g, o (H rows each), as in
//! PyTorch: i=σ(W_ii x+b_ii+W_hi h+b_hi), f=σ(…), g=tanh(…), o=σ(…), c'=f·c+i·g,
//! h'=o·tanh(c'), y = w_out·h' + b_out.

use serde::{Deserialize, Serialize};

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

    /// Check shapes and finiteness; the message names the tensor at fault.
    pub fn validate(&self) -> Result<(), String> {
        let (i, h) = (self.input_size, self.hidden_size);
        if i == 0 || h == 0 {
            return Err(format!(
                "input_size {i} and hidden_size {h} must both be at least 1"
            ));
        }
        let shapes = [
            ("w_ih", self.w_ih.len(), 4 * h * i),
            ("w_hh", self.w_hh.len(), 4 * h * h),
            ("b_ih", self.b_ih.len(), 4 * h),
            ("b_hh", self.b_hh.len(), 4 * h),
            ("w_out", self.w_out.len(), h),
        ];
        for (name, got, want) in shapes {
            if got != want {
                return Err(format!(
                    "{name} has {got} values, expected {want} for input_size {i}, hidden_size {h}"
                ));
            }
        }
        let tensors: [(&str, &[f64]); 6] = [
            ("w_ih", &self.w_ih),
            ("w_hh", &self.w_hh),
            ("b_ih", &self.b_ih),
            ("b_hh", &self.b_hh),
            ("w_out", &self.w_out),
            ("b_out", core::slice::from_ref(&self.b_out)),
        ];
        for (name, t) in tensors {
            if let Some(k) = t.iter().position(|v| !v.is_finite()) {
                return Err(format!("{name}[{k}] is not finite ({})", t[k]));
            }
        }
        Ok(())
    }
}

impl LstmParams {
    /// Export to the flight crate's f32 weights (values rounded to nearest f32). Refuses
    /// sizes other than I × H, and values that are not finite or overflow f32.
    pub fn to_core<const I: usize, const H: usize>(
        &self,
    ) -> Result<gyrotherm_core::lstm::LstmWeights<I, H>, String> {
        if self.input_size != I || self.hidden_size != H {
            return Err(format!(
                "model has input_size {}, hidden_size {}; the flight network was built for {I}, {H}",
                self.input_size, self.hidden_size
            ));
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
        .map_err(|e| format!("{e} after conversion to f32 (value beyond ±3.4e38)"))
    }
}
