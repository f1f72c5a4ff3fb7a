//! `gyrotherm report` and `gyrotherm allan --plot` run as a user would, on small simulated
//! logs written as CSV.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use gyrotherm::csvlog::write_log;
use gyrotherm::sim::{simulate, Profile, Segment, SimConfig};

mod cli;
use cli::outcome as gyrotherm;

/// A 3900 s temperature cycle (22 → -10 → +50 → 22 °C, about 3 °C/min), 1 Hz.
fn write_sim(dir: &Path, name: &str, seed: u64, table: bool) -> PathBuf {
    let rows = [
        (300.0, 22.0),
        (600.0, -10.0),
        (600.0, -10.0),
        (1200.0, 50.0),
        (600.0, 50.0),
        (600.0, 22.0),
    ];
    let mut cfg = SimConfig::new(Profile {
        name: "short".into(),
        start_c: 22.0,
        segments: rows
            .iter()
            .map(|&(duration_s, target_c)| Segment {
                duration_s,
                target_c,
            })
            .collect(),
    });
    cfg.seed = seed;
    cfg.truth = true;
    if table {
        cfg.table_rate_dps = Some(20.0);
    }
    let path = dir.join(name);
    write_log(&path, &simulate(&cfg).unwrap()).unwrap();
    path
}

/// Decodes, has the size, and is not blank (over 1 % non-white pixels, at least 5 colours:
/// white, grid, text and two curves).
fn check_png(path: &Path, want: (u32, u32)) {
    let img = image::open(path)
        .unwrap_or_else(|e| panic!("{} does not decode: {e}", path.display()))
        .to_rgb8();
    assert_eq!((img.width(), img.height()), want, "{}", path.display());
    let non_white = img.pixels().filter(|p| p.0 != [255, 255, 255]).count() as f64;
    let fraction = non_white / (img.width() * img.height()) as f64;
    assert!(fraction > 0.01, "{}: ink {fraction:.4}", path.display());
    let colours: HashSet<[u8; 3]> = img.pixels().map(|p| p.0).collect();
    assert!(
        colours.len() >= 5,
        "{}: {} colours",
        path.display(),
        colours.len()
    );
}

/// The one HTML link parser of the report tests (the library's `tests/html_refs`).
#[path = "../../gyrotherm/tests/html_refs/mod.rs"]
mod html_refs;
use html_refs::references;

#[test]
fn report_writes_the_page_and_every_figure() {
    let dir = tempfile::tempdir().unwrap();
    let train_s = write_sim(dir.path(), "train_static.csv", 1, false);
    let train_t = write_sim(dir.path(), "train_table.csv", 2, true);
    let test_s = write_sim(dir.path(), "test_static.csv", 3, false);
    let test_t = write_sim(dir.path(), "test_table.csv", 4, true);
    let out = dir.path().join("out/report");
    let s = |p: &Path| p.to_str().unwrap().to_owned();
    let (code, stdout, stderr) = gyrotherm(&[
        "report",
        "--train",
        &s(&train_s),
        "--train",
        &s(&train_t),
        "--test",
        &s(&test_s),
        "--test",
        &s(&test_t),
        "--out",
        &s(&out),
        // A method with an LSTM: its training-loss figure is one of the eight.
        "--methods",
        "linear,poly,residual,published",
        "--epochs",
        "3",
    ]);
    assert_eq!(code, 0, "stdout: {stdout}\nstderr: {stderr}");
    let index = out.join("index.html");
    assert!(
        stdout.contains(&format!("report: {}", index.display())),
        "{stdout}"
    );
    // The table of `gyrotherm compare` is printed too.
    assert!(
        stdout.contains("held-out log") && stdout.contains("bias stability"),
        "{stdout}"
    );
    let html = std::fs::read_to_string(&index).unwrap();
    let refs = references(&html);
    // Ten figures (the coverage map and σ over time included), a PNG and an SVG each, all
    // present.
    assert_eq!(refs.len(), 20, "{refs:?}");
    for r in &refs {
        let p = out.join(r);
        assert!(p.is_file(), "index.html references missing {r}");
        if r.ends_with(".png") {
            let img = image::open(&p).unwrap();
            // Sizes stated in gyrotherm::report::figures: 1000 wide, 600 or 800 high.
            let h = img.height();
            assert!(h == 600 || h == 800, "{r}: height {h}");
            check_png(&p, (1000, h));
        }
    }
    assert!(html.contains("train_static.csv") && html.contains("test_table.csv"));
}

#[test]
fn allan_plot_writes_png_and_svg_with_noise_lines() {
    let dir = tempfile::tempdir().unwrap();
    let log = write_sim(dir.path(), "static.csv", 5, false);
    let png = dir.path().join("adev.png");
    let (code, stdout, stderr) = gyrotherm(&[
        "allan",
        "--input",
        log.to_str().unwrap(),
        "--plot",
        png.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    // The table still goes to stdout; the plot is announced on stderr.
    assert!(stdout.contains("OADEV of gyro_dps"), "{stdout}");
    assert!(
        stderr.contains("adev.png") && stderr.contains("adev.svg"),
        "{stderr}"
    );
    // allan_figure is 1000 × 600 px (gyrotherm::report::figures).
    check_png(&png, (1000, 600));
    let svg = std::fs::read_to_string(dir.path().join("adev.svg")).unwrap();
    // The white-noise region of a 1 Hz FOG log gives an angle random walk line, labelled
    // in °/√h, and the axis is in °/h (gyro_dps converted).
    assert!(svg.contains("ARW N ="), "no ARW line in the legend");
    assert!(svg.contains("σ(τ) (°/h)"), "σ axis not in °/h");

    // A non-rate column is drawn in its own unit, without noise lines.
    let png_t = dir.path().join("temp");
    let (code, _, stderr) = gyrotherm(&[
        "allan",
        "--input",
        log.to_str().unwrap(),
        "--column",
        "temp_c",
        "--plot",
        png_t.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let svg = std::fs::read_to_string(dir.path().join("temp.svg")).unwrap();
    assert!(
        svg.contains("σ(τ) (°C)") && !svg.contains("ARW"),
        "temp_c plot"
    );
    check_png(&dir.path().join("temp.png"), (1000, 600));
}

#[test]
fn report_errors_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.csv");
    let train = write_sim(dir.path(), "train.csv", 6, false);
    let (code, _, stderr) = gyrotherm(&[
        "report",
        "--train",
        train.to_str().unwrap(),
        "--test",
        missing.to_str().unwrap(),
        "--out",
        dir.path().join("r").to_str().unwrap(),
    ]);
    assert_eq!(code, 2);
    assert!(stderr.contains("missing.csv"), "{stderr}");
    assert!(!dir.path().join("r/index.html").exists());
}
