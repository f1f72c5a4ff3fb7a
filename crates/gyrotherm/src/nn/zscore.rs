//! Z-score normalisation, part of the model: x' = (x - mean) / std, per channel.

use serde::{Deserialize, Serialize};

/// Per-channel mean and standard deviation (population, n) of the training data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ZScore {
    pub mean: Vec<f64>,
    pub std: Vec<f64>,
}

impl ZScore {
    /// Fit to `rows` of `channels` values each (row-major `data`, `data.len() % channels == 0`).
    /// A channel with zero spread gets std 1 so that it maps to 0 instead of dividing by zero.
    pub fn fit(data: &[f64], channels: usize) -> ZScore {
        let n = data.len().checked_div(channels).unwrap_or(0);
        let mut mean = vec![0.0; channels];
        let mut std = vec![1.0; channels];
        if n == 0 {
            return ZScore { mean, std };
        }
        for c in 0..channels {
            let m = data.iter().skip(c).step_by(channels).sum::<f64>() / n as f64;
            let v = data
                .iter()
                .skip(c)
                .step_by(channels)
                .map(|x| (x - m) * (x - m))
                .sum::<f64>()
                / n as f64;
            mean[c] = m;
            std[c] = if v.sqrt() > 0.0 && v.is_finite() {
                v.sqrt()
            } else {
                1.0
            };
        }
        ZScore { mean, std }
    }

    /// (x - mean) / std for channel `c`.
    pub fn apply(&self, c: usize, x: f64) -> f64 {
        (x - self.mean[c]) / self.std[c]
    }

    /// x·std + mean for channel `c`.
    pub(crate) fn invert(&self, c: usize, z: f64) -> f64 {
        z * self.std[c] + self.mean[c]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_apply_invert() {
        // Two channels: [1,2,3] (mean 2, population std sqrt(2/3)) and a constant 5.
        let z = ZScore::fit(&[1.0, 5.0, 2.0, 5.0, 3.0, 5.0], 2);
        assert_eq!(z.mean, vec![2.0, 5.0]);
        assert!((z.std[0] - (2.0f64 / 3.0).sqrt()).abs() < 1e-15);
        assert_eq!(z.std[1], 1.0);
        assert!((z.invert(0, z.apply(0, 2.7)) - 2.7).abs() < 1e-15);
    }
}
