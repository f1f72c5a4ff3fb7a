//! Messages name the flags `--help` shows: a user reading a message looks the flag up in
//! `--help`, so a message naming a flag that is hidden (or gone) leaves them stuck.
//!
//! The flags are those the real binary's `--help` lists, for every command and subcommand;
//! the messages are the string text of the library and the CLI (code lines outside comments
//! and test modules).

use std::collections::BTreeSet;
use std::path::Path;

mod cli;

/// Every `--flag` in the text.
fn flags_in(text: &str) -> Vec<String> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i + 2 < b.len() {
        let starts = b[i] == b'-'
            && b[i + 1] == b'-'
            && b[i + 2].is_ascii_lowercase()
            && (i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'-'));
        if !starts {
            i += 1;
            continue;
        }
        let mut j = i + 2;
        while j < b.len() && (b[j].is_ascii_lowercase() || b[j].is_ascii_digit() || b[j] == b'-') {
            j += 1;
        }
        out.push(text[i..j].trim_end_matches('-').to_owned());
        i = j;
    }
    out
}

/// `gyrotherm ARGS --help` and, recursively, its subcommands': every flag listed.
fn help_flags(args: &mut Vec<String>, into: &mut BTreeSet<String>) {
    let mut cmd = cli::gyrotherm();
    cmd.args(args.iter()).arg("--help");
    let out = cmd.output().expect("run gyrotherm");
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    into.extend(flags_in(&text));
    let subcommands: Vec<String> = text
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .filter_map(|l| l.split_whitespace().next().map(str::to_owned))
        .filter(|c| c != "help")
        .collect();
    for c in subcommands {
        args.push(c);
        help_flags(args, into);
        args.pop();
    }
}

/// (file, line number, flag) of every flag named in the code of the `.rs` files under `dir`.
fn named_flags(dir: &Path, out: &mut Vec<(String, usize, String)>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            named_flags(&path, out);
            continue;
        }
        if path.extension().is_none_or(|e| e != "rs") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        for (n, line) in text.lines().enumerate() {
            if line.trim() == "#[cfg(test)]" {
                break; // the test module tests the aliases themselves
            }
            let code = line.trim_start();
            // A deprecation warning names the hidden spelling it replaces.
            if code.starts_with("//")
                || code.starts_with("#[arg(")
                || code.contains("alias")
                || code.contains("is deprecated")
            {
                continue;
            }
            for f in flags_in(code) {
                out.push((path.display().to_string(), n + 1, f));
            }
        }
    }
}

#[test]
fn messages_name_the_flags_help_shows() {
    let mut shown = BTreeSet::new();
    help_flags(&mut Vec::new(), &mut shown);
    assert!(
        shown.contains("--tau-s") && shown.contains("--fill-gaps-max-s"),
        "help not read: {shown:?}"
    );
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut named = Vec::new();
    named_flags(&root.join("src"), &mut named);
    named_flags(&root.join("../gyrotherm/src"), &mut named);
    let hidden: Vec<String> = named
        .iter()
        .filter(|(_, _, f)| !shown.contains(f))
        .map(|(file, line, f)| format!("{file}:{line}: {f}"))
        .collect();
    assert!(
        hidden.is_empty(),
        "messages name flags --help does not show:\n{}",
        hidden.join("\n")
    );
}
