//! The bridges to autopilots and ROS, through the real binary: `export --target ardupilot|px4`
//! (the fit printed, what the polynomial leaves out, the file written atomically into
//! `--out`), the deprecated `--lang` still writing what `--target` writes (with a warning) for
//! one release, flags refused where they
//! mean nothing, and `allan --kalibr` (the file written with the figures the library reads,
//! bounds printed, a bad topic refused).

use std::path::Path;

mod cli;
use cli::{assert_exit, gyrotherm, run_ok, simulate_args};

/// A `thermal` model (the default method) trained on a fast-cycle static log.
fn thermal_model(dir: &Path) -> std::path::PathBuf {
    let log = simulate_args(dir, "log.csv", &["--profile", "fast-cycle", "--seed", "1"]);
    let model = dir.join("m.json");
    run_ok(
        gyrotherm()
            .args(["train", "--input"])
            .arg(&log)
            .arg("--out")
            .arg(&model),
    );
    model
}

#[test]
fn export_writes_autopilot_parameters_with_the_fit_printed() {
    let dir = tempfile::tempdir().unwrap();
    let model = thermal_model(dir.path());
    let out = dir.path().join("params");
    let r = run_ok(
        gyrotherm()
            .args(["export", "--target", "ardupilot", "--axis", "z", "--model"])
            .arg(&model)
            .arg("--out")
            .arg(&out),
    );
    let err = String::from_utf8_lossy(&r.stderr);
    for want in [
        "axis Z: fit error max",
        "°/h",
        "not carried",
        "T - lag",
        "wrote",
    ] {
        assert!(err.contains(want), "{want}:\n{err}");
    }
    let text = std::fs::read_to_string(out.join("gyro_tcal.parm")).unwrap();
    assert!(text.contains("\nINS_TCAL1_ENABLE 1\n"), "{text}");
    assert!(text.contains("\nINS_TCAL1_GYR3_Z "), "{text}");
    assert!(
        text.contains("\nINS_TCAL1_GYR1_X 0\n"),
        "X is left uncorrected:\n{text}"
    );

    let r = run_ok(
        gyrotherm()
            .args([
                "export",
                "--target",
                "px4",
                "--device-id",
                "0x260009",
                "--instance",
                "1",
            ])
            .arg("--model")
            .arg(&model)
            .arg("--out")
            .arg(&out),
    );
    let text = std::fs::read_to_string(out.join("gyro_tc.params")).unwrap();
    assert!(text.contains("\n1\t1\tTC_G1_ID\t2490377\t6\n"), "{text}");
    assert!(text.contains("\n1\t1\tTC_G_ENABLE\t1\t6\n"), "{text}");
    assert!(String::from_utf8_lossy(&r.stderr).contains("axis X: fit error max"));

    // PX4 without the device id: exit 2, naming the flag; nothing written.
    let empty = dir.path().join("empty");
    let r = gyrotherm()
        .args(["export", "--target", "px4", "--model"])
        .arg(&model)
        .arg("--out")
        .arg(&empty)
        .output()
        .unwrap();
    assert_exit(&r, 2);
    assert!(String::from_utf8_lossy(&r.stderr).contains("--device-id"));
    assert!(!empty.join("gyro_tc.params").exists());
}

#[test]
fn lang_is_deprecated_and_autopilot_flags_are_refused_for_code() {
    let dir = tempfile::tempdir().unwrap();
    let model = thermal_model(dir.path());
    let old = dir.path().join("lang");
    let r = run_ok(
        gyrotherm()
            .args(["export", "--lang", "c", "--model"])
            .arg(&model)
            .arg("--out")
            .arg(&old),
    );
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        err.contains("--lang is deprecated and will be removed: use --target c"),
        "{err}"
    );
    let r = gyrotherm()
        .args(["export", "--lang", "px4", "--model"])
        .arg(&model)
        .arg("--out")
        .arg(dir.path().join("px4"))
        .output()
        .unwrap();
    assert_exit(&r, 2);
    let r = gyrotherm()
        .args(["export", "--lang", "c", "--target", "rust", "--model"])
        .arg(&model)
        .arg("--out")
        .arg(dir.path().join("both"))
        .output()
        .unwrap();
    assert_exit(&r, 2);
    let out = dir.path().join("c");
    run_ok(
        gyrotherm()
            .args(["export", "--target", "c", "--model"])
            .arg(&model)
            .arg("--out")
            .arg(&out),
    );
    for f in ["gyrotherm_model.c", "gyrotherm_model.h"] {
        assert_eq!(
            std::fs::read(out.join(f)).unwrap(),
            std::fs::read(old.join(f)).unwrap(),
            "{f}: --lang c writes what --target c writes"
        );
    }
    let r = gyrotherm()
        .args(["export", "--target", "c", "--axis", "y", "--model"])
        .arg(&model)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_exit(&r, 2);
    assert!(String::from_utf8_lossy(&r.stderr).contains("--axis is for --target ardupilot or px4"));
    let help = run_ok(gyrotherm().args(["export", "--help"]));
    let help = String::from_utf8_lossy(&help.stdout);
    for t in ["ardupilot", "px4", "rust"] {
        assert!(help.contains(t), "{help}");
    }
    assert!(!help.contains("--lang"), "hidden\n{help}");
}

/// Standard normal pairs: SplitMix64 (Steele, Lea & Flood 2014) and the Box–Muller
/// transform.
struct Normal(u64);

impl Normal {
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        ((z >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    fn pair(&mut self) -> (f64, f64) {
        let (u, v) = (self.uniform(), self.uniform());
        let r = (-2.0 * u.ln()).sqrt();
        let a = 2.0 * std::f64::consts::PI * v;
        (r * a.cos(), r * a.sin())
    }
}

#[test]
fn allan_writes_the_kalibr_file() {
    let dir = tempfile::tempdir().unwrap();
    // 100 Hz white rate noise plus a rate random walk, as a gyrotherm CSV.
    let (tau0, n, k) = (0.01, 0.002, 3f64.sqrt() * 0.002 / 20.0);
    let mut rng = Normal(5);
    let mut walk = 0.0;
    let mut csv = String::from("time_s,gyro_dps,temp_c\n");
    for i in 0..300_000 {
        let (w, v) = rng.pair();
        walk += k * f64::sqrt(tau0) * v;
        csv.push_str(&format!(
            "{},{},25\n",
            i as f64 * tau0,
            n / f64::sqrt(tau0) * w + walk
        ));
    }
    let input = dir.path().join("still.csv");
    std::fs::write(&input, csv).unwrap();
    let yaml = dir.path().join("imu.yaml");
    let r = run_ok(
        gyrotherm()
            .arg("allan")
            .arg("--input")
            .arg(&input)
            .arg("--kalibr")
            .arg(&yaml)
            .args(["--rostopic", "/imu1", "--json"]),
    );
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        err.contains("gyroscope_noise_density") && err.contains("68.3 % bounds"),
        "{err}"
    );
    let text = std::fs::read_to_string(&yaml).unwrap();
    let value = |key: &str| -> String {
        text.lines()
            .find_map(|l| l.strip_prefix(&format!("{key}: ")))
            .unwrap_or_else(|| panic!("{key}:\n{text}"))
            .to_owned()
    };
    let nd: f64 = value("gyroscope_noise_density").parse().unwrap();
    let rad = std::f64::consts::PI / 180.0;
    assert!((nd / (n * rad) - 1.0).abs() < 0.05, "{nd} vs {}", n * rad);
    let rw: f64 = value("gyroscope_random_walk").parse().unwrap();
    assert!(rw > 0.0 && rw.is_finite());
    assert_eq!(value("update_rate"), "1.0e+2");
    assert_eq!(value("rostopic"), "/imu1");
    // The JSON on stdout is untouched by the file.
    let json: serde_json::Value = serde_json::from_slice(&r.stdout).unwrap();
    assert!(json["noise"]["arw_deg_rt_h"]["value"].is_number());

    // A topic that would break the YAML, and a deviation Kalibr's figures are not read from.
    for (args, want) in [
        (vec!["--rostopic", "/imu: 1"], "rostopic"),
        (vec!["--kind", "mdev"], "--kind oadev"),
    ] {
        let other = dir.path().join("other.yaml");
        let r = gyrotherm()
            .arg("allan")
            .arg("--input")
            .arg(&input)
            .arg("--kalibr")
            .arg(&other)
            .args(&args)
            .output()
            .unwrap();
        assert_exit(&r, 2);
        assert!(
            String::from_utf8_lossy(&r.stderr).contains(want),
            "{args:?}"
        );
        assert!(!other.exists());
    }
}
