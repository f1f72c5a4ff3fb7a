//! Fitting settings: one struct for `gyrotherm train` (and the fit part of `compare`,
//! `report`, `demo`) and Python's `fit()`.
//!
//! The settings sit below what they configure: this file imports only the rules, the methods
//! and the library's target constants. The fit and the comparison build their configurations
//! from it ([`FitSettings::fit_config`] in [`crate::fit`], [`FitSettings::compare_config`] in
//! [`crate::compare`]).

use super::method::{Method, DEFAULT_METHOD, METHODS, METHOD_NAMES};
use crate::setting_rule::{check, Rule, SettingError};
pub use crate::setting_rule::{MAX_EPOCHS, MAX_WINDOWS};
use crate::targets;

/// Default random seed of the LSTM initialisation and window order.
pub const DEFAULT_SEED: u64 = 0;
/// Default bias target smoothing window, s (100 s as published, He et al. 2024 §2).
pub const DEFAULT_BIAS_WINDOW_S: f64 = targets::BIAS_WINDOW_S;
/// Default time dropped at the start of each rate-table segment, s.
pub const DEFAULT_SETTLE_S: f64 = targets::SETTLE_S;
/// Default highest power of T in the `poly` bias model.
pub const DEFAULT_POLY_TEMP_DEGREE: u8 = 3;
/// Default highest power of dT in the `poly` bias model.
pub const DEFAULT_POLY_RATE_DEGREE: u8 = 1;
/// Default hidden units of the LSTM recipes: 8, as published (He et al. 2024, §2).
pub(crate) const DEFAULT_HIDDEN: usize = 8;
/// Hidden units of `thermal-lstm`'s LSTM: 32, chosen against 16 on the design family
/// (docs/experiments/lstm-capacity.md). A `hidden` setting, when given, overrides it.
pub(crate) const THERMAL_LSTM_HIDDEN: usize = 32;
/// Training windows per Adam step of `thermal-lstm`'s LSTM (and `auto`'s candidate): 32, kept
/// against 128 on the design family (docs/experiments/lstm-capacity.md). A `windows` setting,
/// when given, overrides it.
pub(crate) const THERMAL_LSTM_WINDOWS: usize = 32;

/// The hidden sizes flight code and its exports are built for, as text: "8, 16, 32 or 64".
pub(crate) fn hidden_sizes_text() -> String {
    let n: Vec<String> = gyrotherm_core::compensator::HIDDEN_SIZES
        .iter()
        .map(|h| h.to_string())
        .collect();
    match n.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
        _ => n.join(""),
    }
}

/// What the windows setting does, with its bound and default: the help of every front end's
/// option.
pub fn windows_help() -> String {
    format!(
        "Training windows per Adam step of an LSTM trained in minibatches (thermal-lstm, \
         auto's LSTM candidate), 1 to {MAX_WINDOWS} (default: {THERMAL_LSTM_WINDOWS}); other \
         methods do not read it"
    )
}

/// What the hidden-size setting does, with the sizes it takes and its defaults: the help
/// of every front end's option.
pub fn hidden_help() -> String {
    format!(
        "Hidden units of the method's LSTM: {}, the sizes flight code and its exports are \
         built for (default: the method's own, {DEFAULT_HIDDEN} as published, \
         {THERMAL_LSTM_HIDDEN} for thermal-lstm)",
        hidden_sizes_text()
    )
}

/// Default least relative drop of an inertial-unit axis's cross-validated RMS for a further
/// temperature sensor to join its model: −1, a sensor joins unless it doubles the
/// cross-validated RMS (chosen on the design family against +0.02, which kept one sensor
/// per axis: docs/experiments/imu.md).
pub(crate) const DEFAULT_IMU_MIN_GAIN: f64 = -1.0;

/// The terms each further sensor of an inertial-unit axis adds: its temperature and its lag
/// differences, linearly. `T, T², T³` and the lags with the first sensor chosen by the
/// combined score ([`FirstBy::Combined`]) lowered the design family's worst case
/// (5.88 → 4.41× the noise floor) but not the confirmation family's (5.25 → 5.31×), for
/// about 60 % more training time: kept as an experiment option
/// (docs/experiments/imu-worst-model.md).
pub(crate) const DEFAULT_IMU_EXTRA_TERMS: ExtraTerms = ExtraTerms::Linear;

/// How an inertial-unit axis chooses the sensor that comes first (with the full basis): the
/// lowest one-sensor cross-validated RMS (see [`DEFAULT_IMU_EXTRA_TERMS`] for the variant
/// tried against it).
pub(crate) const DEFAULT_IMU_FIRST: FirstBy = FirstBy::Single;

/// An inertial unit's lag search (only the search: the sensor selection and the final fits
/// use every labelled step) scores each candidate on every fifth labelled step of its
/// one-sensor targets, a fifth of the search's work per sensor; the bias target is a 100 s
/// moving average at 1 Hz, so neighbouring steps carry nearly the same information. Chosen
/// on the design family against every step (same median and worst case within its noise)
/// and every tenth step (a higher worst case): docs/experiments/imu.md. The one-axis fit
/// searches on every step.
pub(crate) const IMU_IDENTIFY_EVERY: usize = 5;

/// The terms a further sensor adds (`extra_terms`; the default
/// is `DEFAULT_IMU_EXTRA_TERMS`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExtraTerms {
    /// `T` and each lag difference, linearly.
    Linear,
    /// `T` alone.
    Temp,
    /// `T` and the fastest lag difference.
    TempFast,
    /// `T, T², T³` and each lag difference.
    Cubic,
    /// The first sensor's basis less its constant (`T, T², T³, Dj, T·D1` with `lean`).
    Same,
}

/// Which sensor comes first (gets the full basis; the default is `DEFAULT_IMU_FIRST`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FirstBy {
    /// The lowest one-sensor cross-validated RMS.
    Single,
    /// The lowest cross-validated RMS of the model on every sensor with it first.
    Combined,
    /// The bias model is the average of the fits with each chosen sensor first
    /// (`fit_multi_averaged`); the order (and the scale factor) as `Single`.
    Average,
}

/// Which temperature sensors each axis of an inertial unit may read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ImuSensors {
    /// Every listed sensor; cross-validation decides which stay (several per axis).
    #[default]
    All,
    /// One sensor per axis, the one whose fit has the lowest cross-validated RMS.
    ChooseOne,
}

/// How the axes of an inertial unit use its temperature sensors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuFitSettings {
    /// Which sensors an axis may read.
    pub sensors: ImuSensors,
    /// Least relative drop of the cross-validated RMS for a further sensor to join
    /// (negative: the rise it may cause, −1 allowing up to double).
    pub min_gain: f64,
    /// Experiment (0: off): the weight of the first sensor's one-sensor bias model in an
    /// average with the several-sensor bias model.
    /// An experiment knob: public only with the `experiments` feature.
    #[cfg(feature = "experiments")]
    pub blend: f64,
    #[cfg(not(feature = "experiments"))]
    pub(crate) blend: f64,
    /// Experiment (None: the recipe's grid): the decades (lowest, highest power of ten) of
    /// the ridge strengths the several-sensor fits and the sensor selection try.
    /// An experiment knob: public only with the `experiments` feature.
    #[cfg(feature = "experiments")]
    pub multi_ridge_decades: Option<(i32, i32)>,
    #[cfg(not(feature = "experiments"))]
    pub(crate) multi_ridge_decades: Option<(i32, i32)>,
    /// The further sensors' terms (`DEFAULT_IMU_EXTRA_TERMS`; the others are experiments).
    pub multi_extra: ExtraTerms,
    /// How the first sensor is chosen (`DEFAULT_IMU_FIRST`; the others are experiments).
    /// An experiment knob: public only with the `experiments` feature.
    #[cfg(feature = "experiments")]
    pub multi_first: FirstBy,
    #[cfg(not(feature = "experiments"))]
    pub(crate) multi_first: FirstBy,
    /// Experiment (0: the identification's): folds of the sensor selection's
    /// cross-validation.
    /// An experiment knob: public only with the `experiments` feature.
    #[cfg(feature = "experiments")]
    pub multi_select_folds: usize,
    #[cfg(not(feature = "experiments"))]
    pub(crate) multi_select_folds: usize,
    /// Experiment (None: chosen by the scores): under `auto`, the candidate each axis keeps
    /// without scoring, to measure each candidate's held-out figures.
    /// An experiment knob: public only with the `experiments` feature.
    #[cfg(feature = "experiments")]
    pub auto_keep: Option<Method>,
    #[cfg(not(feature = "experiments"))]
    pub(crate) auto_keep: Option<Method>,
}

impl Default for ImuFitSettings {
    fn default() -> Self {
        ImuFitSettings {
            sensors: ImuSensors::default(),
            min_gain: DEFAULT_IMU_MIN_GAIN,
            blend: 0.0,
            multi_ridge_decades: None,
            multi_extra: DEFAULT_IMU_EXTRA_TERMS,
            multi_first: DEFAULT_IMU_FIRST,
            multi_select_folds: 0,
            auto_keep: None,
        }
    }
}

/// How to fit a model.
#[derive(Debug, Clone, PartialEq)]
pub struct FitSettings {
    /// Fitting method ([`DEFAULT_METHOD`]).
    pub method: Method,
    /// Training epochs of the method's LSTM (None: the method's own).
    pub epochs: Option<usize>,
    /// Random seed of the LSTM initialisation and window order.
    pub seed: u64,
    /// Hidden units of the method's LSTM (None: the method's own, `DEFAULT_HIDDEN` as
    /// published, `THERMAL_LSTM_HIDDEN` for `thermal-lstm`). The trainer takes other sizes,
    /// but a model file must run in flight, whose network is built for the sizes of
    /// [`gyrotherm_core::compensator::HIDDEN_SIZES`]: [`FitSettings::validate`] accepts
    /// those only.
    pub hidden: Option<usize>,
    /// Training windows per Adam step of an LSTM trained in minibatches (`thermal-lstm`, and
    /// `auto`'s LSTM candidate; None: the method's own, 32). Methods that train on every
    /// window in turn do not read it.
    pub windows: Option<usize>,
    /// Bias target smoothing window, s (centred moving average).
    pub bias_window_s: f64,
    /// Time dropped at the start of each rate-table segment, s.
    pub settle_s: f64,
    /// Highest power of T in the `poly` bias model.
    pub poly_temp_degree: u8,
    /// Highest power of dT in the `poly` bias model.
    pub poly_rate_degree: u8,
    /// Include the T·dT cross term in the `poly` bias model.
    pub cross: bool,
    /// With two or more static (or rate-table) training logs: keep the residual LSTM only if,
    /// trained without each log in turn, it also improves that log.
    pub validate_on_runs: bool,
}

impl Default for FitSettings {
    fn default() -> Self {
        FitSettings {
            method: DEFAULT_METHOD,
            epochs: None,
            seed: DEFAULT_SEED,
            hidden: None,
            windows: None,
            bias_window_s: DEFAULT_BIAS_WINDOW_S,
            settle_s: DEFAULT_SETTLE_S,
            poly_temp_degree: DEFAULT_POLY_TEMP_DEGREE,
            poly_rate_degree: DEFAULT_POLY_RATE_DEGREE,
            cross: true,
            validate_on_runs: false,
        }
    }
}

impl FitSettings {
    /// Check every value; the error names the setting and the rule.
    pub fn validate(&self) -> Result<(), SettingError> {
        if let Some(e) = self.epochs.filter(|e| !(1..=MAX_EPOCHS).contains(e)) {
            return Err(SettingError::Invalid {
                setting: "epochs",
                value: e.to_string(),
                rule: Rule::Epochs,
            });
        }
        if let Some(h) = self.hidden {
            check("hidden", h as f64, Rule::HiddenUnits)?;
        }
        if let Some(w) = self.windows.filter(|w| !(1..=MAX_WINDOWS).contains(w)) {
            return Err(SettingError::Invalid {
                setting: "windows",
                value: w.to_string(),
                rule: Rule::Windows,
            });
        }
        check("bias_window_s", self.bias_window_s, Rule::PositiveSeconds)?;
        check("settle_s", self.settle_s, Rule::NonNegativeSeconds)?;
        // `lstm`, which older model files record, is no method a fit can use.
        if !METHODS.contains(&self.method) {
            return Err(SettingError::unknown(
                "method",
                self.method.as_str(),
                &METHOD_NAMES,
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An epoch count beyond the bound is refused with the setting, the value and the bound,
    /// before anything is trained or reserved (`Vec::with_capacity(epochs)` aborted the
    /// process at 1e11, and `usize::MAX` panicked with "capacity overflow").
    #[test]
    fn epochs_beyond_the_bound_are_refused_by_name() {
        for e in [0, MAX_EPOCHS + 1, 100_000_000_000, usize::MAX] {
            let s = FitSettings {
                epochs: Some(e),
                ..FitSettings::default()
            };
            let err = s.validate().unwrap_err();
            assert_eq!(err.setting(), "epochs");
            let msg = err.to_string();
            assert_eq!(
                msg,
                format!("epochs must be a whole number from 1 to {MAX_EPOCHS}, not {e}")
            );
        }
        for e in [1, 300, MAX_EPOCHS] {
            let s = FitSettings {
                epochs: Some(e),
                ..FitSettings::default()
            };
            assert!(s.validate().is_ok(), "{e}");
        }
        assert!(Rule::Epochs.holds(MAX_EPOCHS as f64) && !Rule::Epochs.holds(0.5));
    }

    /// The windows per Adam step are refused outside 1 to the bound, by name, with the bound
    /// the message states equal to the one checked.
    #[test]
    fn windows_outside_the_bound_are_refused_by_name() {
        for w in [0, MAX_WINDOWS + 1, usize::MAX] {
            let s = FitSettings {
                windows: Some(w),
                ..FitSettings::default()
            };
            let err = s.validate().unwrap_err();
            assert_eq!(err.setting(), "windows");
            assert_eq!(
                err.to_string(),
                format!("windows must be a whole number from 1 to {MAX_WINDOWS}, not {w}")
            );
        }
        for w in [1, 128, MAX_WINDOWS] {
            let s = FitSettings {
                windows: Some(w),
                ..FitSettings::default()
            };
            assert!(s.validate().is_ok(), "{w}");
        }
        assert!(Rule::Windows.holds(MAX_WINDOWS as f64) && !Rule::Windows.holds(0.5));
    }
}
