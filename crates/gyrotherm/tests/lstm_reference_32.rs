//! The LSTM engine at 32 hidden units against PyTorch: `tests/data/pytorch_lstm_5x32.json`,
//! made by `tests/data/gen_pytorch_lstm_32.py` (torch 2.15, `nn.LSTM(5, 32) + nn.Linear(32, 1)`
//! in float64): outputs and final states of three runs, and a minibatch of windows with the
//! burn-in left out of the loss (its gradient, then three clipped Adam steps with cosine
//! learning-rate decay). The file stores computed values to 8 significant digits.

use gyrotherm::nn::adam::{clip_grad_norm, cosine_lr, Adam};
use gyrotherm::nn::{
    batch_loss_and_grad, loss_and_grad, predict_with_state, LstmParams, Precision, Sequence,
};
use serde_json::Value;

mod lstm_layout;
use lstm_layout::{flatten, unflatten};

/// Outputs, final states and losses: 1e-6 relative, as for the 8-unit reference
/// (`tests/lstm_reference.rs`); the file's 8 significant digits are 5e-9 relative.
const OUT_REL_TOL: f64 = 1e-6;
/// Gradients, gradient norms and parameters after Adam steps: 1e-5 relative, as for the
/// 8-unit reference.
const GRAD_REL_TOL: f64 = 1e-5;
/// The f32 batched kernel (the training default) against PyTorch's f64 gradient: within this
/// fraction of the largest gradient magnitude (f32 ε = 6e-8 summed over 4 windows × 40 steps;
/// a wrong term would be off by O(1)).
const F32_GRAD_TOL: f64 = 1e-4;
/// Denominators of relative errors are floored here (values this small compare absolutely).
const REL_FLOOR: f64 = 1e-9;

fn load() -> Value {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/pytorch_lstm_5x32.json"
    );
    let text = std::fs::read_to_string(path).expect("reference file readable");
    serde_json::from_str(&text).expect("reference JSON parses")
}

fn flat(v: &Value) -> Vec<f64> {
    match v {
        Value::Array(a) => a.iter().flat_map(flat).collect(),
        Value::Number(n) => vec![n.as_f64().unwrap()],
        other => panic!("unexpected JSON value {other}"),
    }
}

fn sizes(r: &Value) -> (usize, usize) {
    (
        r["input_size"].as_u64().unwrap() as usize,
        r["hidden_size"].as_u64().unwrap() as usize,
    )
}

fn params(p: &Value, i: usize, h: usize) -> LstmParams {
    LstmParams {
        input_size: i,
        hidden_size: h,
        w_ih: flat(&p["weight_ih"]),
        w_hh: flat(&p["weight_hh"]),
        b_ih: flat(&p["bias_ih"]),
        b_hh: flat(&p["bias_hh"]),
        w_out: flat(&p["head_weight"]),
        b_out: flat(&p["head_bias"])[0],
    }
}

/// Max relative error of `got` against `want`, asserting `tol`.
fn compare(what: &str, got: &[f64], want: &[f64], tol: f64) {
    assert_eq!(got.len(), want.len(), "{what}: length");
    let mut worst = (0.0f64, 0usize);
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        let rel = (g - w).abs() / w.abs().max(REL_FLOOR);
        if rel > worst.0 {
            worst = (rel, k);
        }
    }
    let k = worst.1;
    assert!(
        worst.0 <= tol,
        "{what}[{k}]: want {}, got {}, rel err {:e} > {tol:e}",
        want[k],
        got[k],
        worst.0
    );
    println!("{what}: max rel err {:e} (at {k})", worst.0);
}

/// The windows of one minibatch step: inputs and targets cut from the stored series.
struct Batch {
    x: Vec<Vec<f64>>,
    t: Vec<Vec<f64>>,
}

fn batch(mb: &Value, step: &Value, n_in: usize) -> Batch {
    let w = mb["window"].as_u64().unwrap() as usize;
    let (sx, st) = (flat(&mb["series_x"]), flat(&mb["series_target"]));
    let starts: Vec<usize> = step["starts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_u64().unwrap() as usize)
        .collect();
    Batch {
        x: starts
            .iter()
            .map(|&s| sx[s * n_in..(s + w) * n_in].to_vec())
            .collect(),
        t: starts.iter().map(|&s| st[s..s + w].to_vec()).collect(),
    }
}

impl Batch {
    fn seqs(&self) -> Vec<Sequence<'_>> {
        self.x
            .iter()
            .zip(&self.t)
            .map(|(x, t)| Sequence::new(x, t))
            .collect()
    }
}

#[test]
fn forward_matches_pytorch_at_32_units() {
    let r = load();
    let (i, h) = sizes(&r);
    assert_eq!(h, 32);
    let p = params(&r["params"], i, h);
    for case in r["cases"].as_array().unwrap() {
        let name = case["name"].as_str().unwrap();
        let out = predict_with_state(
            &p,
            &flat(&case["x"]),
            &flat(&case["h0"]),
            &flat(&case["c0"]),
        )
        .unwrap();
        compare(&format!("{name} y"), &out.y, &flat(&case["y"]), OUT_REL_TOL);
        compare(
            &format!("{name} h_n"),
            &out.h_n,
            &flat(&case["h_n"]),
            OUT_REL_TOL,
        );
        compare(
            &format!("{name} c_n"),
            &out.c_n,
            &flat(&case["c_n"]),
            OUT_REL_TOL,
        );
    }
    let case = &r["cases"][0];
    let (x, target) = (flat(&case["x"]), flat(&case["target"]));
    let (loss, _) = loss_and_grad(&p, &[Sequence::new(&x, &target)]).unwrap();
    compare(
        "case 0 loss",
        &[loss],
        &[case["loss"].as_f64().unwrap()],
        OUT_REL_TOL,
    );
}

/// The batched kernel (one matrix product per step over the windows), in f64, on the batch
/// and on the batch three times over (one and three workers), and the whole-run kernel with each window as a run whose burn-in is
/// masked: each against PyTorch's loss and gradient of every parameter.
#[test]
fn minibatch_gradient_matches_pytorch_at_32_units() {
    let r = load();
    let (i, h) = sizes(&r);
    let p = params(&r["params"], i, h);
    let mb = &r["minibatch"];
    let burn_in = mb["burn_in"].as_u64().unwrap() as usize;
    let step = &mb["steps"][0];
    let b = batch(mb, step, i);
    let want_loss = step["loss_before_step"].as_f64().unwrap();
    let want = flatten(&params(&mb["grad_step0"], i, h));
    // The batch three times over has the same MSE and gradient, and with 12 windows the
    // per-step products are wide enough for matrixmultiply (chunks of 8 and 4 windows).
    let tripled: Vec<Sequence<'_>> = (0..3).flat_map(|_| b.seqs()).collect();
    for (windows, threads) in [(b.seqs(), 1), (tripled.clone(), 1), (tripled, 3)] {
        let (loss, grad) =
            batch_loss_and_grad(&p, &windows, burn_in, Precision::F64, threads).unwrap();
        compare(
            &format!("batched loss ({threads} workers)"),
            &[loss],
            &[want_loss],
            OUT_REL_TOL,
        );
        compare(
            &format!("batched grad ({threads} workers)"),
            &flatten(&grad),
            &want,
            GRAD_REL_TOL,
        );
    }
    let masks: Vec<Vec<bool>> =
        b.t.iter()
            .map(|t| (0..t.len()).map(|k| k >= burn_in).collect())
            .collect();
    let runs: Vec<Sequence<'_>> = b
        .seqs()
        .into_iter()
        .zip(&masks)
        .map(|(s, m)| s.with_mask(m))
        .collect();
    let (loss, grad) = loss_and_grad(&p, &runs).unwrap();
    compare("whole-run kernel loss", &[loss], &[want_loss], OUT_REL_TOL);
    compare(
        "whole-run kernel grad",
        &flatten(&grad),
        &want,
        GRAD_REL_TOL,
    );

    // f32 (the training default): within F32_GRAD_TOL of the largest gradient.
    let (_, g32) = batch_loss_and_grad(&p, &b.seqs(), burn_in, Precision::F32, 0).unwrap();
    let scale = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let worst = flatten(&g32)
        .iter()
        .zip(&want)
        .map(|(a, b)| (a - b).abs() / scale)
        .fold(0.0, f64::max);
    assert!(
        worst <= F32_GRAD_TOL,
        "f32 batched gradient off by {worst:e} of max |g|"
    );
}

/// Three steps of the minibatch recipe as the trainer takes them: batched gradient, clipping
/// to the stored norm, Adam with the cosine-decayed rate; losses, norms, rates and the final
/// parameters against PyTorch.
#[test]
fn clipped_cosine_adam_steps_match_pytorch_at_32_units() {
    let r = load();
    let (i, h) = sizes(&r);
    let mut p = params(&r["params"], i, h);
    let mb = &r["minibatch"];
    let burn_in = mb["burn_in"].as_u64().unwrap() as usize;
    let (lr, clip) = (
        mb["lr"].as_f64().unwrap(),
        mb["clip_grad_norm"].as_f64().unwrap(),
    );
    let steps = mb["steps"].as_array().unwrap();
    let mut theta = flatten(&p);
    // torch.optim.Adam defaults besides lr, as the reference's "optimizer" field states.
    let mut adam = Adam::new(theta.len(), lr, 0.9, 0.999, 1e-8);
    for (k, step) in steps.iter().enumerate() {
        let b = batch(mb, step, i);
        let (loss, grad) = batch_loss_and_grad(&p, &b.seqs(), burn_in, Precision::F64, 0).unwrap();
        compare(
            &format!("step {k} loss"),
            &[loss],
            &[step["loss_before_step"].as_f64().unwrap()],
            OUT_REL_TOL,
        );
        let mut g = flatten(&grad);
        let norm = clip_grad_norm(&mut g, clip);
        compare(
            &format!("step {k} grad norm"),
            &[norm],
            &[step["grad_norm_before_clip"].as_f64().unwrap()],
            GRAD_REL_TOL,
        );
        adam.lr = cosine_lr(lr, k, steps.len());
        compare(
            &format!("step {k} lr"),
            &[adam.lr],
            &[step["lr"].as_f64().unwrap()],
            1e-15,
        );
        adam.step(&mut theta, &g);
        p = unflatten(&theta, i, h);
    }
    let want = flatten(&params(&mb["params_after"], i, h));
    compare("params after the steps", &theta, &want, GRAD_REL_TOL);
}

/// The flight network (`gyrotherm_core::lstm::Lstm<5, 32>`, f32) on the same runs: each
/// output and the final state within f32 rounding of PyTorch's f64 (1e-4 of the largest
/// magnitude; a wrong term would be off by O(1)).
#[test]
fn flight_network_matches_pytorch_at_32_units() {
    const F32_TOL: f64 = 1e-4;
    let r = load();
    let (i, h) = sizes(&r);
    assert_eq!((i, h), (5, 32));
    let p = params(&r["params"], i, h);
    let w = p.to_core::<5, 32>().unwrap();
    let close = |what: &str, got: &[f64], want: &[f64]| {
        assert_eq!(got.len(), want.len(), "{what}: length");
        let scale = want.iter().fold(1e-3f64, |a, v| a.max(v.abs()));
        for (k, (g, w)) in got.iter().zip(want).enumerate() {
            assert!(
                (g - w).abs() <= F32_TOL * scale,
                "{what}[{k}]: want {w}, got {g}"
            );
        }
    };
    for case in r["cases"].as_array().unwrap() {
        let name = case["name"].as_str().unwrap();
        let mut net = gyrotherm_core::lstm::Lstm::<5, 32>::new(&w);
        let f32s = |v: Vec<f64>| -> [f32; 32] { std::array::from_fn(|j| v[j] as f32) };
        net.set_state(&f32s(flat(&case["h0"])), &f32s(flat(&case["c0"])))
            .unwrap();
        let x = flat(&case["x"]);
        let y: Vec<f64> = x
            .chunks(5)
            .map(|row| {
                let xs: [f32; 5] = std::array::from_fn(|k| row[k] as f32);
                f64::from(net.step(&xs).unwrap())
            })
            .collect();
        close(&format!("{name} y"), &y, &flat(&case["y"]));
        let hn: Vec<f64> = net.hidden().iter().map(|v| f64::from(*v)).collect();
        let cn: Vec<f64> = net.cell().iter().map(|v| f64::from(*v)).collect();
        close(&format!("{name} h_n"), &hn, &flat(&case["h_n"]));
        close(&format!("{name} c_n"), &cn, &flat(&case["c_n"]));
    }
}
