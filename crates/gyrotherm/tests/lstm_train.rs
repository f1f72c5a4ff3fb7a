//! Training behaviour: the loss curve, determinism, masks, early stopping, truncated BPTT,
//! and the exported f32 flight network against the f64 training forward pass.

use gyrotherm::nn::{
    evaluate_mse, init_params, loss_and_grad, predict, train_lstm, train_normalised, train_pair,
    Bptt, LrSchedule, Precision, Sequence, StopReason, TrainConfig, WindowStart,
};
use gyrotherm_core::lstm::Lstm;

/// A compressed thermal-chamber cycle (room, cool, soak cold, heat, soak hot), °C at 1 Hz,
/// `steps` samples; ramps at 0.1 °C/s.
fn chamber_temp_c(steps: usize) -> Vec<f64> {
    let seg = steps as f64 / 6.0;
    (0..steps)
        .map(|t| {
            let t = t as f64;
            let ramp = |t0: f64, from: f64, to: f64| {
                let dur = ((to - from) / 0.1).abs();
                from + (to - from) * ((t - t0) / dur).clamp(0.0, 1.0)
            };
            if t < seg {
                25.0
            } else if t < 3.0 * seg {
                ramp(seg, 25.0, -40.0)
            } else {
                ramp(3.0 * seg, -40.0, 60.0)
            }
        })
        .collect()
}

/// Inputs [T, dT] with dT(t) = (T(t) - T(t-20)) / 20 (He et al. 2024, §2; held at the first
/// sample before t = 20), row-major.
fn inputs(temp_c: &[f64]) -> Vec<f64> {
    temp_c
        .iter()
        .enumerate()
        .flat_map(|(t, v)| [*v, (v - temp_c[t.saturating_sub(20)]) / 20.0])
        .collect()
}

/// Bias of a gyro whose coil lags the case by a first-order time constant of 150 s: a static
/// term in the coil temperature plus a Shupe term in its rate (docs/method.md §1).
fn lagged_bias(temp_c: &[f64]) -> Vec<f64> {
    let mut coil = temp_c[0];
    temp_c
        .iter()
        .map(|v| {
            let prev = coil;
            coil += (v - coil) / 150.0;
            0.002 * (coil - 20.0) + 0.5 * (coil - prev)
        })
        .collect()
}

#[test]
fn loss_drops_mostly_in_first_100_epochs() {
    let temp = chamber_temp_c(3000);
    let (x, y) = (inputs(&temp), lagged_bias(&temp));
    let cfg = TrainConfig {
        epochs: 300,
        ..TrainConfig::default()
    };
    let fit = train_normalised(&[Sequence::new(&x, &y)], &[], 2, &cfg, &mut |_, _| {}).unwrap();
    let h = &fit.output.loss_history;
    let (l0, l100, lend) = (h[0], h[100], *h.last().unwrap());
    println!("loss: epoch 0 {l0:.4}, epoch 100 {l100:.4}, epoch 299 {lend:.4}");
    // The target is z-scored, so predicting its mean gives MSE 1: a fit must get well below.
    assert!(lend < 0.05, "final normalised MSE {lend} not below 0.05");
    // He et al. 2024 (§3, loss curve): most of the drop within the first 100 iterations.
    let share = (l0 - l100) / (l0 - lend);
    assert!(
        share > 0.8,
        "only {share:.3} of the drop in the first 100 epochs (want > 0.8)"
    );
}

#[test]
fn truncated_bptt_also_learns() {
    let temp = chamber_temp_c(3000);
    let (x, y) = (inputs(&temp), lagged_bias(&temp));
    let mut finals = Vec::new();
    for start in [WindowStart::Carried, WindowStart::Zero] {
        let cfg = TrainConfig {
            epochs: 40,
            bptt: Bptt::Truncated {
                window: 500,
                burn_in: 100,
                batch: 2,
                start,
            },
            ..TrainConfig::default()
        };
        let fit = train_normalised(&[Sequence::new(&x, &y)], &[], 2, &cfg, &mut |_, _| {}).unwrap();
        let h = &fit.output.loss_history;
        println!("{start:?}: loss {} -> {}", h[0], h.last().unwrap());
        assert!(*h.last().unwrap() < 0.2 * h[0], "{start:?}: {h:?}");
        finals.push(fit.output.params);
    }
    assert_ne!(finals[0], finals[1], "window start states had no effect");
}

fn small_problem() -> (Vec<f64>, Vec<f64>) {
    let temp = chamber_temp_c(600);
    let x: Vec<f64> = inputs(&temp).iter().map(|v| v / 30.0).collect();
    let y: Vec<f64> = lagged_bias(&temp).iter().map(|v| v * 10.0).collect();
    (x, y)
}

#[test]
fn same_seed_same_params_bit_for_bit() {
    let (x, y) = small_problem();
    let runs = [Sequence::new(&x, &y)];
    let truncated = Bptt::Truncated {
        window: 100,
        burn_in: 20,
        batch: 3,
        start: WindowStart::Carried,
    };
    for (precision, bptt) in [
        (Precision::F64, Bptt::Full),
        (Precision::F32, Bptt::Full),
        (Precision::F32, truncated),
    ] {
        let cfg = TrainConfig {
            epochs: 15,
            seed: 42,
            precision,
            bptt,
            ..TrainConfig::default()
        };
        let a = train_lstm(&runs, &[], 2, &cfg, &mut |_, _| {}).unwrap();
        let b = train_lstm(&runs, &[], 2, &cfg, &mut |_, _| {}).unwrap();
        assert_eq!(a, b, "{precision:?} {bptt:?}: two trainings differ");
        let c = train_lstm(
            &runs,
            &[],
            2,
            &TrainConfig {
                seed: 43,
                ..cfg.clone()
            },
            &mut |_, _| {},
        )
        .unwrap();
        assert_ne!(a.params, c.params, "seed has no effect");
        // On two threads, each network exactly as on its own.
        let (pa, pb) = train_pair(
            (&runs, &[], &mut |_, _| {}),
            (&runs, &[], &mut |_, _| {}),
            2,
            &cfg,
        );
        assert_eq!(pa.unwrap(), a);
        assert_eq!(pb.unwrap(), a);
    }
}

#[test]
fn masked_steps_contribute_nothing() {
    let (x, y) = small_problem();
    let mask: Vec<bool> = (0..y.len()).map(|t| t % 4 != 0).collect();
    let mut y2 = y.clone();
    for (t, v) in y2.iter_mut().enumerate() {
        if !mask[t] {
            *v = if t % 8 == 0 { f64::NAN } else { 1e6 };
        }
    }
    let p = init_params(2, 8, 1);
    let a = loss_and_grad(&p, &[Sequence::new(&x, &y).with_mask(&mask)]).unwrap();
    let b = loss_and_grad(&p, &[Sequence::new(&x, &y2).with_mask(&mask)]).unwrap();
    assert_eq!(a, b, "masked targets changed the loss or gradient");
    // Mean over counted steps: the loss is the mean of the counted squared errors.
    let pred = predict(&p, &x).unwrap();
    let (mut sum, mut n) = (0.0, 0);
    for t in (0..y.len()).filter(|&t| mask[t]) {
        sum += (pred[t] - y[t]).powi(2);
        n += 1;
    }
    let want = sum / n as f64;
    assert!(
        (a.0 - want).abs() <= 1e-12 * want,
        "loss want {want}, got {}",
        a.0
    );
}

#[test]
fn validation_keeps_best_and_target_loss_stops() {
    let (x, y) = small_problem();
    let (xv, yv) = (x[..600].to_vec(), y[..300].to_vec());
    let runs = [Sequence::new(&x, &y)];
    let val = [Sequence::new(&xv, &yv)];
    let cfg = TrainConfig {
        epochs: 40,
        precision: Precision::F64,
        patience: Some(5),
        ..TrainConfig::default()
    };
    let mut seen = Vec::new();
    let out = train_lstm(&runs, &val, 2, &cfg, &mut |e, l| seen.push((e, l))).unwrap();
    let best = out.best_epoch.unwrap();
    let vh = &out.val_loss_history;
    assert!(
        vh.iter().all(|v| *v >= vh[best]),
        "best epoch {best} is not the minimum of {vh:?}"
    );
    let got = evaluate_mse(&out.params, &val, Precision::F64).unwrap();
    assert_eq!(got, vh[best], "returned params are not the best epoch's");
    assert_eq!(seen.len(), out.loss_history.len());
    if out.stop == StopReason::Patience {
        assert_eq!(vh.len(), best + 6);
    }

    let cfg = TrainConfig {
        epochs: 12,
        precision: Precision::F64,
        ..TrainConfig::default()
    };
    let free = train_lstm(&runs, &[], 2, &cfg, &mut |_, _| {}).unwrap();
    let target = free.loss_history[..=10]
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min);
    let cfg = TrainConfig {
        epochs: 40,
        target_loss: Some(target),
        ..cfg
    };
    let out = train_lstm(&runs, &[], 2, &cfg, &mut |_, _| {}).unwrap();
    assert_eq!(out.stop, StopReason::TargetLoss);
    let h = &out.loss_history;
    assert!(*h.last().unwrap() <= target && h[..h.len() - 1].iter().all(|l| *l > target));
}

#[test]
fn bad_input_is_refused_with_a_message() {
    let (mut x, y) = small_problem();
    let cfg = TrainConfig::default();
    x[7] = f64::NAN;
    let e = train_lstm(&[Sequence::new(&x, &y)], &[], 2, &cfg, &mut |_, _| {}).unwrap_err();
    assert!(e.to_string().contains("input 1 at step 3"), "{e}");
    let e = train_lstm(&[Sequence::new(&x[..10], &y)], &[], 2, &cfg, &mut |_, _| {}).unwrap_err();
    assert!(e.to_string().contains("input values"), "{e}");
}

/// The exported f32 flight network, stepped sample by sample, against the f64 training-side
/// forward pass over a 30,000-step run (the export must agree within 1e-5 relative: f32 rounding over
/// the run, far below a wrong weight's effect), at the published size and at 32 and 64 hidden
/// units (the flight crate's network is generic over its size).
#[test]
fn core_f32_matches_training_forward_over_30000_steps() {
    core_matches_training::<8>(2024);
    core_matches_training::<32>(2032);
    core_matches_training::<64>(2064);
}

fn core_matches_training<const H: usize>(seed: u64) {
    // Error relative to max(|y_t|, RMS of y over the run): pointwise relative error is
    // meaningless where y crosses zero.
    const REL_TOL: f64 = 1e-5;
    let mut p = init_params(2, H, seed);
    // Weights of trained magnitude (gates driven out of their linear range).
    for v in p.w_ih.iter_mut().chain(&mut p.w_hh) {
        *v *= 3.0;
    }
    // Normalised inputs: a chamber cycle scaled to about ±1.7 and its rate, z-scored.
    let temp = chamber_temp_c(30_000);
    let raw = inputs(&temp);
    let z = gyrotherm::nn::ZScore::fit(&raw, 2);
    let x: Vec<f64> = raw
        .iter()
        .enumerate()
        .map(|(k, v)| z.apply(k % 2, *v))
        .collect();
    let want = predict(&p, &x).unwrap();
    let rms = (want.iter().map(|v| v * v).sum::<f64>() / want.len() as f64).sqrt();
    let mut net = Lstm::new(&p.to_core::<2, H>().unwrap());
    let mut worst = (0.0f64, 0usize);
    for (t, xt) in x.chunks_exact(2).enumerate() {
        let got = net.step(&[xt[0] as f32, xt[1] as f32]).unwrap() as f64;
        let rel = (got - want[t]).abs() / want[t].abs().max(rms);
        if rel > worst.0 {
            worst = (rel, t);
        }
    }
    let t = worst.1;
    println!(
        "H {H}: max rel err {:e} at step {t} (y {}, rms {rms})",
        worst.0, want[t]
    );
    assert!(
        worst.0 <= REL_TOL,
        "H {H}, step {t}: want {}, rel err {:e}",
        want[t],
        worst.0
    );
}

/// Minibatch truncated BPTT on sampled windows (the recipe of larger networks: windows with
/// a burn-in, clipped Adam steps with cosine decay): the same parameters to the bit on one and
/// on three workers (chunks are summed in a fixed order), in f64 and f32, and it learns the
/// lagged bias: the last batches' loss under a fifth of the first's.
#[test]
fn sampled_minibatch_training_is_deterministic_and_learns() {
    let temp = chamber_temp_c(6000);
    let (x, y) = (inputs(&temp), lagged_bias(&temp));
    let zx = gyrotherm::nn::ZScore::fit(&x, 2);
    let zy = gyrotherm::nn::ZScore::fit(&y, 1);
    let xn: Vec<f64> = x
        .iter()
        .enumerate()
        .map(|(k, v)| zx.apply(k % 2, *v))
        .collect();
    let yn: Vec<f64> = y.iter().map(|v| zy.apply(0, *v)).collect();
    let runs = [
        Sequence::new(&xn[..8000], &yn[..4000]),
        Sequence::new(&xn[8000..], &yn[4000..]),
    ];
    for precision in [Precision::F64, Precision::F32] {
        let cfg = |threads| TrainConfig {
            hidden_size: 16,
            epochs: 120,
            lr: 5e-3,
            clip_grad_norm: Some(1.0),
            bptt: Bptt::Sampled {
                window: 300,
                burn_in: 100,
                batch: 20,
            },
            lr_schedule: LrSchedule::Cosine,
            precision,
            threads,
            seed: 5,
            ..TrainConfig::default()
        };
        let one = train_lstm(&runs, &[], 2, &cfg(1), &mut |_, _| {}).unwrap();
        let three = train_lstm(&runs, &[], 2, &cfg(3), &mut |_, _| {}).unwrap();
        assert_eq!(one, three, "{precision:?}: one worker and three differ");
        let h = &one.loss_history;
        assert_eq!(h.len(), 120);
        let mean = |s: &[f64]| s.iter().sum::<f64>() / s.len() as f64;
        let (first, last) = (mean(&h[..5]), mean(&h[h.len() - 10..]));
        println!("{precision:?}: first batches {first:.4}, last {last:.4}");
        assert!(last < 0.2 * first, "{precision:?}: loss {first} -> {last}");
    }
}

/// Sampled windows need some run longer than the burn-in; the error says what to change.
#[test]
fn sampled_training_refuses_runs_no_longer_than_the_burn_in() {
    let (x, y) = small_problem();
    let cfg = TrainConfig {
        bptt: Bptt::Sampled {
            window: 5000,
            burn_in: y.len(),
            batch: 4,
        },
        ..TrainConfig::default()
    };
    let e = train_lstm(&[Sequence::new(&x, &y)], &[], 2, &cfg, &mut |_, _| {}).unwrap_err();
    assert!(e.to_string().contains("lower the burn-in"), "{e}");
}

#[test]
fn to_core_refuses_wrong_size() {
    let p = init_params(2, 8, 0);
    let e = p.to_core::<2, 4>().unwrap_err();
    assert!(e.to_string().contains("hidden_size 8"), "{e}");
}
