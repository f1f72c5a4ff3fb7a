//! Model files: exact round trip and clear refusals.

use gyrotherm::baseline::Terms;
use gyrotherm::csvlog::TestLog;
use gyrotherm::features::FeatureSpec;
use gyrotherm::model::{
    data_digest, sha256_hex, FeatureDef, Method, ModelFile, Range, SubModel, TrainingInfo,
};
use gyrotherm::nn::params::LstmParams;
use gyrotherm::nn::zscore::ZScore;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::Path;

/// An error as the user reads it: its message and its causes (`gyrotherm::error_chain`).
trait ChainText {
    fn chain_text(&self) -> String;
}

impl<E: std::error::Error + 'static> ChainText for E {
    fn chain_text(&self) -> String {
        gyrotherm::error_chain(self)
    }
}

fn training() -> TrainingInfo {
    TrainingInfo {
        temp_range_c: Range {
            min: -40.0,
            max: 60.0,
        },
        rate_range_c_per_s: Range {
            min: -0.05,
            max: 0.05,
        },
        data_digest_sha256: sha256_hex(b"training data"),
        epochs: Some(1000),
        final_loss: Some(0.1 + 0.2),
        seed: Some(42),
        created_by: gyrotherm::model::created_by(),
        inputs: vec!["static.csv".into(), "dynamic.csv".into()],
    }
}

fn random_vec(rng: &mut ChaCha8Rng, n: usize) -> Vec<f64> {
    (0..n).map(|_| rng.gen_range(-1.0..1.0) / 3.0).collect()
}

fn lstm_sub(rng: &mut ChaCha8Rng, inputs: usize, hidden: usize) -> SubModel {
    let mut p = LstmParams::zeros(inputs, hidden);
    p.w_ih = random_vec(rng, p.w_ih.len());
    p.w_hh = random_vec(rng, p.w_hh.len());
    p.b_ih = random_vec(rng, p.b_ih.len());
    p.b_hh = random_vec(rng, p.b_hh.len());
    p.w_out = random_vec(rng, p.w_out.len());
    p.b_out = rng.gen();
    SubModel::Lstm {
        params: p,
        input_norm: ZScore {
            mean: random_vec(rng, inputs),
            std: random_vec(rng, inputs)
                .iter()
                .map(|v| v.abs() + 0.1)
                .collect(),
        },
        target_norm: ZScore {
            mean: vec![1.0 + 1e-6 / 3.0],
            std: vec![1e-6 / 7.0],
        },
    }
}

fn lstm_model() -> ModelFile {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    ModelFile {
        format_version: 1,
        method: Method::Lstm,
        features: FeatureDef::from_spec(&FeatureSpec::PUBLISHED),
        bias: Some(lstm_sub(&mut rng, 2, 8)),
        scale: Some(lstm_sub(&mut rng, 2, 8)),
        training: training(),
        coverage: None,
        columns: None,
        coverage_note: None,
        method_choice: None,
    }
}

fn poly_model() -> ModelFile {
    let spec = FeatureSpec::THERMAL_STATE;
    let terms = Terms::linear(spec.n_features());
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    ModelFile {
        format_version: 1,
        method: Method::Poly,
        features: FeatureDef::from_spec(&spec),
        bias: Some(SubModel::Baseline {
            coefficients: random_vec(&mut rng, terms.len()),
            terms,
        }),
        scale: None,
        training: TrainingInfo {
            epochs: None,
            seed: None,
            ..training()
        },
        coverage: None,
        columns: None,
        coverage_note: None,
        method_choice: None,
    }
}

/// Every f64 in a JSON value, in order, as bits.
fn float_bits(v: &serde_json::Value, out: &mut Vec<u64>) {
    match v {
        serde_json::Value::Number(n) => {
            if let Some(f) = n.as_f64() {
                out.push(f.to_bits())
            }
        }
        serde_json::Value::Array(a) => a.iter().for_each(|x| float_bits(x, out)),
        serde_json::Value::Object(o) => o.values().for_each(|x| float_bits(x, out)),
        _ => {}
    }
}

fn assert_bit_exact(a: &ModelFile, b: &ModelFile) {
    // PartialEq on f64 would accept -0.0 == 0.0; compare the bits of every number too.
    assert_eq!(a, b);
    let (mut x, mut y) = (Vec::new(), Vec::new());
    float_bits(&serde_json::to_value(a).unwrap(), &mut x);
    float_bits(&serde_json::to_value(b).unwrap(), &mut y);
    assert_eq!(x, y);
    assert!(!x.is_empty());
}

#[test]
fn round_trip_is_bit_exact() {
    let dir = tempfile::tempdir().unwrap();
    for (name, m) in [("lstm.json", lstm_model()), ("poly.json", poly_model())] {
        let path = dir.path().join(name);
        m.save(&path).unwrap();
        let back = ModelFile::load(&path).unwrap();
        assert_bit_exact(&m, &back);
        // Directly on the parameters too.
        if let (Some(SubModel::Lstm { params: a, .. }), Some(SubModel::Lstm { params: b, .. })) =
            (&m.bias, &back.bias)
        {
            for (x, y) in a.w_ih.iter().zip(&b.w_ih) {
                assert_eq!(x.to_bits(), y.to_bits());
            }
        }
    }
}

#[test]
fn feature_definition_round_trips_to_the_core_spec() {
    let spec = FeatureSpec {
        smoothing_window_s: 10.0,
        ..FeatureSpec::THERMAL_STATE
    };
    let back = FeatureDef::from_spec(&spec).to_spec().unwrap();
    assert_eq!(back, spec);
    assert_eq!(poly_model().feature_spec().unwrap().n_features(), 5);
    let core = poly_model().bias.unwrap().baseline_core().unwrap().unwrap();
    assert_eq!(core.n_terms(), 6);
}

fn save_text(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Load `value` written to a file; the error must contain every string in `want` and the path.
fn expect_load_error(value: &serde_json::Value, want: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let p = save_text(dir.path(), "m.json", &value.to_string());
    let e = ModelFile::load(&p).unwrap_err().chain_text();
    assert!(e.contains(&p.display().to_string()), "no path in {e:?}");
    for w in want {
        assert!(e.contains(w), "want {w:?} in {e:?}");
    }
}

fn lstm_json() -> serde_json::Value {
    serde_json::to_value(lstm_model()).unwrap()
}

#[test]
fn unknown_version_says_which_are_supported() {
    let mut v = lstm_json();
    v["format_version"] = 2.into();
    expect_load_error(&v, &["unsupported format_version 2", "reads version 1"]);
    v["format_version"] = "one".into();
    expect_load_error(&v, &["unsupported format_version \"one\""]);
}

#[test]
fn wrong_shapes_are_refused() {
    let mut v = lstm_json();
    v["bias"]["lstm"]["params"]["w_ih"]
        .as_array_mut()
        .unwrap()
        .pop();
    expect_load_error(&v, &["bias: w_ih has 63 values, expected 64"]);
    let mut v = lstm_json();
    v["scale"]["lstm"]["input_norm"]["std"] = serde_json::json!([1.0]);
    expect_load_error(&v, &["scale: input_norm has 2 means and 1 stds"]);
    let mut v = lstm_json();
    v["features"]["lag_tau_s"] = serde_json::json!([300.0]);
    expect_load_error(&v, &["input_size is 2 but the feature definition gives 3"]);
    let mut v = serde_json::to_value(poly_model()).unwrap();
    v["bias"]["baseline"]["coefficients"]
        .as_array_mut()
        .unwrap()
        .push(1.0.into());
    expect_load_error(&v, &["coefficients has 7 values for 6 terms"]);
}

#[test]
fn non_finite_weights_are_refused() {
    // JSON cannot hold NaN; an overflowing literal or a null is what a broken writer leaves.
    let text = serde_json::to_string(&lstm_model()).unwrap();
    let v = lstm_json();
    let b = v["bias"]["lstm"]["params"]["b_out"].to_string();
    let dir = tempfile::tempdir().unwrap();
    let needle = format!("\"b_out\":{b}");
    assert!(text.contains(&needle));
    let p = save_text(
        dir.path(),
        "a.json",
        &text.replacen(&needle, "\"b_out\":1e999", 1),
    );
    let e = ModelFile::load(&p).unwrap_err().chain_text();
    assert!(e.contains("number out of range"), "{e}");
    let p = save_text(
        dir.path(),
        "b.json",
        &text.replacen(&needle, "\"b_out\":null", 1),
    );
    let e = ModelFile::load(&p).unwrap_err().chain_text();
    assert!(e.contains("invalid type: null"), "{e}");
    // And a model with a NaN weight is not saved at all.
    let mut m = lstm_model();
    if let Some(SubModel::Lstm { params, .. }) = &mut m.scale {
        params.w_hh[5] = f64::NAN;
    }
    let path = dir.path().join("nan.json");
    let e = m.save(&path).unwrap_err().chain_text();
    assert!(e.contains("scale: w_hh[5] is not finite"), "{e}");
    assert!(!path.exists());
    let mut m = poly_model();
    if let Some(SubModel::Baseline { coefficients, .. }) = &mut m.bias {
        coefficients[2] = f64::INFINITY;
    }
    assert!(m
        .validate()
        .unwrap_err()
        .chain_text()
        .contains("coefficients[2] is not finite"));
}

#[test]
fn missing_and_unknown_fields_are_named() {
    let mut v = lstm_json();
    v["training"].as_object_mut().unwrap().remove("created_by");
    expect_load_error(&v, &["missing field `created_by`"]);
    let mut v = lstm_json();
    v.as_object_mut().unwrap().remove("method");
    expect_load_error(&v, &["missing field `method`"]);
    let mut v = lstm_json();
    v.as_object_mut().unwrap().remove("format_version");
    expect_load_error(&v, &["missing field `format_version`"]);
    let mut v = lstm_json();
    v["features"]["rate_lag"] = 20.into();
    expect_load_error(&v, &["unknown field `rate_lag`"]);
    let mut v = lstm_json();
    v["method"] = "cubic".into();
    expect_load_error(&v, &["unknown variant `cubic`"]);
}

#[test]
fn inconsistent_content_is_refused() {
    let mut m = poly_model();
    m.method = Method::Linear;
    m.scale = lstm_model().scale;
    assert!(m
        .validate()
        .unwrap_err()
        .chain_text()
        .contains("an lstm sub-model in a model whose method is linear"));
    let mut m = poly_model();
    m.bias = None;
    assert!(m
        .validate()
        .unwrap_err()
        .chain_text()
        .contains("nothing to compensate"));
    let mut m = poly_model();
    m.training.temp_range_c = Range {
        min: 5.0,
        max: -5.0,
    };
    assert!(m
        .validate()
        .unwrap_err()
        .chain_text()
        .contains("temp_range_c"));
    let mut m = poly_model();
    m.training.data_digest_sha256 = "abc".into();
    assert!(m
        .validate()
        .unwrap_err()
        .chain_text()
        .contains("64 hexadecimal"));
    let dir = tempfile::tempdir().unwrap();
    let e = ModelFile::load(&dir.path().join("absent.json")).unwrap_err();
    assert!(e.to_string().contains("cannot read model file"), "{e}");
    let p = save_text(dir.path(), "junk.json", "{ not json");
    assert!(ModelFile::load(&p)
        .unwrap_err()
        .chain_text()
        .contains("not valid JSON"));
}

#[test]
fn digest_is_sha256_of_the_documented_bytes() {
    // Known answer: SHA-256("abc") from FIPS 180-2, appendix B.1.
    assert_eq!(
        sha256_hex(b"abc"),
        "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
    );
    let log = TestLog {
        time_s: vec![0.0, 1.0],
        gyro_dps: vec![0.5, -0.5],
        temp_c: vec![20.0, 20.5],
        ..TestLog::default()
    };
    let mut bytes = 2u64.to_le_bytes().to_vec();
    for v in [0.0f64, 1.0, 0.5, -0.5, 20.0, 20.5] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    bytes.push(0);
    assert_eq!(data_digest(&[&log]), sha256_hex(&bytes));
    let mut other = log.clone();
    other.temp_c[1] = 20.25;
    assert_ne!(data_digest(&[&log]), data_digest(&[&other]));
}

#[test]
fn fitted_baseline_saves_and_flies() {
    // End to end: features → fit → model file → load → core evaluator, equal to the fit.
    use gyrotherm::baseline::fit;
    use gyrotherm::features::extract;
    use gyrotherm::model::training_ranges;
    let n = 2000;
    let time_s: Vec<f64> = (0..n).map(|i| i as f64 * 0.5).collect();
    let temp_c: Vec<f64> = time_s
        .iter()
        .map(|t| 25.0 + 20.0 * (t / 300.0).sin())
        .collect();
    let log = TestLog {
        gyro_dps: vec![0.0; n],
        time_s,
        temp_c,
        ..TestLog::default()
    };
    let spec = FeatureSpec::PUBLISHED;
    let tab = extract(&log, &spec).unwrap();
    assert_eq!(tab.n_rows(), 1000);
    // Bias target per sample, picked at the steps: 1e-3 + 1e-5·T (°/s).
    let per_sample: Vec<f64> = log.temp_c.iter().map(|t| 1e-3 + 1e-5 * t).collect();
    let y = tab.at_steps(&per_sample).unwrap();
    assert!(tab.at_steps(&per_sample[..10]).is_none());
    let f = fit(&tab, &y, None, &Terms::linear(2)).unwrap();
    let (temp_range_c, rate_range_c_per_s) = training_ranges(&[&tab]).unwrap();
    assert!(temp_range_c.min >= 5.0 && temp_range_c.max <= 45.0);
    assert!(rate_range_c_per_s.contains(0.0));
    let m = ModelFile {
        format_version: 1,
        method: Method::Linear,
        features: FeatureDef::from_spec(&spec),
        bias: Some(SubModel::from_fit(&f)),
        scale: None,
        training: TrainingInfo {
            temp_range_c,
            rate_range_c_per_s,
            data_digest_sha256: data_digest(&[&log]),
            epochs: None,
            final_loss: Some(f.rms_residual),
            seed: None,
            created_by: gyrotherm::model::created_by(),
            inputs: vec!["synthetic".into()],
        },
        coverage: None,
        columns: None,
        coverage_note: None,
        method_choice: None,
    };
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("linear.json");
    m.save(&path).unwrap();
    let back = ModelFile::load(&path).unwrap();
    let core = back.bias.unwrap().baseline_core().unwrap().unwrap();
    for (r, want) in y.iter().enumerate() {
        let got = core.eval(tab.row(r)).unwrap();
        assert!((got - f.predict_row(tab.row(r))).abs() < 1e-15, "row {r}");
        assert!(
            (got - want).abs() < 1e-12,
            "row {r}: want {want}, got {got}"
        );
    }
}

/// A residual sub-model whose LSTM reads the base prediction: `n_features + 1` LSTM inputs.
fn residual_model(reads_base: bool, lstm_inputs: usize) -> ModelFile {
    let spec = FeatureSpec::THERMAL_STATE;
    let terms = Terms::linear(spec.n_features());
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let coefficients = random_vec(&mut rng, terms.len());
    let SubModel::Lstm {
        params,
        input_norm,
        target_norm,
    } = lstm_sub(&mut rng, lstm_inputs, 8)
    else {
        unreachable!()
    };
    ModelFile {
        format_version: 1,
        method: Method::Lstm,
        features: FeatureDef::from_spec(&spec),
        bias: Some(SubModel::Residual {
            terms,
            coefficients,
            params,
            input_norm,
            target_norm,
            lstm_reads_base: reads_base,
        }),
        scale: None,
        training: training(),
        coverage: None,
        columns: None,
        coverage_note: None,
        method_choice: None,
    }
}

/// `lstm_reads_base` round-trips bit-exactly, flies, is checked against the LSTM's input count
/// (features + 1), and a file without the field (written before it existed) reads as `false`.
#[test]
fn residual_reading_the_base_round_trips_and_is_checked() {
    let dir = tempfile::tempdir().unwrap();
    let m = residual_model(true, 6);
    let path = dir.path().join("residual.json");
    m.save(&path).unwrap();
    let back = ModelFile::load(&path).unwrap();
    assert_bit_exact(&m, &back);
    assert!(matches!(
        back.bias,
        Some(SubModel::Residual {
            lstm_reads_base: true,
            ..
        })
    ));
    gyrotherm::compensate::compensator(&back).unwrap();

    // Wrong input counts, either way round, are refused with the count named.
    let e = residual_model(true, 5).validate().unwrap_err().chain_text();
    assert!(e.contains("input_size is 5") && e.contains("6"), "{e}");
    let e = residual_model(false, 6)
        .validate()
        .unwrap_err()
        .chain_text();
    assert!(e.contains("input_size is 6"), "{e}");

    // An older file (no `lstm_reads_base` key) loads as features-only.
    let mut v = serde_json::to_value(residual_model(false, 5)).unwrap();
    let removed = v["bias"]["residual"]
        .as_object_mut()
        .unwrap()
        .remove("lstm_reads_base");
    assert_eq!(removed, Some(serde_json::Value::Bool(false)));
    let p = save_text(dir.path(), "old.json", &v.to_string());
    let old = ModelFile::load(&p).unwrap();
    assert_eq!(old, residual_model(false, 5));
    // The same old file with a 6-input LSTM is refused (it would need the flag).
    let mut v = serde_json::to_value(residual_model(true, 6)).unwrap();
    v["bias"]["residual"]
        .as_object_mut()
        .unwrap()
        .remove("lstm_reads_base");
    expect_load_error(&v, &["input_size is 6"]);
}
