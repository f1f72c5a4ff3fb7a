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
