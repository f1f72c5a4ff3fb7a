//! `gyrotherm export --lang c`: the generated C, built with gcc `-std=c99 -O2
//! -ffp-contract=off -Wall -Wextra -Werror -pedantic` together with a small driver
//! (tests/export_c/driver.c), gives the same rate, bias, scale factor and status as
//! `gyrotherm compensate --stream`, to the last bit (parsed doubles compared), on a 30,000-line
//! seed-shock run with and without injected faults (spikes, NaN bursts, stuck readings, gyro
//! NaN, repeated time stamps), and on the faulty run with dropouts, for every method and recipe (linear, poly, each LSTM recipe, bias-only) and for
//! constructed models that are sure to hold every part (residual LSTM on a baseline, with and
//! without the base value as input; moving average and lag levels).

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

mod cli;
use cli::{gyrotherm, run_ok};

fn have_gcc() -> bool {
    Command::new("gcc")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
}

use cli::simulate_args as simulate;

/// Deterministic weights in [-0.5, 0.5) (a 64-bit LCG, Knuth's MMIX constants).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }
    fn vec(&mut self, n: usize) -> Vec<f64> {
        (0..n).map(|_| self.next()).collect()
    }
}

fn lstm_json(
    rng: &mut Lcg,
    inputs: usize,
    mean: &[f64],
    std: &[f64],
    target: (f64, f64),
) -> serde_json::Value {
    serde_json::json!({
        "params": {
            "input_size": inputs, "hidden_size": 8,
            "w_ih": rng.vec(32 * inputs), "w_hh": rng.vec(256), "b_ih": rng.vec(32),
            "b_hh": rng.vec(32), "w_out": rng.vec(8), "b_out": rng.next(),
        },
        "input_norm": {"mean": mean, "std": std},
        "target_norm": {"mean": [target.0], "std": [target.1]},
    })
}

/// Linear terms over `nf` features: 1, x_0, …, x_{nf-1}.
fn linear_terms(nf: usize, rng: &mut Lcg, scale: f64) -> (serde_json::Value, Vec<f64>) {
    let mut powers = vec![vec![0u8; nf]];
    for i in 0..nf {
        let mut p = vec![0u8; nf];
        p[i] = 1;
        powers.push(p);
    }
    let mut c: Vec<f64> = rng.vec(nf + 1).iter().map(|v| v * scale).collect();
    c[0] = 2.7e-3;
    (serde_json::json!({"n_features": nf, "powers": powers}), c)
}

/// Models built here so that every part is certainly present: a residual LSTM on a baseline
/// (thermal-state features) without and with the base value as input, and a spec with a moving
/// average and lag levels and differences.
fn constructed_models(dir: &Path, template: &Path) -> Vec<(String, PathBuf)> {
    let base: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(template).unwrap()).unwrap();
    let mut rng = Lcg(7);
    let mut out = Vec::new();
    let specs = [
        (
            "residual-constructed",
            serde_json::json!({"step_period_s": 1.0, "rate_lag_s": 20.0, "smoothing_window_s": 0.0,
                "lag_tau_s": [300.0, 1000.0, 3000.0], "lag_outputs": "diff_from_t"}),
            5,
            false,
        ),
        (
            "residual-reads-base-ma-both",
            serde_json::json!({"step_period_s": 1.0, "rate_lag_s": 20.0, "smoothing_window_s": 10.0,
                "lag_tau_s": [300.0, 1000.0], "lag_outputs": "both",
                "temp_sensor": {"min_c": -55.0, "max_c": 80.0, "max_rate_c_per_s": 1.0,
                                "step_allowance_c": 0.5, "degraded_after_s": 30.0}}),
            7,
            true,
        ),
    ];
    for (name, features, nf, reads_base) in specs {
        let mut m = base.clone();
        // Made by hand from a trained file: unsealed (a stale checksum would be refused).
        m.as_object_mut().unwrap().remove("content_sha256");
        m["method"] = "lstm".into();
        m["features"] = features;
        let (terms, coefficients) = linear_terms(nf, &mut rng, 1e-6);
        let n_in = nf + usize::from(reads_base);
        let mut mean = vec![20.0, 0.0];
        mean.resize(n_in, 1.0);
        let mut std = vec![30.0, 0.03];
        std.resize(n_in, 5.0);
        if reads_base {
            mean[nf] = 2.7e-3;
            std[nf] = 5e-5;
        }
        let mut bias = lstm_json(&mut rng, n_in, &mean, &std, (0.0, 2e-5));
        bias["terms"] = terms;
        bias["coefficients"] = coefficients.into();
        bias["lstm_reads_base"] = reads_base.into();
        m["bias"] = serde_json::json!({ "residual": bias });
        let scale = lstm_json(&mut rng, nf, &mean[..nf], &std[..nf], (1.0, 3e-5));
        m["scale"] = serde_json::json!({ "lstm": scale });
        let path = dir.join(format!("m_{name}.json"));
        std::fs::write(&path, serde_json::to_string_pretty(&m).unwrap()).unwrap();
        out.push((name.to_owned(), path));
    }
    out
}

/// Compare the driver's output with the stream's: (lines compared, lines differing).
fn compare(c_out: &str, stream_out: &str) -> (usize, usize, [usize; 4]) {
    let mut s_lines = stream_out.lines();
    let header: Vec<&str> = s_lines.next().unwrap().split(',').collect();
    let idx = |n: &str| header.iter().position(|h| *h == n).unwrap();
    let (ri, bi, ki, si) = (
        idx("gyro_comp_dps"),
        idx("bias_dps"),
        idx("scale"),
        idx("status"),
    );
    let mut c_lines = c_out.lines();
    c_lines.next();
    let (mut n, mut bad, mut statuses) = (0, 0, [0usize; 4]);
    let num =
        |s: &str| -> Option<u64> { (!s.is_empty()).then(|| s.parse::<f64>().unwrap().to_bits()) };
    for (c, s) in c_lines.zip(s_lines) {
        let c: Vec<&str> = c.split(',').collect();
        let s: Vec<&str> = s.split(',').collect();
        n += 1;
        let same = c[0] == s[si]
            && num(c[1]) == num(s[ri])
            && num(c[2]) == num(s[bi])
            && num(c[3]) == num(s[ki]);
        if !same {
            if bad < 3 {
                eprintln!(
                    "differs: C {c:?} vs stream {:?}",
                    [s[si], s[ri], s[bi], s[ki]]
                );
            }
            bad += 1;
        }
        let k = ["ok", "held", "degraded", "invalid"]
            .iter()
            .position(|v| *v == c[0])
            .unwrap();
        statuses[k] += 1;
    }
    (n, bad, statuses)
}

#[test]
fn generated_c_equals_compensate_stream_to_the_last_bit() {
    if !have_gcc() {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "gcc is required in CI for the C export test"
        );
        eprintln!("skipped: gcc not found (the C export test needs it)");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (train_s, train_t) = cli::fast_cycle_training_pair(d);
    let base = ["--profile", "seed-shock", "--seed", "3"];
    let clean = simulate(d, "clean.csv", &base);
    let mut fault_args = base.to_vec();
    fault_args.extend([
        "--spikes-per-hour",
        "4",
        "--nan-bursts-per-hour",
        "0.5",
        "--stuck-temp-per-hour",
        "0.5",
        "--stuck-temp-s",
        "120",
        "--stuck-value-per-hour",
        "0.3",
    ]);
    let faulty = simulate(d, "faulty.csv", &fault_args);
    // The same with dropouts (time gaps: lags advance over the elapsed time).
    fault_args.extend(["--dropouts-per-hour", "1"]);
    let gaps = simulate(d, "faulty_gaps.csv", &fault_args);
    // Gyro faults too: every 997th line's gyro is NaN (invalid), every 1009th line's time
    // repeats the previous one (held).
    let text = std::fs::read_to_string(&faulty).unwrap();
    let mut prev_time = String::new();
    let edited: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            let mut f: Vec<String> = l.split(',').map(str::to_owned).collect();
            if i > 0 && i % 997 == 0 {
                f[1] = "NaN".into();
            }
            if i > 1 && i % 1009 == 0 {
                f[0] = prev_time.clone();
            }
            prev_time = f[0].clone();
            f.join(",")
        })
        .collect();
    std::fs::write(&faulty, edited.join("\n") + "\n").unwrap();

    let mut models: Vec<(String, PathBuf)> = Vec::new();
    let mut train = |name: &str, args: &[&str], table: bool| {
        let path = d.join(format!("m_{name}.json"));
        let mut cmd = gyrotherm();
        cmd.arg("train").args(args).arg("--input").arg(&train_s);
        if table {
            cmd.arg("--input").arg(&train_t);
        }
        run_ok(cmd.arg("--out").arg(&path));
        models.push((name.to_owned(), path));
    };
    train("linear", &["--method", "linear"], true);
    train("poly", &["--method", "poly"], true);
    for recipe in ["residual", "generic", "direct", "published"] {
        train(recipe, &["--method", recipe], true);
    }
    train("linear-bias-only", &["--method", "linear"], false);
    train("published-bias-only", &["--method", "published"], false);
    let template = models[0].1.clone();
    models.extend(constructed_models(d, &template));

    let driver = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/export_c/driver.c");
    let mut failures = Vec::new();
    for (name, model) in &models {
        let m: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(model).unwrap()).unwrap();
        let kind = |t: &str| {
            m[t].as_object()
                .and_then(|o| o.keys().next().cloned())
                .unwrap_or_else(|| "none".into())
        };
        let out_dir = d.join(format!("c_{name}"));
        run_ok(
            gyrotherm()
                .args(["export", "--lang", "c", "--model"])
                .arg(model)
                .arg("--out")
                .arg(&out_dir),
        );
        let exe = out_dir.join("driver");
        run_ok(
            Command::new("gcc")
                .args([
                    "-std=c99",
                    "-O2",
                    "-ffp-contract=off",
                    "-Wall",
                    "-Wextra",
                    "-Werror",
                    "-pedantic",
                    "-I",
                ])
                .arg(&out_dir)
                .arg(&driver)
                .arg(out_dir.join("gyrotherm_model.c"))
                .arg("-lm")
                .arg("-o")
                .arg(&exe),
        );
        for (run, input) in [("clean", &clean), ("faulty", &faulty), ("gaps", &gaps)] {
            let c_out =
                run_ok(Command::new(&exe).stdin(Stdio::from(std::fs::File::open(input).unwrap())));
            let stream = run_ok(
                gyrotherm()
                    .args(["compensate", "--stream", "--model"])
                    .arg(model)
                    .stdin(Stdio::from(std::fs::File::open(input).unwrap())),
            );
            let (n, bad, st) = compare(
                &String::from_utf8_lossy(&c_out.stdout),
                &String::from_utf8_lossy(&stream.stdout),
            );
            let lines = std::fs::read_to_string(input).unwrap().lines().count() - 1;
            println!(
                "{name:28} bias {:9} scale {:9} {run:6}: {n} lines, {bad} differ \
                 (ok {}, held {}, degraded {}, invalid {})",
                kind("bias"),
                kind("scale"),
                st[0],
                st[1],
                st[2],
                st[3]
            );
            if bad > 0 || n != lines {
                failures.push(format!(
                    "{name} {run}: {bad} of {n} lines differ ({lines} input)"
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
