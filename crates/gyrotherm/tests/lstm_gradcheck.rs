//! Finite-difference check of the hand-written BPTT: every parameter of every tensor, central
//! differences in f64, against `loss_and_grad`.

use gyrotherm::nn::{init_params, loss_and_grad, Sequence};

mod lstm_layout;
use lstm_layout::{flatten, unflatten};

/// Central-difference step. Truncation error ~h²·|L'''| ≈ 1e-10, rounding ~ε·L/h ≈ 1e-11.
const FD_STEP: f64 = 1e-5;
/// Relative error tolerance |g_bptt - g_fd| / max(|g_fd|, FLOOR): a wrong term in a
/// derivative gives errors of order 1, the differences' own error is ≲ 1e-7 relative.
const REL_TOL: f64 = 1e-5;
/// Gradients smaller than this are compared absolutely, to 1e-9 (= REL_TOL·FLOOR): the
/// differences themselves carry an absolute error of ~1e-10.
const FLOOR: f64 = 1e-4;

/// A smooth, deterministic input/target run: `steps` × `ni` inputs of normalised magnitude.
fn run(steps: usize, ni: usize) -> (Vec<f64>, Vec<f64>) {
    let x: Vec<f64> = (0..steps * ni)
        .map(|k| {
            let (t, c) = ((k / ni) as f64, (k % ni) as f64);
            (0.13 * t + 0.7 * c).sin() * (1.0 + 0.3 * c)
        })
        .collect();
    let y: Vec<f64> = (0..steps).map(|t| (0.05 * t as f64).cos() * 0.8).collect();
    (x, y)
}

fn check(ni: usize, nh: usize, steps: usize, masked: bool) -> f64 {
    let mut p = init_params(ni, nh, 7);
    // Larger weights than at init, so gates leave their linear range (as after training).
    for v in p.w_hh.iter_mut().chain(&mut p.w_ih) {
        *v *= 3.0;
    }
    let (x, y) = run(steps, ni);
    let mask: Vec<bool> = (0..steps).map(|t| t % 3 != 1).collect();
    let seq = if masked {
        Sequence::new(&x, &y).with_mask(&mask)
    } else {
        Sequence::new(&x, &y)
    };
    let (_, grad) = loss_and_grad(&p, &[seq]).unwrap();
    let g = flatten(&grad);
    let theta = flatten(&p);
    let names = ["w_ih", "w_hh", "b_ih", "b_hh", "w_out", "b_out"];
    let sizes = [4 * nh * ni, 4 * nh * nh, 4 * nh, 4 * nh, nh, 1];
    let mut worst = 0.0f64;
    let mut k = 0;
    for (name, n) in names.iter().zip(sizes) {
        let mut worst_t = 0.0f64;
        for _ in 0..n {
            let mut tp = theta.clone();
            tp[k] += FD_STEP;
            let lp = loss_and_grad(&unflatten(&tp, ni, nh), &[seq]).unwrap().0;
            tp[k] -= 2.0 * FD_STEP;
            let lm = loss_and_grad(&unflatten(&tp, ni, nh), &[seq]).unwrap().0;
            let fd = (lp - lm) / (2.0 * FD_STEP);
            let rel = (g[k] - fd).abs() / fd.abs().max(FLOOR);
            assert!(
                rel <= REL_TOL,
                "I={ni} H={nh} {name} (flat {k}): finite difference {fd:e}, BPTT {:e}, rel err {rel:e}",
                g[k]
            );
            worst_t = worst_t.max(rel);
            k += 1;
        }
        println!("I={ni} H={nh} masked={masked} {name}: max rel err {worst_t:e}");
        worst = worst.max(worst_t);
    }
    worst
}

#[test]
fn gradient_matches_finite_differences_published_size() {
    // I = 2, H = 8: the published network, through the size-specialised kernel.
    check(2, 8, 60, false);
}

#[test]
fn gradient_matches_finite_differences_other_size_masked() {
    // I = 3, H = 5 through the general kernel, with a loss mask.
    check(3, 5, 40, true);
}
