//! Why an inertial-unit model ([`super::ImuModel`]) cannot be read, written or applied. Its
//! fit's own errors are [`crate::fit::unit::UnitFitError`].

use std::path::PathBuf;

use crate::json_keys::DuplicateKey;
use crate::model::{CompensateError, ModelFileError, SubModelError, Target, CHECKSUM_KEY};

/// Why an inertial-unit model cannot be read, written or applied.
#[derive(Debug)]
#[non_exhaustive]
pub enum ImuError {
    /// The model of axis `gyro` is not valid.
    Axis {
        gyro: String,
        source: Box<ModelFileError>,
    },
    /// The file's structure is inconsistent (the message says what).
    Layout(String),
    /// Further sensor `temp` of axis `gyro`: its part of the bias or scale factor is not
    /// valid.
    FurtherSensor {
        gyro: String,
        temp: String,
        part: Target,
        source: Box<SubModelError>,
    },
    /// The text is not an inertial-unit model (JSON error, or a field).
    Json(serde_json::Error),
    /// An object names a key twice: which value counts would depend on the reader, and the
    /// content hash covers only one.
    DuplicateKey(DuplicateKey),
    /// `content_sha256` does not match the content.
    Checksum { found: String, computed: String },
    /// The log lacks a column the model needs.
    MissingColumn { column: String, role: &'static str },
    /// The compensator of axis `gyro` could not be built.
    Compensate {
        gyro: String,
        source: Box<CompensateError>,
    },
    /// A file could not be read or written.
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
}

impl std::fmt::Display for ImuError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ImuError::Axis { gyro, .. } => write!(f, "the model of axis {gyro}"),
            ImuError::Layout(m) => write!(f, "{m}"),
            ImuError::FurtherSensor {
                gyro, temp, part, ..
            } => write!(f, "axis {gyro}: further sensor {temp}, {}", part.as_str()),
            ImuError::Json(_) => write!(f, "not an inertial-unit model file"),
            ImuError::DuplicateKey(d) => d.fmt(f),
            ImuError::Checksum { found, computed } => write!(
                f,
                "{CHECKSUM_KEY} {found} does not match the content ({computed}): the file was \
                 changed after it was written"
            ),
            ImuError::MissingColumn { column, role } => write!(
                f,
                "the log has no {role} column {column:?}, which the model needs (name the \
                 columns with --gyro-col/--temp-col as at training)"
            ),
            ImuError::Compensate { gyro, .. } => write!(f, "axis {gyro}"),
            ImuError::Io { path, .. } => write!(f, "{}", path.display()),
        }
    }
}

impl std::error::Error for ImuError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ImuError::Axis { source, .. } => Some(source.as_ref()),
            ImuError::FurtherSensor { source, .. } => Some(source.as_ref()),
            ImuError::Json(e) => Some(e),
            ImuError::Compensate { source, .. } => Some(source.as_ref()),
            ImuError::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}
