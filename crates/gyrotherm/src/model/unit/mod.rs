//! One model file for an inertial unit: per gyro axis a bias and a scale-factor model, the
//! gyro columns and the temperature sensors the unit's log must hold, and which sensors each
//! axis reads.
//!
//! An axis reads one sensor, an ordinary single-sensor [`ModelFile`], or several: the first
//! sensor's model plus each further sensor's linear part ([`SensorModel`]), run by the
//! flight [`AxisCompensator`](gyrotherm_core::multi::AxisCompensator); such an axis also keeps
//! its first sensor's one-sensor model as its `fallback` ([`ImuAxis::fallback`]), which it
//! runs on (status `fallback`) while a further sensor is given up on. How the axes are fitted:
//! [`crate::fit::unit`]; how a log is compensated with them: [`crate::compensate::unit`].
//!
//! The file is JSON with `imu_format_version` (which tells it from a single-axis file, whose
//! format is unchanged): 1 when every axis reads one sensor (as older builds wrote), 2 when
//! an axis reads several; sealed with `content_sha256` like a single-axis file. It is read
//! with a single-axis file's checks ([`crate::model`]): a key named twice is refused, a file
//! without its seal is read with a warning for the caller to tell ([`Seal::warning`]), every
//! axis's model is checked as a single-axis model, each further sensor's parts as least-squares
//! sub-models (plausible coefficients, one per term), and B and K of the whole axis, further
//! sensors included, must stay plausible over the training range. A unit has 1 to
//! [`MAX_STREAM_AXES`] axes, each on a gyro column of its own.

use serde::{Deserialize, Serialize};
use std::path::Path;

use crate::csvlog::ReadOptions;
use crate::flight_size::{build_sized, FlightAxis, HiddenSize};
use crate::model::{
    content_digest_of, parse_sealed, ModelFile, Seal, SealedTextError, SubModel, CHECKSUM_KEY,
};

mod checks;
mod error;

use checks::{axes_hidden_size, boxed_axis, each_axis, repeated};
pub(crate) use checks::{axis_checks, check_axis_count};
pub use error::ImuError;

pub use crate::flight_size::MAX_STREAM_AXES;

/// Version of the inertial-unit file layout when an axis reads several sensors.
pub const IMU_FORMAT_VERSION: u32 = 2;
/// Version of the layout when every axis reads one sensor (the first layout; such files are
/// written as before).
pub const IMU_FORMAT_VERSION_ONE_SENSOR: u32 = 1;
/// The key that marks an inertial-unit model file.
pub(crate) const IMU_VERSION_KEY: &str = "imu_format_version";

/// A sensor tried for an axis and its score.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorScore {
    /// The temperature column.
    pub temp: String,
    /// Cross-validated RMS of the fit on this sensor (bias °/s, or K for a scale-only
    /// axis); None when the method has no cross-validation.
    pub cv_rms: Option<f64>,
}

/// A further sensor an axis reads (`temps[i + 1]` for `more[i]`): its lags and its parts of
/// the bias and the scale factor, each a baseline over that sensor's features (`T, dT,
/// T − lag_j(T)`, the first sensor's step period and rate lag) without a constant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorModel {
    /// Time constants of this sensor's lags, s, fastest first.
    pub lags_s: Vec<f64>,
    /// Its part of the bias, °/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bias: Option<SubModel>,
    /// Its part of the scale factor.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<SubModel>,
}

/// One gyro axis of the unit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImuAxis {
    /// The gyro column.
    pub gyro: String,
    /// The temperature columns this axis's model reads, the first sensor first.
    pub temps: Vec<String>,
    /// Every sensor tried, in column order, with its one-sensor score.
    pub scores: Vec<SensorScore>,
    /// The first sensor's bias and scale-factor model (the whole model with one sensor).
    pub model: ModelFile,
    /// The further sensors' parts, in the order of `temps[1..]` (empty: one sensor).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub more: Vec<SensorModel>,
    /// Cross-validated RMS of the bias on all the sensors read (with several).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub multi_cv_rms: Option<f64>,
    /// With further sensors: the one-sensor model on the first sensor alone (its `thermal`
    /// fit), which the axis runs on while a further sensor is given up on (status
    /// `fallback`, [`gyrotherm_core::multi`]). Files written before it have none: such an
    /// axis stays held and then degraded while a further sensor is lost.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fallback: Option<ModelFile>,
}

/// An inertial unit's model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImuModel {
    /// [`IMU_FORMAT_VERSION`].
    pub imu_format_version: u32,
    /// The gyro columns, in the order of the axes (and of the exported `gyro[]`).
    pub gyro_cols: Vec<String>,
    /// The temperature columns, in the order of the exported `temp[]`.
    pub temp_cols: Vec<String>,
    /// One entry per gyro column, same order.
    pub axes: Vec<ImuAxis>,
}

/// Whether model-file text is an inertial unit's (it has [`IMU_VERSION_KEY`]): the one place
/// the two file forms are told apart (by `unit_model::Model::load`).
pub(crate) fn is_imu_model_text(text: &str) -> bool {
    serde_json::from_str::<serde_json::Value>(text.strip_prefix('\u{feff}').unwrap_or(text))
        .ok()
        .and_then(|v| v.get(IMU_VERSION_KEY).cloned())
        .is_some()
}

impl ImuModel {
    /// Checks the layout (one axis per gyro column, in order; each axis's sensors among the
    /// temperature columns) and every axis's model.
    pub fn validate(&self) -> Result<(), ImuError> {
        self.validate_columns()?;
        // The axes' checks (each runs its models over the training range) on a thread per
        // axis; the first axis in order that fails is told, as checking in turn would.
        each_axis(&self.axes, |a| axis_checks(&self.temp_cols, a))
            .into_iter()
            .collect()
    }

    /// [`ImuModel::validate`]'s checks of the file's version and gyro columns.
    pub(crate) fn validate_columns(&self) -> Result<(), ImuError> {
        // What is wrong with the axes is said before the version: the version expected
        // follows from them.
        if self.axes.is_empty() || self.gyro_cols.is_empty() {
            return Err(ImuError::Layout(
                "the model has no gyro axes (`axes` and `gyro_cols` must list at least one); \
                 re-train"
                    .into(),
            ));
        }
        check_axis_count(self.axes.len().max(self.gyro_cols.len()))?;
        if let Some((g, i, j)) = repeated(&self.gyro_cols) {
            return Err(ImuError::Layout(format!(
                "gyro column {g:?} is listed twice in `gyro_cols` (axes {i} and {j}): each axis \
                 reads a gyro column of its own; re-train, or check a hand edit"
            )));
        }
        if let Some((t, i, j)) = repeated(&self.temp_cols) {
            return Err(ImuError::Layout(format!(
                "temperature column {t:?} is listed twice in `temp_cols` (entries {i} and {j}); \
                 re-train, or check a hand edit"
            )));
        }
        let several = self.axes.iter().any(|a| a.temps.len() > 1);
        let expected = if several {
            IMU_FORMAT_VERSION
        } else {
            IMU_FORMAT_VERSION_ONE_SENSOR
        };
        if self.imu_format_version != expected {
            return Err(ImuError::Layout(format!(
                "{IMU_VERSION_KEY} {} is not supported here (this build reads \
                 {IMU_FORMAT_VERSION_ONE_SENSOR} when every axis reads one sensor, \
                 {IMU_FORMAT_VERSION} when an axis reads several)",
                self.imu_format_version
            )));
        }
        let gyros: Vec<&String> = self.axes.iter().map(|a| &a.gyro).collect();
        if gyros != self.gyro_cols.iter().collect::<Vec<_>>() || gyros.is_empty() {
            return Err(ImuError::Layout(
                "the axes must list the gyro columns, in order".into(),
            ));
        }
        Ok(())
    }

    /// The flight compensator of one axis: its first sensor's
    /// [`Compensator`](gyrotherm_core::compensator::Compensator) and each further sensor's
    /// pipeline and parts, reading the indices of its sensors among
    /// [`ImuModel::temp_cols`], at the unit's LSTM size ([`ImuModel::hidden_size`]).
    pub(crate) fn axis_compensator(&self, a: &ImuAxis) -> Result<FlightAxis, ImuError> {
        let size = self.hidden_size()?;
        Ok(build_sized!(FlightAxis, size, H => boxed_axis::<H>(&self.temp_cols, a)?))
    }

    /// The LSTM size every axis of the unit runs at: the largest LSTM of any axis's model or
    /// fallback (8 without one). An LSTM of a size flight code is not built for is refused,
    /// naming the axis and the size.
    pub fn hidden_size(&self) -> Result<HiddenSize, ImuError> {
        axes_hidden_size(&self.axes)
    }

    /// The sealed JSON text (pretty; `content_sha256` of the compact content last).
    pub fn to_json(&self) -> Result<String, ImuError> {
        self.validate()?;
        let text = serde_json::to_string_pretty(self).map_err(ImuError::Json)?;
        let body = text.strip_suffix("\n}").unwrap_or(&text);
        Ok(format!(
            "{body},\n  \"{CHECKSUM_KEY}\": \"{}\"\n}}\n",
            self.content_digest()?
        ))
    }

    /// The `content_sha256` of the model: SHA-256 of its compact JSON content (how the file
    /// is formatted does not change it).
    pub fn content_digest(&self) -> Result<String, ImuError> {
        content_digest_of(self).map_err(ImuError::Json)
    }

    /// Parse and check the text (the checksum, when present, must match).
    pub fn from_json(text: &str) -> Result<ImuModel, ImuError> {
        Self::from_json_sealed(text).map(|(m, _)| m)
    }

    /// [`from_json`](Self::from_json), also saying whether the text was sealed (a caller
    /// warns on [`Seal::Absent`], see [`Seal::warning`]). Read as a single-axis file is: a
    /// key named twice in any object is refused.
    pub fn from_json_sealed(text: &str) -> Result<(ImuModel, Seal), ImuError> {
        let (m, sealed) = Self::parse(text, true)?;
        Ok((m, if sealed { Seal::Verified } else { Seal::Absent }))
    }

    /// The model and whether the text held a checksum (checked only when `verify`).
    fn parse(text: &str, verify: bool) -> Result<(ImuModel, bool), ImuError> {
        let (m, sealed): (ImuModel, bool) =
            parse_sealed(text, verify, |_| Ok::<(), std::convert::Infallible>(())).map_err(
                |e| match e {
                    SealedTextError::DuplicateKey(d) => ImuError::DuplicateKey(d),
                    SealedTextError::NotJson(e) | SealedTextError::Fields(e) => ImuError::Json(e),
                    SealedTextError::Refused(never) => match never {},
                    SealedTextError::Checksum { found, computed } => {
                        ImuError::Checksum { found, computed }
                    }
                },
            )?;
        m.validate()?;
        Ok((m, sealed))
    }

    /// Re-seal a unit model file after a deliberate hand edit, as [`ModelFile::seal`]: read
    /// it without checking its `content_sha256`, check everything else, and write it back
    /// with a new one. Returns the model and its new digest.
    pub fn seal(path: &Path) -> Result<(ImuModel, String), ImuError> {
        let text = read_text(path)?;
        let (m, _) = Self::parse(&text, false)?;
        m.save(path)?;
        let digest = m.content_digest()?;
        Ok((m, digest))
    }

    /// Write atomically.
    pub fn save(&self, path: &Path) -> Result<(), ImuError> {
        let text = self.to_json()?;
        crate::atomic_file::write_bytes_atomically(path, text.as_bytes()).map_err(|source| {
            ImuError::Io {
                path: path.to_path_buf(),
                source,
            }
        })
    }

    /// Read and check a file.
    pub fn load(path: &Path) -> Result<ImuModel, ImuError> {
        Self::load_sealed(path).map(|(m, _)| m)
    }

    /// [`load`](Self::load), also saying whether the file was sealed (a caller warns on
    /// [`Seal::Absent`]; see [`Seal::warning`]).
    pub fn load_sealed(path: &Path) -> Result<(ImuModel, Seal), ImuError> {
        Self::from_json_sealed(&read_text(path)?)
    }

    /// Read options naming the model's columns (the rest of `base` kept): its gyro columns
    /// and the temperature columns its axes read ([`ImuModel::temps_read`]).
    pub fn read_options(&self, base: &ReadOptions) -> ReadOptions {
        ReadOptions {
            gyro_col: self.gyro_cols.join(","),
            temp_col: self.temps_read().join(","),
            ..base.clone()
        }
    }

    /// The temperature columns some axis reads, in the order of [`ImuModel::temp_cols`]: the
    /// ones a log must hold (a column no axis reads changes no output).
    pub fn temps_read(&self) -> Vec<&str> {
        self.temp_cols
            .iter()
            .filter(|t| self.axes.iter().any(|a| a.temps.contains(t)))
            .map(String::as_str)
            .collect()
    }

    /// Index of each axis's first (or only) sensor in the temperature columns.
    pub(crate) fn sensor_index(&self) -> Vec<usize> {
        self.axes
            .iter()
            .map(|a| {
                self.temp_cols
                    .iter()
                    .position(|t| *t == a.temps[0])
                    .unwrap_or(0)
            })
            .collect()
    }
}

/// The text of the file `path`.
fn read_text(path: &Path) -> Result<String, ImuError> {
    crate::input_file::read_capped_to_string(path, crate::input_file::InputKind::Model).map_err(
        |source| ImuError::Io {
            path: path.to_path_buf(),
            source,
        },
    )
}
