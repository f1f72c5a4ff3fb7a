//! Figures 5 and 6: the scale factor per rate segment and the output at the table rates.

use super::{fmt_num, Builder};
use crate::compare::{CompareConfig, MethodResult};
use crate::csvlog::TestLog;
use crate::fit::NamedLog;
use crate::metrics::{self, ScaleFactorOptions, DPS_TO_DPH};
use crate::report::figures::{
    rate_table_figure, scale_factor_figure, RateAxis, RateSegment, RateTableData, ScaleFactorData,
};
use crate::report::ReportError;

/// Figure 5's data: one point per usable rate segment.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ScalePoints {
    /// Middle of each rate segment, s.
    pub time_s: Vec<f64>,
    /// Measured K − 1, ppm: K = (segment mean − local bias) / table rate of the raw output
    /// ([`metrics::scale_factor()`], `scale_over_time`).
    pub measured_ppm: Vec<f64>,
    /// Predicted K − 1, ppm: mean of `scale` over the samples the measurement used (the
    /// segment after its settle time).
    pub predicted_ppm: Vec<f64>,
}

/// Measured against predicted scale factor of a rate-table log: `scale` is the predicted K
/// per sample (e.g. `Compensated::scale`), `settle_s` the time dropped at each segment start.
/// Errors: no table column, `scale` of another length, or a log the scale-factor metric
/// refuses (its message).
pub fn scale_factor_points(
    log: &TestLog,
    scale: &[f64],
    settle_s: f64,
) -> Result<ScalePoints, String> {
    let Some(table) = log.table_dps.as_deref() else {
        return Err("the log has no table_dps column".to_owned());
    };
    if scale.len() != log.len() {
        return Err(format!(
            "{} predicted scale factors for {} samples",
            scale.len(),
            log.len()
        ));
    }
    let opts = ScaleFactorOptions {
        settle_s,
        ..Default::default()
    };
    let r = metrics::scale_factor(&log.time_s, &log.gyro_dps, table, &opts)
        .map_err(|e| e.to_string())?;
    // `scale_over_time` has one entry per usable non-stop segment, in order; the used
    // samples are the tail of the segment (the settle time is dropped at its start).
    let rate_segs = r
        .segments
        .iter()
        .filter(|s| s.used_samples > 0 && s.table_dps.abs() > opts.rate_tol_dps);
    let mut out = ScalePoints::default();
    for (seg, k) in rate_segs.zip(&r.scale_over_time) {
        let used = &scale[seg.end - seg.used_samples..seg.end];
        let mean = used.iter().sum::<f64>() / used.len() as f64;
        out.time_s.push(k.time_s);
        out.measured_ppm.push((k.scale - 1.0) * 1e6);
        out.predicted_ppm.push((mean - 1.0) * 1e6);
    }
    Ok(out)
}

/// Figures 5 and 6 on a rate-table log, `m` the compensation shown.
pub(super) fn rate_table_figures(
    b: &mut Builder,
    l: &NamedLog,
    m: &MethodResult,
    cfg: &CompareConfig,
) -> Result<(), ReportError> {
    let log: &TestLog = l.log;
    let Some(table) = log.table_dps.as_deref() else {
        b.note(5, "the rate-table log has no table_dps column");
        b.note(6, "the rate-table log has no table_dps column");
        return Ok(());
    };
    let label = m.label;
    match scale_factor_points(log, &m.compensated.scale, cfg.settle_s) {
        Err(e) => b.note(5, &format!("{}: {e}", l.name)),
        Ok(ScalePoints {
            time_s: t,
            measured_ppm: measured,
            predicted_ppm: predicted,
        }) => {
            if t.is_empty() {
                b.note(5, &format!("{} has no usable rate segment", l.name));
            } else {
                let files = scale_factor_figure(
                    &b.path(4),
                    &ScaleFactorData {
                        time_s: &t,
                        measured_ppm: &measured,
                        predicted_ppm: &predicted,
                    },
                )?;
                b.add(
                    &files,
                    format!(
                        "Scale factor of {} per rate segment, as K − 1 in ppm: measured \
                         ((segment mean − local bias) / table rate, raw output, first {} s of \
                         each segment dropped) against predicted ({label} model's K, mean over \
                         the same samples).",
                        l.name,
                        fmt_num(cfg.settle_s)
                    ),
                );
            }
        }
    }

    // 6: the highest positive and the lowest negative table rate.
    let mut rates: Vec<f64> = table.iter().copied().filter(|w| *w != 0.0).collect();
    rates.sort_by(f64::total_cmp);
    rates.dedup();
    let mut chosen = Vec::new();
    if let Some(&w) = rates.last().filter(|w| **w > 0.0) {
        chosen.push(w);
    }
    if let Some(&w) = rates.first().filter(|w| **w < 0.0) {
        chosen.push(w);
    }
    if chosen.is_empty() {
        b.note(6, &format!("{} has no non-zero table rate", l.name));
        return Ok(());
    }
    let tol = crate::table_segments::RATE_TOLERANCE_DPS;
    let segs = crate::table_segments::segments(table, tol);
    // (table rate °/s, time s, error before °/h, error after °/h)
    type RateErrors = (f64, Vec<f64>, Vec<f64>, Vec<f64>);
    let mut data: Vec<RateErrors> = Vec::new();
    for &w in &chosen {
        let (mut x, mut before, mut after) = (Vec::new(), Vec::new(), Vec::new());
        for s in segs.iter().filter(|s| (s.rate_dps - w).abs() <= tol) {
            if !x.is_empty() {
                // A gap between segments: the figure breaks its lines at non-finite values.
                x.push(f64::NAN);
                before.push(f64::NAN);
                after.push(f64::NAN);
            }
            let t0 = log.time_s[s.start];
            for i in s.start..s.end {
                if log.time_s[i] - t0 < cfg.settle_s {
                    continue;
                }
                x.push(log.time_s[i]);
                before.push((log.gyro_dps[i] - w) * DPS_TO_DPH);
                after.push((m.compensated.gyro_comp_dps[i] - w) * DPS_TO_DPH);
            }
        }
        if x.iter().any(|t| t.is_finite()) {
            data.push((w, x, before, after));
        }
    }
    if data.is_empty() {
        b.note(
            6,
            &format!("{}: no samples left after the settle time", l.name),
        );
        return Ok(());
    }
    let segments: Vec<RateSegment> = data
        .iter()
        .map(|(w, x, before, after)| RateSegment {
            rate_dps: *w,
            x,
            before_dph: before,
            after_dph: after,
        })
        .collect();
    let files = rate_table_figure(
        &b.path(5),
        &RateTableData {
            axis: RateAxis::TimeS,
            segments: &segments,
        },
    )?;
    let rates: Vec<String> = chosen.iter().map(|w| format!("{w:+} °/s")).collect();
    b.add(
        &files,
        format!(
            "Output error (output − table rate, °/h) of {} at {} before and after {label} \
             compensation; first {} s of each segment dropped.",
            l.name,
            rates.join(" and "),
            fmt_num(cfg.settle_s)
        ),
    );
    Ok(())
}
