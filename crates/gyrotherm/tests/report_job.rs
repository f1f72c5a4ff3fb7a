//! The full report (`report::write_full_report`) over small simulated logs: every figure of
//! the report is written, decodes as a PNG of its stated size and is not blank; the page
//! references only files that exist, carries the comparison numbers, and notes the figures
//! that cannot apply.

mod html_refs;
use html_refs::references;

use std::collections::HashSet;
use std::path::Path;

use gyrotherm::compare::{compare, Candidate, CompareConfig, Comparison};
use gyrotherm::csvlog::TestLog;
use gyrotherm::fit::NamedLog;
use gyrotherm::report::write_full_report;
use gyrotherm::report::FIGURE_STEMS;
use gyrotherm::sim::{simulate, Profile, Segment, SimConfig};

/// A 3900 s cycle: 22 °C, down to -10 °C at 3.2 °C/min, soak, up to +50 °C at 3 °C/min,
/// soak, back to 22 °C. Short enough for the test suite, long enough for 100 s averages,
/// rate-table segments of 300 s and an Allan curve to τ ≈ 1000 s.
fn short_profile() -> Profile {
    let rows = [
        (300.0, 22.0),
        (600.0, -10.0),
        (600.0, -10.0),
        (1200.0, 50.0),
        (600.0, 50.0),
        (600.0, 22.0),
    ];
    Profile {
        name: "short".into(),
        start_c: 22.0,
        segments: rows
            .iter()
            .map(|&(duration_s, target_c)| Segment {
                duration_s,
                target_c,
            })
            .collect(),
    }
}

fn sim(seed: u64, table: bool) -> TestLog {
    sim_profile(short_profile(), seed, table)
}

/// A cycle hotter, colder and faster than [`short_profile`]: a model trained on the short
/// one extrapolates in temperature and in temperature rate.
fn wide_profile() -> Profile {
    let rows = [
        (300.0, 22.0),
        (400.0, -30.0),
        (600.0, -30.0),
        (600.0, 70.0),
        (600.0, 70.0),
        (600.0, 22.0),
    ];
    Profile {
        name: "wide".into(),
        start_c: 22.0,
        segments: rows
            .iter()
            .map(|&(duration_s, target_c)| Segment {
                duration_s,
                target_c,
            })
            .collect(),
    }
}

fn sim_profile(profile: Profile, seed: u64, table: bool) -> TestLog {
    let mut cfg = SimConfig::new(profile);
    cfg.seed = seed;
    cfg.truth = true;
    if table {
        cfg.table_rate_dps = Some(20.0);
    }
    simulate(&cfg).expect("simulate")
}

/// Figure sizes stated in `report::figures` (1000 wide; 600 high for one panel, 800 for two;
/// figure 6 is 400 per panel, two panels for ±20 °/s).
const STATED_SIZE: [(u32, u32); 10] = [
    (1000, 800),
    (1000, 600),
    (1000, 600),
    (1000, 800),
    (1000, 600),
    (1000, 800),
    (1000, 600),
    (1000, 600),
    (1000, 600),
    (1000, 800),
];

fn check_png(path: &Path, want: (u32, u32)) {
    let img = image::open(path)
        .unwrap_or_else(|e| panic!("{} does not decode: {e}", path.display()))
        .to_rgb8();
    assert_eq!(
        (img.width(), img.height()),
        want,
        "{}: want {want:?} got {}x{}",
        path.display(),
        img.width(),
        img.height()
    );
    let total = (img.width() * img.height()) as f64;
    let non_white = img.pixels().filter(|p| p.0 != [255, 255, 255]).count() as f64;
    // Axes, grid, text and curves are well over 1 % of the pixels; a blank figure has 0.
    const MIN_INK_FRACTION: f64 = 0.01;
    assert!(
        non_white / total > MIN_INK_FRACTION,
        "{}: only {:.4} of pixels are not white (want > {MIN_INK_FRACTION})",
        path.display(),
        non_white / total
    );
    // White, grid grey, black text and at least two curve colours.
    let colours: HashSet<[u8; 3]> = img.pixels().map(|p| p.0).collect();
    const MIN_COLOURS: usize = 5;
    assert!(
        colours.len() >= MIN_COLOURS,
        "{}: {} distinct colours (want >= {MIN_COLOURS})",
        path.display(),
        colours.len()
    );
}

fn named<'a>(logs: &'a [(String, TestLog)]) -> Vec<NamedLog<'a>> {
    logs.iter()
        .map(|(n, l)| NamedLog { name: n, log: l })
        .collect()
}

fn run_compare(train: &[NamedLog], test: &[NamedLog], cfg: &CompareConfig) -> Comparison {
    compare(train, test, cfg, &|_, _, _, _| {}).expect("comparison")
}

#[test]
fn full_report_over_simulated_logs_draws_every_figure() {
    let train = vec![
        ("train_static.csv".to_owned(), sim(1, false)),
        ("train_table.csv".to_owned(), sim(2, true)),
    ];
    let test = vec![
        ("test_static.csv".to_owned(), sim(3, false)),
        ("test_table.csv".to_owned(), sim(4, true)),
    ];
    let (train_n, test_n) = (named(&train), named(&test));
    let mut cfg = CompareConfig::default();
    // A recipe with an LSTM (the training-loss figure needs one; the default `thermal` has
    // none), and a few epochs: the figures, not the fit quality, are under test.
    let mut residual = gyrotherm::fit::RecipeSettings::residual();
    residual.epochs = 3;
    cfg.candidates = vec![
        Candidate::linear(),
        Candidate::poly(),
        Candidate {
            method: gyrotherm::Method::Residual,
            recipe: Some(residual),
        },
        Candidate::published(Some(3)),
    ];
    let cmp = run_compare(&train_n, &test_n, &cfg);

    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("report");
    let index = write_full_report(&out, &train_n, &test_n, &cmp, &cfg).expect("report");
    assert_eq!(index, out.join("index.html"));
    let html = std::fs::read_to_string(&index).unwrap();

    for (stem, size) in FIGURE_STEMS.iter().zip(STATED_SIZE) {
        let png = out.join(format!("{stem}.png"));
        let svg = out.join(format!("{stem}.svg"));
        assert!(png.is_file(), "{} missing", png.display());
        assert!(svg.is_file(), "{} missing", svg.display());
        check_png(&png, size);
        let svg_text = std::fs::read_to_string(&svg).unwrap();
        assert!(svg_text.contains("<svg"), "{} is not SVG", svg.display());
        assert!(
            html.contains(&format!("src=\"{stem}.png\"")),
            "page does not show {stem}.png"
        );
    }
    // Every link of the page is a file in the report folder.
    let refs = references(&html);
    assert_eq!(refs.len(), 2 * FIGURE_STEMS.len(), "{refs:?}");
    for r in &refs {
        assert!(out.join(r).is_file(), "index.html references missing {r}");
    }
    assert!(
        !html.contains("Figures not drawn"),
        "no figure may be left out here"
    );
    assert!(
        !html.contains("<script") && !html.contains("http"),
        "self-contained page"
    );

    // The table carries the comparison's own numbers, formatted as `gyrotherm compare` does.
    let s = &cmp.tests[0];
    let raw_bs = s
        .raw
        .bias_stability_dph
        .expect("static log has bias stability");
    assert!(
        html.contains(&format!("<td>{raw_bs:.5}</td>")),
        "raw bias stability {raw_bs:.5} missing"
    );
    for m in &s.methods {
        let v = m.performance.bias_stability_dph.unwrap();
        assert!(
            html.contains(&format!("<td>{v:.5}</td>")),
            "{} {v:.5} missing",
            m.label
        );
    }
    let floor = s.floor_dph.expect("simulated with truth: noise floor");
    assert!(html.contains(&format!("<td>{floor:.5}</td>")));
    let t = &cmp.tests[1];
    let sf = t.raw.sf_error_ppm.expect("rate-table log has an SF error");
    assert!(
        html.contains(&format!("<td>{sf:.1}</td>")),
        "raw SF error {sf:.1} missing"
    );
    // Figure 4 shows every model's predicted bias, the report's main (recipe) model and the
    // published LSTM both.
    let fig4 = html
        .split("<figcaption>Figure 4. ")
        .nth(1)
        .and_then(|c| c.split("</figcaption>").next())
        .expect("figure 4 captioned");
    for label in &s.methods {
        assert!(
            fig4.contains(&gyrotherm::report::html::escape(label.label)),
            "figure 4 leaves out {}: {fig4}",
            label.label
        );
    }
    // Metadata: the digest the model file carries.
    for f in &cmp.fits {
        assert!(html.contains(&f.model.training.data_digest_sha256));
    }
    // The model table: one column per model, named as in the comparison table (the
    // published recipe has its own, named after its authors), every row as wide.
    let models = html_table(&html, "models");
    let labels: Vec<&str> = cmp.columns.iter().map(|c| c.label).collect();
    assert_eq!(models[0][1..], labels[..], "one column per model, in order");
    assert!(labels.contains(&"LSTM, He et al."), "no published column");
    for row in &models {
        assert_eq!(row.len(), 1 + labels.len(), "ragged row {row:?}");
    }
    let col = |key: &str| 1 + cmp.columns.iter().position(|c| c.key == key).unwrap();
    // Methods are one flat list: the method row names each, and no model has a recipe row.
    let method = table_row(&models, "method");
    assert_eq!(method[col("linear")], "linear");
    assert_eq!(method[col("residual")], "residual");
    assert_eq!(method[col("published")], "published");
    assert!(models.iter().all(|r| r[0] != "recipe"), "{models:?}");
    // Epochs and loss only where an LSTM was kept: the published recipe always keeps one.
    let net = table_row(&models, "bias LSTM training");
    assert_eq!(net[col("linear")], "—");
    assert_eq!(net[col("poly")], "—");
    assert!(
        net[col("published")].starts_with("3 epochs, final loss "),
        "{net:?}"
    );
    assert!(
        !html.contains("0 epochs"),
        "a model without an LSTM shows no epochs"
    );
    // Lags read as whole seconds.
    check_input_names(&table_row(&models, "inputs")[1..]);
    assert!(!html.contains("T_lag"), "raw feature names on the page");
    // Only the figures and the page: no temporary files left.
    let names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names.len(), 2 * FIGURE_STEMS.len() + 1, "{names:?}");
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
fn figures_that_cannot_apply_are_noted_not_errors() {
    // Static logs only and no LSTM: no loss curve, no scale-factor or rate-table figure. The
    // predicted bias is drawn for every model (least-squares ones too).
    let train = vec![("train.csv".to_owned(), sim(5, false))];
    let test = vec![("test.csv".to_owned(), sim(6, false))];
    let (train_n, test_n) = (named(&train), named(&test));
    let cfg = CompareConfig {
        candidates: vec![Candidate::linear(), Candidate::poly()],
        ..CompareConfig::default()
    };
    let cmp = run_compare(&train_n, &test_n, &cfg);
    let dir = tempfile::tempdir().unwrap();
    let index = write_full_report(dir.path(), &train_n, &test_n, &cmp, &cfg).expect("report");
    let html = std::fs::read_to_string(&index).unwrap();
    // The coverage figures need only a model with a least-squares bias: both have maps.
    let drawn = [0usize, 1, 3, 6, 7, 8, 9];
    for (k, (stem, size)) in FIGURE_STEMS.iter().zip(STATED_SIZE).enumerate() {
        let png = dir.path().join(format!("{stem}.png"));
        // One number, one figure: a drawn figure's caption and a note on a figure not drawn
        // use the figure's own number, so no two figures on the page share one.
        let caption = format!("<figcaption>Figure {}. ", k + 1);
        if drawn.contains(&k) {
            check_png(&png, size);
            assert_eq!(
                html.matches(&caption).count(),
                1,
                "figure {} ({stem}) is not captioned as such",
                k + 1
            );
        } else {
            assert!(!html.contains(&caption), "figure {} is not drawn", k + 1);
            assert!(!png.exists(), "{stem} should not be drawn");
            assert!(
                html.contains(&format!("Figure {} (", k + 1)),
                "no note for figure {}",
                k + 1
            );
        }
    }
    assert!(html.contains("no model in this comparison trained an LSTM"));
    assert!(html.contains("no rate-table held-out log given"));
    for r in references(&html) {
        assert!(
            dir.path().join(&r).is_file(),
            "index.html references missing {r}"
        );
    }
}

/// The cells of the HTML table of class `class` in `html`: the header row first, each cell's
/// text with the spaces normalised (no-break spaces read as spaces).
fn html_table(html: &str, class: &str) -> Vec<Vec<String>> {
    let start = html
        .find(&format!("<table class=\"{class}\">"))
        .unwrap_or_else(|| panic!("no table of class {class}"));
    let end = start + html[start..].find("</table>").expect("unterminated table");
    html[start..end]
        .split("<tr>")
        .skip(1)
        .map(|row| {
            row.split(['<'])
                .filter_map(|part| {
                    part.strip_prefix("td>")
                        .or_else(|| part.strip_prefix("th>"))
                        .map(|t| t.replace('\u{a0}', " "))
                })
                .collect()
        })
        .collect()
}

/// The row of `table` whose first cell is `field`.
fn table_row<'a>(table: &'a [Vec<String>], field: &str) -> &'a [String] {
    table
        .iter()
        .find(|r| r.first().map(String::as_str) == Some(field))
        .unwrap_or_else(|| panic!("no row {field:?} in {table:?}"))
}

/// The items of the page's warning list.
fn html_warnings(html: &str) -> Vec<String> {
    let Some(start) = html.find("<ul class=\"warnings\">") else {
        return Vec::new();
    };
    let end = start + html[start..].find("</ul>").unwrap();
    html[start..end]
        .split("<li>")
        .skip(1)
        .map(|li| li.split("</li>").next().unwrap().to_owned())
        .collect()
}

/// Each input of each model reads `T`, `dT/dt` or `T − lag N s` / `T lag N s` with N a
/// whole number of seconds.
fn check_input_names(cells: &[String]) {
    for cell in cells.iter().filter(|c| c.as_str() != "—") {
        for name in cell.split(", ") {
            if let Some(rest) = name
                .strip_prefix("T − lag ")
                .or_else(|| name.strip_prefix("T lag "))
            {
                let secs = rest
                    .strip_suffix(" s")
                    .unwrap_or_else(|| panic!("{name:?}"));
                assert!(
                    secs.parse::<u64>().is_ok(),
                    "lag {name:?} is not in whole seconds"
                );
            } else {
                assert!(["T", "dT/dt"].contains(&name), "unexpected input {name:?}");
            }
        }
    }
}

#[test]
fn lag_inputs_read_in_whole_seconds() {
    let mut spec = gyrotherm::features::FeatureSpec::THERMAL_STATE;
    spec.lag_tau_s[0] = 266.26613644776796;
    let names: Vec<String> = gyrotherm::report::input_names(&spec)
        .iter()
        .map(|n| n.replace('\u{a0}', " "))
        .collect();
    assert_eq!(names[..3], ["T", "dT/dt", "T − lag 266 s"], "{names:?}");
    check_input_names(&[names.join(", ")]);
    // A name never breaks across lines inside a table cell.
    for n in gyrotherm::report::input_names(&spec) {
        assert!(!n.contains(' '), "{n:?} holds a breaking space");
    }
}

#[test]
fn extrapolation_is_said_once_naming_the_models() {
    // Trained on the short cycle, tested on a hotter, faster one: both models extrapolate in
    // temperature and in temperature rate, two findings the comparison states per model.
    let train = vec![("train.csv".to_owned(), sim(10, false))];
    let test = vec![("hot.csv".to_owned(), sim_profile(wide_profile(), 11, false))];
    let (train_n, test_n) = (named(&train), named(&test));
    let cfg = CompareConfig {
        candidates: vec![Candidate::linear(), Candidate::poly()],
        ..CompareConfig::default()
    };
    let cmp = run_compare(&train_n, &test_n, &cfg);
    assert_eq!(
        cmp.tests[0].warnings.len(),
        4,
        "two findings for each of two models: {:?}",
        cmp.tests[0].warnings
    );
    let dir = tempfile::tempdir().unwrap();
    let index = write_full_report(dir.path(), &train_n, &test_n, &cmp, &cfg).expect("report");
    let html = std::fs::read_to_string(&index).unwrap();
    let warnings = html_warnings(&html);
    assert_eq!(warnings.len(), 2, "one line per finding: {warnings:#?}");
    let unique: HashSet<&String> = warnings.iter().collect();
    assert_eq!(unique.len(), warnings.len(), "repeated: {warnings:#?}");
    for (w, what) in warnings.iter().zip(["temperature ", "temperature rate "]) {
        assert!(w.starts_with(&format!("hot.csv: {what}")), "{w}");
        assert!(
            w.contains("the models “linear” and “poly” extrapolate there"),
            "both models named: {w}"
        );
        // Each model is named once in the line.
        for label in ["“linear”", "“poly”"] {
            assert_eq!(w.matches(label).count(), 1, "{w}");
        }
    }
    // No field of an LSTM appears for least-squares models: those rows are dropped.
    let models = html_table(&html, "models");
    assert_eq!(models[0], ["field", "linear", "poly"]);
    for field in [
        "recipe",
        "seed",
        "bias LSTM training",
        "scale-factor LSTM training",
    ] {
        assert!(
            models.iter().all(|r| r[0] != field),
            "row {field:?} applies to no model here: {models:?}"
        );
    }
    check_input_names(&table_row(&models, "inputs")[1..]);

    // The coverage figure marks the hotter, faster run's excursions outside the training
    // region in their own colour, and its caption gives the share the track counts.
    let t = gyrotherm::coverage_track::track(&cmp.fits[1].model, &test[0].1)
        .unwrap()
        .expect("poly has a coverage map");
    let outside = t.shares().unwrap()[2];
    assert!(outside > 0.05, "the wide run leaves the region: {outside}");
    assert!(
        html.contains(&format!("{:.1} % outside", 100.0 * outside)),
        "caption lacks the outside share {outside}"
    );
    let red = count_colour(
        &dir.path().join("fig9_coverage.png"),
        gyrotherm::report::coverage_figures::OUTSIDE,
    );
    assert!(red > 100, "outside stretch not drawn: {red} px");
    // Tested on the training cycle (another run): less of it outside. Not none: a 3900 s log
    // fills only a few of the 16 × 12 cells with the 100 steps a covered cell needs.
    let same = vec![("same.csv".to_owned(), sim(12, false))];
    let same_n = named(&same);
    let cmp = run_compare(&train_n, &same_n, &cfg);
    let dir = tempfile::tempdir().unwrap();
    write_full_report(dir.path(), &train_n, &same_n, &cmp, &cfg).expect("report");
    let t = gyrotherm::coverage_track::track(&cmp.fits[1].model, &same[0].1)
        .unwrap()
        .unwrap();
    let same_outside = t.shares().unwrap()[2];
    assert!(
        same_outside + 0.2 < outside,
        "same cycle {same_outside} against the wide one {outside}"
    );
}

/// Pixels of exactly `rgb` in the PNG at `path`.
fn count_colour(path: &Path, rgb: (u8, u8, u8)) -> usize {
    let img = image::open(path).unwrap().to_rgb8();
    img.pixels()
        .filter(|p| p.0 == [rgb.0, rgb.1, rgb.2])
        .count()
}

#[test]
fn mismatched_logs_are_refused() {
    let train = vec![("train.csv".to_owned(), sim(7, false))];
    let (train_n, test_n) = (named(&train), named(&train));
    let cfg = CompareConfig {
        candidates: vec![Candidate::linear()],
        ..CompareConfig::default()
    };
    let cmp = run_compare(&train_n, &test_n, &cfg);
    let dir = tempfile::tempdir().unwrap();
    let err = write_full_report(dir.path(), &train_n, &[], &cmp, &cfg)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("0 held-out logs given but the comparison has 1"),
        "{err}"
    );
}

#[test]
fn measured_scale_factor_follows_simulator_truth() {
    // Independent check of figure 5's data: with the simulator's true K as the "prediction",
    // the scale factor measured from the raw output (segment mean minus the local bias of
    // the neighbouring stops, over the table rate) must agree with the true K averaged over
    // the same samples. Output = bias + K·Ω + noise (sim), so the difference is the noise
    // mean (~0.003 °/h over 290 s) and the bias change the stop average does not cancel
    // (≲ 0.1 °/h), over 20 °/s = 72 000 °/h: ≲ 1.5 ppm.
    const TOL_PPM: f64 = 3.0;
    let log = sim(8, true);
    let truth = log
        .extra_f64(gyrotherm::csvlog::TRUE_SCALE_COL)
        .expect("simulated with truth");
    let p = gyrotherm::report::scale_factor_points(&log, &truth, 10.0).unwrap();
    // 3900 s in 300 s segments, +Ω / stop / −Ω / stop: 7 rate segments.
    assert_eq!(p.time_s.len(), 7, "rate segments: {:?}", p.time_s);
    for ((t, m), k) in p.time_s.iter().zip(&p.measured_ppm).zip(&p.predicted_ppm) {
        assert!(
            (m - k).abs() < TOL_PPM,
            "segment at {t} s: want {k:.2} ppm (truth) got {m:.2} ppm, error {:.2}",
            m - k
        );
    }
    // Wrong length and a static log are errors, not panics.
    assert!(gyrotherm::report::scale_factor_points(&log, &truth[1..], 10.0).is_err());
    assert!(gyrotherm::report::scale_factor_points(&sim(9, false), &truth, 10.0).is_err());
}
