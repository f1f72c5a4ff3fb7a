//! `--out` as a user gives it: a symbolic link, a FIFO, a device, `-` for standard output,
//! and an interrupted run. Links are refused (never written through), FIFOs and devices
//! written straight,
//! `-` is standard output, and a SIGTERM leaves neither a temporary file nor a damaged
//! output behind.
#![cfg(unix)]

use std::io::{Read, Write};
use std::os::unix::fs::FileTypeExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

mod cli;
use cli::gyrotherm;

/// A 30 s constant-temperature profile: a simulate run of 30 rows.
fn profile(dir: &Path) -> PathBuf {
    let p = dir.join("profile.txt");
    std::fs::write(&p, "30,25\n").unwrap();
    p
}

fn simulate_to(dir: &Path, out: &str) -> Output {
    gyrotherm()
        .current_dir(dir)
        .args(["simulate", "--profile-file"])
        .arg(profile(dir))
        .args(["--out", out])
        .output()
        .unwrap()
}

fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

fn mkfifo(path: &Path) {
    let st = Command::new("mkfifo").arg(path).status().expect("mkfifo");
    assert!(st.success());
}

fn is_fifo(path: &Path) -> bool {
    std::fs::symlink_metadata(path)
        .unwrap()
        .file_type()
        .is_fifo()
}

/// Exit 2 naming the link and what to do; the link and everything else in `dir` as before.
fn assert_link_refused(dir: &Path, out: &Output, link: &str, before: &[&str]) {
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(&format!("{link} is a symbolic link"))
            && stderr.contains("remove the link"),
        "{stderr}"
    );
    assert!(std::fs::symlink_metadata(dir.join(link))
        .unwrap()
        .file_type()
        .is_symlink());
    assert_eq!(entries(dir), before);
}

#[test]
fn out_through_a_symlink_is_refused_and_the_target_kept() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("real.csv"), "old").unwrap();
    std::os::unix::fs::symlink("real.csv", dir.path().join("link.csv")).unwrap();
    let out = simulate_to(dir.path(), "link.csv");
    assert_link_refused(
        dir.path(),
        &out,
        "link.csv",
        &["link.csv", "profile.txt", "real.csv"],
    );
    assert_eq!(
        std::fs::read_to_string(dir.path().join("real.csv")).unwrap(),
        "old"
    );
}

#[test]
fn out_to_a_fifo_writes_into_it() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("pipe");
    mkfifo(&fifo);
    let (tx, rx) = std::sync::mpsc::channel();
    {
        let fifo = fifo.clone();
        std::thread::spawn(move || tx.send(std::fs::read_to_string(fifo).unwrap()));
    }
    let out = simulate_to(dir.path(), "pipe");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // A writer that replaced the FIFO instead never opened it: the reader waits for ever.
    let text = rx
        .recv_timeout(Duration::from_secs(20))
        .expect("nothing was written into the FIFO");
    assert!(text.starts_with("time_s,gyro_dps,temp_c\n"), "{text}");
    assert_eq!(text.lines().count(), 31);
    assert!(is_fifo(&fifo), "the FIFO was replaced");
    assert_eq!(entries(dir.path()), ["pipe", "profile.txt"]);
}

#[test]
fn out_to_a_link_to_dev_null_is_refused_and_keeps_the_link_and_the_device() {
    let dir = tempfile::tempdir().unwrap();
    std::os::unix::fs::symlink("/dev/null", dir.path().join("sink")).unwrap();
    let out = simulate_to(dir.path(), "sink");
    assert_link_refused(dir.path(), &out, "sink", &["profile.txt", "sink"]);
    assert_eq!(
        std::fs::read_link(dir.path().join("sink")).unwrap(),
        Path::new("/dev/null")
    );
    assert!(std::fs::metadata("/dev/null")
        .unwrap()
        .file_type()
        .is_char_device());
}

#[test]
fn out_to_dev_null_succeeds_and_leaves_it_a_device() {
    // Guard: a build that takes /dev/null for a file would replace it (as root) before the
    // assertion below could fail, so ask the library first.
    assert!(matches!(
        gyrotherm::atomic_file::destination(Path::new("/dev/null")).unwrap(),
        gyrotherm::atomic_file::Destination::Direct(_)
    ));
    let dir = tempfile::tempdir().unwrap();
    let out = simulate_to(dir.path(), "/dev/null");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(std::fs::metadata("/dev/null")
        .unwrap()
        .file_type()
        .is_char_device());
}

#[test]
fn out_dash_is_standard_output() {
    let dir = tempfile::tempdir().unwrap();
    let out = simulate_to(dir.path(), "-");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.starts_with("time_s,gyro_dps,temp_c\n"), "{text}");
    assert_eq!(text.lines().count(), 31);
    assert_eq!(entries(dir.path()), ["profile.txt"], "no file named `-`");
}

#[test]
fn out_dev_stdout_is_standard_output() {
    let dir = tempfile::tempdir().unwrap();
    let out = simulate_to(dir.path(), "/dev/stdout");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    assert_eq!(text.lines().count(), 31);
}

#[test]
fn out_to_a_directory_is_refused_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("d")).unwrap();
    let out = simulate_to(dir.path(), "d");
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("d is a directory"), "{err}");
    assert_eq!(
        entries(dir.path().join("d").as_path()),
        Vec::<String>::new()
    );
}

/// A compensate run reading a FIFO is stopped by SIGTERM while its output is half written:
/// the previous output stays as it was and no hidden temporary file is left.
#[test]
fn sigterm_mid_write_removes_the_temporary_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let train_log = d.join("train.csv");
    let st = gyrotherm()
        .args(["simulate", "--profile", "fast-cycle", "--out"])
        .arg(&train_log)
        .stderr(Stdio::null())
        .status()
        .unwrap();
    assert!(st.success());
    let model = d.join("m.json");
    let st = gyrotherm()
        .args(["train", "--method", "linear", "--input"])
        .arg(&train_log)
        .arg("--out")
        .arg(&model)
        .stderr(Stdio::null())
        .status()
        .unwrap();
    assert!(st.success());
    let log = std::fs::read_to_string(&train_log).unwrap();
    std::fs::remove_file(&train_log).unwrap();

    let fifo = d.join("in.fifo");
    mkfifo(&fifo);
    let out = d.join("out.csv");
    std::fs::write(&out, "old").unwrap();
    let mut child = gyrotherm()
        .args(["compensate", "--sample-period-s", "1", "--model"])
        .arg(&model)
        .arg("--input")
        .arg(&fifo)
        .arg("--out")
        .arg(&out)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Opening blocks until the child opens its end.
    let mut w = std::fs::OpenOptions::new().write(true).open(&fifo).unwrap();
    let half: String = log.lines().take(5000).map(|l| format!("{l}\n")).collect();
    w.write_all(half.as_bytes()).unwrap();
    w.flush().unwrap();
    let t0 = Instant::now();
    let temp_exists = || entries(d).iter().any(|n| n.starts_with(".out.csv.tmp"));
    while !temp_exists() {
        assert!(t0.elapsed() < Duration::from_secs(20), "no temporary file");
        std::thread::sleep(Duration::from_millis(20));
    }
    let st = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(st.success());
    let status = child.wait().unwrap();
    drop(w);
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    assert!(!status.success(), "{err}");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "old");
    assert_eq!(entries(d), ["in.fifo", "m.json", "out.csv"]);
}
