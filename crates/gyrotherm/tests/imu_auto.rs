//! `auto` on an inertial unit: per axis, the `thermal` fit (as `--method thermal` builds it,
//! on one sensor or several) against `thermal-lstm` on that fit (as `--method thermal-lstm`
//! builds it), both scored on held-out validation of the training runs. The choice (and the
//! scores) go into the axis's model and `train`'s lines, the axis kept is the one the chosen
//! method fits by name, and the file round-trips through its checks.

use gyrotherm::csvlog::{ImuLog, LogSet, ReadOptions};
use gyrotherm::fit::unit::fit_imu;
use gyrotherm::fit::FitConfig;
use gyrotherm::model::unit::{ImuAxis, ImuModel, IMU_FORMAT_VERSION};
use gyrotherm::model::{TempSensorDef, Validation};
use gyrotherm::settings::{FitSettings, Method};
use gyrotherm::told::Told;
use gyrotherm::train::{train, TrainEvent};

#[path = "support/unit_1000.rs"]
mod unit_1000;
use unit_1000::run;

#[path = "support/unit_choice.rs"]
mod unit_choice;
use unit_choice::{recorded, scores};

fn runs(which: &[(u64, Option<usize>)]) -> Vec<(String, ImuLog)> {
    which
        .iter()
        .map(|&(seed, table)| (format!("{seed} {table:?}"), run(seed, table)))
        .collect()
}

/// [`runs`] with the first temperature sensor only: `thermal` then reads one sensor and
/// `auto` scores both candidates.
fn one_sensor(which: &[(u64, Option<usize>)]) -> Vec<(String, ImuLog)> {
    let mut logs = runs(which);
    for (_, l) in &mut logs {
        l.temp.truncate(1);
    }
    logs
}

/// The recorded choice's two scores (°/s), checked: `thermal` and `thermal-lstm` in that
/// order, finite, and the lower one chosen (`thermal` on a tie).
fn scored(a: &ImuAxis, validation: Validation) -> (f64, f64) {
    let choice = recorded(a);
    let (t, l) = scores(choice, validation);
    assert!(t.is_finite() && l.is_finite() && t > 0.0, "{t} {l}");
    let lower = if l < t {
        Method::ThermalLstm
    } else {
        Method::Thermal
    };
    // Equal left-out scores (every fold's LSTM gated out) let the LSTM's own gate decide.
    if !choice.folds_left_out_the_lstm() {
        assert_eq!(choice.chosen, lower, "{}", choice.describe());
    }
    (t, l)
}

fn config(method: Method) -> FitConfig {
    FitSettings {
        method,
        // A short LSTM training keeps the test quick; the choice is what is tested.
        epochs: matches!(method, Method::Auto | Method::ThermalLstm).then_some(60),
        ..FitSettings::default()
    }
    .fit_config()
    .unwrap()
}

/// `auto` through `train`, as the command line runs it: the unit model, the lines told at
/// the end, then the progress lines told while it fitted.
fn train_auto(logs: Vec<(String, ImuLog)>) -> (ImuModel, Vec<String>, Vec<String>) {
    let steps = std::sync::Mutex::new(Vec::new());
    let trained = train(
        &LogSet::of_unit_logs(logs),
        &config(Method::Auto),
        &TempSensorDef::default(),
        &ReadOptions::default(),
        &|e| {
            if let TrainEvent::Axis(s) = e {
                steps.lock().unwrap().push(s.line);
            }
        },
    )
    .unwrap();
    let steps = steps.into_inner().unwrap();
    let lines = trained
        .told(std::path::Path::new("m.json"), 0.0)
        .into_iter()
        .map(|t| match t {
            Told::Line(s) | Told::Note(s) | Told::Warning(s) | Told::Item(s) => s,
        })
        .collect();
    let m = ImuModel::from_json(&trained.model.to_json().unwrap())
        .expect("a unit's logs gave a unit's model file");
    (m, lines, steps)
}

/// `auto`'s axis `a` is, but for its recorded choice, the x axis `method` fits by name on
/// `logs`, to the bit (JSON included); returns that fit.
fn assert_fitted_by_name(a: &ImuAxis, logs: &[(String, ImuLog)], method: Method) -> ImuModel {
    let by_name = fit_imu(
        logs,
        &config(method),
        &TempSensorDef::default(),
        &|_, _, _, _, _| {},
    )
    .unwrap();
    let mut same = a.clone();
    same.model.method_choice = None;
    assert_eq!(same, by_name.axes[0]);
    assert_eq!(
        serde_json::to_string(&same).unwrap(),
        serde_json::to_string(&by_name.axes[0]).unwrap()
    );
    by_name
}

/// While it fitted, each of the x axis's `of` left-out runs was told as its fold started.
fn assert_each_fold_told(steps: &[String], of: usize) {
    for run in 1..=of {
        let want = format!(
            "gyro_x_dps: auto: fitting thermal and thermal-lstm without static run {run} of {of}"
        );
        assert!(
            steps.iter().any(|l| l.contains(&want)),
            "{want}: {steps:#?}"
        );
    }
}

/// A static run (seed 1) and a table run per axis (seed 2), two temperature sensors: `thermal`
/// reads both on the x axis, and the LSTM candidate rides on that several-sensor fit. The x
/// axis has three static runs (its own and the y and z table runs), each left out in turn.
#[test]
fn auto_scores_a_several_sensor_thermal_axis_against_the_lstm_on_that_fit() {
    let logs = runs(&[(1, None), (2, Some(0)), (2, Some(1)), (2, Some(2))]);
    let (model, lines, steps) = train_auto(logs.clone());
    assert_each_fold_told(&steps, 3);
    let a = &model.axes[0];
    scored(a, Validation::LeaveOneRunOut);
    assert_eq!(a.temps.len(), 2, "{:?}", a.scores);
    // The axis kept is the chosen method's by name, to the bit, but for the recorded choice.
    let chosen = a.model.method_choice.as_ref().unwrap().chosen;
    let by_name = assert_fitted_by_name(a, &logs, chosen);
    assert_eq!(model.imu_format_version, IMU_FORMAT_VERSION);
    assert!(
        lines.iter().any(|l| l
            .starts_with("gyro_x_dps: method chosen on each static run left out in turn")),
        "{lines:#?}"
    );
    // The file round-trips with its checks; a file without the choice (as older builds and
    // every other method write it) loads too.
    let text = model.to_json().unwrap();
    assert_eq!(ImuModel::from_json(&text).unwrap(), model);
    let older = by_name.to_json().unwrap();
    assert!(!older.contains("method_choice"));
    assert_eq!(ImuModel::from_json(&older).unwrap(), by_name);
    // The choice is sealed with the rest.
    let other = match chosen {
        Method::Thermal => "thermal-lstm",
        _ => "thermal",
    };
    let edited = text.replacen(
        &format!("\"chosen\": \"{chosen}\""),
        &format!("\"chosen\": \"{other}\""),
        1,
    );
    assert_ne!(edited, text);
    assert!(ImuModel::from_json(&edited).is_err());
}

/// A unit file written when `auto` kept a several-sensor `thermal` axis unscored
/// (`"validation": "several-sensors"`) still loads, and says why it was kept.
#[test]
fn a_file_with_an_unscored_several_sensor_choice_still_loads() {
    let logs = runs(&[(1, None), (2, Some(0)), (2, Some(1)), (2, Some(2))]);
    let mut model = fit_imu(
        &logs,
        &config(Method::Thermal),
        &TempSensorDef::default(),
        &|_, _, _, _, _| {},
    )
    .unwrap();
    let choice: gyrotherm::model::MethodChoice = serde_json::from_str(
        r#"{"validation": "several-sensors", "candidates": [], "chosen": "thermal"}"#,
    )
    .unwrap();
    assert!(choice.describe().contains("several temperature sensors"));
    model.axes[0].model.method_choice = Some(choice);
    let text = model.to_json().unwrap();
    assert!(text.contains("\"several-sensors\""));
    assert_eq!(ImuModel::from_json(&text).unwrap(), model);
}

/// The same runs with one temperature sensor: the x axis has three static runs (its own and
/// the y and z table runs), each left out in turn, and both candidates are scored.
#[test]
fn auto_on_a_one_sensor_axis_scores_both_on_each_left_out_run() {
    let logs = one_sensor(&[(1, None), (2, Some(0)), (2, Some(1)), (2, Some(2))]);
    let (model, lines, steps) = train_auto(logs);
    assert_each_fold_told(&steps, 3);
    let a = &model.axes[0];
    scored(a, Validation::LeaveOneRunOut);
    assert_eq!(a.temps.len(), 1);
    // `train` tells every candidate's score and the choice, per axis.
    let told = lines
        .iter()
        .find(|l| l.starts_with("gyro_x_dps: method chosen on each static run left out in turn"))
        .unwrap_or_else(|| panic!("{lines:#?}"));
    assert!(
        told.contains("thermal") && told.contains("thermal-lstm"),
        "{told}"
    );
    assert!(told.contains('*'), "{told}");
    let text = model.to_json().unwrap();
    assert!(text.contains("\"leave-one-run-out\""));
    assert_eq!(ImuModel::from_json(&text).unwrap(), model);
}

/// One static run and one temperature sensor: the candidates are scored on the LSTM's
/// held-out blocks of it, both through the same prediction.
#[test]
fn with_one_static_run_auto_scores_on_held_out_blocks() {
    let (model, lines, steps) = train_auto(one_sensor(&[(1, None), (2, Some(0))]));
    // The LSTM candidate's training is told before it starts.
    assert!(
        steps
            .iter()
            .any(|l| l.contains("gyro_x_dps: auto: training thermal-lstm on")),
        "{steps:#?}"
    );
    let a = &model.axes[0];
    scored(a, Validation::HeldOutBlocks);
    assert!(lines
        .iter()
        .any(|l| l.starts_with("gyro_x_dps: method chosen on held-out blocks")));
    let text = model.to_json().unwrap();
    assert_eq!(ImuModel::from_json(&text).unwrap(), model);
}

/// One Adam step cannot lower the held-out residual by the gate's 5 % (the LSTM's output
/// layer starts at zero), so every fold leaves its LSTM out: the scores are equal, the fit on
/// every run decides by its own gate, and that gate leaves the LSTM out too. The axis then
/// keeps `thermal`, says so, and is `thermal`'s fit by name, to the bit.
#[test]
fn when_every_gate_leaves_the_lstm_out_the_axis_keeps_thermal_and_says_so() {
    let logs = one_sensor(&[(1, None), (2, Some(0)), (2, Some(1)), (2, Some(2))]);
    let cfg = FitSettings {
        method: Method::Auto,
        epochs: Some(1),
        ..FitSettings::default()
    }
    .fit_config()
    .unwrap();
    let model = fit_imu(&logs, &cfg, &TempSensorDef::default(), &|_, _, _, _, _| {}).unwrap();
    let a = &model.axes[0];
    let choice = recorded(a);
    let (t, l) = scores(choice, Validation::LeaveOneRunOut);
    assert_eq!(t, l, "every fold's gate left its LSTM out");
    assert!(choice.folds_left_out_the_lstm());
    assert!(choice.lstm_left_out, "{}", choice.describe());
    assert_eq!(choice.chosen, Method::Thermal);
    assert!(
        choice
            .describe()
            .contains("and so did thermal-lstm's fit on every run"),
        "{}",
        choice.describe()
    );
    assert_fitted_by_name(a, &logs, Method::Thermal);
    // The flag is written, sealed and read back.
    let text = model.to_json().unwrap();
    assert!(text.contains("\"lstm_left_out\": true"), "{text}");
    assert_eq!(ImuModel::from_json(&text).unwrap(), model);
}
