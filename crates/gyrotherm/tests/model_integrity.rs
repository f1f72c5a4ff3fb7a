//! Model files are checked when loaded: a content checksum (re-sealed on purpose with
//! `ModelFile::seal`), plausible coefficients and outputs over the training range, and a
//! byte-order mark is accepted as in logs.

use gyrotherm::model::{ModelFile, CHECKSUM_KEY};
use serde_json::{json, Value};

/// An error as the user reads it: its message and its causes (`gyrotherm::error_chain`).
trait ChainText {
    fn chain_text(&self) -> String;
}

impl<E: std::error::Error + 'static> ChainText for E {
    fn chain_text(&self) -> String {
        gyrotherm::error_chain(self)
    }
}

/// A linear model as `gyrotherm train --method linear` writes one (fast-cycle profile):
/// B ≈ 2.8e-3 °/s, K ≈ 1.0003 over -29.8 to 70.4 °C.
fn linear() -> Value {
    json!({
        "format_version": 1, "method": "linear",
        "features": {"step_period_s": 1.0, "rate_lag_s": 20.0, "smoothing_window_s": 0.0,
                     "lag_tau_s": [], "lag_outputs": "diff_from_t"},
        "bias": {"baseline": {"terms": {"n_features": 2, "powers": [[0, 0], [1, 0], [0, 1]]},
                 "coefficients": [0.0027569503410293872, 1.1729644843148304e-06, 0.00010133064497718164]}},
        "scale": {"baseline": {"terms": {"n_features": 2, "powers": [[0, 0], [1, 0], [0, 1]]},
                  "coefficients": [1.0002578767007753, 9.083930143213933e-07, -0.00021387351834198826]}},
        "training": {"temp_range_c": {"min": -29.8125, "max": 70.375},
                     "rate_range_c_per_s": {"min": -0.0875, "max": 0.0875},
                     "data_digest_sha256": "30d4b8ab79b048f01aab0c81da07c7ee0aac77c3209a51f2976c0d528981f351",
                     "epochs": null, "final_loss": null, "seed": null,
                     "created_by": "gyrotherm 0.1.0", "inputs": ["fc.csv", "fct.csv"]}
    })
}

fn write(dir: &std::path::Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn load_err(dir: &std::path::Path, v: &Value) -> String {
    let p = write(dir, "m.json", &v.to_string());
    let e = ModelFile::load(&p).unwrap_err().chain_text();
    assert!(e.contains(&p.display().to_string()), "no file named in {e}");
    e
}

#[test]
fn a_saved_model_is_sealed_and_an_edit_is_caught_until_resealed() {
    let dir = tempfile::tempdir().unwrap();
    let m = ModelFile::from_json(&linear().to_string()).unwrap();
    let p = dir.path().join("m.json");
    m.save(&p).unwrap();
    let text = std::fs::read_to_string(&p).unwrap();
    let v: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v[CHECKSUM_KEY], m.content_digest().unwrap().as_str());
    assert_eq!(ModelFile::load(&p).unwrap(), m);

    // Layout does not matter: the same content, compact and with keys reordered, loads.
    write(dir.path(), "m.json", &v.to_string());
    assert_eq!(ModelFile::load(&p).unwrap(), m);

    // A value edited by hand is caught, naming the file and the way out.
    let edited = text.replace("1.0002578767007753", "1.0102578767007753");
    assert_ne!(edited, text);
    write(dir.path(), "m.json", &edited);
    let e = ModelFile::load(&p).unwrap_err().chain_text();
    assert!(e.contains(&p.display().to_string()), "{e}");
    assert!(
        e.contains(CHECKSUM_KEY) && e.contains("gyrotherm model seal"),
        "{e}"
    );

    // Re-sealed on purpose, it loads with the edited value.
    let (sealed, digest) = ModelFile::seal(&p).unwrap();
    assert_eq!(ModelFile::load(&p).unwrap(), sealed);
    assert_ne!(sealed, m);
    assert_ne!(digest, m.content_digest().unwrap());
}

#[test]
fn a_byte_order_mark_is_accepted() {
    let dir = tempfile::tempdir().unwrap();
    let m = ModelFile::from_json(&linear().to_string()).unwrap();
    let p = write(
        dir.path(),
        "bom.json",
        &format!("\u{feff}{}", m.to_json().unwrap()),
    );
    assert_eq!(ModelFile::load(&p).unwrap(), m);
}

#[test]
fn absurd_but_finite_models_are_refused_naming_the_file_and_target() {
    let dir = tempfile::tempdir().unwrap();
    // Bias 1e308 °/s.
    let mut v = linear();
    v["bias"]["baseline"]["coefficients"][0] = json!(1e308);
    let e = load_err(dir.path(), &v);
    assert!(e.contains("bias") && e.contains("implausibly large"), "{e}");
    // Scale 1e-300: K ≈ 0.
    let mut v = linear();
    v["scale"]["baseline"]["coefficients"][0] = json!(1e-300);
    let e = load_err(dir.path(), &v);
    assert!(e.contains("scale") && e.contains("K = "), "{e}");
    // K crossing zero inside the training range: 0.5 − 0.02·T is ≤ 0 above 25 °C.
    let mut v = linear();
    v["scale"]["baseline"]["coefficients"] = json!([0.5, -0.02, 0.0]);
    let e = load_err(dir.path(), &v);
    assert!(e.contains("scale: predicts K = "), "{e}");
    assert!(e.contains("inside the training range"), "{e}");
    // Bias of 5000 °/s at the top of the range (50·T).
    let mut v = linear();
    v["bias"]["baseline"]["coefficients"] = json!([0.0, 50.0, 0.0]);
    let e = load_err(dir.path(), &v);
    assert!(e.contains("bias: predicts B = "), "{e}");
}
