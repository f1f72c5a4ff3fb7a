//! Adam (Kingma & Ba 2015), arithmetic as in `torch.optim.Adam` (single-tensor path,
//! `amsgrad=False`, `weight_decay=0`):
//!
//! ```text
//! t += 1
//! m = m + (1-β1)·(g - m)                  (torch: exp_avg.lerp_(grad, 1-β1))
//! v = β2·v + (1-β2)·g²
//! θ = θ - (lr / (1-β1^t)) · m / (√v / √(1-β2^t) + ε)
//! ```
//!
//! Defaults β1 0.9, β2 0.999, ε 1e-8 (PyTorch's, used by He et al. 2024 with lr 0.01).

/// Adam state over a flat f64 parameter vector.
#[derive(Debug, Clone, PartialEq)]
pub struct Adam {
    /// Learning rate (0.01 in He et al. 2024).
    pub lr: f64,
    /// First-moment decay β1.
    pub beta1: f64,
    /// Second-moment decay β2.
    pub beta2: f64,
    /// ε added to the denominator.
    pub eps: f64,
    m: Vec<f64>,
    v: Vec<f64>,
    t: u64,
}

impl Adam {
    /// Fresh state (zero moments, step 0) for `n` parameters.
    pub fn new(n: usize, lr: f64, beta1: f64, beta2: f64, eps: f64) -> Adam {
        Adam {
            lr,
            beta1,
            beta2,
            eps,
            m: vec![0.0; n],
            v: vec![0.0; n],
            t: 0,
        }
    }

    /// Steps taken so far.
    pub fn steps(&self) -> u64 {
        self.t
    }

    /// One update of `params` with gradient `grad` (same length as at construction).
    pub fn step(&mut self, params: &mut [f64], grad: &[f64]) {
        self.t += 1;
        let t = self.t as f64;
        let bias_correction1 = 1.0 - self.beta1.powf(t);
        let bias_correction2 = 1.0 - self.beta2.powf(t);
        let step_size = self.lr / bias_correction1;
        let bc2_sqrt = bias_correction2.sqrt();
        let w1 = 1.0 - self.beta1;
        let w2 = 1.0 - self.beta2;
        for (((p, g), m), v) in params
            .iter_mut()
            .zip(grad)
            .zip(&mut self.m)
            .zip(&mut self.v)
        {
            *m += w1 * (g - *m);
            *v = *v * self.beta2 + w2 * g * g;
            let denom = v.sqrt() / bc2_sqrt + self.eps;
            *p += -step_size * (*m / denom);
        }
    }
}

/// The cosine-decayed learning rate before Adam step `step` (from 0) of `total`:
/// `lr·(1 + cos(π·step/total))/2`, PyTorch's `CosineAnnealingLR(T_max = total, eta_min = 0)`
/// in closed form (Loshchilov & Hutter 2017, eq. 5, without restarts).
pub fn cosine_lr(lr: f64, step: usize, total: usize) -> f64 {
    let frac = step as f64 / total.max(1) as f64;
    lr * (1.0 + (std::f64::consts::PI * frac).cos()) / 2.0
}

/// Scale `grad` so that its Euclidean norm is at most `max_norm`, as
/// `torch.nn.utils.clip_grad_norm_`: coefficient max_norm / (‖g‖ + 1e-6), applied when < 1.
/// Returns the norm before clipping.
pub fn clip_grad_norm(grad: &mut [f64], max_norm: f64) -> f64 {
    let norm = grad.iter().map(|g| g * g).sum::<f64>().sqrt();
    let coef = max_norm / (norm + 1e-6);
    if coef < 1.0 {
        for g in grad.iter_mut() {
            *g *= coef;
        }
    }
    norm
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clip_scales_to_max_norm_only_when_above() {
        // ‖(3, 4)‖ = 5: clipped to 1 gives (0.6, 0.8) up to the 1e-6 guard of torch's formula.
        let mut g = [3.0, 4.0];
        assert_eq!(clip_grad_norm(&mut g, 1.0), 5.0);
        let want = [0.6, 0.8];
        for (got, want) in g.iter().zip(want) {
            assert!((got - want).abs() < 1e-6, "want {want}, got {got}");
        }
        let mut g = [0.3, 0.4];
        clip_grad_norm(&mut g, 1.0);
        assert_eq!(g, [0.3, 0.4]);
    }

    /// Loshchilov & Hutter 2017, eq. 5 (η_min = 0, no restart): η_max at the start, half of
    /// it midway, zero at the end.
    #[test]
    fn cosine_lr_runs_from_lr_to_zero() {
        assert_eq!(cosine_lr(0.01, 0, 10), 0.01);
        assert!((cosine_lr(0.01, 5, 10) - 0.005).abs() < 1e-18);
        assert!(cosine_lr(0.01, 10, 10).abs() < 1e-18);
        assert!(cosine_lr(0.01, 2, 10) > cosine_lr(0.01, 3, 10));
    }

    #[test]
    fn first_step_moves_each_parameter_by_lr() {
        // Kingma & Ba 2015, §2.1: with bias correction, the first step is lr·g/(|g| + ε'),
        // i.e. lr·sign(g) for |g| ≫ ε.
        let mut p = [1.0, -2.0, 0.5];
        let mut adam = Adam::new(3, 0.01, 0.9, 0.999, 1e-8);
        adam.step(&mut p, &[0.5, -3.0, 1e-3]);
        let want = [0.99, -1.99, 0.49];
        for (got, want) in p.iter().zip(want) {
            assert!((got - want).abs() < 1e-7, "want {want}, got {got}");
        }
        assert_eq!(adam.steps(), 1);
    }
}
