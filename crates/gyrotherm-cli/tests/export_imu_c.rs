//! `gyrotherm export --target c` of inertial-unit models: the generated C (`gt_step_imu_bk`,
//! and `gt_step_imu` beside it), built with gcc `-std=c99 -ffp-contract=off -Wall -Wextra
//! -Werror -pedantic`, gives every axis the same status, rate, bias and scale factor as
//! `compensate --stream` with the unit model (in process: `compensate_imu_lines`), to the last
//! bit, and `gt_coverage_of_axis` the verdict and sigma_dph of the core's coverage map on that
//! axis's compensator (the core `Unit` stepped alongside; two axis models in three carry a
//! map), on generated units (one to three axes, each axis one of the generated single-axis
//! models of every method, one to five temperature sensors, each axis on one to four drawn
//! sensors: the first through its model, each further one with drawn lags (0 to 4) and drawn
//! linear parts of B and K, either, both or neither; in even units each axis with further
//! sensors carries a fallback, another generated model) under faulted streams: one sensor NaN
//! for a minute and out of range, in units 2 and 3 of every 4 a sensor that dies for good
//! (NaN from line 350 on: the axes reading it as a further sensor run on their fallback in
//! even units, stay degraded in odd ones), time glitches and lasting clock resets and jumps,
//! huge and non-finite gyro samples. The units' column names hold `*/` and `??`: none reaches
//! the generated text. In every fourth unit the first model's LSTMs have 32 hidden units
//! (drawn anew), so the unit runs at 32 and its 8-unit models (fallbacks, other axes) are
//! widened with zero units.

use std::path::{Path, PathBuf};
use std::process::Command;

mod cli;
use cli::run_ok;
mod export_gen;
use export_gen::{generated_model, Lcg, HUGE};

/// Units in the test.
const UNITS: usize = 120;
/// Units linked into one driver binary.
const BATCH: usize = 60;
/// Lines per stream.
const LINES: usize = 600;
/// Lines of the long streams (units 13, 53 and 93): past 65,536 feature steps, so that a step
/// index or time kept in too narrow a type in the C state shows as a difference.
const LONG_LINES: usize = 70_000;

/// Whether unit `u` streams [`LONG_LINES`] lines: its faults stop after [`LINES`] and the
/// clock runs on at 1 Hz, each step one more than the last.
fn long_stream(u: usize) -> bool {
    u % 40 == 13
}

/// Whether unit `u`'s first axis model has its LSTMs at 32 hidden units.
fn wide_lstm(u: usize) -> bool {
    u % 4 == 3
}

/// `model` with each LSTM (plain or residual) replaced by one of `hidden` units drawn from
/// `rng`, reading the same inputs with the same normalisation.
fn with_hidden(mut model: serde_json::Value, hidden: usize, rng: &mut Lcg) -> serde_json::Value {
    for target in ["bias", "scale"] {
        for kind in ["lstm", "residual"] {
            let Some(l) = model.get_mut(target).and_then(|t| t.get_mut(kind)) else {
                continue;
            };
            let inputs = l["params"]["input_size"].as_u64().unwrap() as usize;
            let g = 4 * hidden;
            l["params"] = serde_json::json!({
                "input_size": inputs, "hidden_size": hidden,
                "w_ih": rng.vec(g * inputs), "w_hh": rng.vec(g * hidden), "b_ih": rng.vec(g),
                "b_hh": rng.vec(g), "w_out": rng.vec(hidden), "b_out": rng.next(),
            });
        }
    }
    model
}

fn have_gcc() -> bool {
    Command::new("gcc")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
}

/// A further sensor's part of B or K: linear in its features (`T`, `dT`, the smoothed `T`
/// when the axis smooths, `T - lag_j(T)`), no constant, small coefficients (a part of K
/// keeps K near its constant).
fn further_part(rng: &mut Lcg, nf: usize, scale: f64) -> serde_json::Value {
    let powers: Vec<Vec<u8>> = (0..nf)
        .map(|i| (0..nf).map(|j| u8::from(i == j)).collect())
        .collect();
    let c: Vec<f64> = (0..nf).map(|_| scale * rng.next()).collect();
    serde_json::json!({"baseline": {"terms": {"n_features": nf, "powers": powers},
                                    "coefficients": c}})
}

/// Unit `u`: its model JSON, axis count and temperature count. Axis `k` is generated model
/// `3u + k` (kinds cycle through every method) on a drawn first sensor, and reads up to three
/// further drawn sensors (as many as the unit has), each with its own drawn lags and parts;
/// in an even unit such an axis has generated model `3u + k + 1` as its fallback.
fn unit_model(u: usize) -> (serde_json::Value, usize, usize) {
    let mut rng = Lcg(0x1417 + u as u64);
    let pick = |rng: &mut Lcg, n: usize| ((rng.next() + 0.5) * n as f64) as usize % n;
    let n_axes = 1 + (u + pick(&mut rng, 3)) % 3;
    let n_temps = 1 + pick(&mut rng, 5);
    let gyro_cols: Vec<String> = (0..n_axes).map(|k| format!("g{k} */ x??=")).collect();
    let temp_cols: Vec<String> = (0..n_temps).map(|j| format!("t{j} */??/")).collect();
    let mut several = false;
    let axes: Vec<serde_json::Value> = (0..n_axes)
        .map(|k| {
            let mut model = generated_model(3 * u + k);
            if wide_lstm(u) && k == 0 {
                model = with_hidden(model, 32, &mut Lcg(0x3232 + u as u64));
            }
            // Draw the sensors: a shuffled list of the unit's, then how many to read.
            let mut order: Vec<usize> = (0..n_temps).collect();
            for i in (1..n_temps).rev() {
                order.swap(i, pick(&mut rng, i + 1));
            }
            let n_read = 1 + pick(&mut rng, n_temps.min(4));
            several |= n_read > 1;
            let smooth = model["features"]["smoothing_window_s"].as_f64().unwrap() > 0.0;
            let more: Vec<serde_json::Value> = order[1..n_read]
                .iter()
                .map(|_| {
                    let n_lags = pick(&mut rng, 5);
                    let lags: Vec<f64> = [40.0, 200.0, 800.0, 2500.0][..n_lags].to_vec();
                    let nf = 2 + usize::from(smooth) + n_lags;
                    let mut m = serde_json::json!({"lags_s": lags});
                    // Both parts, K's only, B's only, neither.
                    let which = pick(&mut rng, 4);
                    if which == 0 || which == 2 {
                        m["bias"] = further_part(&mut rng, nf, 1e-4);
                    }
                    if which == 0 || which == 1 {
                        m["scale"] = further_part(&mut rng, nf, 1e-3);
                    }
                    m
                })
                .collect();
            let mut axis = serde_json::json!({
                "gyro": gyro_cols[k],
                "temps": order[..n_read].iter().map(|&j| &temp_cols[j]).collect::<Vec<_>>(),
                "scores": [],
                "model": model,
                "more": more,
            });
            if n_read > 1 && u % 2 == 0 {
                axis["fallback"] = generated_model(3 * u + k + 1);
            }
            axis
        })
        .collect();
    let m = serde_json::json!({
        "imu_format_version": if several { 2 } else { 1 }, "gyro_cols": gyro_cols,
        "temp_cols": temp_cols, "axes": axes,
    });
    (m, n_axes, n_temps)
}

/// Unit `u`'s stream: rows of (t, gyro per axis, temperature per sensor). About one line in
/// eight of the first [`LINES`] has a fault of any kind; sensor `u % temps` is NaN for lines
/// 100 to 159 and reads -127 °C (a DS18B20 bus error) at lines 300 to 304; in units 2 and 3
/// of every 4 sensor `(u + 1) % temps` is NaN from line 350 on (dead for good). A long stream
/// ([`long_stream`]) goes on without faults to [`LONG_LINES`].
fn unit_stream(u: usize, axes: usize, temps: usize) -> Vec<Vec<f64>> {
    let mut rng = Lcg(0xfa17 + u as u64);
    let bad_sensor = u % temps;
    let (mut offset, mut out) = (0.0f64, Vec::new());
    let lines = if long_stream(u) { LONG_LINES } else { LINES };
    for i in 0..lines {
        let x = i as f64;
        let fault = rng.next() + 0.5 < 0.13 && i < LINES;
        let kind = ((rng.next() + 0.5) * 24.0) as usize;
        let axis = ((rng.next() + 0.5) * axes as f64) as usize % axes;
        let sensor = ((rng.next() + 0.5) * temps as f64) as usize % temps;
        let mut t = x + offset;
        let mut g: Vec<f64> = (0..axes)
            .map(|k| 0.01 * (k + 1) as f64 + 1e-3 * rng.next())
            .collect();
        let mut c: Vec<f64> = (0..temps)
            .map(|j| 15.0 + 20.0 * (x / 100.0).sin() + 2.0 * j as f64)
            .collect();
        if (100..160).contains(&i) {
            c[bad_sensor] = f64::NAN;
        }
        if (300..305).contains(&i) {
            c[bad_sensor] = -127.0;
        }
        if u % 4 >= 2 && i >= 350 {
            c[(u + 1) % temps] = f64::NAN;
        }
        if fault {
            match kind {
                0 => t = f64::NAN,
                1 => t = f64::INFINITY,
                2 => t = 1e308,
                3 => t = -1e308,
                4 => t -= 1.0,
                5 => t -= 30.0,
                6 => t += 1e9,
                7 => {
                    offset = -x; // lasting reset to 0
                    t = 0.0;
                }
                8 => {
                    offset += 1e9; // lasting jump
                    t += 1e9;
                }
                9 => offset += 90.0, // a dropout from here on
                10 => g[axis] = f64::NAN,
                11 => g[axis] = HUGE,
                12 => g[axis] = -HUGE,
                13 => g[axis] = f64::INFINITY,
                14 => c[sensor] = f64::NAN,
                15 => c[sensor] = 95.0,
                16 => c[sensor] = 85.0,
                _ => c[sensor] += 30.0 * rng.next(),
            }
        }
        let mut row = vec![t];
        row.extend(g);
        row.extend(c);
        out.push(row);
    }
    out
}

/// `compensate --stream` of the unit, in process: per line and axis (status index, rate or
/// NaN when empty, bias, scale).
/// One axis of a stream line: (status, rate, bias, scale) and (coverage, sigma_dph), the
/// coverage 0 inside, 1 edge, 2 outside, 3 none.
type StreamAxis = ((usize, f64, f64, f64), (usize, f64));

fn stream_in_process(
    model: &gyrotherm::model::unit::ImuModel,
    rows: &[Vec<f64>],
) -> Vec<Vec<StreamAxis>> {
    let mut text = String::from("time_s,");
    let names: Vec<&str> = model
        .gyro_cols
        .iter()
        .chain(&model.temp_cols)
        .map(String::as_str)
        .collect();
    text.push_str(&names.join(","));
    text.push('\n');
    for r in rows {
        let f: Vec<String> = r.iter().map(|v| format!("{v:?}")).collect();
        text.push_str(&f.join(","));
        text.push('\n');
    }
    let mut out = Vec::new();
    gyrotherm::compensate_lines::unit::compensate_imu_lines(
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
    let width = 1 + names.len();
    text.lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            let num = |s: &str| s.parse::<f64>().unwrap_or(f64::NAN);
            (0..model.gyro_cols.len())
                .map(|k| {
                    let a = width + 6 * k;
                    let status = ["ok", "held", "degraded", "invalid", "fallback"]
                        .iter()
                        .position(|s| *s == f[a + 3])
                        .unwrap();
                    // Empty coverage: no verdict (3 or 4 in the C's codes).
                    let coverage = ["inside", "edge", "outside", ""]
                        .iter()
                        .position(|s| *s == f[a + 4])
                        .unwrap();
                    (
                        (status, num(f[a + 2]), num(f[a]), num(f[a + 1])),
                        (coverage, num(f[a + 5])),
                    )
                })
                .collect()
        })
        .collect()
}

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

#[test]
fn generated_unit_c_equals_the_unit_stream() {
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
    let (mut lines, mut axis_lines, mut differ, mut statuses) = (0usize, 0, 0, [0usize; 5]);
    let mut long_lines = 0usize;
    // Units that ran at 32 hidden units (every fourth: its first model's LSTMs).
    let mut wide_units = 0usize;
    let mut verdicts = [0usize; 5];
    // Axis-lines by the number of sensors the axis reads (1 to 4).
    let mut by_sensors = [0usize; 5];
    let mut failures = Vec::new();
    let workers = std::thread::available_parallelism().map_or(2, |n| n.get().min(4));
    for batch in 0..UNITS.div_ceil(BATCH) {
        let ids: Vec<usize> = (batch * BATCH..((batch + 1) * BATCH).min(UNITS)).collect();
        let bdir = d.join(format!("batch{batch}"));
        std::fs::create_dir_all(&bdir).unwrap();
        let mut units = Vec::new();
        for &u in &ids {
            let (json, axes, temps) = unit_model(u);
            let m = gyrotherm::model::unit::ImuModel::from_json(&json.to_string())
                .unwrap_or_else(|e| panic!("generated unit {u}: {e}"));
            if m.hidden_size().unwrap().units() == 32 {
                wide_units += 1;
            }
            let mdir = bdir.join(format!("u{u}"));
            let files =
                gyrotherm::export::unit::export_imu(&m, gyrotherm::export::Lang::C, &mdir).unwrap();
            for f in files {
                let text = std::fs::read_to_string(f).unwrap();
                assert!(gyrotherm::export::is_generated_text(&text), "unit {u}");
                assert!(!text.contains("*/ x") && !text.contains("g0 "), "unit {u}");
            }
            units.push((u, m, mdir, axes, temps));
        }
        let objs: Vec<PathBuf> = std::thread::scope(|s| {
            let chunks: Vec<_> = units.chunks(units.len().div_ceil(workers)).collect();
            let handles: Vec<_> = chunks
                .into_iter()
                .map(|chunk| {
                    let here = &here;
                    s.spawn(move || {
                        chunk
                            .iter()
                            .map(|(u, _, mdir, _, _)| {
                                let obj = mdir.join("unit.o");
                                // -O0 as the single-axis differential test (compile time).
                                gcc(
                                    "-O0",
                                    &[
                                        "-c",
                                        &format!("-DGT_RUN=run_{u}"),
                                        &format!("-Dgt_init=gt_init_{u}"),
                                        &format!("-Dgt_step_imu=gt_step_imu_{u}"),
                                        &format!("-Dgt_step_imu_bk=gt_step_imu_bk_{u}"),
                                        &format!("-Dgt_coverage_of_axis=gt_coverage_of_axis_{u}"),
                                        "-I",
                                        mdir.to_str().unwrap(),
                                    ],
                                    &[&here.join("wrap_imu.c")],
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
        let mut runners = String::new();
        for &u in &ids {
            runners.push_str(&format!(
                "size_t run_{u}(size_t n, const double *in, unsigned char *status, double *out);\n"
            ));
        }
        let list: Vec<String> = ids.iter().map(|u| format!("run_{u}")).collect();
        runners.push_str(&format!(
            "static const runner RUNS[] = {{{}}};\n",
            list.join(", ")
        ));
        std::fs::write(bdir.join("batch_runners.h"), runners).unwrap();
        let exe = bdir.join("batch");
        let main = here.join("batch_imu_main.c");
        let mut files: Vec<&Path> = vec![&main];
        files.extend(objs.iter().map(PathBuf::as_path));
        gcc("-O2", &["-I", bdir.to_str().unwrap()], &files, &exe);
        let streams: Vec<Vec<Vec<f64>>> = units
            .iter()
            .map(|(u, _, _, axes, temps)| unit_stream(*u, *axes, *temps))
            .collect();
        let mut input = Vec::new();
        for ((_, _, _, axes, temps), s) in units.iter().zip(&streams) {
            for v in [s.len(), 1 + axes + temps, *axes] {
                input.extend((v as u64).to_le_bytes());
            }
            for row in s {
                for v in row {
                    input.extend(v.to_le_bytes());
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
        for ((u, m, _, axes, _), s) in units.iter().zip(&streams) {
            if long_stream(*u) {
                // Past 65,536 one-second steps after the last fault (none of the last lines
                // is faulted, so no new time base restarts the count there).
                let tail = &s[LINES..];
                assert!(tail.windows(2).all(|w| w[1][0] - w[0][0] == 1.0));
                assert!(tail.len() > 65_536, "unit {u}");
                long_lines += s.len();
            }
            let want = stream_in_process(m, s);
            assert_eq!(want.len(), s.len(), "unit {u}: one line out per line in");
            // The coverage verdicts: the core unit stepped here, each axis's map on its
            // features (C: 0 inside, 1 edge, 2 outside, 3 no verdict yet, 4 no map).
            let mut unit = gyrotherm::compensate_lines::unit::flight_unit(m).unwrap();
            // An axis on its fallback: the fallback's map on the fallback's features.
            let map_of =
                |f: &gyrotherm::model::ModelFile| f.coverage.as_ref().map(|c| c.to_core().unwrap());
            let maps: Vec<_> = m
                .axes
                .iter()
                .map(|a| (map_of(&a.model), a.fallback.as_ref().and_then(map_of)))
                .collect();
            let cover: Vec<Vec<(usize, f64)>> = s
                .iter()
                .map(|r| {
                    unit.step(r[0], &r[1..1 + axes], &r[1 + axes..]);
                    maps.iter()
                        .enumerate()
                        .map(|(k, (map, fallback_map))| {
                            let axis = unit.axis(k).unwrap();
                            let (map, features) = match axis.fallback() {
                                Some(f) if axis.on_fallback() => (fallback_map, f.features()),
                                _ => (map, axis.features()),
                            };
                            match map {
                                None => (4, f64::NAN),
                                Some(map) => match map.verdict_of(features) {
                                    Some(v) => (v.coverage as usize, v.sigma_dph),
                                    None => (3, f64::NAN),
                                },
                            }
                        })
                        .collect()
                })
                .collect();
            let st: Vec<u8> = out[at..at + s.len() * axes].to_vec();
            at += s.len() * axes;
            let vals: Vec<f64> = out[at..at + s.len() * axes * 40]
                .chunks_exact(8)
                .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
                .collect();
            at += s.len() * axes * 40;
            for (line, w) in want.iter().enumerate() {
                lines += 1;
                let mut same_line = true;
                for (k, &((ws, wr, wb, wk), (scv, ssig))) in w.iter().enumerate() {
                    let j = line * axes + k;
                    let (cs, r, b, sc) = (
                        st[j] as usize,
                        vals[5 * j],
                        vals[5 * j + 1],
                        vals[5 * j + 2],
                    );
                    let (cv, sigma) = (vals[5 * j + 3] as usize, vals[5 * j + 4]);
                    let (wc, wsig) = cover[line][k];
                    // The stream's own coverage columns: the core's verdict, or empty.
                    let stream_same = if wc < 3 {
                        scv == wc && ssig.to_bits() == wsig.to_bits()
                    } else {
                        scv == 3 && ssig.is_nan()
                    };
                    axis_lines += 1;
                    by_sensors[m.axes[k].temps.len()] += 1;
                    statuses[ws] += 1;
                    verdicts[wc] += 1;
                    let same = cs == ws
                        && b.to_bits() == wb.to_bits()
                        && sc.to_bits() == wk.to_bits()
                        && (cs == 3 || r.to_bits() == wr.to_bits())
                        && cv == wc
                        && (sigma.to_bits() == wsig.to_bits() || (sigma.is_nan() && wsig.is_nan()))
                        && stream_same;
                    if !same {
                        same_line = false;
                        if failures.len() < 5 {
                            failures.push(format!(
                                "unit {u} line {line} axis {k} {:?}: C ({cs}, {r:e}, {b:e}, \
                                 {sc:e}, {cv}, {sigma:e}) vs stream ({ws}, {wr:e}, {wb:e}, \
                                 {wk:e}, {wc}, {wsig:e})",
                                s[line]
                            ));
                        }
                    }
                }
                differ += usize::from(!same_line);
            }
        }
        assert_eq!(at, out.len(), "driver output length");
    }
    println!(
        "unit differential: {UNITS} units, {lines} lines ({axis_lines} axis-lines; \
         {long_lines} lines in the long streams) compared, \
         {differ} lines differ (axis-lines ok {}, held {}, degraded {}, invalid {}, fallback {}; coverage \
         inside {}, edge {}, outside {}, no verdict {}, no map {}; axis-lines on an axis reading \
         1, 2, 3, 4 sensors: {:?}); {:.1} s",
        statuses[0],
        statuses[1],
        statuses[2],
        statuses[3],
        statuses[4],
        verdicts[0],
        verdicts[1],
        verdicts[2],
        verdicts[3],
        verdicts[4],
        &by_sensors[1..],
        start.elapsed().as_secs_f64()
    );
    assert!(
        failures.is_empty() && differ == 0,
        "{differ} lines differ: {failures:#?}"
    );
    // Every status occurred often, so each path was compared (fallback: only axes of even
    // units whose further sensor dies for good).
    assert!(statuses.iter().all(|v| *v > 500), "statuses {statuses:?}");
    assert!(verdicts.iter().all(|v| *v > 500), "verdicts {verdicts:?}");
    // Every fourth unit ran at 32 hidden units (an axis model of kind LSTM, widened).
    assert_eq!(wide_units, UNITS / 4);
    // The three long streams were compared.
    assert_eq!(long_lines, 3 * LONG_LINES);
    // Axes reading each number of sensors were compared.
    assert!(
        by_sensors[1..].iter().all(|v| *v > 2000),
        "by sensors {by_sensors:?}"
    );
}
