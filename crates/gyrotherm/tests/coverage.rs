//! The coverage map a model file carries and the per-sample verdict (see
//! `gyrotherm::coverage`): stored and sealed like the rest of the file, absent in older files,
//! and telling the training region from an airborne climb it never saw.
//!
//! Every log here is simulated (`gyrotherm::sim`, default unit): training on `seed-shock`
//! (ramps of 3 °C/min between −40 and +60 °C), held out on `airborne` (a climb from +50 to
//! −45 °C in 10 min, about 9.5 °C/min: three times faster than any training ramp).

use gyrotherm::compensate::compensator;
use gyrotherm::coverage::missing_note;
use gyrotherm::csvlog::TestLog;
use gyrotherm::fit::{fit_model, FitConfig, NamedLog, RecipeSettings};
use gyrotherm::model::{Method, ModelFile, Seal, CHECKSUM_KEY};
use gyrotherm::sim::{simulate_series, SimConfig};

fn sim(profile: &str, seed: u64, table: bool) -> TestLog {
    let mut c = SimConfig::builtin(profile).unwrap();
    c.seed = seed;
    c.table_rate_dps = table.then_some(20.0);
    let s = simulate_series(&c).unwrap();
    TestLog {
        time_s: s.time_s,
        gyro_dps: s.gyro_dps,
        temp_c: s.temp_c,
        table_dps: s.table_dps,
        extra: Vec::new(),
    }
}

fn thermal_model() -> ModelFile {
    let st = sim("seed-shock", 1, false);
    let tab = sim("seed-shock", 2, true);
    let named = [
        NamedLog {
            name: "static",
            log: &st,
        },
        NamedLog {
            name: "table",
            log: &tab,
        },
    ];
    let mut cfg = FitConfig::new(Method::Lstm);
    cfg.recipe = RecipeSettings::of_kind(Method::Thermal);
    let fit = fit_model(&named, &cfg, &|_, _, _| {}).unwrap();
    assert!(fit.coverage_note.is_none(), "{:?}", fit.coverage_note);
    fit.model
}

/// Share of each verdict over a log, and the median σ of each (NaN when none).
fn verdicts(model: &ModelFile, log: &TestLog) -> [(f64, f64); 3] {
    let map = model.coverage.as_ref().unwrap().to_core().unwrap();
    let mut comp = compensator(model).unwrap();
    let mut sig: [Vec<f64>; 3] = Default::default();
    for i in 0..log.len() {
        comp.step(log.time_s[i], log.gyro_dps[i], log.temp_c[i]);
        if let Some(v) = map.verdict_of(comp.features()) {
            sig[v.coverage as usize].push(v.sigma_dph);
        }
    }
    let n: usize = sig.iter().map(Vec::len).sum();
    sig.map(|mut s| {
        s.sort_by(f64::total_cmp);
        let med = s.get(s.len() / 2).copied().unwrap_or(f64::NAN);
        (s.len() as f64 / n as f64, med)
    })
}

#[test]
fn training_region_inside_airborne_climb_outside_with_larger_sigma() {
    let model = thermal_model();
    let c = model.coverage.as_ref().unwrap();
    assert!(c.covered_cells() > 0 && c.covered_cells() < c.n_temp * c.n_rate);
    // The training run itself: most steps lie in a covered cell; the brief passages from a
    // ramp into a soak cross cells with fewer steps than a covered cell needs, a few of them
    // more than one cell from a covered one (about 1 % of the run when this was written).
    let [(inside, s_in), _, (outside, _)] = verdicts(&model, &sim("seed-shock", 1, false));
    assert!(inside > 0.9, "inside share on the training run {inside}");
    assert!(
        outside < 0.03,
        "outside share on the training run {outside}"
    );
    // The airborne climb at 9.5 °C/min leaves the ±3 °C/min region.
    let [_, _, (outside, s_out)] = verdicts(&model, &sim("airborne", 3, false));
    assert!(outside > 0.02, "outside share on airborne {outside}");
    assert!(
        s_out > 2.0 * s_in,
        "σ outside {s_out} °/h should exceed twice σ inside {s_in} °/h"
    );
}

#[test]
fn coverage_is_stored_sealed_and_older_files_load_without_it() {
    let model = thermal_model();
    let text = model.to_json().unwrap();
    let (back, seal) = ModelFile::from_json_sealed(&text).unwrap();
    assert_eq!(seal, Seal::Verified);
    assert_eq!(back, model, "save → load is exact, coverage included");
    assert!(missing_note(&back).is_none());

    // A σ edited after sealing is caught by the content hash.
    let c = model.coverage.as_ref().unwrap();
    let k = c.sigma_dph.iter().position(|s| *s > 0.0).unwrap();
    let mut edited: serde_json::Value = serde_json::from_str(&text).unwrap();
    edited["coverage"]["sigma_dph"][k] = serde_json::json!(c.sigma_dph[k] * 2.0);
    let err = ModelFile::from_json(&edited.to_string()).unwrap_err();
    assert!(err.to_string().contains(CHECKSUM_KEY), "{err}");

    // A file written before coverage maps (same content, no "coverage" key) keeps its seal:
    // the hash of a model without a map does not see the field at all.
    let old = ModelFile {
        coverage: None,
        coverage_note: None,
        method_choice: None,
        ..model.clone()
    };
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let o = v.as_object_mut().unwrap();
    o.remove("coverage");
    o.insert(
        CHECKSUM_KEY.to_owned(),
        serde_json::json!(old.content_digest().unwrap()),
    );
    let (back, seal) = ModelFile::from_json_sealed(&v.to_string()).unwrap();
    assert_eq!(seal, Seal::Verified);
    assert_eq!(back.coverage, None);
    let note = missing_note(&back).unwrap();
    assert!(note.contains("no coverage map"), "{note}");
}

#[test]
fn a_map_the_core_refuses_is_refused_at_load() {
    let model = thermal_model();
    let mut bad = model.clone();
    let c = bad.coverage.as_mut().unwrap();
    c.sigma_dph.iter_mut().for_each(|s| *s = 0.0);
    let err = bad.to_json().unwrap_err();
    let chain = gyrotherm::error_chain(&err);
    assert!(
        chain.contains("coverage") && chain.contains("no covered cell"),
        "{chain}"
    );
}

/// A least-squares model trained on logs too short to map keeps training's reason: a later
/// command (compensate, Python) says that reason, not "written before gyrotherm stored one,
/// or an LSTM alone", which is not true of a fresh least-squares file.
#[test]
fn a_fresh_model_without_a_map_says_why_training_made_none() {
    let mut st = sim("seed-shock", 1, false);
    // The first 3500 s of the run (the hold at 22 °C and the start of the first ramp): a
    // least-squares model fits, its cross-validation folds do not.
    let n = 3500.min(st.len());
    st.time_s.truncate(n);
    st.gyro_dps.truncate(n);
    st.temp_c.truncate(n);
    let named = [NamedLog {
        name: "short",
        log: &st,
    }];
    let fit = fit_model(&named, &FitConfig::new(Method::Thermal), &|_, _, _| {}).unwrap();
    assert!(fit.model.coverage.is_none(), "a 3500 s log was mapped");
    let why = fit
        .coverage_note
        .clone()
        .expect("training says why there is no map");
    let (back, seal) = ModelFile::from_json_sealed(&fit.model.to_json().unwrap()).unwrap();
    assert_eq!(seal, Seal::Verified);
    let note = missing_note(&back).unwrap();
    assert!(
        note.contains(&why),
        "note {note:?} lacks training's reason {why:?}"
    );
    assert!(
        !note.contains("written before") && !note.contains("LSTM alone"),
        "{note}"
    );
}
