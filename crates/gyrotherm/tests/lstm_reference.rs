//! The hand-written LSTM against PyTorch: `reference/lstm/pytorch_lstm_2x8.json`, made by
//! torch 2.15 `nn.LSTM(2, 8) + nn.Linear(8, 1)` in float64 (fixed params, three cases with
//! outputs and final states, MSE loss and every parameter's gradient for case 1, and the params
//! after three `torch.optim.Adam(lr=0.01)` steps).

use gyrotherm::nn::adam::Adam;
use gyrotherm::nn::{loss_and_grad, predict_with_state, LstmParams, Sequence};
use serde_json::Value;

mod lstm_layout;
use lstm_layout::{flatten, unflatten};

/// Outputs, final states and loss: 1e-6 relative (the agreement asked of the training code
/// with PyTorch in f64).
const OUT_REL_TOL: f64 = 1e-6;
/// Gradients and Adam-updated params: 1e-5 relative (the same requirement, looser for
/// quantities summed over the run).
const GRAD_REL_TOL: f64 = 1e-5;
/// Relative error denominators are floored here: values this small are compared absolutely.
const REL_FLOOR: f64 = 1e-12;

mod common;

fn load() -> Option<Value> {
    let path = common::reference_file("lstm/pytorch_lstm_2x8.json")?;
    let text = std::fs::read_to_string(&path).expect("reference file readable");
    Some(serde_json::from_str(&text).expect("reference JSON parses"))
}

fn flat(v: &Value) -> Vec<f64> {
    match v {
        Value::Array(a) => a.iter().flat_map(flat).collect(),
        Value::Number(n) => vec![n.as_f64().unwrap()],
        other => panic!("unexpected JSON value {other}"),
    }
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

/// Max relative error of `got` against `want`, asserting `tol`; returns it.
fn compare(what: &str, got: &[f64], want: &[f64], tol: f64) -> f64 {
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
    worst.0
}

#[test]
#[cfg_attr(
    no_reference_data,
    ignore = "needs ../shared/reference (beside the checkout, or set GYROTHERM_SHARED)"
)]
fn forward_matches_pytorch() {
    let Some(r) = load() else { return };
    let (i, h) = (
        r["input_size"].as_u64().unwrap() as usize,
        r["hidden_size"].as_u64().unwrap() as usize,
    );
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
}

#[test]
#[cfg_attr(
    no_reference_data,
    ignore = "needs ../shared/reference (beside the checkout, or set GYROTHERM_SHARED)"
)]
fn loss_and_gradients_match_pytorch() {
    let Some(r) = load() else { return };
    let p = params(&r["params"], 2, 8);
    let case = &r["cases"][0];
    let (x, target) = (flat(&case["x"]), flat(&case["target"]));
    let (loss, grad) = loss_and_grad(&p, &[Sequence::new(&x, &target)]).unwrap();
    compare(
        "loss",
        &[loss],
        &[case["loss"].as_f64().unwrap()],
        OUT_REL_TOL,
    );
    let g = &case["grad"];
    compare(
        "grad w_ih",
        &grad.w_ih,
        &flat(&g["weight_ih"]),
        GRAD_REL_TOL,
    );
    compare(
        "grad w_hh",
        &grad.w_hh,
        &flat(&g["weight_hh"]),
        GRAD_REL_TOL,
    );
    compare("grad b_ih", &grad.b_ih, &flat(&g["bias_ih"]), GRAD_REL_TOL);
    compare("grad b_hh", &grad.b_hh, &flat(&g["bias_hh"]), GRAD_REL_TOL);
    compare(
        "grad w_out",
        &grad.w_out,
        &flat(&g["head_weight"]),
        GRAD_REL_TOL,
    );
    compare(
        "grad b_out",
        &[grad.b_out],
        &flat(&g["head_bias"]),
        GRAD_REL_TOL,
    );
}

#[test]
#[cfg_attr(
    no_reference_data,
    ignore = "needs ../shared/reference (beside the checkout, or set GYROTHERM_SHARED)"
)]
fn adam_steps_match_pytorch() {
    let Some(r) = load() else { return };
    let mut p = params(&r["params"], 2, 8);
    let case = &r["cases"][0];
    let (x, target) = (flat(&case["x"]), flat(&case["target"]));
    let seq = [Sequence::new(&x, &target)];
    let mut theta = flatten(&p);
    // torch.optim.Adam defaults besides lr, as stated in the reference's "optimizer" field.
    let mut adam = Adam::new(theta.len(), 0.01, 0.9, 0.999, 1e-8);
    for (n, step) in r["adam"]["steps"].as_array().unwrap().iter().enumerate() {
        let (loss, grad) = loss_and_grad(&p, &seq).unwrap();
        compare(
            &format!("adam step {n} loss before"),
            &[loss],
            &[step["loss_before_step"].as_f64().unwrap()],
            OUT_REL_TOL,
        );
        adam.step(&mut theta, &flatten(&grad));
        p = unflatten(&theta, 2, 8);
        let want = flatten(&params(&step["params"], 2, 8));
        compare(
            &format!("adam step {n} params"),
            &theta,
            &want,
            GRAD_REL_TOL,
        );
    }
}

/// Without the reference data the tests above are ignored (the summary says why); under
/// `CI=true` that is a failure.
#[test]
fn reference_data_is_present_under_ci() {
    common::check_reference_data();
}
