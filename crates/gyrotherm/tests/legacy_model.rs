//! Model files written before the methods were one flat list (`"method": "lstm"`, the recipe
//! not recorded) still load, keep their name, and compensate exactly as the same model
//! under its new method name. The fixtures are in `tests/data/` (how they were made:
//! `tests/data/README.md`).

use std::path::PathBuf;

use gyrotherm::model::Seal;
use gyrotherm::{compensate_log, Method, ModelFile, TestLog};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// A temperature ramp across the fixtures' training range (-40..60 °C) at 1 Hz with a
/// constant rate, so both sub-models are exercised.
fn ramp_log() -> TestLog {
    let n = 4000;
    TestLog {
        time_s: (0..n).map(f64::from).collect(),
        gyro_dps: (0..n).map(|i| 0.01 + 1e-6 * f64::from(i % 7)).collect(),
        temp_c: (0..n)
            .map(|i| -30.0 + 80.0 * f64::from(i) / 4000.0)
            .collect(),
        ..Default::default()
    }
}

#[test]
fn old_lstm_files_load_and_compensate_as_the_renamed_model() {
    for (file, now, label) in [
        ("legacy_lstm_thermal.json", "thermal", "thermal-state LS"),
        ("legacy_lstm_published.json", "published", "LSTM"),
    ] {
        let (old, seal) = ModelFile::load_sealed(&fixture(file)).unwrap_or_else(|e| {
            panic!("{file}: {e}");
        });
        assert_eq!(seal, Seal::Verified, "{file}: its checksum still matches");
        assert_eq!(old.method, Method::Lstm, "{file}");
        assert_eq!(
            old.method.as_str(),
            "lstm",
            "{file}: the name it was written with"
        );
        assert_eq!(old.label(), label, "{file}: named by what it holds");
        // The same file under the method a fit writes now.
        // (Its checksum covers the old name, so the copy goes without one.)
        let text = std::fs::read_to_string(fixture(file)).unwrap();
        let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(json["method"], "lstm", "{file}");
        json["method"] = now.into();
        json.as_object_mut().unwrap().remove("content_sha256");
        let renamed_text = json.to_string();
        let renamed = ModelFile::from_json(&renamed_text).unwrap();
        assert_eq!(renamed.method.as_str(), now);
        assert_eq!(renamed.label(), label);
        let log = ramp_log();
        let a = compensate_log(&old, &log).unwrap();
        let b = compensate_log(&renamed, &log).unwrap();
        assert_eq!(
            a.gyro_comp_dps, b.gyro_comp_dps,
            "{file}: same numbers, bit for bit"
        );
        assert_eq!(a.bias_dps, b.bias_dps, "{file}");
        // Saving keeps the name it was read with: nothing claims a recipe the file did not record.
        let again = ModelFile::from_json(&old.to_json().unwrap()).unwrap();
        assert_eq!(again.method, Method::Lstm, "{file}");
    }
}

#[test]
fn method_names_parse_back_and_lstm_is_not_listed() {
    use gyrotherm::settings::{METHODS, METHOD_NAMES};
    for (m, name) in METHODS.iter().zip(METHOD_NAMES) {
        assert_eq!(m.as_str(), name);
        assert_eq!(name.parse::<Method>().unwrap(), *m);
    }
    assert!(!METHOD_NAMES.contains(&"lstm"));
    assert_eq!("lstm".parse::<Method>().unwrap(), Method::Lstm);
    let err = "fancy".parse::<Method>().unwrap_err().to_string();
    assert!(err.contains("method: unknown value \"fancy\""), "{err}");
}

/// Method `lstm`, which older model files record (they load above), is no method a fit or a
/// comparison takes: it is refused by name, with the methods that are.
#[test]
fn the_read_only_lstm_method_is_refused_as_a_setting() {
    use gyrotherm::settings::FitSettings;
    let with = |method| FitSettings {
        method,
        ..FitSettings::default()
    };
    let err = with(Method::Lstm).fit_config().unwrap_err().to_string();
    assert!(
        err.contains("method") && err.contains("lstm") && err.contains("thermal"),
        "{err}"
    );
    assert_eq!(
        with(Method::Generic).fit_config().unwrap().model_method(),
        Method::Generic
    );
    let err = FitSettings::default()
        .compare_config(
            Some(&[Method::Linear, Method::Lstm].map(gyrotherm::compare::ColumnName::Method)),
            100.0,
        )
        .unwrap_err()
        .to_string();
    assert!(err.contains("methods") && err.contains("lstm"), "{err}");
    let err = FitSettings {
        settle_s: -1.0,
        ..FitSettings::default()
    }
    .validate()
    .unwrap_err()
    .to_string();
    assert_eq!(
        err,
        "settle_s = -1 is not zero or a positive number of seconds"
    );
}
