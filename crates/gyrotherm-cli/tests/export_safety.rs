//! What `gyrotherm export` may write, and what a model file may do to it: a training file's
//! name never reaches the generated source (which compiles and defines only the API), a link
//! planted in the output folder is refused and its target left alone, and a model file that
//! names a key twice is refused by every command that loads one.
#![cfg(unix)]

use std::path::{Path, PathBuf};
use std::process::Command;

mod cli;
use cli::{gyrotherm, outcome, run_ok, simulate_args};

/// The name a hostile tester gave a training log: were it pasted into a C comment, the
/// comment would end and `int gt_pwned;` would become a global of the flight code.
const HOSTILE_DIR: &str = "d*/ int gt_pwned; ";

/// A linear model trained on a `fast-cycle` log stored under [`HOSTILE_DIR`], as
/// `gyrotherm train` writes it (sealed).
fn hostile_model(dir: &Path) -> PathBuf {
    let log = simulate_args(dir, "log.csv", &["--profile", "fast-cycle"]);
    std::fs::create_dir_all(dir.join(HOSTILE_DIR)).unwrap();
    let input = dir.join(HOSTILE_DIR).join("*.csv");
    std::fs::rename(&log, &input).unwrap();
    let model = dir.join("m.json");
    run_ok(
        gyrotherm()
            .args(["train", "--method", "linear", "--input"])
            .arg(&input)
            .arg("--out")
            .arg(&model),
    );
    let text = std::fs::read_to_string(&model).unwrap();
    assert!(text.contains("gt_pwned"), "the name is in the model file");
    model
}

fn export(model: &Path, lang: &str, out: &Path) -> std::process::Output {
    gyrotherm()
        .args(["export", "--target", lang, "--model"])
        .arg(model)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap()
}

fn have(tool: &str) -> bool {
    Command::new(tool)
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
}

/// The external symbols `obj` defines, sorted.
fn defined_symbols(obj: &Path) -> Vec<String> {
    let out = run_ok(
        Command::new("nm")
            .args(["--defined-only", "--extern-only", "--format=posix"])
            .arg(obj),
    );
    let mut names: Vec<String> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| l.split_whitespace().next().map(str::to_owned))
        .collect();
    names.sort();
    names
}

#[test]
fn a_training_file_name_never_reaches_the_generated_source() {
    let dir = tempfile::tempdir().unwrap();
    let model = hostile_model(dir.path());
    let (c_dir, rust_dir) = (dir.path().join("outc"), dir.path().join("outrs"));
    for (lang, out) in [("c", &c_dir), ("rust", &rust_dir)] {
        let r = export(&model, lang, out);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    }
    for f in [
        c_dir.join("gyrotherm_model.h"),
        c_dir.join("gyrotherm_model.c"),
        rust_dir.join("gyrotherm_model.rs"),
    ] {
        let text = std::fs::read_to_string(&f).unwrap();
        assert!(
            !text.contains("gt_pwned") && !text.contains(".csv"),
            "{}",
            f.display()
        );
        assert!(
            gyrotherm::export::is_generated_text(&text),
            "{}",
            f.display()
        );
        // The model is named by its content hash instead.
        assert!(text.contains("content_sha256 "), "{}", f.display());
    }
    if !(have("gcc") && have("nm")) {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "gcc and nm are required in CI"
        );
        eprintln!("skipped the compile: gcc or nm not found");
        return;
    }
    let obj = dir.path().join("gyrotherm_model.o");
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
            .arg(c_dir.join("gyrotherm_model.c"))
            .arg("-o")
            .arg(&obj),
    );
    // The header's API and nothing else: everything else in the source is `static`.
    assert_eq!(
        defined_symbols(&obj),
        ["gt_coverage_of", "gt_init", "gt_step"]
    );
}

#[test]
fn export_refuses_a_symlink_in_its_out_folder_and_leaves_the_target() {
    let dir = tempfile::tempdir().unwrap();
    let model = hostile_model(dir.path());
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    let victim = dir.path().join("victim.c");
    std::fs::write(&victim, "precious\n").unwrap();
    std::os::unix::fs::symlink("../victim.c", out.join("gyrotherm_model.c")).unwrap();
    let r = export(&model, "c", &out);
    assert_eq!(r.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&r.stderr);
    assert!(
        stderr.contains("gyrotherm_model.c is a symbolic link")
            && stderr.contains("remove the link"),
        "{stderr}"
    );
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious\n");
    assert_eq!(
        std::fs::read_link(out.join("gyrotherm_model.c")).unwrap(),
        Path::new("../victim.c")
    );
    // Checked before anything is written: no header without its source.
    let mut names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["gyrotherm_model.c"]);
}

#[test]
fn a_model_with_a_key_named_twice_is_refused_by_every_command() {
    let dir = tempfile::tempdir().unwrap();
    let model = hostile_model(dir.path());
    // A decoy array before the real one: serde_json keeps the last, so the seal still
    // matched; another reader could take the first.
    let text = std::fs::read_to_string(&model).unwrap();
    assert!(text.contains("\"coefficients\": ["));
    let dup = text.replacen(
        "\"coefficients\": [",
        "\"coefficients\": [0.5, 0, 0],\n      \"coefficients\": [",
        1,
    );
    let dup_path = dir.path().join("dup.json");
    std::fs::write(&dup_path, dup).unwrap();
    let log = simulate_args(dir.path(), "run.csv", &["--profile", "room-steady"]);
    let (m, l) = (dup_path.to_str().unwrap(), log.to_str().unwrap());
    let out = dir.path().join("out");
    let o = out.to_str().unwrap();
    let comp = dir.path().join("comp.csv");
    for args in [
        vec!["model", "check", m],
        vec!["export", "--model", m, "--target", "c", "--out", o],
        vec![
            "compensate",
            "--model",
            m,
            "--input",
            l,
            "--out",
            comp.to_str().unwrap(),
        ],
    ] {
        let (code, _, stderr) = outcome(&args);
        assert_eq!(code, 2, "{args:?}: {stderr}");
        assert!(
            stderr.contains("bias.baseline.coefficients: key \"coefficients\" appears twice"),
            "{args:?}: {stderr}"
        );
        assert!(stderr.contains("dup.json"), "{args:?}: {stderr}");
    }
    assert!(!out.exists() && !comp.exists());
}
