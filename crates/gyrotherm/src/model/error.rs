//! Why a single gyro's model file cannot be read, checked or written.

use std::path::PathBuf;

use super::seal::supported_list;
use super::{SubModelError, Target, CHECKSUM_KEY};
use crate::json_keys::DuplicateKey;

/// A model that cannot be read, checked or written: the file, the field and the value at
/// fault.
#[derive(Debug)]
#[non_exhaustive]
pub enum ModelFileError {
    /// The file could not be read.
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The file could not be written.
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    /// An error in the model file at `path`.
    InFile {
        path: PathBuf,
        source: Box<ModelFileError>,
    },
    /// A model that fails its checks was not saved.
    NotSaved(Box<ModelFileError>),
    /// The text is not JSON.
    NotJson(serde_json::Error),
    /// An object names a key twice (`path` says where, e.g. `bias.baseline.coefficients`):
    /// which value counts would depend on the reader, and the content hash covers only one.
    DuplicateKey(DuplicateKey),
    /// A field is missing, unknown or of the wrong type.
    Fields(serde_json::Error),
    /// No `format_version` field.
    MissingVersion,
    /// The `content_sha256` written with the model does not match its content (edited or
    /// damaged since it was saved).
    Checksum { found: String, computed: String },
    /// A `format_version` this build does not read (the value as written).
    UnsupportedVersion { found: String },
    /// The feature definition cannot be built.
    Features(gyrotherm_core::features::SpecError),
    /// The `bias` or `scale` sub-model.
    SubModel {
        target: Target,
        source: SubModelError,
    },
    /// A field's value (`field` names it, e.g. `training.final_loss`).
    Invalid { field: String, problem: String },
}

impl ModelFileError {
    pub(crate) fn invalid(field: &str, problem: String) -> Self {
        ModelFileError::Invalid {
            field: field.to_owned(),
            problem,
        }
    }
}

impl std::fmt::Display for ModelFileError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ModelFileError::Read { path, .. } => {
                write!(f, "{}: cannot read model file", path.display())
            }
            ModelFileError::Write { path, .. } => write!(f, "{}", path.display()),
            ModelFileError::InFile { path, .. } => write!(f, "{}", path.display()),
            ModelFileError::NotSaved(_) => f.write_str("not saved"),
            ModelFileError::NotJson(_) => f.write_str("not valid JSON"),
            ModelFileError::DuplicateKey(d) => d.fmt(f),
            ModelFileError::Fields(e) => e.fmt(f),
            ModelFileError::MissingVersion => f.write_str("missing field `format_version`"),
            ModelFileError::UnsupportedVersion { found } => write!(
                f,
                "unsupported format_version {found}: this gyrotherm ({}) reads version {}; use a \
                 matching gyrotherm or re-train",
                env!("CARGO_PKG_VERSION"),
                supported_list()
            ),
            ModelFileError::Features(_) => f.write_str("features"),
            ModelFileError::SubModel { target, .. } => f.write_str(target.as_str()),
            ModelFileError::Checksum { found, computed } => write!(
                f,
                "{CHECKSUM_KEY} is {found} but the content gives {computed}: the file was edited \
                 or damaged after it was saved; re-train, or if the edit is intended, check the \
                 model and run `gyrotherm model seal FILE`"
            ),
            ModelFileError::Invalid { field, problem } if field.is_empty() => f.write_str(problem),
            ModelFileError::Invalid { field, problem } => write!(f, "{field}: {problem}"),
        }
    }
}

impl std::error::Error for ModelFileError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ModelFileError::Read { source, .. } | ModelFileError::Write { source, .. } => {
                Some(source)
            }
            ModelFileError::InFile { source, .. } | ModelFileError::NotSaved(source) => {
                Some(source.as_ref())
            }
            ModelFileError::NotJson(e) => Some(e),
            // Transparent: serde's message is this error's own.
            ModelFileError::Fields(e) => e.source(),
            ModelFileError::Features(e) => Some(e),
            ModelFileError::SubModel { source, .. } => Some(source),
            _ => None,
        }
    }
}
