//! `gyrotherm export --target rust` of an inertial-unit model: the generated module of the
//! `imu_flight` example (a `thermal` model of three gyros and four sensors, the default
//! multi-sensor fit: every axis reads several sensors, first sensors on three different ones),
//! compiled into this test, builds a core `Unit` whose every axis equals
//! `compensate --stream` with the model file (`compensate_imu_lines`) to the last bit, status
//! for status, on a simulated run of the unit with time glitches, lasting clock resets and
//! jumps, one sensor failing, and huge and NaN gyro samples; and the module is what `export`
//! writes today.

#[allow(dead_code)]
#[path = "../../gyrotherm-core/examples/imu_flight/gyrotherm_model.rs"]
mod gyrotherm_model;

use gyrotherm::compensate_lines::unit::compensate_imu_lines;
use gyrotherm::compensate_lines::Mode;
use gyrotherm::model::unit::ImuModel;
use gyrotherm::sim::imu::{imu_from_family, simulate_imu, ImuConfig};
use gyrotherm::sim::{Profile, SimConfig};
use gyrotherm_core::unit::Unit;

fn example_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../gyrotherm-core/examples/imu_flight")
}

/// The example's generated module is current: regenerate it with
/// `gyrotherm export --model model.json --target rust --out .` in its directory.
#[test]
fn imu_flight_example_module_is_current() {
    let model = ImuModel::load(&example_dir().join("model.json")).unwrap();
    let want = std::fs::read_to_string(example_dir().join("gyrotherm_model.rs")).unwrap();
    let files =
        gyrotherm::export::unit::generate_imu(&model, gyrotherm::export::Lang::Rust).unwrap();
    assert_eq!(files.len(), 1);
    assert!(
        files[0].1 == want,
        "examples/imu_flight/gyrotherm_model.rs is stale; regenerate it"
    );
    assert!(gyrotherm::export::is_generated_text(&want));
    for name in model.gyro_cols.iter().chain(&model.temp_cols) {
        assert!(!want.contains(name.as_str()), "{name} in the module");
    }
}

/// The module's unit (with `fallbacks`) against the stream of `model` on the faulted run,
/// `dead` also losing the second sensor for good from line 20,000 on: lines compared, lines
/// that differ, per axis the lines not ok and the lines on the fallback.
fn module_vs_stream(
    model: &ImuModel,
    fallbacks: &[Option<gyrotherm_core::static_model::StaticModel>],
    dead: bool,
) -> (usize, usize, Vec<usize>, Vec<usize>) {
    let cfg = ImuConfig {
        run: SimConfig {
            seed: 7,
            ..SimConfig::new(Profile::builtin("seed-shock").unwrap())
        },
        unit: imu_from_family(1000),
        table_axis: 0,
    };
    let log = simulate_imu(&cfg).unwrap();
    let n_axes = model.gyro_cols.len();
    let col = |list: &[gyrotherm::csvlog::NamedSeries], name: &str| {
        list.iter()
            .find(|s| s.name == *name)
            .map(|s| s.values.clone())
            .unwrap()
    };
    let gyro: Vec<Vec<f64>> = model.gyro_cols.iter().map(|g| col(&log.gyro, g)).collect();
    let temp: Vec<Vec<f64>> = model.temp_cols.iter().map(|t| col(&log.temp, t)).collect();
    // Faults: time glitches (1e308, NaN, +1e9 s, −1e308, repeats), a lasting clock reset and
    // a lasting jump; the second sensor NaN for 200 s and at −127 °C for 20 s; huge and NaN
    // gyro samples.
    let mut rows: Vec<Vec<f64>> = Vec::new();
    let mut prev = 0.0;
    for i in 0..log.len() {
        let mut t = match i {
            12_000..15_000 => log.time_s[i] - 12_000.0,
            15_000.. => log.time_s[i] + 1e9,
            _ => log.time_s[i],
        };
        match i {
            3_001 => t = 1e308,
            4_001 => t = f64::NAN,
            5_001 => t += 1e9,
            6_001 => t = -1e308,
            7_001..=7_004 => t = prev,
            _ => {}
        }
        prev = t;
        let mut row = vec![t];
        row.extend(gyro.iter().map(|g| g[i]));
        row.extend(temp.iter().map(|c| c[i]));
        match i {
            8_000..8_200 => row[1 + n_axes + 1] = f64::NAN,
            20_000.. if dead => row[1 + n_axes + 1] = f64::NAN,
            9_000..9_020 => row[1 + n_axes + 1] = -127.0,
            10_001 => row[1] = 1.797e308,
            10_003 => row[2] = -1.797e308,
            10_005 => row[3] = f64::NAN,
            _ => {}
        }
        rows.push(row);
    }
    let mut text = String::from("time_s,");
    text.push_str(
        &model
            .gyro_cols
            .iter()
            .chain(&model.temp_cols)
            .cloned()
            .collect::<Vec<_>>()
            .join(","),
    );
    text.push('\n');
    for r in &rows {
        let f: Vec<String> = r.iter().map(|v| format!("{v:?}")).collect();
        text.push_str(&f.join(","));
        text.push('\n');
    }
    let mut out = Vec::new();
    compensate_imu_lines(
        model,
        text.as_bytes(),
        "generated".as_ref(),
        &gyrotherm::ReadOptions::default(),
        &mut out,
        Mode::Stream,
        false,
    )
    .unwrap();
    let out = String::from_utf8(out).unwrap();
    let mut unit: Unit<{ gyrotherm_model::AXES }> = Unit::from_static_fallbacks(
        &gyrotherm_model::MODELS,
        &gyrotherm_model::CHANNELS,
        &gyrotherm_model::SENSORS,
        fallbacks,
        gyrotherm_model::TEMPS,
    )
    .unwrap();
    let width = 1 + n_axes + model.temp_cols.len();
    let (mut lines, mut differ) = (0, 0);
    let (mut not_ok, mut on_fallback) = (vec![0usize; n_axes], vec![0usize; n_axes]);
    for (r, l) in rows.iter().zip(out.lines().skip(1)) {
        let f: Vec<&str> = l.split(',').collect();
        let got = unit.step(r[0], &r[1..1 + n_axes], &r[1 + n_axes..]);
        lines += 1;
        let mut same = true;
        for (k, c) in got.iter().enumerate() {
            let a = width + 6 * k;
            let num = |s: &str| s.parse::<f64>().unwrap_or(f64::NAN).to_bits();
            same &= num(f[a]) == c.bias_dps.to_bits()
                && num(f[a + 1]) == c.scale.to_bits()
                && f[a + 3] == c.status.as_str()
                && match c.rate() {
                    Some(v) => num(f[a + 2]) == v.to_bits(),
                    None => f[a + 2].is_empty(),
                };
            not_ok[k] += usize::from(c.status != gyrotherm_core::Status::Ok);
            on_fallback[k] += usize::from(c.status == gyrotherm_core::Status::Fallback);
        }
        differ += usize::from(!same);
    }
    assert_eq!(lines, rows.len());
    (lines, differ, not_ok, on_fallback)
}

#[test]
fn generated_unit_module_equals_the_stream_to_the_last_bit() {
    let model = ImuModel::load(&example_dir().join("model.json")).unwrap();
    // The example's file predates fallbacks: it has none.
    assert!(gyrotherm_model::FALLBACKS.iter().all(Option::is_none));
    let (lines, differ, not_ok, _) = module_vs_stream(&model, &gyrotherm_model::FALLBACKS, false);
    println!(
        "rust unit module vs stream: {lines} lines, {differ} differ; not ok per axis {not_ok:?}"
    );
    assert_eq!(differ, 0);
    // The module's axes read further sensors (so their code was compared), and every axis
    // that reads the failing sensor (temps[1]) is held through its 200 s of NaN.
    assert!(gyrotherm_model::SENSORS.iter().all(|s| !s.is_empty()));
    for (k, n) in not_ok.iter().enumerate() {
        let reads_1 = gyrotherm_model::CHANNELS[k] == 1
            || gyrotherm_model::SENSORS[k].iter().any(|s| s.channel == 1);
        assert!(!reads_1 || *n >= 200, "axis {k}: {not_ok:?}");
    }
}

/// With fallbacks (each axis's first-sensor model standing in for its fallback, as static data
/// like the module's) and the second sensor lost for good: the core unit built from the
/// static data equals the stream of the model file with the same fallbacks, line for line,
/// and every axis that reads that sensor as a further one runs on its fallback.
#[test]
fn static_fallbacks_equal_the_stream_when_a_further_sensor_dies() {
    let mut model = ImuModel::load(&example_dir().join("model.json")).unwrap();
    for a in &mut model.axes {
        a.fallback = Some(a.model.clone());
    }
    model.validate().unwrap();
    let fallbacks: Vec<Option<gyrotherm_core::static_model::StaticModel>> = model
        .axes
        .iter()
        .map(|a| Some(gyrotherm::export::static_model(&a.model).unwrap()))
        .collect();
    let (lines, differ, _, on_fallback) = module_vs_stream(&model, &fallbacks, true);
    println!("rust unit with fallbacks vs stream: {lines} lines, {differ} differ; on fallback per axis {on_fallback:?}");
    assert_eq!(differ, 0);
    for (k, n) in on_fallback.iter().enumerate() {
        let further_1 = gyrotherm_model::SENSORS[k].iter().any(|s| s.channel == 1);
        if further_1 {
            assert!(*n > 5_000, "axis {k}: {on_fallback:?}");
        } else {
            assert_eq!(*n, 0, "axis {k}");
        }
    }
}
