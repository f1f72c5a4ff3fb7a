//! `evaluate` on an inertial unit's log: the figures of each gyro column, raw and with a unit
//! model compensated, each axis judged as a single-axis log ([`axis_test_log`]) against a spec
//! sheet when one is given.

use serde::Serialize;

use crate::compare::unit::axis_test_log;
use crate::compensate::unit::compensate_imu;
use crate::csvlog::{ImuLog, TestLog, GYRO_COL};
use crate::metrics::Evaluation;
use crate::model::unit::ImuModel;
use crate::settings::evaluate::{EvaluateSettings, ResolvedTau};
use crate::spec::unit::{ImuJudgeError, UnitVerdict};
use crate::spec::{self, MeasureOptions, Spec, SpecError, Verdict};

/// The figures of one axis: of the raw gyro column, and of its compensated output when a
/// unit model was given.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub(crate) struct AxisEvaluation {
    /// The gyro column.
    pub gyro: String,
    /// The temperature columns its model reads (empty without a model).
    pub temps: Vec<String>,
    pub raw: Evaluation,
    pub compensated: Option<Evaluation>,
    /// The axis's verdict against a spec sheet ([`evaluate_imu_spec`]): of the compensated
    /// output when a unit model was given, else of the raw column.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verdict: Option<Verdict>,
}

/// What [`evaluate_imu_spec`] returns: the axes' figures (each with its verdict when a spec
/// sheet was given), the τ used, and the unit's verdict.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct UnitEvaluation {
    pub axes: Vec<AxisEvaluation>,
    pub tau: ResolvedTau,
    pub verdict: Option<UnitVerdict>,
}

impl UnitEvaluation {
    /// The form `gyrotherm evaluate --json` prints for a unit (and Python returns): `tau_s`,
    /// `axes` (each with its `verdict` when judged, in the single-axis verdict's form) and,
    /// when judged, the unit's `verdict` beside them.
    pub fn to_json(&self) -> serde_json::Value {
        let mut j = serde_json::json!({ "tau_s": self.tau.tau_s, "axes": self.axes });
        if let (Some(v), Some(o)) = (&self.verdict, j.as_object_mut()) {
            o.insert(
                "verdict".into(),
                serde_json::to_value(v).unwrap_or(serde_json::Value::Null),
            );
        }
        j
    }
}

/// `evaluate` on a unit log: the figures of each gyro column (raw, in °/s as read), and with
/// `model` of each axis's compensated output (`G_comp`, the flight compensator's output as
/// `compensate` writes it); `settings.column` must be the default (the gyro columns are
/// named by the log's column list). With `spec`, each axis judged against the spec sheet as the
/// single-axis `evaluate --spec` judges one column (the same figures, measured on the axis's
/// single-axis log, [`axis_test_log`]): the compensated output when `model` is given (the
/// unit as it is flown), else the raw gyro column. `log_name` names the log in the
/// verdicts' lines. The unit passes only when every axis passes.
pub(crate) fn evaluate_imu_spec(
    log: &ImuLog,
    model: Option<&ImuModel>,
    settings: &EvaluateSettings,
    spec: Option<&Spec>,
    log_name: &str,
) -> Result<UnitEvaluation, ImuJudgeError> {
    if settings.column != GYRO_COL {
        return Err(ImuJudgeError::Layout(format!(
            "column {:?}: a unit log is judged per gyro column (--gyro-col lists them); leave \
             the column at its default {GYRO_COL}",
            settings.column
        )));
    }
    if log.gyro.is_empty() || log.temp.is_empty() {
        return Err(ImuJudgeError::Layout(
            "the log has no gyro or no temperature column".into(),
        ));
    }
    let comp = model
        .map(|m| compensate_imu(m, log))
        .transpose()
        .map_err(ImuJudgeError::Unit)?;
    let mut axes = Vec::with_capacity(log.gyro.len());
    let mut tau = None;
    for (k, g) in log.gyro.iter().enumerate() {
        let axis_log = axis_test_log(log, k, 0);
        let tau0_s = axis_log.sample_period_s();
        if !(tau0_s.is_finite() && tau0_s > 0.0) {
            return Err(ImuJudgeError::Layout(
                "cannot tell the sample period (need at least two samples with increasing time)"
                    .into(),
            ));
        }
        let judge = |values: &[f64], output: &'static str, name: String| {
            let (mut e, t) = settings
                .evaluate(&axis_log, values, tau0_s)
                .map_err(|source| ImuJudgeError::Evaluate {
                    gyro: g.name.clone(),
                    output,
                    source,
                })?;
            e.column = name;
            Ok::<_, ImuJudgeError>((e, t))
        };
        let (raw, t) = judge(&g.values, "raw", g.name.clone())?;
        tau.get_or_insert(t);
        // The axis's compensated output and sensors (compensate_imu returns the model's axes
        // in order; this column's is found by name), or none without a model.
        let comp_axis = match (&comp, model) {
            (Some(c), Some(m)) => {
                let i = m
                    .axes
                    .iter()
                    .position(|a| a.gyro == g.name)
                    .ok_or_else(|| {
                        ImuJudgeError::Layout(format!("the model has no axis {}", g.name))
                    })?;
                Some((c[i].gyro_comp_dps.as_slice(), &m.axes[i].temps))
            }
            _ => None,
        };
        let (compensated, temps) = match comp_axis {
            Some((values, temps)) => {
                let (e, _) = judge(values, "compensated", format!("{}_comp", g.name))?;
                (Some(e), temps.clone())
            }
            None => (None, Vec::new()),
        };
        let verdict = match spec {
            Some(sp) => {
                let (values, output) = match comp_axis {
                    Some((values, _)) => (values, "compensated"),
                    None => (g.values.as_slice(), "raw"),
                };
                Some(judge_axis(
                    sp, &axis_log, values, settings, tau0_s, log_name, &g.name, output,
                )?)
            }
            None => None,
        };
        axes.push(AxisEvaluation {
            gyro: g.name.clone(),
            temps,
            raw,
            compensated,
            verdict,
        });
    }
    let tau = tau.ok_or_else(|| ImuJudgeError::Layout("no gyro column".into()))?;
    let verdict = spec.map(|sp| {
        UnitVerdict::from_axes(
            &sp.name,
            &sp.sha256,
            if model.is_some() {
                "compensated"
            } else {
                "raw"
            },
            axes.iter()
                .map(|a| (a.gyro.as_str(), a.verdict.as_ref().is_none_or(|v| v.pass))),
        )
    });
    Ok(UnitEvaluation { axes, tau, verdict })
}

/// One axis's output judged against `spec`, as `evaluate --spec` judges one column.
#[allow(clippy::too_many_arguments)]
fn judge_axis(
    spec: &Spec,
    axis_log: &TestLog,
    values: &[f64],
    settings: &EvaluateSettings,
    tau0_s: f64,
    log_name: &str,
    gyro: &str,
    output: &'static str,
) -> Result<Verdict, ImuJudgeError> {
    let (rate_dps, evaluation, _) =
        settings
            .prepare(values, tau0_s)
            .map_err(|source| ImuJudgeError::Evaluate {
                gyro: gyro.to_owned(),
                output,
                source,
            })?;
    let opts = MeasureOptions {
        evaluation,
        noise_terms: spec.needs_noise_terms(),
    };
    let spec_err = |source| ImuJudgeError::Spec {
        gyro: gyro.to_owned(),
        output,
        source: Box::new(source),
    };
    let f = spec::measure(axis_log, &rate_dps, &opts).map_err(|source| {
        spec_err(SpecError::Measure {
            log: log_name.to_owned(),
            source,
        })
    })?;
    spec::judge(spec, &[(log_name.to_owned(), f)]).map_err(spec_err)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::csvlog::NamedSeries;

    fn series(name: &str, v: [f64; 2]) -> NamedSeries {
        NamedSeries {
            name: name.into(),
            values: v.into(),
        }
    }

    #[test]
    fn evaluate_refuses_a_column_other_than_the_gyros() {
        let log = ImuLog {
            time_s: vec![0.0, 1.0],
            gyro: vec![series("gx", [1.0, 2.0])],
            temp: vec![series("t", [20.0, 21.0])],
            ..Default::default()
        };
        let s = EvaluateSettings {
            column: "other_dps".into(),
            ..Default::default()
        };
        let e = evaluate_imu_spec(&log, None, &s, None, "")
            .unwrap_err()
            .to_string();
        assert!(e.contains("judged per gyro column"), "{e}");
    }
}
