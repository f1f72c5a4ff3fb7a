//! The `thermal-lstm` method (the thermal model plus a residual LSTM, minibatch training, kept
//! only where it beats the thermal model on held-out blocks) and `auto` (the better of
//! `thermal` and `thermal-lstm` on held-out validation). The networks here are small and
//! briefly trained (8 units, flight code's size, so the models also run through the flight
//! compensator): these tests check the mechanics, not the accuracy.

use gyrotherm::compensate::compensate_log;
use gyrotherm::csvlog::TestLog;
use gyrotherm::fit::{fit_model, FitConfig, FitOutcome, LstmVerdict, NamedLog};
use gyrotherm::model::{Method, ModelFile, SubModel, Validation};
use gyrotherm::sim::{random_unit, simulate, SimConfig};

#[path = "support/sigma_shrunk.rs"]
mod sigma_shrunk;
use sigma_shrunk::assert_sigma_shrunk;

fn sim(profile: &str, seed: u64, table: bool) -> TestLog {
    let mut c = SimConfig::builtin(profile).unwrap();
    c.unit = random_unit(1016);
    c.seed = seed;
    c.table_rate_dps = table.then_some(20.0);
    simulate(&c).unwrap()
}

fn fit(logs: &[(&str, &TestLog)], cfg: &FitConfig) -> FitOutcome {
    let named: Vec<NamedLog> = logs
        .iter()
        .map(|(name, log)| NamedLog { name, log })
        .collect();
    fit_model(&named, cfg, &|_, _, _| {}).unwrap()
}

/// A small, briefly trained configuration of `method`.
fn small(method: Method) -> FitConfig {
    let mut c = FitConfig::new(method);
    c.seed = 1;
    c.recipe.hidden = 8;
    c.recipe.epochs = 40;
    c.recipe.batch = 8;
    c
}

/// Kept, the LSTM reads the thermal states and the thermal model's prediction, the model is
/// labelled `thermal-lstm`, and its coverage σ is the thermal model's shrunk by what the LSTM
/// gained on the held-out blocks; left out by its gate, the model is the thermal model,
/// coefficient for coefficient (coverage map included), and labelled `thermal`. The scale factor is the thermal
/// model's either way. The in-memory prediction of the bias model matches the flight
/// compensator's.
#[test]
fn thermal_lstm_is_labelled_by_what_it_holds() {
    let (s, t) = (sim("seed-shock", 7, false), sim("seed-shock", 8, true));
    let logs = [("s.csv", &s), ("t.csv", &t)];
    let plain = fit(&logs, &FitConfig::new(Method::Thermal));
    let mut keep = small(Method::ThermalLstm);
    keep.recipe.min_val_improvement = -1.0;
    let kept = fit(&logs, &keep);
    let summary = kept.bias_training.as_ref().unwrap();
    assert_eq!(summary.lstm_verdict, Some(LstmVerdict::Kept));
    let (base_rms, kept_rms) = summary.held_out_rms.expect("held-out blocks");
    assert!(kept_rms <= base_rms, "{kept_rms} > {base_rms}");
    assert!(matches!(
        kept.model.bias,
        Some(SubModel::Residual {
            lstm_reads_base: true,
            ..
        })
    ));
    assert_eq!(kept.model.method, Method::ThermalLstm);
    assert_eq!(kept.model.scale, plain.model.scale);
    // σ per cell: the thermal model's cross-validated map, shrunk by the ratio the held-out
    // blocks measured with the LSTM and without (the counts and RMS left as they are).
    let ratio = if kept_rms < base_rms {
        kept_rms / base_rms
    } else {
        1.0
    };
    assert_sigma_shrunk(
        kept.model.coverage.as_ref().unwrap(),
        plain.model.coverage.as_ref().unwrap(),
        ratio,
    );
    // Ground (f64) and flight (f32) bias over a held-out run.
    let held = sim("slow-ramp", 9, false);
    let flight = compensate_log(&kept.model, &held).unwrap();
    let spec = kept.model.feature_spec().unwrap();
    let table = gyrotherm::features::extract(&held, &spec).unwrap();
    let ground = kept
        .model
        .bias
        .as_ref()
        .unwrap()
        .predict_table(&table)
        .unwrap();
    let rows = table.row_of_sample(held.len());
    let worst = rows
        .iter()
        .zip(&flight.bias_dps)
        .map(|(&r, b)| (ground[r] - b).abs())
        .fold(0.0f64, f64::max);
    let swing = flight.bias_dps.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    assert!(worst <= 1e-4 * swing, "worst {worst:e} °/s of {swing:e}");

    let mut drop = small(Method::ThermalLstm);
    drop.recipe.min_val_improvement = 2.0;
    let left_out = fit(&logs, &drop);
    assert!(matches!(
        left_out.bias_training.as_ref().unwrap().lstm_verdict,
        Some(LstmVerdict::LeftOut { .. })
    ));
    assert_eq!(left_out.model.method, Method::Thermal);
    assert_eq!(left_out.model.bias, plain.model.bias);
    assert_eq!(left_out.model.scale, plain.model.scale);
    assert_eq!(left_out.model.coverage, plain.model.coverage);
}

/// With two static runs, `auto` leaves each out in turn, scores both candidates on it, keeps
/// the lower score, says so in one line, and the model file records it (and reads it back);
/// with one static run it scores them on held-out blocks. The model is the chosen
/// candidate's own fit.
#[test]
fn auto_scores_both_candidates_and_records_the_choice() {
    let (s1, s2, t) = (
        sim("seed-shock", 11, false),
        sim("fast-cycle", 12, false),
        sim("seed-shock", 13, true),
    );
    let logs = [("s1.csv", &s1), ("s2.csv", &s2), ("t.csv", &t)];
    let auto = fit(&logs, &small(Method::Auto));
    let choice = auto
        .model
        .method_choice
        .clone()
        .expect("auto records its choice");
    assert_eq!(choice.validation, Validation::LeaveOneRunOut);
    let methods: Vec<Method> = choice.candidates.iter().map(|c| c.method).collect();
    assert_eq!(methods, [Method::Thermal, Method::ThermalLstm]);
    assert!(choice
        .candidates
        .iter()
        .all(|c| c.bias_rms_dps.is_finite() && c.bias_rms_dps > 0.0));
    let best = choice
        .candidates
        .iter()
        .min_by(|a, b| a.bias_rms_dps.total_cmp(&b.bias_rms_dps))
        .unwrap();
    assert_eq!(choice.chosen, best.method);
    let mut own = small(choice.chosen);
    if choice.chosen == Method::Thermal {
        own = FitConfig::new(Method::Thermal);
        own.seed = 1;
    }
    let alone = fit(&logs, &own);
    assert_eq!(auto.model.bias, alone.model.bias);
    assert_eq!(auto.model.method, alone.model.method);
    let named: Vec<NamedLog> = logs
        .iter()
        .map(|(name, log)| NamedLog { name, log })
        .collect();
    let lines = auto.describe(&named, &small(Method::Auto)).join("\n");
    assert!(
        lines.contains("method chosen on each static run left out in turn"),
        "{lines}"
    );
    let back = ModelFile::from_json(&auto.model.to_json().unwrap()).unwrap();
    assert_eq!(back.method_choice, Some(choice));

    let one = fit(&[("s1.csv", &s1), ("t.csv", &t)], &small(Method::Auto));
    let choice = one.model.method_choice.expect("auto records its choice");
    assert_eq!(choice.validation, Validation::HeldOutBlocks);
    assert_eq!(choice.candidates.len(), 2);
}

/// One static run too short for the blocks `thermal-lstm` holds out (fewer than four blocks of
/// 2048 steps): nothing could score the LSTM, so `auto` fits `thermal` alone, its model
/// exactly, with no choice recorded.
#[test]
fn auto_on_a_run_too_short_for_held_out_blocks_is_thermal() {
    let cut = |mut l: TestLog, n: usize| {
        l.time_s.truncate(n);
        l.gyro_dps.truncate(n);
        l.temp_c.truncate(n);
        if let Some(t) = l.table_dps.as_mut() {
            t.truncate(n);
        }
        l
    };
    let s = cut(sim("seed-shock", 11, false), 6000);
    let t = cut(sim("seed-shock", 13, true), 6000);
    let logs = [("s.csv", &s), ("t.csv", &t)];
    let auto = fit(&logs, &small(Method::Auto));
    let mut own = FitConfig::new(Method::Thermal);
    own.seed = 1;
    let thermal = fit(&logs, &own);
    assert_eq!(auto.model.method, Method::Thermal);
    assert_eq!(auto.model.method_choice, None);
    assert_eq!(auto.model.bias, thermal.model.bias);
    assert_eq!(auto.model.scale, thermal.model.scale);
    assert!(auto.bias_training.as_ref().is_none_or(|t| t.epochs == 0));
}
