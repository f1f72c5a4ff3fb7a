use std::path::Path;

use super::*;

fn parse(text: &str) -> Result<Spec, SpecError> {
    Spec::parse(text, Path::new("spec.toml"))
}

#[test]
fn parses_limits_in_figure_order() {
    let s = parse(
        "name = \"acceptance\"\n[limits]\nsf_thermal_error_ppm = { max = 30 }\n\
         bias_stability_dph = { max = 0.02 }\nbias_dph = { min = -0.5, max = 0.5 }\n",
    )
    .unwrap();
    assert_eq!(s.name, "acceptance");
    let keys: Vec<&str> = s.limits().map(|(d, _)| d.key).collect();
    assert_eq!(
        keys,
        ["bias_dph", "bias_stability_dph", "sf_thermal_error_ppm"]
    );
    // An integer limit (30) is read as the number it is.
    assert_eq!(s.limit("sf_thermal_error_ppm").unwrap().max, Some(30.0));
    assert!(!s.needs_noise_terms());
}

#[test]
fn unknown_figure_names_place_and_nearest_names() {
    let e = parse("[limits]\nbias_stabilty_dph = { max = 0.02 }\n").unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.starts_with("spec.toml:2:1: unknown figure `bias_stabilty_dph`"),
        "{msg}"
    );
    assert!(msg.contains("did you mean `bias_stability_dph`"), "{msg}");
    // A name near nothing lists every known figure instead.
    let msg = parse("[limits]\nzzz = { max = 1 }\n")
        .unwrap_err()
        .to_string();
    assert!(msg.contains("known figures: bias_dph,"), "{msg}");
}

#[test]
fn malformed_limits_are_refused_with_place() {
    let cases = [
        // (text, what the message must contain)
        (
            "[limits]\nbias_dph = { }\n",
            "spec.toml:2:12: limit on `bias_dph`: give `min`",
        ),
        (
            "[limits]\nbias_dph = { min = 2, max = 1 }\n",
            "min = 2 is above max = 1",
        ),
        (
            "[limits]\nbias_dph = { max = nan }\n",
            "is not a finite number",
        ),
        ("[limits]\nbias_dph = { max = \"0.1\" }\n", "spec.toml:2:"),
        (
            "[limits]\nbias_dph = { maximum = 1 }\n",
            "unknown field `maximum`",
        ),
        ("[limit]\nbias_dph = { max = 1 }\n", "unknown field `limit`"),
        ("name = \"x\"\n", "no limits"),
        ("[limits\n", "spec.toml:1:"),
    ];
    for (text, want) in cases {
        let msg = parse(text).unwrap_err().to_string();
        assert!(msg.contains(want), "{text:?}: want {want:?} in {msg:?}");
    }
}

#[test]
fn judge_gives_value_limit_margin_and_verdict() {
    let s =
        parse("[limits]\nbias_stability_dph = { max = 0.02 }\nbias_dph = { min = -1 }\n").unwrap();
    let mut a = Figures::new();
    a.insert("bias_stability_dph", 0.015);
    a.insert("bias_dph", 0.3);
    let mut b = Figures::new();
    b.insert("bias_stability_dph", 0.025);
    let v = judge(&s, &[("a.csv".into(), a.clone()), ("b.csv".into(), b)]).unwrap();
    assert!(!v.pass);
    let got: Vec<(&str, &str, bool)> = v
        .figures
        .iter()
        .map(|f| (f.figure, f.log.as_str(), f.pass))
        .collect();
    assert_eq!(
        got,
        [
            ("bias_dph", "a.csv", true),
            ("bias_stability_dph", "a.csv", true),
            ("bias_stability_dph", "b.csv", false),
        ]
    );
    // Margins by hand: -1 → 0.3 is 1.3 inside; 0.02 − 0.015 = 0.005; 0.02 − 0.025 = −0.005.
    let m: Vec<f64> = v.figures.iter().map(|f| f.margin).collect();
    for (g, w) in m.iter().zip([1.3, 0.005, -0.005]) {
        assert!((g - w).abs() < 1e-12, "margin {g} want {w}");
    }
    let v = judge(&s, &[("a.csv".into(), a)]).unwrap();
    assert!(v.pass);
    assert_eq!(v.lines().last().unwrap(), "verdict: PASS (spec spec.toml)");
}

#[test]
fn a_figure_no_log_gives_is_an_error() {
    let s = parse("[limits]\nsf_thermal_error_ppm = { max = 30 }\n").unwrap();
    let mut f = Figures::new();
    f.insert("bias_stability_dph", 0.01);
    let e = judge(&s, &[("static.csv".into(), f)]).unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains("`sf_thermal_error_ppm`") && msg.contains("a rate-table log"),
        "{msg}"
    );
}

#[test]
fn method_md_defines_every_figure() {
    // docs/method.md §7 is the table of definitions a spec's figures follow; every key the
    // code accepts must have its row (and no row may name a key the code refuses).
    let doc = include_str!("../../../../docs/method.md");
    let table: Vec<&str> = doc
        .lines()
        .skip_while(|l| !l.starts_with("## 7."))
        .filter_map(|l| l.strip_prefix("| `"))
        .filter_map(|l| l.split('`').next())
        .collect();
    let keys: Vec<&str> = FIGURES.iter().map(|d| d.key).collect();
    assert_eq!(table, keys);
}

#[test]
fn edit_distance_is_levenshtein() {
    // Classic textbook pairs.
    assert_eq!(edit_distance("kitten", "sitting"), 3);
    assert_eq!(edit_distance("", "abc"), 3);
    assert_eq!(edit_distance("flaw", "lawn"), 2);
}
