//! The report over small synthetic data: every figure is written as PNG and SVG of its
//! stated size, is not blank, has text drawn (the embedded font works), and the HTML page
//! references only files that exist.

mod html_refs;
use html_refs::references;

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use gyrotherm::report::FigureFiles;
use gyrotherm::report::*;

/// A synthetic run: a sine temperature cycle, a gyro lagging it, a bias following
/// temperature and its rate, and deterministic pseudo-noise (an LCG).
struct Run {
    time_s: Vec<f64>,
    temp_c: Vec<f64>,
    chamber_c: Vec<f64>,
    rate_c_per_min: Vec<f64>,
    gyro_dph: Vec<f64>,
}

fn synthetic_run(n: usize, dt_s: f64, seed: u64) -> Run {
    let mut state = seed;
    let mut noise = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    };
    let time_s: Vec<f64> = (0..n).map(|i| i as f64 * dt_s).collect();
    let period = n as f64 * dt_s;
    let chamber_c: Vec<f64> = time_s
        .iter()
        .map(|t| 25.0 + 40.0 * (2.0 * std::f64::consts::PI * t / period).sin())
        .collect();
    // The gyro lags the chamber: first-order response, time constant 600 s.
    let mut temp_c = Vec::with_capacity(n);
    let mut g = chamber_c[0];
    for &c in &chamber_c {
        g += (c - g) * dt_s / 600.0;
        temp_c.push(g);
    }
    let rate_c_per_min: Vec<f64> = (0..n)
        .map(|i| {
            let j = i.max(1);
            (temp_c[j] - temp_c[j - 1]) / dt_s * 60.0
        })
        .collect();
    let gyro_dph = (0..n)
        .map(|i| 0.05 * (temp_c[i] - 25.0) + 2.0 * rate_c_per_min[i] + 0.5 * noise())
        .collect();
    Run {
        time_s,
        temp_c,
        chamber_c,
        rate_c_per_min,
        gyro_dph,
    }
}

/// Decode a PNG with the `image` crate.
fn decode(path: &Path) -> image::RgbImage {
    image::open(path)
        .unwrap_or_else(|e| panic!("{} does not decode: {e}", path.display()))
        .to_rgb8()
}

/// Non-blank checks on a decoded figure: size as stated, enough non-white pixels, several
/// distinct colours, and dark (text) pixels in the left margin where the rotated y-axis
/// title is drawn.
fn check_png(files: &FigureFiles) {
    let img = decode(&files.png);
    assert_eq!(
        (img.width(), img.height()),
        (files.width_px, files.height_px),
        "{}: want {}x{} got {}x{}",
        files.png.display(),
        files.width_px,
        files.height_px,
        img.width(),
        img.height()
    );
    let total = (img.width() * img.height()) as f64;
    let non_white = img.pixels().filter(|p| p.0 != [255, 255, 255]).count() as f64;
    // A drawn figure has axes, grid, text and curves: well over 1 % non-white; a blank one 0.
    const MIN_INK_FRACTION: f64 = 0.01;
    assert!(
        non_white / total > MIN_INK_FRACTION,
        "{}: only {:.4} of pixels are not white (want > {MIN_INK_FRACTION})",
        files.png.display(),
        non_white / total
    );
    let colours: HashSet<[u8; 3]> = img.pixels().map(|p| p.0).collect();
    // White, grid grey, black text and at least one curve colour (plus anti-aliasing).
    const MIN_COLOURS: usize = 4;
    assert!(
        colours.len() >= MIN_COLOURS,
        "{}: {} distinct colours (want >= {MIN_COLOURS})",
        files.png.display(),
        colours.len()
    );
    check_legends(files, &img);
    check_lines_inside(files, &img);
    // The y-axis title is drawn rotated in the leftmost ~40 px, where nothing else is drawn:
    // dark pixels there are glyphs, so text renders.
    let dark_in_margin = (0..40)
        .flat_map(|x| (0..img.height()).map(move |y| (x, y)))
        .filter(|&(x, y)| img.get_pixel(x, y).0.iter().all(|&c| c < 100))
        .count();
    const MIN_TEXT_PIXELS: usize = 30;
    assert!(
        dark_in_margin >= MIN_TEXT_PIXELS,
        "{}: {dark_in_margin} dark pixels in the y-label margin (want >= {MIN_TEXT_PIXELS}): \
         is the font rendering?",
        files.png.display()
    );
}

/// Legends hide no data: each legend box lies inside the image and overlaps no panel's
/// plotting area, and the box is drawn where the layout says (its top edge is the legend
/// border colour, a colour no series or grid line uses).
fn check_legends(files: &FigureFiles, img: &image::RgbImage) {
    let name = files.png.display();
    let (w, h) = (img.width() as i32, img.height() as i32);
    assert!(!files.layout.is_empty(), "{name}: no panel layout");
    for (k, panel) in files.layout.iter().enumerate() {
        let p = panel.plot;
        assert!(
            p.x0 >= 0 && p.y0 >= 0 && p.x1 <= w && p.y1 <= h && p.x0 < p.x1 && p.y0 < p.y1,
            "{name}: panel {k} plotting area {p:?} outside the {w}x{h} image"
        );
        let Some(l) = panel.legend else { continue };
        assert!(
            l.x0 >= 0 && l.y0 >= 0 && l.x1 <= w && l.y1 <= h,
            "{name}: panel {k} legend {l:?} outside the {w}x{h} image"
        );
        for (j, other) in files.layout.iter().enumerate() {
            assert!(
                !l.overlaps(&other.plot),
                "{name}: legend of panel {k} {l:?} covers the plotting area of panel {j} {:?}",
                other.plot
            );
        }
        let border = [
            LEGEND_BORDER_RGB.0,
            LEGEND_BORDER_RGB.1,
            LEGEND_BORDER_RGB.2,
        ];
        let top = (l.x0..l.x1 - 1)
            .filter(|&x| img.get_pixel(x as u32, l.y0 as u32).0 == border)
            .count() as i32;
        // The text stays inside its box: the right edge is whole (text drawn past the box
        // would cover it).
        let right = (l.y0..l.y1)
            .filter(|&y| img.get_pixel((l.x1 - 1) as u32, y as u32).0 == border)
            .count() as i32;
        assert_eq!(
            right,
            l.y1 - l.y0,
            "{name}: legend of panel {k}: the right edge of {l:?} is crossed"
        );
        assert!(
            top * 10 >= (l.x1 - l.x0 - 1) * 9,
            "{name}: legend of panel {k}: {top} of {} pixels of its top edge {l:?} are the \
             border colour; it is not drawn where the layout says",
            l.x1 - l.x0 - 1
        );
    }
}

/// The series colours of the figures (the plot palette, Okabe & Ito 2008, darkened), which no
/// axis, grid or text uses.
const SERIES_RGB: [[u8; 3]; 7] = [
    [0, 90, 170],
    [213, 94, 0],
    [0, 140, 100],
    [150, 80, 150],
    [200, 150, 0],
    [86, 160, 220],
    [180, 40, 40],
];

/// Lines stay inside their plotting area: no pixel of a series colour outside every panel's
/// plotting area and legend box (a line crossing the frame, or a stroke spiking out of it).
fn check_lines_inside(files: &FigureFiles, img: &image::RgbImage) {
    let inside = |x: i32, y: i32| {
        files
            .layout
            .iter()
            .any(|p| p.plot.contains(x, y) || p.legend.is_some_and(|l| l.contains(x, y)))
    };
    let outside: Vec<(u32, u32)> = img
        .enumerate_pixels()
        .filter(|(x, y, px)| SERIES_RGB.contains(&px.0) && !inside(*x as i32, *y as i32))
        .map(|(x, y, _)| (x, y))
        .take(5)
        .collect();
    assert!(
        outside.is_empty(),
        "{}: series pixels outside the plotting area, e.g. {outside:?} (plot areas {:?})",
        files.png.display(),
        files.layout.iter().map(|p| p.plot).collect::<Vec<_>>()
    );
}

/// SVG: starts with `<svg`, has the stated size, contains each given text, is closed.
fn check_svg(files: &FigureFiles, texts: &[&str]) {
    let svg = std::fs::read_to_string(&files.svg)
        .unwrap_or_else(|e| panic!("{}: {e}", files.svg.display()));
    assert!(
        svg.trim_start().starts_with("<svg"),
        "{}: does not start with <svg",
        files.svg.display()
    );
    assert!(svg.contains(&format!("width=\"{}\"", files.width_px)));
    assert!(svg.contains(&format!("height=\"{}\"", files.height_px)));
    for t in texts {
        // These labels contain no XML markup characters, so they appear verbatim.
        assert!(
            svg.contains(t),
            "{}: text {t:?} missing",
            files.svg.display()
        );
    }
    assert!(
        svg.trim_end().ends_with("</svg>"),
        "{}: not closed",
        files.svg.display()
    );
}

/// A synthetic Allan curve: white rate noise σ/√τ plus a rate-random-walk rise, ±10 % bars.
fn synthetic_allan(label: &str, sigma_1s: f64) -> AllanCurve {
    let points = (0..12)
        .map(|k| {
            let tau_s = 2f64.powi(k);
            let dev = sigma_1s / tau_s.sqrt() + 0.002 * tau_s.sqrt();
            AllanPointPlot {
                tau_s,
                dev,
                lo: dev * 0.9,
                hi: dev * 1.1,
            }
        })
        .collect();
    AllanCurve {
        label: label.to_owned(),
        points,
    }
}

type Written = Vec<(FigureFiles, Vec<&'static str>)>;

fn write_all_figures(dir: &Path, train: &Run, test: &Run) -> Written {
    let mut out = Vec::new();
    let f = temperature_figure(
        &dir.join("fig1_temperature"),
        &TemperatureData {
            time_s: &test.time_s,
            gyro_temp_c: &test.temp_c,
            chamber_temp_c: Some(&test.chamber_c),
            temp_rate_c_per_min: &test.rate_c_per_min,
        },
    )
    .unwrap();
    out.push((
        f,
        vec!["temperature (°C)", "temperature rate (°C/min)", "time (s)"],
    ));

    let f = raw_output_figure(
        &dir.join("fig2_raw.png"),
        &RawOutputData {
            time_s: &test.time_s,
            gyro_dph: &test.gyro_dph,
            window_s: 100.0,
        },
    )
    .unwrap();
    out.push((f, vec!["gyro output (°/h)", "100 s moving average"]));

    let loss_bias: Vec<f64> = (0..60).map(|e| 1.0 / (1.0 + e as f64) + 0.01).collect();
    let loss_sf: Vec<f64> = (0..60)
        .map(|e| 0.5 * (-0.05 * e as f64).exp() + 0.02)
        .collect();
    let f = loss_figure(
        &dir.join("fig3_loss"),
        &[
            LossCurve {
                label: "bias network",
                loss: &loss_bias,
            },
            LossCurve {
                label: "scale-factor network",
                loss: &loss_sf,
            },
        ],
    )
    .unwrap();
    out.push((f, vec!["epoch", "bias network"]));

    // "Prediction": the noise-free law of the synthetic run.
    let predicted: Vec<f64> = (0..test.time_s.len())
        .map(|i| 0.05 * (test.temp_c[i] - 25.0) + 2.0 * test.rate_c_per_min[i])
        .collect();
    let f = bias_figure(
        &dir.join("fig4_bias"),
        &BiasData {
            time_s: &test.time_s,
            measured_dph: &test.gyro_dph,
            predicted: &[NamedSeries {
                label: "law",
                values_dph: &predicted,
            }],
        },
    )
    .unwrap();
    out.push((f, vec!["bias (°/h)", "residual (°/h)"]));

    let seg_t: Vec<f64> = (0..12).map(|k| 300.0 + 600.0 * k as f64).collect();
    let sf_meas: Vec<f64> = seg_t.iter().map(|t| 50.0 * (t / 2000.0).sin()).collect();
    let sf_pred: Vec<f64> = seg_t
        .iter()
        .map(|t| 48.0 * (t / 2000.0).sin() + 2.0)
        .collect();
    let f = scale_factor_figure(
        &dir.join("fig5_scale_factor"),
        &ScaleFactorData {
            time_s: &seg_t,
            measured_ppm: &sf_meas,
            predicted_ppm: &sf_pred,
        },
    )
    .unwrap();
    out.push((f, vec!["scale-factor deviation (ppm)"]));

    let after: Vec<f64> = test
        .gyro_dph
        .iter()
        .zip(&predicted)
        .map(|(a, b)| a - b)
        .collect();
    let neg: Vec<f64> = test.gyro_dph.iter().map(|v| -v).collect();
    let neg_after: Vec<f64> = after.iter().map(|v| -v).collect();
    let f = rate_table_figure(
        &dir.join("fig6_rate_table"),
        &RateTableData {
            axis: RateAxis::TempC,
            segments: &[
                RateSegment {
                    rate_dps: 20.0,
                    x: &test.temp_c,
                    before_dph: &test.gyro_dph,
                    after_dph: &after,
                },
                RateSegment {
                    rate_dps: -20.0,
                    x: &test.temp_c,
                    before_dph: &neg,
                    after_dph: &neg_after,
                },
            ],
        },
    )
    .unwrap();
    out.push((f, vec!["gyro temperature (°C)", "after compensation"]));

    let linear: Vec<f64> = test
        .gyro_dph
        .iter()
        .zip(&test.temp_c)
        .map(|(g, t)| g - 0.05 * (t - 25.0))
        .collect();
    let f = compensation_figure(
        &dir.join("fig7_compensation"),
        &CompensationData {
            time_s: &test.time_s,
            series: &[
                NamedSeries {
                    label: "raw",
                    values_dph: &test.gyro_dph,
                },
                NamedSeries {
                    label: "linear",
                    values_dph: &linear,
                },
                NamedSeries {
                    label: "LSTM",
                    values_dph: &after,
                },
                // A label ending in a full stop, at the end of the legend's row.
                NamedSeries {
                    label: "LSTM, He et al.",
                    values_dph: &after,
                },
            ],
            window_s: 100.0,
        },
    )
    .unwrap();
    out.push((f, vec!["100 s means", "LSTM"]));

    let f = allan_figure(
        &dir.join("fig8_allan.png"),
        &[
            synthetic_allan("raw", 0.5),
            synthetic_allan("compensated", 0.2),
        ],
        &[
            NoiseLine {
                label: "ARW".to_owned(),
                term: NoiseTerm::AngleRandomWalk { n: 0.2 },
            },
            NoiseLine {
                label: "bias instability".to_owned(),
                term: NoiseTerm::BiasInstability { b: 0.03 },
            },
            NoiseLine {
                label: "RRW".to_owned(),
                term: NoiseTerm::RateRandomWalk { k: 0.0035 },
            },
        ],
        "°/h",
    )
    .unwrap();
    out.push((f, vec!["Allan deviation", "(°/h)", "bias instability"]));

    // The second data set through the generic writer, at another size.
    let f = write_figure(
        &dir.join("extra_train_temperature"),
        &Figure {
            title: "Training run".into(),
            x_label: "time (s)".into(),
            log_x: false,
            width_px: 800,
            height_px: 500,
            panels: vec![Panel {
                y_label: "temperature (°C)".into(),
                log_y: false,
                series: vec![Series::line("gyro", &train.time_s, &train.temp_c)],
            }],
        },
    )
    .unwrap();
    out.push((f, vec!["Training run"]));
    out
}

#[test]
fn report_over_two_synthetic_runs() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("report");
    std::fs::create_dir_all(&out).unwrap();
    let train = synthetic_run(20_000, 1.0, 1);
    let test = synthetic_run(12_000, 1.0, 2);
    let figures = write_all_figures(&out, &train, &test);
    assert_eq!(figures.len(), 9);
    for (files, texts) in &figures {
        assert!(files.png.is_file(), "{} missing", files.png.display());
        assert!(files.svg.is_file(), "{} missing", files.svg.display());
        check_png(files);
        check_svg(files, texts);
    }
    // Both panels of the temperature figure have a legend (so the legend checks above are
    // not vacuous).
    assert_eq!(figures[0].0.layout.len(), 2);
    assert!(figures[0].0.layout.iter().all(|p| p.legend.is_some()));
    // Stated sizes (figure.rs: 1000 wide, 600 high for one panel, 800 for two).
    let size = |k: usize| (figures[k].0.width_px, figures[k].0.height_px);
    assert_eq!(size(0), (1000, 800));
    assert_eq!(size(1), (1000, 600));
    assert_eq!(size(8), (800, 500));

    let content = ReportContent {
        title: "gyrotherm report <test> & check".into(),
        headline: vec!["every model is worse than <raw>".into()],
        table_notes: vec!["poly: not fitted: <singular>".into()],
        table: Some(Table {
            headers: vec![
                "method".into(),
                "bias stability (°/h)".into(),
                "scale-factor error (ppm)".into(),
            ],
            rows: vec![
                vec!["raw".into(), "0.512".into(), "48.0".into()],
                vec!["LSTM".into(), "0.071".into()],
            ],
        }),
        metadata: vec![("hidden units".into(), "16".into())],
        models: Some(Table {
            headers: vec!["field".into(), "a <model>".into(), "b".into()],
            rows: vec![vec!["inputs".into(), "T".into(), "—".into()]],
        }),
        warnings: vec!["temperature 70 °C is outside the training range <-40, 60>".into()],
        figures: figures
            .iter()
            .map(|(f, _)| ReportFigure::from_files(f, "caption for <figure>"))
            .collect(),
        notes: vec!["figure 9 not drawn: <no data>".into()],
    };
    let index = write_report(&out, &content).unwrap();
    let html = std::fs::read_to_string(&index).unwrap();
    assert!(html.starts_with("<!DOCTYPE html>"));
    assert!(
        html.contains("gyrotherm report &lt;test&gt; &amp; check"),
        "title not escaped"
    );
    assert!(!html.contains("<test>"), "raw markup leaked into the page");
    assert!(html.contains("&lt;-40, 60&gt;"), "warning not escaped");
    assert!(html.contains("&lt;no data&gt;"), "note not shown escaped");
    // The headline comes first, above the comparison; a column's note right under it.
    let headline = html
        .find("<p class=\"headline\">every model is worse than &lt;raw&gt;</p>")
        .expect("headline shown escaped");
    let table = html.find("<table class=\"comparison\">").unwrap();
    let note = html
        .find("<li>poly: not fitted: &lt;singular&gt;</li>")
        .expect("table note shown escaped");
    assert!(headline < table && table < note);
    // A table wider than the page (many model columns at 1400 px) scrolls in its own box
    // instead of running past the page's edge.
    assert!(html.contains("div.table-wrap{max-width:100%;overflow-x:auto}"));
    assert_eq!(
        html.matches("<div class=\"table-wrap\">\n<table").count(),
        html.matches("<table").count(),
        "every table sits in a scrolling box"
    );
    assert!(!html.contains("<script"), "page must hold no script");
    assert!(
        !html.contains("http://") && !html.contains("https://"),
        "no network link"
    );
    let refs = references(&html);
    assert_eq!(
        refs.len(),
        2 * figures.len(),
        "want a PNG and an SVG link per figure: {refs:?}"
    );
    for r in &refs {
        let p: PathBuf = out.join(r);
        assert!(
            p.is_file(),
            "index.html references {r}, which does not exist"
        );
    }
    // The model table: a column per model, escaped.
    assert!(html.contains(
        "<table class=\"models\">\n<thead><tr><th>field</th><th>a &lt;model&gt;</th><th>b</th></tr>"
    ));
    // A short row is padded to the header width.
    assert!(html.contains("<td>LSTM</td><td>0.071</td><td></td>"));
    // Only the figures and the page were written: no temporary files left behind.
    let names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(
        names.iter().all(|n| !n.starts_with('.')),
        "temp files left: {names:?}"
    );
    assert_eq!(names.len(), 2 * figures.len() + 1);
    if let Ok(keep) = std::env::var("GYROTHERM_KEEP_REPORT") {
        // Manual inspection: copy the report out of the temp dir.
        let keep = Path::new(&keep);
        std::fs::create_dir_all(keep).unwrap();
        for n in &names {
            std::fs::copy(out.join(n), keep.join(n)).unwrap();
        }
    }
}

#[test]
fn report_creates_missing_dir_and_rejects_missing_figure() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("a/b");
    let content = ReportContent {
        title: "empty".into(),
        ..Default::default()
    };
    let index = write_report(&out, &content).unwrap();
    assert!(index.is_file());
    let content = ReportContent {
        title: "broken".into(),
        figures: vec![ReportFigure {
            png: "nope.png".into(),
            svg: None,
            caption: String::new(),
            number: None,
        }],
        ..Default::default()
    };
    let err = write_report(&out, &content).unwrap_err().to_string();
    assert!(
        err.contains("nope.png"),
        "error should name the file: {err}"
    );
    let content = ReportContent {
        figures: vec![ReportFigure {
            png: "../escape.png".into(),
            svg: None,
            caption: String::new(),
            number: None,
        }],
        ..Default::default()
    };
    assert!(
        write_report(&out, &content).is_err(),
        "paths outside DIR refused"
    );
}

#[test]
fn single_path_for_allan_plot() {
    // `gyrotherm allan --plot FILE.png` passes FILE.png; both files land beside it.
    let dir = tempfile::tempdir().unwrap();
    let files = allan_figure(
        &dir.path().join("adev.png"),
        &[synthetic_allan("rate", 0.3)],
        &[],
        "°/h",
    )
    .unwrap();
    assert_eq!(files.png, dir.path().join("adev.png"));
    assert_eq!(files.svg, dir.path().join("adev.svg"));
    check_png(&files);
}

#[test]
fn bad_data_is_an_error_naming_the_series() {
    let dir = tempfile::tempdir().unwrap();
    let err = bias_figure(
        &dir.path().join("b"),
        &BiasData {
            time_s: &[0.0, 1.0, 2.0],
            measured_dph: &[1.0, 2.0],
            predicted: &[NamedSeries {
                label: "m",
                values_dph: &[1.0, 2.0, 3.0],
            }],
        },
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("measured_dph"), "{err}");
    let err = raw_output_figure(
        &dir.path().join("r"),
        &RawOutputData {
            time_s: &[0.0],
            gyro_dph: &[0.0],
            window_s: 0.0,
        },
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("window"), "{err}");
    // Nothing was written for the failed figures.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn font_registration_is_thread_safe() {
    // Several threads drawing at once all register through the same OnceLock.
    let dir = tempfile::tempdir().unwrap();
    std::thread::scope(|s| {
        for k in 0..4 {
            let path = dir.path().join(format!("t{k}"));
            s.spawn(move || {
                let files = allan_figure(&path, &[synthetic_allan("x", 0.1)], &[], "°/h").unwrap();
                check_png(&files);
            });
        }
    });
}

#[test]
fn degenerate_data_draws_without_panic() {
    // Empty, constant, non-finite and extreme data: each figure is still written (empty
    // axes or a flat line), never a panic.
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, Vec<f64>, Vec<f64>); 6] = [
        ("empty", vec![], vec![]),
        ("one", vec![1.0], vec![2.0]),
        ("constant", vec![0.0, 1.0, 2.0], vec![5.0; 3]),
        ("nan", vec![0.0, 1.0, 2.0], vec![f64::NAN; 3]),
        (
            "mixed",
            vec![0.0, f64::INFINITY, 2.0, 3.0],
            vec![1.0, 2.0, f64::NEG_INFINITY, -4.0],
        ),
        ("huge", vec![0.0, 1.0, 2.0], vec![-1e300, 0.0, 1e300]),
    ];
    for (name, t, y) in &cases {
        let files = raw_output_figure(
            &dir.path().join(format!("raw_{name}")),
            &RawOutputData {
                time_s: t,
                gyro_dph: y,
                window_s: 100.0,
            },
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        let img = decode(&files.png);
        assert_eq!((img.width(), img.height()), (1000, 600), "{name}");
        let loss = loss_figure(
            &dir.path().join(format!("loss_{name}")),
            &[LossCurve {
                label: "loss",
                loss: y,
            }],
        );
        assert!(loss.is_ok(), "{name}: {loss:?}");
        let allan = allan_figure(
            &dir.path().join(format!("allan_{name}")),
            &[AllanCurve {
                label: name.to_string(),
                points: t
                    .iter()
                    .zip(y)
                    .map(|(&tau_s, &dev)| AllanPointPlot {
                        tau_s,
                        dev,
                        lo: dev,
                        hi: dev,
                    })
                    .collect(),
            }],
            &[NoiseLine {
                label: "ARW".into(),
                term: NoiseTerm::AngleRandomWalk { n: 1.0 },
            }],
            "°/h",
        );
        assert!(allan.is_ok(), "{name}: {allan:?}");
    }
}

#[test]
fn non_finite_values_break_lines() {
    // y = 0 on x in [0, 10], a NaN, then y = 1 on x in [20, 30]: joined, the line would run
    // through (15, 0.5), the middle of the plot; broken, no pixel of the line's colour lies in
    // the columns around x = 15.
    let mut x: Vec<f64> = (0..=10).map(f64::from).collect();
    let mut y = vec![0.0; x.len()];
    x.push(f64::NAN);
    y.push(f64::NAN);
    x.extend((20..=30).map(f64::from));
    y.extend([1.0; 11]);
    const RED: (u8, u8, u8) = (255, 0, 0);
    let fig = Figure {
        title: "gap".into(),
        x_label: "x (s)".into(),
        log_x: false,
        width_px: 1000,
        height_px: 600,
        panels: vec![Panel {
            y_label: "y (°/h)".into(),
            log_y: false,
            // No label: no legend box in the plot.
            series: vec![Series::line("", &x, &y).with_color(RED)],
        }],
    };
    let dir = tempfile::tempdir().unwrap();
    let files = write_figure(&dir.path().join("gap"), &fig).unwrap();
    let img = decode(&files.png);
    let red_columns: Vec<u32> = (0..img.width())
        .filter(|&c| (0..img.height()).any(|r| img.get_pixel(c, r).0 == [255, 0, 0]))
        .collect();
    assert!(!red_columns.is_empty(), "the two runs are drawn");
    // x in [0, 30] spans the plot area (≈ columns 80..990): x = 13.5..16.5 lies well inside
    // columns 480..600 only if the gap is drawn; the runs end at x = 10 and start at x = 20.
    let in_gap: Vec<u32> = red_columns
        .iter()
        .copied()
        .filter(|c| (500..580).contains(c))
        .collect();
    assert!(
        in_gap.is_empty(),
        "line drawn across the gap at columns {in_gap:?}"
    );
}

#[test]
fn legend_hides_no_data_in_the_corner() {
    // A line rising to the top right corner of its plot, where a legend inside the plot
    // (upper right) would sit: the line's own colour must show there, and the legend must
    // lie below the plotting area.
    let dir = tempfile::tempdir().unwrap();
    let x: Vec<f64> = (0..=100).map(f64::from).collect();
    let y: Vec<f64> = x.iter().map(|v| v * v).collect();
    let rgb = (213, 94, 0);
    let fig = Figure {
        title: "corner".into(),
        x_label: "x (s)".into(),
        log_x: false,
        width_px: FIGURE_WIDTH_PX,
        height_px: FIGURE_HEIGHT_PX,
        panels: vec![Panel {
            y_label: "y (°C)".into(),
            log_y: false,
            series: vec![
                Series::line("a long legend label for the rising series", &x, &y).with_color(rgb),
                Series::line("second label", &x, &x),
            ],
        }],
    };
    let files = write_figure(&dir.path().join("corner"), &fig).unwrap();
    assert_eq!(
        figure_layout(&fig).unwrap(),
        files.layout,
        "layout without drawing"
    );
    let img = decode(&files.png);
    check_legends(&files, &img);
    let panel = files.layout[0];
    let (p, l) = (
        panel.plot,
        panel.legend.expect("labelled series have a legend"),
    );
    assert!(
        l.y0 >= p.y1,
        "legend {l:?} not below the plotting area {p:?}"
    );
    // The top right fifth of the plotting area (where the line ends).
    let corner = PixelRect {
        x0: p.x1 - (p.x1 - p.x0) / 5,
        y0: p.y0,
        x1: p.x1,
        y1: p.y0 + (p.y1 - p.y0) / 5,
    };
    let line_pixels = (corner.x0..corner.x1)
        .flat_map(|x| (corner.y0..corner.y1).map(move |y| (x, y)))
        .filter(|&(x, y)| img.get_pixel(x as u32, y as u32).0 == [rgb.0, rgb.1, rgb.2])
        .count();
    // The line crosses the corner's height (≈ 100 px) at a slope under 2: 2 px wide, well
    // over 50 pixels of its colour.
    const MIN_LINE_PIXELS: usize = 50;
    assert!(
        line_pixels >= MIN_LINE_PIXELS,
        "{line_pixels} pixels of the series colour in the top right corner {corner:?} (want \
         >= {MIN_LINE_PIXELS}): something covers the data there"
    );
}
