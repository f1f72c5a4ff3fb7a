//! `gyrotherm::export`: the static (flight) form of a model builds a compensator that equals
//! the one built from the model file, bit for bit and status for status, on a faulted run; the
//! Rust module of the flight-loop example is what `export --target rust` writes today.

use gyrotherm::export::static_model;
use gyrotherm::model::ModelFile;
use gyrotherm::sim::{simulate, FaultParams, Profile, SimConfig};
use gyrotherm_core::Compensator;

fn example_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../gyrotherm-core/examples/flight_loop")
}

#[test]
fn static_model_compensates_like_the_model_file() {
    let model = ModelFile::load(&example_dir().join("model.json")).unwrap();
    let cfg = SimConfig {
        faults: FaultParams {
            spikes_per_hour: 20.0,
            nan_bursts_per_hour: 2.0,
            nan_burst_s: 30.0,
            stuck_temp_per_hour: 2.0,
            stuck_temp_s: 120.0,
            dropouts_per_hour: 2.0,
            dropout_s: 5.0,
            ..Default::default()
        },
        ..SimConfig::new(Profile::builtin("seed-shock").unwrap())
    };
    let log = simulate(&cfg).unwrap();
    let mut a = gyrotherm::compensate::compensator(&model).unwrap();
    let mut b = Compensator::from_static(&static_model(&model).unwrap()).unwrap();
    let mut not_ok = 0;
    for i in 0..log.len() {
        let (t, g, c) = (log.time_s[i], log.gyro_dps[i], log.temp_c[i]);
        let (x, y) = (a.step(t, g, c), b.step(t, g, c));
        assert_eq!(x.status, y.status, "sample {i}");
        for (u, v) in [
            (x.rate_dps, y.rate_dps),
            (x.bias_dps, y.bias_dps),
            (x.scale, y.scale),
        ] {
            assert_eq!(u.to_bits(), v.to_bits(), "sample {i}");
        }
        not_ok += usize::from(x.status != gyrotherm_core::Status::Ok);
    }
    assert!(
        not_ok > 50,
        "the run exercised the fault path ({not_ok} samples)"
    );
}

/// The example's generated module is current: regenerate it with
/// `gyrotherm export --model model.json --target rust --out .` in its directory.
#[test]
fn flight_loop_example_module_is_current() {
    let dir = example_dir();
    let model = ModelFile::load(&dir.join("model.json")).unwrap();
    let want = std::fs::read_to_string(dir.join("gyrotherm_model.rs")).unwrap();
    let text = {
        let tmp = tempfile::tempdir().unwrap();
        gyrotherm::export::export(&model, gyrotherm::export::Lang::Rust, tmp.path()).unwrap();
        std::fs::read_to_string(tmp.path().join("gyrotherm_model.rs")).unwrap()
    };
    assert!(
        text == want,
        "examples/flight_loop/gyrotherm_model.rs is stale; regenerate it"
    );
}

/// The example model with its bias LSTM widened to 32 hidden units of fresh weights (the
/// scale-factor LSTM stays at 8): the model runs at 32.
fn model_32() -> ModelFile {
    let path = example_dir().join("model.json");
    let mut m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    m.as_object_mut().unwrap().remove("content_sha256");
    let p = &mut m["bias"]["lstm"]["params"];
    let inputs = p["input_size"].as_u64().unwrap() as usize;
    let mut state = 12345u64;
    let mut vec = |n: usize| -> Vec<f64> {
        (0..n)
            .map(|_| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.6
            })
            .collect()
    };
    let h = 32;
    p["hidden_size"] = h.into();
    p["w_ih"] = vec(4 * h * inputs).into();
    p["w_hh"] = vec(4 * h * h).into();
    p["b_ih"] = vec(4 * h).into();
    p["b_hh"] = vec(4 * h).into();
    p["w_out"] = vec(h).into();
    ModelFile::from_json(&m.to_string()).unwrap()
}

#[test]
fn a_32_unit_static_model_compensates_like_the_model_file() {
    use gyrotherm::flight_size::{FlightCompensator, HiddenSize};
    let model = model_32();
    let cfg = SimConfig {
        faults: FaultParams {
            spikes_per_hour: 20.0,
            dropouts_per_hour: 2.0,
            dropout_s: 5.0,
            ..Default::default()
        },
        ..SimConfig::new(Profile::builtin("seed-shock").unwrap())
    };
    let log = simulate(&cfg).unwrap();
    let mut a = gyrotherm::compensate::compensator(&model).unwrap();
    assert_eq!(a.hidden(), HiddenSize::H32);
    assert!(matches!(a, FlightCompensator::H32(_)));
    let s = gyrotherm::export::sized_static_model::<32>(&model).unwrap();
    let mut b = Compensator::<32>::from_static(&s).unwrap();
    for i in 0..log.len() {
        let (t, g, c) = (log.time_s[i], log.gyro_dps[i], log.temp_c[i]);
        let (x, y) = (a.step(t, g, c), b.step(t, g, c));
        assert_eq!(x.status, y.status, "sample {i}");
        assert_eq!(x.rate_dps.to_bits(), y.rate_dps.to_bits(), "sample {i}");
        assert_eq!(x.bias_dps.to_bits(), y.bias_dps.to_bits(), "sample {i}");
    }
    // The 8-unit form refuses it, naming the size; the Rust text carries the size.
    let e = gyrotherm::error_chain(&static_model(&model).unwrap_err());
    assert!(e.contains("32"), "{e}");
    let files = gyrotherm::export::generate(&model, gyrotherm::export::Lang::Rust).unwrap();
    assert!(files[0].1.contains("pub static MODEL: StaticModel<32> = "));
}

#[test]
fn an_unsupported_lstm_size_is_refused_naming_it() {
    let path = example_dir().join("model.json");
    let mut m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    m.as_object_mut().unwrap().remove("content_sha256");
    let p = &mut m["bias"]["lstm"]["params"];
    let inputs = p["input_size"].as_u64().unwrap() as usize;
    let h = 12;
    p["hidden_size"] = h.into();
    p["w_ih"] = vec![0.01; 4 * h * inputs].into();
    p["w_hh"] = vec![0.01; 4 * h * h].into();
    p["b_ih"] = vec![0.0; 4 * h].into();
    p["b_hh"] = vec![0.0; 4 * h].into();
    p["w_out"] = vec![0.01; h].into();
    let e = match ModelFile::from_json(&m.to_string()) {
        Err(e) => gyrotherm::error_chain(&e),
        Ok(model) => match gyrotherm::compensate::compensator(&model) {
            Err(e) => gyrotherm::error_chain(&e),
            Ok(_) => panic!("a 12-unit LSTM was accepted"),
        },
    };
    assert!(
        e.contains("12 hidden units") && e.contains("8, 16, 32 or 64"),
        "{e}"
    );
}
