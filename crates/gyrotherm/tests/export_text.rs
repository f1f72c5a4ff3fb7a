//! What `gyrotherm::export` writes is the generator's own text and numbers, never a string
//! from the model file: with arbitrary Unicode (comment ends, newlines, bare CRs, trigraphs,
//! bidirectional overrides, quotes, backslashes, inner attributes) in every free-text field
//! of a model, the generated files equal those of the same model with plain strings except
//! for the content hash, hold only printable ASCII and newlines, and compile: the C with the
//! strict flags of the C export test (defining exactly `gt_coverage_of`, `gt_init` and `gt_step`), the Rust
//! module against gyrotherm-core.

use std::cell::RefCell;
use std::path::Path;
use std::process::Command;

use gyrotherm::export::{generate, is_generated_text, Lang};
use gyrotherm::model::ModelFile;
use proptest::collection::vec;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

/// Cases checked on the text alone (cheap: two generations each).
const TEXT_CASES: u32 = 256;
/// Of those, the first this many are also compiled, C and Rust: a few dozen keeps the test
/// to seconds (gcc -O2 takes a fraction of a second per file; the Rust modules build in one
/// cargo call).
const COMPILED_CASES: usize = 24;

/// The flight-loop example's model: LSTM bias and scale.
fn lstm_model() -> ModelFile {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../gyrotherm-core/examples/flight_loop/model.json");
    ModelFile::load(&p).unwrap()
}

/// A linear model as `gyrotherm train --method linear` writes one (fast-cycle profile; the
/// same numbers as the model in tests/model_integrity.rs).
fn linear_model() -> ModelFile {
    ModelFile::from_json(
        r#"{"format_version": 1, "method": "linear",
        "features": {"step_period_s": 1.0, "rate_lag_s": 20.0, "smoothing_window_s": 0.0,
                     "lag_tau_s": [], "lag_outputs": "diff_from_t"},
        "bias": {"baseline": {"terms": {"n_features": 2, "powers": [[0, 0], [1, 0], [0, 1]]},
                 "coefficients": [0.0027569503410293872, 1.1729644843148304e-06, 0.00010133064497718164]}},
        "scale": {"baseline": {"terms": {"n_features": 2, "powers": [[0, 0], [1, 0], [0, 1]]},
                  "coefficients": [1.0002578767007753, 9.083930143213933e-07, -0.00021387351834198826]}},
        "training": {"temp_range_c": {"min": -29.8125, "max": 70.375},
                     "rate_range_c_per_s": {"min": -0.0875, "max": 0.0875},
                     "data_digest_sha256": "30d4b8ab79b048f01aab0c81da07c7ee0aac77c3209a51f2976c0d528981f351",
                     "epochs": null, "final_loss": null, "seed": null,
                     "created_by": "gyrotherm 0.1.0", "inputs": ["fc.csv", "fct.csv"]}}"#,
    )
    .unwrap()
}

/// Text that would break or subvert a C comment, a Rust `//!` line or the C preprocessor,
/// mixed with arbitrary Unicode scalar values.
fn hostile_string() -> impl Strategy<Value = String> {
    let piece = prop_oneof![
        4 => any::<char>().prop_map(String::from),
        1 => prop::sample::select(vec![
            "*/", "/*", "//", "\n", "\r", "\r\n", "??/", "??=", "\u{202e}", "\u{2066}",
            "\u{2028}", "\u{feff}", "\0", "\t", "\"", "'", "\\", "#![", "@ABOUT@", "@DATA@", "@COVERAGE@",
            "*/ #undef isfinite\n#define isfinite(x) 1\n/*",
            "*/ int gt_pwned; /*",
            "#![doc = include_str!(\"/etc/hostname\")]",
            "\n#![cfg(any())]\n",
            "\n}\npub static X: u8 = 0;\n",
        ])
        .prop_map(str::to_owned),
    ];
    vec(piece, 0..12).prop_map(|v| v.concat())
}

/// `created_by` and the training inputs: the model's free-text fields.
fn hostile_fields() -> impl Strategy<Value = (String, Vec<String>)> {
    (hostile_string(), vec(hostile_string(), 0..4))
}

fn with_fields(model: &ModelFile, (created_by, inputs): &(String, Vec<String>)) -> ModelFile {
    let mut m = model.clone();
    m.training.created_by = created_by.clone();
    m.training.inputs = inputs.clone();
    m
}

/// The generated files with the content hash masked.
fn masked(model: &ModelFile, lang: Lang) -> Vec<(&'static str, String)> {
    let digest = model.content_digest().unwrap();
    let files = generate(model, lang).unwrap();
    files
        .into_iter()
        .map(|(name, text)| {
            assert!(
                text.contains(&digest),
                "{name} does not name the model by its content hash"
            );
            (name, text.replace(&digest, "<digest>"))
        })
        .collect()
}

#[test]
fn free_text_fields_never_reach_the_generated_files_and_the_files_compile() {
    let bases = [lstm_model(), linear_model()];
    let plain: Vec<[Vec<(&str, String)>; 2]> = bases
        .iter()
        .map(|m| [masked(m, Lang::C), masked(m, Lang::Rust)])
        .collect();
    let kept = RefCell::new(Vec::new());
    let mut runner = TestRunner::new_with_rng(
        Config {
            cases: TEXT_CASES,
            failure_persistence: None,
            ..Config::default()
        },
        // Fixed seed: the same cases in every run (the fuzz target `export` explores more).
        TestRng::deterministic_rng(RngAlgorithm::ChaCha),
    );
    let case = RefCell::new(0usize);
    runner
        .run(&hostile_fields(), |fields| {
            let n = *case.borrow();
            *case.borrow_mut() += 1;
            let which = n % bases.len();
            let model = with_fields(&bases[which], &fields);
            for (lang, want) in [Lang::C, Lang::Rust].into_iter().zip(&plain[which]) {
                let got = masked(&model, lang);
                for ((name, g), (_, w)) in got.iter().zip(want) {
                    prop_assert!(
                        is_generated_text(g),
                        "{name}: a byte outside the generator's set, fields {fields:?}"
                    );
                    prop_assert!(
                        g == w,
                        "{name} differs from the plain model's, fields {fields:?}"
                    );
                }
            }
            let mut kept = kept.borrow_mut();
            if kept.len() < COMPILED_CASES {
                kept.push(model);
            }
            Ok(())
        })
        .unwrap();
    let kept = kept.into_inner();
    assert_eq!(kept.len(), COMPILED_CASES);
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("export_text");
    let _ = std::fs::remove_dir_all(dir.join("c"));
    compile_c(&dir.join("c"), &kept);
    compile_rust(&dir.join("rust"), &kept);
}

fn have(tool: &str) -> bool {
    Command::new(tool)
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
}

fn run_ok(cmd: &mut Command) -> std::process::Output {
    let out = cmd.output().unwrap_or_else(|e| panic!("{cmd:?}: {e}"));
    assert!(
        out.status.success(),
        "{cmd:?} failed:\n{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Each model's C, compiled as tests/export_c.rs in gyrotherm-cli compiles it; each object
/// defines the header's two functions and nothing else.
fn compile_c(dir: &Path, models: &[ModelFile]) {
    if !(have("gcc") && have("nm")) {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "gcc and nm are required in CI"
        );
        eprintln!("skipped the C compile: gcc or nm not found");
        return;
    }
    for (i, m) in models.iter().enumerate() {
        let case = dir.join(format!("case{i}"));
        gyrotherm::export::export(m, Lang::C, &case).unwrap();
        let obj = case.join("gyrotherm_model.o");
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
                    "-c",
                ])
                .arg(case.join("gyrotherm_model.c"))
                .arg("-o")
                .arg(&obj),
        );
        let nm = run_ok(
            Command::new("nm")
                .args(["--defined-only", "--extern-only", "--format=posix"])
                .arg(&obj),
        );
        let mut names: Vec<String> = String::from_utf8_lossy(&nm.stdout)
            .lines()
            .filter_map(|l| l.split_whitespace().next().map(str::to_owned))
            .collect();
        names.sort();
        assert_eq!(
            names,
            ["gt_coverage_of", "gt_init", "gt_step"],
            "case {i}: {:?}",
            m.training
        );
    }
}

/// All models' Rust modules in one scratch crate that depends on gyrotherm-core by path,
/// built with warnings denied. The crate names each module's `MODEL`, so a module that
/// an attribute emptied (`#![cfg(any())]`) fails the build.
fn compile_rust(dir: &Path, models: &[ModelFile]) {
    let src = dir.join("src");
    let _ = std::fs::remove_dir_all(&src);
    std::fs::create_dir_all(&src).unwrap();
    let core = Path::new(env!("CARGO_MANIFEST_DIR")).join("../gyrotherm-core");
    std::fs::write(
        dir.join("Cargo.toml"),
        format!(
            "[package]\nname = \"export-text-check\"\nversion = \"0.0.0\"\nedition = \"2021\"\n\
             publish = false\n\n[dependencies]\ngyrotherm-core = {{ path = {:?} }}\n\n\
             # Its own workspace: the folder lies inside this repository.\n[workspace]\n",
            core.canonicalize().unwrap()
        ),
    )
    .unwrap();
    // The workspace's lock file, so the build uses the versions already downloaded.
    let lock = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../Cargo.lock");
    if !dir.join("Cargo.lock").exists() {
        std::fs::copy(lock, dir.join("Cargo.lock")).unwrap();
    }
    let mut lib = String::from("#![deny(warnings)]\n");
    let mut refs = Vec::new();
    for (i, m) in models.iter().enumerate() {
        let files = generate(m, Lang::Rust).unwrap();
        std::fs::write(src.join(format!("m{i}.rs")), &files[0].1).unwrap();
        lib.push_str(&format!("pub mod m{i};\n"));
        refs.push(format!("&m{i}::MODEL"));
    }
    lib.push_str(&format!(
        "pub static ALL: [&gyrotherm_core::static_model::StaticModel; {}] = [{}];\n",
        refs.len(),
        refs.join(", ")
    ));
    std::fs::write(src.join("lib.rs"), lib).unwrap();
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    run_ok(
        Command::new(cargo)
            .args(["build", "--offline", "--quiet", "--manifest-path"])
            .arg(dir.join("Cargo.toml"))
            .env("CARGO_TARGET_DIR", dir.join("target"))
            .env_remove("RUSTFLAGS"),
    );
}
