//! The figures a spec sheet can limit: their keys (the names `gyrotherm evaluate --json` and
//! `gyrotherm allan --json` print), units and definitions, and how they are measured on one
//! output column of one log. docs/method.md §7 tabulates the same list with the clause of
//! the standard each follows; a test keeps the two in step.

use std::collections::BTreeMap;

use crate::allan::{self, DevKind, NoiseModel, TauSet};
use crate::csvlog::TestLog;
use crate::metrics::{self, EvaluationError, EvaluationOptions};

/// One figure a spec sheet may limit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FigureDef {
    /// The key in `[limits]`, in `evaluate --json` and in the lot database.
    pub key: &'static str,
    /// Unit of its value.
    pub unit: &'static str,
    /// What it is, in a few words.
    pub what: &'static str,
    /// Which log gives it: static logs, rate-table logs, or both.
    pub from: LogKind,
}

/// The kind of log a figure is measured on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LogKind {
    /// A log without a table column (or a table standing still).
    Static,
    /// A rate-table log.
    RateTable,
    /// Either kind (bias and bias stability come from the stop segments of a rate table).
    Any,
}

/// Every figure a spec sheet may limit, in the order verdicts are printed.
pub const FIGURES: &[FigureDef] = &[
    FigureDef {
        key: "bias_dph",
        unit: "°/h",
        what: "bias B0, mean output",
        from: LogKind::Any,
    },
    FigureDef {
        key: "bias_stability_dph",
        unit: "°/h",
        what: "bias stability, 1σ of τ-means",
        from: LogKind::Any,
    },
    FigureDef {
        key: "arw_deg_rt_h",
        unit: "°/√h",
        what: "angle random walk (Allan curve, slope −1/2)",
        from: LogKind::Static,
    },
    FigureDef {
        key: "bias_instability_dph",
        unit: "°/h",
        what: "bias instability (Allan curve, flat part)",
        from: LogKind::Static,
    },
    FigureDef {
        key: "rrw_deg_h_rt_h",
        unit: "°/h/√h",
        what: "rate random walk (Allan curve, slope +1/2)",
        from: LogKind::Static,
    },
    FigureDef {
        key: "quantization_arcsec",
        unit: "″",
        what: "quantization noise (Allan curve, slope −1)",
        from: LogKind::Static,
    },
    FigureDef {
        key: "rate_ramp_deg_h2",
        unit: "°/h²",
        what: "rate ramp (Allan curve, slope +1)",
        from: LogKind::Static,
    },
    FigureDef {
        key: "scale_factor",
        unit: "1",
        what: "scale factor K, least-squares slope",
        from: LogKind::RateTable,
    },
    FigureDef {
        key: "intercept_dps",
        unit: "°/s",
        what: "scale-factor fit intercept F0",
        from: LogKind::RateTable,
    },
    FigureDef {
        key: "nonlinearity_ppm",
        unit: "ppm",
        what: "scale-factor nonlinearity",
        from: LogKind::RateTable,
    },
    FigureDef {
        key: "asymmetry_ppm",
        unit: "ppm",
        what: "scale-factor asymmetry",
        from: LogKind::RateTable,
    },
    FigureDef {
        key: "sf_error_ppm",
        unit: "ppm",
        what: "max |K(t) − 1| over the rate segments",
        from: LogKind::RateTable,
    },
    FigureDef {
        key: "sf_thermal_error_ppm",
        unit: "ppm",
        what: "scale-factor thermal error, max |K(t) − K_ref|",
        from: LogKind::RateTable,
    },
];

/// The definition of `key`, if it is a known figure.
pub fn figure(key: &str) -> Option<&'static FigureDef> {
    FIGURES.iter().find(|f| f.key == key)
}

/// Measured figures of one output column of one log, by key. Figures the log cannot give
/// (noise terms of a rate-table log, scale factor of a static one, a noise term whose slope
/// the Allan curve does not show) are absent, never NaN.
pub type Figures = BTreeMap<&'static str, f64>;

/// Settings of a measurement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeasureOptions {
    /// Bias-stability smoothing time and scale-factor settings (`gyrotherm evaluate`).
    pub evaluation: EvaluationOptions,
    /// Whether to read the Allan noise terms (static logs; one OADEV curve at octave τ).
    pub noise_terms: bool,
}

impl Default for MeasureOptions {
    fn default() -> Self {
        MeasureOptions {
            evaluation: EvaluationOptions::default(),
            noise_terms: true,
        }
    }
}

/// Every figure of `output_dps` (°/s, one value per sample of `log`): the figures of
/// `gyrotherm evaluate` and, for a static log when asked, the Allan noise terms of
/// `gyrotherm allan`.
pub fn measure(
    log: &TestLog,
    output_dps: &[f64],
    opts: &MeasureOptions,
) -> Result<Figures, EvaluationError> {
    let period = log.sample_period_s();
    let e = metrics::evaluate(
        "gyro_dps",
        &log.time_s,
        output_dps,
        period,
        log.table_dps.as_deref(),
        &opts.evaluation,
    )?;
    let mut f = Figures::new();
    let mut put = |k: &'static str, v: f64| {
        if v.is_finite() {
            f.insert(k, v);
        }
    };
    put("bias_dph", e.bias_dph);
    put("bias_stability_dph", e.bias_stability_dph);
    if let Some(s) = &e.scale {
        put("scale_factor", s.scale_factor);
        put("intercept_dps", s.intercept_dps);
        put("nonlinearity_ppm", s.nonlinearity_ppm);
        if let Some(a) = s.asymmetry_ppm {
            put("asymmetry_ppm", a);
        }
        put("sf_thermal_error_ppm", s.sf_thermal_error_ppm);
        let sf_error = s
            .scale_over_time
            .iter()
            .map(|k| (k.scale - 1.0).abs() * 1e6)
            .filter(|v| v.is_finite())
            .reduce(f64::max);
        if let Some(v) = sf_error {
            put("sf_error_ppm", v);
        }
    }
    if opts.noise_terms && log.is_static() {
        // The noise terms are defined on the Allan deviation (IEEE Std 952 annex C); octave
        // τ is what `gyrotherm allan` uses by default, so the numbers agree with it. A curve
        // that cannot be made (too short a log) gives no noise term rather than an error:
        // a limit on one is then refused as a figure the run cannot give.
        if let Ok(curve) = allan::deviation(
            output_dps,
            period,
            DevKind::Oadev,
            &TauSet::Octave,
            NoiseModel::Identify,
        ) {
            let t = allan::noise_terms(&curve, 3600.0);
            let terms = [
                ("arw_deg_rt_h", t.arw_deg_rt_h),
                ("bias_instability_dph", t.bias_instability_dph),
                ("rrw_deg_h_rt_h", t.rrw_deg_h_rt_h),
                ("quantization_arcsec", t.quantization_arcsec),
                ("rate_ramp_deg_h2", t.rate_ramp_deg_h2),
            ];
            for (k, v) in terms {
                if let Some(v) = v {
                    put(k, v.value);
                }
            }
        }
    }
    Ok(f)
}
