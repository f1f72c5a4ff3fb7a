//! Verdicts of a held-out comparison: each model column judged on every held-out log.

use serde::Serialize;

use super::{judge, measure, MeasureOptions, Spec, SpecError, Verdict};
use crate::compare::{CompareConfig, Comparison};
use crate::fit::NamedLog;
use crate::metrics::EvaluationOptions;

/// The verdict of one column of a comparison.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub(crate) struct ColumnVerdict {
    /// The column's key (`linear`, `poly`, `lstm`, `published`).
    pub key: &'static str,
    /// Its name in the table.
    pub label: &'static str,
    pub verdict: Verdict,
}

/// Judge the compensated output of every column of `cmp` (run on `test`) against `spec`,
/// with the comparison's τ and settle time.
pub(crate) fn judge_comparison(
    spec: &Spec,
    cmp: &Comparison,
    test: &[NamedLog],
    cfg: &CompareConfig,
) -> Result<Vec<ColumnVerdict>, SpecError> {
    let opts = MeasureOptions {
        evaluation: EvaluationOptions {
            tau_s: cfg.tau_s,
            settle_s: cfg.settle_s,
            reference_scale: None,
        },
        noise_terms: spec.needs_noise_terms(),
    };
    let mut out = Vec::new();
    for col in &cmp.columns {
        let mut measured = Vec::new();
        for (t, r) in test.iter().zip(&cmp.tests) {
            // A column that could not compensate this log has no output to judge here; the
            // table and the warnings say why.
            let Some(m) = r.methods.iter().find(|m| m.key == col.key) else {
                continue;
            };
            let f = measure(t.log, &m.compensated.gyro_comp_dps, &opts).map_err(|source| {
                SpecError::Measure {
                    log: t.name.to_string(),
                    source,
                }
            })?;
            measured.push((t.name.to_string(), f));
        }
        out.push(ColumnVerdict {
            key: col.key,
            label: col.label,
            verdict: judge(spec, &measured)?,
        });
    }
    Ok(out)
}
