//! The report's warnings: each extrapolation finding said once per held-out log, naming the
//! models it concerns (the models of a comparison usually share their training ranges, so
//! one finding per model would repeat the same sentence for each of them).

use crate::compare::{Comparison, TestResult};
use crate::compensate::extrapolation_warnings;
use crate::fit::NamedLog;

/// The end of an extrapolation warning ([`extrapolation_warnings`]), rewritten to name the
/// models.
const EXTRAPOLATES: &str = "; the model extrapolates there";

/// One line per distinct finding on each held-out log, in the order first found: the
/// finding, then the models it concerns. A warning of `cmp` that is not an extrapolation
/// finding of one of its models is kept as it is.
pub(crate) fn grouped_warnings(test: &[NamedLog], cmp: &Comparison) -> Vec<String> {
    let mut out = Vec::new();
    for (log, result) in test.iter().zip(&cmp.tests) {
        // (finding, labels of the models it concerns)
        let mut findings: Vec<(String, Vec<&str>)> = Vec::new();
        let mut covered = Vec::new();
        for (fit, col) in cmp.fits.iter().zip(&cmp.columns) {
            for w in extrapolation_warnings(&fit.model, log.log) {
                covered.push(per_model_text(result, col.label, &w));
                match findings.iter_mut().find(|(f, _)| *f == w) {
                    Some((_, labels)) => {
                        if !labels.contains(&col.label) {
                            labels.push(col.label);
                        }
                    }
                    None => findings.push((w, vec![col.label])),
                }
            }
        }
        let all = cmp.columns.len();
        for (finding, labels) in &findings {
            out.push(format!(
                "{}: {}",
                result.name,
                name_models(finding, labels, all)
            ));
        }
        out.extend(
            result
                .warnings
                .iter()
                .filter(|w| !covered.contains(w))
                .cloned(),
        );
    }
    out
}

/// The per-model form the comparison gives a finding (see [`crate::compare`]).
fn per_model_text(result: &TestResult, label: &str, finding: &str) -> String {
    format!("{} ({label} model): {finding}", result.name)
}

/// `finding` with the models it concerns named: "…; the “linear” model extrapolates
/// there", "…; the models “linear” and “poly” extrapolate there", "…; all 4 models
/// (“a”, “b”, “c” and “d”) extrapolate there". Labels are quoted because some hold commas.
fn name_models(finding: &str, labels: &[&str], all: usize) -> String {
    let quoted: Vec<String> = labels.iter().map(|l| format!("“{l}”")).collect();
    let list = match quoted.as_slice() {
        [] => String::new(),
        [one] => one.clone(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    };
    let who = match labels.len() {
        1 => format!("the {list} model extrapolates"),
        n if n == all && n > 2 => format!("all {n} models ({list}) extrapolate"),
        _ => format!("the models {list} extrapolate"),
    };
    match finding.strip_suffix(EXTRAPOLATES) {
        Some(head) => format!("{head}; {who} there"),
        None => format!("{finding} ({who})"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn models_are_named_once() {
        let f = "temperature 1 to 2 °C leaves the training range 0 to 1 °C; the model extrapolates there";
        assert_eq!(
            name_models(f, &["linear"], 4),
            "temperature 1 to 2 °C leaves the training range 0 to 1 °C; the “linear” model extrapolates there"
        );
        assert_eq!(
            name_models(f, &["linear", "LSTM, He et al."], 4),
            "temperature 1 to 2 °C leaves the training range 0 to 1 °C; the models “linear” and “LSTM, He et al.” extrapolate there"
        );
        assert_eq!(
            name_models(f, &["a", "b", "c"], 3),
            "temperature 1 to 2 °C leaves the training range 0 to 1 °C; all 3 models (“a”, “b” and “c”) extrapolate there"
        );
        assert_eq!(
            name_models("odd finding", &["a"], 3),
            "odd finding (the “a” model extrapolates)"
        );
    }
}
