//! `gyrotherm export --target c`: the generated C, built with gcc `-std=c99 -O2
//! -ffp-contract=off -Wall -Wextra -Werror -pedantic` together with a small driver
//! (tests/export_c/driver.c), gives the same rate, bias, scale factor and status as
//! `gyrotherm compensate --stream`, to the last bit (parsed doubles compared), and the same
//! coverage verdict and sigma_dph (`gt_coverage_of`, for models trained with a coverage map;
//! both columns empty alike otherwise), on a 30,000-line
//! seed-shock run with and without injected faults (spikes, NaN bursts, stuck readings, gyro
//! NaN, repeated time stamps), and on the faulty run with dropouts, for every method and recipe (linear, poly, each LSTM recipe, bias-only) and for
//! constructed models that are sure to hold every part (residual LSTM on a baseline, with and
//! without the base value as input; moving average and lag levels).

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

mod cli;
use cli::{gyrotherm, run_ok};
mod export_gen;
use export_gen::{generated_model, linear_terms, lstm_json_sized, Lcg, HUGE};

fn have_gcc() -> bool {
    Command::new("gcc")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
}

use cli::simulate_args as simulate;

/// Models built here so that every part is certainly present: a residual LSTM on a baseline
/// (thermal-state features) without and with the base value as input, and a spec with a moving
/// average and lag levels and differences; and a residual LSTM of 32 hidden units beside an
/// 8-unit scale-factor LSTM (the model runs at 32, the smaller network widened with zero units).
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
            8,
        ),
        (
            "residual-32-units",
            serde_json::json!({"step_period_s": 1.0, "rate_lag_s": 20.0, "smoothing_window_s": 0.0,
                "lag_tau_s": [300.0, 1000.0, 3000.0], "lag_outputs": "diff_from_t"}),
            5,
            false,
            32,
        ),
        (
            "residual-reads-base-ma-both",
            serde_json::json!({"step_period_s": 1.0, "rate_lag_s": 20.0, "smoothing_window_s": 10.0,
                "lag_tau_s": [300.0, 1000.0], "lag_outputs": "both",
                "temp_sensor": {"min_c": -55.0, "max_c": 80.0, "max_rate_c_per_s": 1.0,
                                "step_allowance_c": 0.5, "degraded_after_s": 30.0}}),
            7,
            true,
            8,
        ),
    ];
    for (name, features, nf, reads_base, hidden) in specs {
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
        let mut bias = lstm_json_sized(&mut rng, n_in, hidden, &mean, &std, (0.0, 2e-5));
        bias["terms"] = terms;
        bias["coefficients"] = coefficients.into();
        bias["lstm_reads_base"] = reads_base.into();
        m["bias"] = serde_json::json!({ "residual": bias });
        let scale = lstm_json_sized(&mut rng, nf, 8, &mean[..nf], &std[..nf], (1.0, 3e-5));
        m["scale"] = serde_json::json!({ "lstm": scale });
        let path = dir.join(format!("m_{name}.json"));
        std::fs::write(&path, serde_json::to_string_pretty(&m).unwrap()).unwrap();
        out.push((name.to_owned(), path));
    }
    out
}

/// Compare the driver's output with the stream's: (lines compared, lines differing, lines
/// per status, lines per coverage verdict inside, edge, outside).
fn compare(c_out: &str, stream_out: &str) -> (usize, usize, [usize; 4], [usize; 3]) {
    let mut s_lines = stream_out.lines();
    let header: Vec<&str> = s_lines.next().unwrap().split(',').collect();
    let idx = |n: &str| header.iter().position(|h| *h == n).unwrap();
    let (ri, bi, ki, si) = (
        idx("gyro_comp_dps"),
        idx("bias_dps"),
        idx("scale"),
        idx("status"),
    );
    let (ci, gi) = (idx("coverage"), idx("sigma_dph"));
    let mut c_lines = c_out.lines();
    c_lines.next();
    let (mut n, mut bad, mut statuses, mut cover) = (0, 0, [0usize; 4], [0usize; 3]);
    let num =
        |s: &str| -> Option<u64> { (!s.is_empty()).then(|| s.parse::<f64>().unwrap().to_bits()) };
    for (c, s) in c_lines.zip(s_lines) {
        let c: Vec<&str> = c.split(',').collect();
        let s: Vec<&str> = s.split(',').collect();
        n += 1;
        let same = c[0] == s[si]
            && num(c[1]) == num(s[ri])
            && num(c[2]) == num(s[bi])
            && num(c[3]) == num(s[ki])
            && c[4] == s[ci]
            && num(c[5]) == num(s[gi]);
        if !same {
            if bad < 3 {
                eprintln!(
                    "differs: C {c:?} vs stream {:?}",
                    [s[si], s[ri], s[bi], s[ki], s[ci], s[gi]]
                );
            }
            bad += 1;
        }
        let k = ["ok", "held", "degraded", "invalid"]
            .iter()
            .position(|v| *v == c[0])
            .unwrap();
        statuses[k] += 1;
        if let Some(v) = ["inside", "edge", "outside"]
            .iter()
            .position(|v| *v == c[4])
        {
            cover[v] += 1;
        }
    }
    (n, bad, statuses, cover)
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
    // repeats the previous one (held); and the time faults below.
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
            // Time faults (single: 1e308, NaN, +1e9 s, −1e308, five repeats; lasting: a clock
            // reset to 0 at line 20,000, a +1e9 s jump at 25,000) and overflow gyro samples.
            if i > 0 {
                let t: f64 = f[0].parse().unwrap();
                let t = match i {
                    20_000..25_000 => t - 20_000.0,
                    25_000.. => t + 1e9,
                    _ => t,
                };
                f[0] = format!("{t:?}");
                match i {
                    5_003 => f[0] = "1e308".into(),
                    7_001 => f[0] = format!("{:?}", t + 1e9),
                    9_001 => f[0] = "NaN".into(),
                    10_001 => f[0] = "-1e308".into(),
                    11_001..=11_005 => f[0] = prev_time.clone(),
                    13_001 | 21_001 => f[1] = "1.797e308".into(),
                    13_003 | 21_003 => f[1] = "-1.797e308".into(),
                    _ => {}
                }
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
    let mut covered_lines = 0usize;
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
                .args(["export", "--target", "c", "--model"])
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
            let (n, bad, st, cv) = compare(
                &String::from_utf8_lossy(&c_out.stdout),
                &String::from_utf8_lossy(&stream.stdout),
            );
            let lines = std::fs::read_to_string(input).unwrap().lines().count() - 1;
            println!(
                "{name:28} bias {:9} scale {:9} {run:6}: {n} lines, {bad} differ \
                 (ok {}, held {}, degraded {}, invalid {}; inside {}, edge {}, outside {})",
                kind("bias"),
                kind("scale"),
                st[0],
                st[1],
                st[2],
                st[3],
                cv[0],
                cv[1],
                cv[2]
            );
            covered_lines += cv.iter().sum::<usize>();
            if bad > 0 || n != lines {
                failures.push(format!(
                    "{name} {run}: {bad} of {n} lines differ ({lines} input)"
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
    // The trained least-squares models carry a coverage map: the verdict was compared.
    assert!(
        covered_lines > 100_000,
        "only {covered_lines} lines had a coverage verdict"
    );
}

// The differential test: many generated models, C against the stream, line by line.

/// Models in the differential test (each method, scale factor above and below 1).
const DIFF_MODELS: usize = 1000;
/// Models linked into one driver binary.
const BATCH: usize = 100;

/// The fixed stream: 1 Hz, a temperature cycle and ramp, with every time fault (1e308,
/// −1e308, NaN, +inf, single +1e9 s, repeated, backward, a 90 s dropout, 70 NaN times, a
/// lasting reset to 0 and a lasting +1e9 s jump), overflow and NaN gyro samples, and
/// temperature faults.
fn fixed_stream() -> Vec<(f64, f64, f64)> {
    let mut out = Vec::new();
    for i in 0..900usize {
        if (200..290).contains(&i) || (300..305).contains(&i) {
            continue; // dropouts
        }
        let x = i as f64;
        let mut t = match i {
            600..=749 => x - 600.0,
            750.. => x + 1e9,
            _ => x,
        };
        let mut g = 0.01 + 1e-4 * (x / 7.0).sin();
        let mut temp = 20.0 + 15.0 * (x / 150.0).sin() + 0.01 * x;
        match i {
            50 => t = 1e308,
            60 => t = f64::NAN,
            70 => t = f64::INFINITY,
            80 => t = x + 1e9,
            90..=95 => t = 89.0,
            100 => t = -1e308,
            110 => t = x - 30.0,
            120 => g = HUGE,
            121 => g = -HUGE,
            122 => g = f64::NAN,
            123 => g = f64::INFINITY,
            130 | 160..=189 => temp = f64::NAN,
            140 => temp = 85.0,
            150 => temp = -127.0,
            400..=469 => t = f64::NAN,
            500 => (t, g) = (1e308, HUGE),
            _ => {}
        }
        out.push((t, g, temp));
    }
    out
}

/// A random stream for model `seed`: about one line in eight is a fault of any kind, and
/// clock resets and jumps sometimes last.
fn random_stream(seed: u64) -> Vec<(f64, f64, f64)> {
    let mut rng = Lcg(seed);
    let (mut offset, mut out) = (0.0f64, Vec::new());
    for i in 0..700usize {
        let x = i as f64;
        let u = rng.next() + 0.5;
        let kind = ((rng.next() + 0.5) * 40.0) as usize;
        let mut t = x + offset;
        let mut g = 0.01 + 1e-3 * rng.next();
        let mut temp = 15.0 + 20.0 * (x / 100.0).sin();
        if u < 0.13 {
            match kind {
                0 => t = f64::NAN,
                1 => t = f64::INFINITY,
                2 => t = f64::NEG_INFINITY,
                3 => t = 1e308,
                4 => t = -1e308,
                5 => t -= 1.0,
                6 => t -= 30.0,
                7 => t += 1e9,
                8 => t += 45.0,
                9 => {
                    offset = -x; // lasting reset to 0
                    t = 0.0;
                }
                10 => {
                    offset += 1e9; // lasting jump
                    t += 1e9;
                }
                11 => offset += 90.0, // a dropout from here on
                12 => temp = f64::NAN,
                13 => temp = 85.0,
                14 => temp = -127.0,
                15 => temp = 95.0,
                16 => g = f64::NAN,
                17 => g = HUGE,
                18 => g = -HUGE,
                19 => g = f64::INFINITY,
                20 => (t, g, temp) = (f64::NAN, HUGE, f64::NAN),
                _ => temp += 30.0 * rng.next(),
            }
        }
        out.push((t, g, temp));
    }
    out
}

/// `compensate --stream`, in process: (status, rate or NaN when empty, bias, scale, coverage
/// verdict (0 inside, 1 edge, 2 outside; None when empty), sigma_dph or NaN when empty) per
/// line.
type StreamLine = (usize, f64, f64, f64, Option<usize>, f64);

fn stream_in_process(model: &gyrotherm::ModelFile, samples: &[(f64, f64, f64)]) -> Vec<StreamLine> {
    let mut text = String::from("time_s,gyro_dps,temp_c\n");
    for (t, g, c) in samples {
        text.push_str(&format!("{t:?},{g:?},{c:?}\n"));
    }
    let mut out = Vec::new();
    gyrotherm::compensate_lines(
        model,
        text.as_bytes(),
        Path::new("generated"),
        &gyrotherm::ReadOptions::default(),
        &mut out,
        gyrotherm::compensate_lines::Mode::Stream,
        false,
    )
    .unwrap();
    let text = String::from_utf8(out).unwrap();
    text.lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let status = ["ok", "held", "degraded", "invalid"]
                .iter()
                .position(|s| *s == f[6])
                .unwrap();
            let num = |s: &str| s.parse::<f64>().unwrap_or(f64::NAN);
            let cover = ["inside", "edge", "outside"]
                .iter()
                .position(|s| *s == f[7]);
            (status, num(f[5]), num(f[3]), num(f[4]), cover, num(f[8]))
        })
        .collect()
}

/// gcc with the flags above at optimisation level `opt`.
fn gcc(opt: &str, args: &[&str], files: &[&Path], out: &Path) {
    run_ok(
        Command::new("gcc")
            .arg(opt)
            .args([
                "-std=c99",
                "-ffp-contract=off",
                "-Wall",
                "-Wextra",
                "-Werror",
                "-pedantic",
            ])
            .args(args)
            .args(files)
            .arg("-lm")
            .arg("-o")
            .arg(out),
    );
}

/// 1,000 generated models (every method; scale factor above and below 1), each exported to
/// C, built with the same flags as above (at -O0) and run over two faulted streams (the
/// fixed one and a random one per model, both with time faults and overflow gyro samples):
/// every line's status, rate, bias and scale equal `compensate --stream`'s to the last bit, and
/// so do the coverage verdict and sigma_dph of `gt_coverage_of` (two models in three carry a
/// random coverage map; the rest must answer GT_NO_MAP).
#[test]
fn generated_c_equals_the_stream_for_a_thousand_generated_models() {
    if !have_gcc() {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "gcc is required in CI for the C export test"
        );
        eprintln!("skipped: gcc not found (the C export test needs it)");
        return;
    }
    let start = std::time::Instant::now();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let here = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/export_c");
    let fixed = fixed_stream();
    let (mut lines, mut differ, mut statuses) = (0usize, 0usize, [0usize; 4]);
    let mut verdicts = [0usize; 3];
    let mut failures = Vec::new();
    let workers = std::thread::available_parallelism().map_or(2, |n| n.get().min(4));
    for batch in 0..DIFF_MODELS.div_ceil(BATCH) {
        let ids: Vec<usize> = (batch * BATCH..((batch + 1) * BATCH).min(DIFF_MODELS)).collect();
        let bdir = d.join(format!("batch{batch}"));
        std::fs::create_dir_all(&bdir).unwrap();
        // Export and compile each model into its own object (in parallel).
        let mut models = Vec::new();
        for &i in &ids {
            let text = serde_json::to_string(&generated_model(i)).unwrap();
            let m = gyrotherm::ModelFile::from_json(&text)
                .unwrap_or_else(|e| panic!("generated model {i}: {e}"));
            let mdir = bdir.join(format!("m{i}"));
            gyrotherm::export::export(&m, gyrotherm::export::Lang::C, &mdir).unwrap();
            models.push((i, m, mdir));
        }
        let objs: Vec<PathBuf> = std::thread::scope(|s| {
            let chunks: Vec<&[(usize, gyrotherm::ModelFile, PathBuf)]> =
                models.chunks(models.len().div_ceil(workers)).collect();
            let handles: Vec<_> = chunks
                .into_iter()
                .map(|chunk| {
                    let here = &here;
                    s.spawn(move || {
                        chunk
                            .iter()
                            .map(|(i, _, mdir)| {
                                let obj = mdir.join("model.o");
                                // -O0: compiling 1,000 models is most of this test's
                                // time (0.2 s each at -O0, 0.3 s at -O2, measured); the
                                // -O2 build is the other test's. x86-64 SSE arithmetic is
                                // IEEE at every level, and -ffp-contract=off holds.
                                gcc(
                                    "-O0",
                                    &[
                                        "-c",
                                        &format!("-DGT_RUN=run_{i}"),
                                        &format!("-Dgt_init=gt_init_{i}"),
                                        &format!("-Dgt_step=gt_step_{i}"),
                                        &format!("-Dgt_coverage_of=gt_coverage_of_{i}"),
                                        "-I",
                                        mdir.to_str().unwrap(),
                                    ],
                                    &[&here.join("wrap.c")],
                                    &obj,
                                );
                                obj
                            })
                            .collect::<Vec<_>>()
                    })
                })
                .collect();
            handles
                .into_iter()
                .flat_map(|h| h.join().unwrap())
                .collect()
        });
        let mut runners = String::from("#define STREAMS 2u\n");
        for &i in &ids {
            runners.push_str(&format!(
                "void run_{i}(size_t n, const double *in, unsigned char *status, double *out);\n"
            ));
        }
        let list: Vec<String> = ids.iter().map(|i| format!("run_{i}")).collect();
        runners.push_str(&format!(
            "static const runner RUNS[] = {{{}}};\n",
            list.join(", ")
        ));
        std::fs::write(bdir.join("batch_runners.h"), runners).unwrap();
        let exe = bdir.join("batch");
        let mut files: Vec<&Path> = vec![];
        let main = here.join("batch_main.c");
        files.push(&main);
        files.extend(objs.iter().map(PathBuf::as_path));
        gcc("-O2", &["-I", bdir.to_str().unwrap()], &files, &exe);
        // Input: each model's two streams.
        let streams: Vec<[Vec<(f64, f64, f64)>; 2]> = ids
            .iter()
            .map(|&i| [fixed.clone(), random_stream(0xfa17 + i as u64)])
            .collect();
        let mut input = Vec::new();
        for ss in &streams {
            for s in ss {
                input.extend((s.len() as u64).to_le_bytes());
                for (t, g, c) in s {
                    for v in [t, g, c] {
                        input.extend(v.to_le_bytes());
                    }
                }
            }
        }
        std::fs::write(bdir.join("in.bin"), input).unwrap();
        run_ok(
            Command::new(&exe)
                .arg(bdir.join("in.bin"))
                .arg(bdir.join("out.bin")),
        );
        let out = std::fs::read(bdir.join("out.bin")).unwrap();
        let mut at = 0usize;
        let f64_at = |at: &mut usize| {
            let v = f64::from_le_bytes(out[*at..*at + 8].try_into().unwrap());
            *at += 8;
            v
        };
        for ((i, m, _), ss) in models.iter().zip(&streams) {
            for (k, s) in ss.iter().enumerate() {
                let want = stream_in_process(m, s);
                assert_eq!(want.len(), s.len(), "model {i}: one line out per line in");
                let st: Vec<u8> = out[at..at + s.len()].to_vec();
                at += s.len();
                // Without a verdict the C says why: no map in the model, or none yet.
                let no_verdict = if m.coverage.is_some() { 3 } else { 4 };
                for (line, (w, c_status)) in want.iter().zip(st).enumerate() {
                    let (r, b, sc) = (f64_at(&mut at), f64_at(&mut at), f64_at(&mut at));
                    let (cv, sigma) = (f64_at(&mut at) as usize, f64_at(&mut at));
                    let c_status = c_status as usize;
                    let same_cover = match w.4 {
                        Some(v) => cv == v && sigma.to_bits() == w.5.to_bits(),
                        None => cv == no_verdict && sigma.is_nan(),
                    };
                    let same = c_status == w.0
                        && b.to_bits() == w.2.to_bits()
                        && sc.to_bits() == w.3.to_bits()
                        && (c_status == 3 || r.to_bits() == w.1.to_bits())
                        && same_cover;
                    lines += 1;
                    statuses[c_status.min(3)] += 1;
                    if let Some(v) = w.4 {
                        verdicts[v] += 1;
                    }
                    if !same {
                        differ += 1;
                        if failures.len() < 5 {
                            failures.push(format!(
                                "model {i} stream {k} line {line} {:?}: C ({c_status}, {r:e}, \
                                 {b:e}, {sc:e}, {cv}, {sigma:e}) vs stream {w:?}",
                                s[line]
                            ));
                        }
                    }
                }
            }
        }
        assert_eq!(at, out.len(), "driver output length");
    }
    println!(
        "differential: {DIFF_MODELS} models × 2 streams: {lines} lines compared, {differ} differ \
         (ok {}, held {}, degraded {}, invalid {}; coverage inside {}, edge {}, outside {}); \
         {:.1} s",
        statuses[0],
        statuses[1],
        statuses[2],
        statuses[3],
        verdicts[0],
        verdicts[1],
        verdicts[2],
        start.elapsed().as_secs_f64()
    );
    assert!(
        failures.is_empty() && differ == 0,
        "{differ} lines differ: {failures:#?}"
    );
    // Every verdict occurred, so each branch of the port was compared.
    assert!(verdicts.iter().all(|v| *v > 1000), "verdicts {verdicts:?}");
}
