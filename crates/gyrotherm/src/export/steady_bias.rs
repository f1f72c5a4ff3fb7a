//! What the autopilot targets ([`super::ardupilot`], [`super::px4`]) share: the model's
//! steady-state bias over its training temperature range, the least-squares cubic fitted to
//! it, how well that cubic holds, and what it cannot carry.
//!
//! **Steady state.** Both autopilots correct the gyro offset by a polynomial in the IMU
//! temperature alone. A gyrotherm model reads more: the temperature rate dT, the thermal-state
//! lags, an LSTM's memory. At a constant temperature held long enough, dT is 0, every lag has
//! reached T (so `T − lag` is 0) and an LSTM has settled; what remains is the steady-state bias
//! B(T), the part a polynomial in T can carry. It is computed by running the model's own
//! flight compensator ([`crate::compensate::compensator`], or the unit's axis compensators)
//! on a constant temperature: the lags start at the first sample's temperature and dT is 0
//! from the first step, so a least-squares model is settled at once; an LSTM is stepped until
//! its output stops changing.
//!
//! **Fit.** B(T) is sampled at [`GRID_POINTS`] temperatures evenly over the training range the
//! model file records (`training.temp_range_c`; for a unit, the range every axis was trained
//! over), converted from °/s to rad/s (both autopilots work in rad/s), and fitted by least
//! squares with `c0 + c1·x + c2·x² + c3·x³` (x the target's temperature variable). The
//! coefficients are rounded to `f32`, as both autopilots store their parameters, and the fit
//! error is that of the rounded numbers: max and RMS of the difference over the grid, in °/h.
//!
//! **Axes.** A single-gyro model is one axis: [`AutopilotSettings::axis`] picks which of the
//! autopilot's X, Y, Z it fills, and the other two get zero coefficients (the autopilot leaves
//! them as they are). An inertial-unit model must have three axes: X, Y and Z in its column
//! order.

use std::fmt::Write as _;

use gyrotherm_core::features::FeatureKind;

use super::{ExportError, ExportTarget};
use crate::model::unit::ImuModel;
use crate::model::{ModelFile, SubModel};
use crate::settings::autopilot::AutopilotSettings;
use crate::settings::SettingError;

/// Temperatures the steady-state bias is sampled at, evenly over the training range.
pub const GRID_POINTS: usize = 201;
/// A training range narrower than this is warned about, °C: ArduPilot's own learning asks
/// for at least 10 °C (`TEMP_RANGE_MIN` in `AP_InertialSensor_tempcal.cpp`), and a cubic over
/// less says little about the temperatures beyond it, where both autopilots hold the
/// correction at its edge value.
pub const MIN_RANGE_C: f64 = 10.0;
/// Most steps an LSTM is run at one temperature to settle (about 55 h at 1 s).
const MAX_SETTLE_STEPS: u32 = 200_000;
/// An output that changes less than this per step for [`SETTLED_STEPS`] steps is settled,
/// °/s (3.6e-7 °/h).
const SETTLED_DPS: f64 = 1e-10;
const SETTLED_STEPS: u32 = 100;
/// °/s to °/h.
const DPH_PER_DPS: f64 = 3600.0;

/// Why a model cannot be written as autopilot parameters.
#[derive(Debug)]
#[non_exhaustive]
pub enum AutopilotError {
    /// A setting is refused.
    Setting(SettingError),
    /// PX4 export without the gyro's device id.
    NoDeviceId,
    /// An inertial-unit model whose axis count is not three.
    Axes { n: usize },
    /// The training range recorded in the model is unusable (not finite, empty, or the
    /// unit's axes were trained over ranges that do not overlap).
    Range { min_c: f64, max_c: f64 },
    /// The model gives no bias at this temperature (axis 0 = X).
    NoBias { axis: usize, temp_c: f64 },
    /// The model's output does not settle at this temperature (an LSTM that oscillates).
    Unsettled { axis: usize, temp_c: f64 },
    /// The least-squares fit failed.
    Fit,
    /// The target writes flight code, not autopilot parameters.
    NotAutopilot(ExportTarget),
}

impl std::fmt::Display for AutopilotError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let axis = axis_name;
        match self {
            AutopilotError::Setting(e) => e.fmt(f),
            AutopilotError::NoDeviceId => f.write_str(
                "PX4 matches TC_Gn_ID to the gyro's device id: give it with --device-id (the \
                 DEVICE_ID of the sensor_gyro topic, or the value of CAL_GYROn_ID)",
            ),
            AutopilotError::Axes { n } => write!(
                f,
                "the inertial-unit model has {n} gyro axes; an autopilot IMU has three (X, Y, Z \
                 in the model's column order): fit the unit on three gyro columns, or export \
                 each axis's single-gyro model with --axis"
            ),
            AutopilotError::Range { min_c, max_c } => write!(
                f,
                "the model's training temperature range ({min_c} to {max_c} °C) holds no \
                 interval to fit a polynomial over"
            ),
            AutopilotError::NoBias { axis: a, temp_c } => write!(
                f,
                "axis {}: the model gives no bias at {temp_c} °C (outside its temperature \
                 sensor's limits?)",
                axis(*a)
            ),
            AutopilotError::Unsettled { axis: a, temp_c } => write!(
                f,
                "axis {}: the model's bias does not settle at a constant {temp_c} °C, so it \
                 has no steady state for a polynomial to carry",
                axis(*a)
            ),
            AutopilotError::Fit => f.write_str("the least-squares polynomial fit failed"),
            AutopilotError::NotAutopilot(t) => {
                write!(f, "target {t} writes flight code, not autopilot parameters")
            }
        }
    }
}

impl From<AutopilotError> for ExportError {
    fn from(e: AutopilotError) -> Self {
        ExportError::Autopilot(e)
    }
}

// The setting's own text is in the message, so it is no further source.
impl std::error::Error for AutopilotError {}

/// The model an autopilot export reads.
#[derive(Debug, Clone, Copy)]
pub enum ModelRef<'a> {
    /// A single-gyro model.
    Single(&'a ModelFile),
    /// An inertial-unit model (three axes).
    Unit(&'a ImuModel),
}

/// What a steady-state polynomial leaves out, in the generator's words.
const NOTE_RATE_LAG: &str = "the bias terms in dT and in T - lag (the response to temperature \
                             change) are zero at steady state and are not carried";
const NOTE_LSTM: &str = "the LSTM's response to temperature history is not carried, only its \
                         settled output at constant temperature";
const NOTE_SCALE: &str = "the scale-factor model is not carried (the autopilot's gyro \
                          temperature calibration corrects the offset only)";
const NOTE_COVERAGE: &str = "the coverage map and the output status are not carried";
const NOTE_MORE: &str = "further temperature sensors are taken at the IMU temperature";
const NOTE_NO_BIAS: &str = "an axis without a bias model gets zero coefficients";
const NOTE_SINGLE: &str = "a single-gyro model fills one axis; the other two get zero \
                           coefficients (left uncorrected)";
const NOTE_CLAMP: &str = "outside TMIN..TMAX the autopilot holds the correction at its edge \
                          value";

/// The model's steady-state bias over its training range, per autopilot axis.
#[derive(Debug, Clone, PartialEq)]
pub struct SteadyBias {
    /// The training range as the autopilot stores it (`f32`), °C.
    pub temp_min_c: f32,
    pub temp_max_c: f32,
    /// The grid, °C: [`GRID_POINTS`] temperatures evenly from `temp_min_c` to `temp_max_c`.
    pub temps_c: Vec<f64>,
    /// B(T) at each grid temperature, °/s, per axis X, Y, Z (None: the axis is left
    /// uncorrected).
    pub bias_dps: [Option<Vec<f64>>; 3],
    /// What a polynomial in T does not carry of this model.
    pub notes: Vec<&'static str>,
    /// Warnings about the fit's footing (a narrow training range).
    pub warnings: Vec<String>,
    /// The model's content hash (SHA-256, lower-case hex), computed here.
    pub model_sha256: String,
}

/// The notes for one single-gyro model.
fn notes_of(model: &ModelFile, notes: &mut Vec<&'static str>) {
    let spec = model.feature_spec().ok();
    let reads_change = |sub: &SubModel| {
        let (SubModel::Baseline { terms, .. } | SubModel::Residual { terms, .. }) = sub else {
            return false;
        };
        terms.powers.iter().any(|p| {
            p.iter().enumerate().any(|(i, &k)| {
                k > 0
                    && matches!(
                        spec.and_then(|s| s.kind(i)),
                        Some(FeatureKind::Rate | FeatureKind::LagDiff(_)) | None
                    )
            })
        })
    };
    let mut add = |n: &'static str| {
        if !notes.contains(&n) {
            notes.push(n);
        }
    };
    match &model.bias {
        None => add(NOTE_NO_BIAS),
        Some(sub) => {
            if reads_change(sub) {
                add(NOTE_RATE_LAG);
            }
            if sub.lstm().is_some() {
                add(NOTE_LSTM);
            }
        }
    }
    if model.scale.is_some() {
        add(NOTE_SCALE);
    }
    if model.coverage.is_some() {
        add(NOTE_COVERAGE);
    }
}

/// One axis's flight compensator, stepped at a constant temperature.
enum AxisComp {
    Single(Box<crate::flight_size::FlightCompensator>),
    Unit(Box<crate::flight_size::FlightAxis>, usize),
}

impl AxisComp {
    fn step(&mut self, t: f64, temp_c: f64) -> gyrotherm_core::compensator::Corrected {
        match self {
            AxisComp::Single(c) => c.step(t, 0.0, temp_c),
            AxisComp::Unit(c, n_temps) => {
                let temps = vec![temp_c; *n_temps];
                c.step(t, 0.0, &temps)
            }
        }
    }
    fn period_s(&self) -> f64 {
        match self {
            AxisComp::Single(c) => c.spec().step_period_s,
            AxisComp::Unit(c, _) => c.first().spec().step_period_s,
        }
    }
    fn settle_s(&self) -> f64 {
        match self {
            AxisComp::Single(c) => c.spec().settle_s(),
            AxisComp::Unit(c, _) => c.first().spec().settle_s(),
        }
    }
}

impl Clone for AxisComp {
    fn clone(&self) -> Self {
        match self {
            AxisComp::Single(c) => AxisComp::Single(c.clone()),
            AxisComp::Unit(c, n) => AxisComp::Unit(c.clone(), *n),
        }
    }
}

/// B at a constant `temp_c`, °/s: the compensator from rest, stepped until settled.
fn settled_bias(fresh: &AxisComp, axis: usize, temp_c: f64) -> Result<f64, AutopilotError> {
    let mut c = fresh.clone();
    let p = fresh.period_s();
    // Past the longest window a feature reads, so that every step is a full one.
    let min_steps = (fresh.settle_s() / p).ceil() as u32 + 2;
    let mut last = f64::NAN;
    let mut quiet = 0u32;
    for k in 0..MAX_SETTLE_STEPS {
        let out = c.step(f64::from(k) * p, temp_c);
        if out.status != gyrotherm_core::compensator::Status::Ok || !out.bias_dps.is_finite() {
            if k >= min_steps {
                return Err(AutopilotError::NoBias { axis, temp_c });
            }
            continue;
        }
        let b = out.bias_dps;
        quiet = if (b - last).abs() <= SETTLED_DPS {
            quiet + 1
        } else {
            0
        };
        last = b;
        if k >= min_steps && quiet >= SETTLED_STEPS {
            return Ok(b);
        }
    }
    Err(AutopilotError::Unsettled { axis, temp_c })
}

/// The model's steady-state bias over its training range (see the module doc).
pub fn steady_bias(
    model: ModelRef<'_>,
    settings: &AutopilotSettings,
) -> Result<SteadyBias, ExportError> {
    let mut notes = Vec::new();
    let (range, comps, digest): (_, [Option<AxisComp>; 3], String) = match model {
        ModelRef::Single(m) => {
            notes_of(m, &mut notes);
            notes.push(NOTE_SINGLE);
            m.validate().map_err(ExportError::Model)?;
            let c = crate::compensate::compensator(m).map_err(ExportError::Flight)?;
            let mut comps: [Option<AxisComp>; 3] = [None, None, None];
            if m.bias.is_some() {
                comps[settings.axis.index()] = Some(AxisComp::Single(Box::new(c)));
            }
            let r = m.training.temp_range_c;
            let digest = m.content_digest().map_err(ExportError::Model)?;
            ((r.min, r.max), comps, digest)
        }
        ModelRef::Unit(u) => {
            u.validate().map_err(ExportError::Unit)?;
            if u.axes.len() != 3 {
                return Err(AutopilotError::Axes { n: u.axes.len() }.into());
            }
            let mut min = f64::NEG_INFINITY;
            let mut max = f64::INFINITY;
            let mut comps: [Option<AxisComp>; 3] = [None, None, None];
            for (i, a) in u.axes.iter().enumerate() {
                notes_of(&a.model, &mut notes);
                if !a.more.is_empty() && !notes.contains(&NOTE_MORE) {
                    notes.push(NOTE_MORE);
                }
                min = min.max(a.model.training.temp_range_c.min);
                max = max.min(a.model.training.temp_range_c.max);
                let has_bias = a.model.bias.is_some() || a.more.iter().any(|m| m.bias.is_some());
                if has_bias {
                    let c = u.axis_compensator(a).map_err(ExportError::Unit)?;
                    comps[i] = Some(AxisComp::Unit(Box::new(c), u.temp_cols.len()));
                }
            }
            let digest = u.content_digest().map_err(ExportError::Unit)?;
            ((min, max), comps, digest)
        }
    };
    notes.push(NOTE_CLAMP);
    let (min_c, max_c) = range;
    let (lo, hi) = (min_c as f32, max_c as f32);
    if !(lo.is_finite() && hi.is_finite() && hi > lo) {
        return Err(AutopilotError::Range { min_c, max_c }.into());
    }
    let (lo64, hi64) = (f64::from(lo), f64::from(hi));
    let temps_c: Vec<f64> = (0..GRID_POINTS)
        .map(|i| lo64 + (hi64 - lo64) * i as f64 / (GRID_POINTS - 1) as f64)
        .collect();
    let mut warnings = Vec::new();
    if hi64 - lo64 < MIN_RANGE_C {
        warnings.push(format!(
            "the model was trained over {:.2} °C only ({lo64} to {hi64} °C), under {MIN_RANGE_C} \
             °C: the polynomial is fitted to that span and held at its edge values beyond it",
            hi64 - lo64
        ));
    }
    let mut bias_dps: [Option<Vec<f64>>; 3] = [None, None, None];
    for (axis, comp) in comps.iter().enumerate() {
        if let Some(c) = comp {
            let b = temps_c
                .iter()
                .map(|&t| settled_bias(c, axis, t))
                .collect::<Result<Vec<f64>, _>>()?;
            bias_dps[axis] = Some(b);
        }
    }
    Ok(SteadyBias {
        temp_min_c: lo,
        temp_max_c: hi,
        temps_c,
        bias_dps,
        notes,
        warnings,
        model_sha256: digest,
    })
}

/// Least squares `y ≈ c0 + c1·x + c2·x² + c3·x³`; the columns are built on x scaled to
/// [-1, 1] (well conditioned for any range) and the coefficients turned back to powers of x.
pub(crate) fn fit_cubic(x: &[f64], y: &[f64]) -> Option<[f64; 4]> {
    if x.len() != y.len() || x.len() < 4 {
        return None;
    }
    let (lo, hi) = x
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let m = 0.5 * (lo + hi);
    let h = 0.5 * (hi - lo);
    if !(h > 0.0 && h.is_finite()) {
        return None;
    }
    let a = nalgebra::DMatrix::from_fn(x.len(), 4, |r, c| ((x[r] - m) / h).powi(c as i32));
    let b = nalgebra::DVector::from_column_slice(y);
    let sol = a.svd(true, true).solve(&b, 1e-12).ok()?;
    // Σ b_k ((x − m)/h)^k = Σ_j x^j Σ_{k≥j} b_k C(k, j) (−m)^(k−j) / h^k.
    const BINOM: [[f64; 4]; 4] = [
        [1.0, 0.0, 0.0, 0.0],
        [1.0, 1.0, 0.0, 0.0],
        [1.0, 2.0, 1.0, 0.0],
        [1.0, 3.0, 3.0, 1.0],
    ];
    let mut c = [0.0; 4];
    for (k, row) in BINOM.iter().enumerate() {
        let bk = sol[k] / h.powi(k as i32);
        for (j, cj) in c.iter_mut().enumerate().take(k + 1) {
            *cj += bk * row[j] * (-m).powi((k - j) as i32);
        }
    }
    c.iter().all(|v| v.is_finite()).then_some(c)
}

/// `c0 + c1·x + c2·x² + c3·x³` (Horner).
pub fn cubic(c: &[f64; 4], x: f64) -> f64 {
    c[0] + (c[1] + (c[2] + c[3] * x) * x) * x
}

/// The correction the autopilot's firmware computes from the written parameters (as stored,
/// f32): per axis X, Y, Z a cubic in `clamp(T, t_min_c, t_max_c) - t_ref_c`, rad/s.
#[derive(Debug, Clone, PartialEq)]
pub struct Correction {
    /// Coefficients of x⁰ … x³ per axis, rad/s per °C^k.
    pub coef_rad: [[f64; 4]; 3],
    pub t_min_c: f64,
    pub t_max_c: f64,
    pub t_ref_c: f64,
}

impl Correction {
    /// The offset the firmware subtracts from `axis` (0 X, 1 Y, 2 Z) at `temp_c`, °/s (a
    /// temperature that is not finite gives NaN: the firmware's reading would be refused).
    pub fn offset_dps(&self, axis: usize, temp_c: f64) -> f64 {
        let x = temp_c.clamp(self.t_min_c, self.t_max_c) - self.t_ref_c;
        self.coef_rad
            .get(axis)
            .map_or(0.0, |c| cubic(c, x) / RAD_PER_DEG)
    }
}

/// How well the written polynomial holds over the grid, °/h.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitError {
    /// Largest |model − polynomial|, °/h.
    pub max_dph: f64,
    /// RMS of model − polynomial, °/h.
    pub rms_dph: f64,
}

impl FitError {
    /// Of the residuals `r` (°/s).
    pub fn of(r: &[f64]) -> FitError {
        let max = r.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let rms = (r.iter().map(|v| v * v).sum::<f64>() / r.len().max(1) as f64).sqrt();
        FitError {
            max_dph: max * DPH_PER_DPS,
            rms_dph: rms * DPH_PER_DPS,
        }
    }
}

/// °/s to rad/s.
pub(crate) const RAD_PER_DEG: f64 = std::f64::consts::PI / 180.0;

/// What an autopilot target wrote (or would write).
#[derive(Debug, Clone, PartialEq)]
pub struct AutopilotExport {
    /// The file's name in the output folder.
    pub file_name: &'static str,
    /// The file's text: the generator's words and numbers only.
    pub text: String,
    /// The fit error per axis X, Y, Z (None: left uncorrected).
    pub fit: [Option<FitError>; 3],
    /// The steady-state bias it was fitted to, with the notes and warnings.
    pub steady: SteadyBias,
    /// A line on what the fit error includes (the constant's handling differs by target).
    pub error_means: &'static str,
    /// What the firmware computes from the written parameters.
    pub correction: Correction,
}

impl AutopilotExport {
    /// The lines the CLI prints (stderr): the fit per axis, what is not carried, warnings.
    pub fn summary(&self) -> Vec<String> {
        self.lines("°")
    }

    /// [`summary`](Self::summary), the degree sign spelled `deg` (ASCII, for the file).
    fn lines(&self, deg: &str) -> Vec<String> {
        let s = &self.steady;
        let mut out = vec![format!(
            "polynomial fitted to the model's steady-state bias at {} temperatures from {} to {} \
             {deg}C ({})",
            s.temps_c.len(),
            s.temp_min_c,
            s.temp_max_c,
            self.error_means
        )];
        for (i, f) in self.fit.iter().enumerate() {
            let name = axis_name(i);
            out.push(match f {
                Some(f) => format!(
                    "  axis {name}: fit error max {} {deg}/h, RMS {} {deg}/h",
                    dph_text(f.max_dph),
                    dph_text(f.rms_dph)
                ),
                None => format!("  axis {name}: zero coefficients (not corrected)"),
            });
        }
        out.push("not carried by the polynomial:".to_owned());
        out.extend(s.notes.iter().map(|n| format!("  - {n}")));
        out.extend(
            s.warnings
                .iter()
                .map(|w| format!("warning: {}", w.replace('°', deg))),
        );
        out
    }

    /// The header of the file: `first` (what it is), the model's hash, the summary, and
    /// `more` (how the firmware uses the numbers), each line a `#` comment.
    pub(crate) fn header(&self, first: &str, more: &[&str]) -> String {
        let mut t = String::new();
        let _ = writeln!(t, "# {first}");
        let _ = writeln!(t, "# model content_sha256 {}", self.steady.model_sha256);
        for line in self
            .lines("deg")
            .iter()
            .map(String::as_str)
            .chain(more.iter().copied())
        {
            if line.is_empty() {
                t.push_str("#\n");
            } else {
                let _ = writeln!(t, "# {line}");
            }
        }
        t
    }
}

/// An error in °/h for the summary: four decimals, or three significant digits below 0.01.
fn dph_text(v: f64) -> String {
    if v >= 0.01 {
        format!("{v:.4}")
    } else {
        format!("{v:.2e}")
    }
}

/// The autopilot's name of axis `i` (0 = X).
pub(crate) fn axis_name(i: usize) -> &'static str {
    ["X", "Y", "Z"].get(i).copied().unwrap_or("?")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cubic_is_fitted_exactly_over_any_range() {
        let c = [1e-4, -2e-6, 3e-8, -4e-10];
        for (lo, hi) in [(-40.0, 85.0), (30.0, 31.0), (-5.0, 5.0)] {
            let x: Vec<f64> = (0..50).map(|i| lo + (hi - lo) * i as f64 / 49.0).collect();
            let y: Vec<f64> = x.iter().map(|&v| cubic(&c, v)).collect();
            let got = fit_cubic(&x, &y).unwrap();
            for (&xi, &yi) in x.iter().zip(&y) {
                assert!((cubic(&got, xi) - yi).abs() < 1e-15, "{lo}..{hi}");
            }
        }
        assert!(fit_cubic(&[1.0; 10], &[0.0; 10]).is_none());
    }
}
