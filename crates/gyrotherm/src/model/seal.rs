//! Model-file text: JSON in and out, the `content_sha256` seal, and files on disk.

use super::*;
use crate::input_file::{read_capped_to_string, InputKind};

impl ModelFile {
    /// SHA-256 of the model's content (its compact JSON, fields in declaration order):
    /// layout and key order of the file do not change it, any value does.
    pub fn content_digest(&self) -> Result<String, ModelFileError> {
        content_digest_of(self).map_err(ModelFileError::Fields)
    }

    /// The JSON text (pretty, shortest round-trip floats), after [`validate`](Self::validate),
    /// sealed with `content_sha256` (see [`content_digest`](Self::content_digest)) as the
    /// last key.
    pub fn to_json(&self) -> Result<String, ModelFileError> {
        self.validate()?;
        let text = serde_json::to_string_pretty(self).map_err(ModelFileError::Fields)?;
        let digest = self.content_digest()?;
        let body = text.strip_suffix("\n}").unwrap_or(&text);
        Ok(format!("{body},\n  \"{CHECKSUM_KEY}\": \"{digest}\"\n}}"))
    }

    /// Parse and check JSON text: a leading byte-order mark is skipped; a `content_sha256`
    /// must match the content (a file without one, written before files were sealed or by
    /// hand, is read on its other checks).
    pub fn from_json(text: &str) -> Result<ModelFile, ModelFileError> {
        Self::from_json_sealed(text).map(|(m, _)| m)
    }

    /// [`from_json`](Self::from_json), also saying whether the text was sealed.
    pub fn from_json_sealed(text: &str) -> Result<(ModelFile, Seal), ModelFileError> {
        let (m, sealed) = Self::parse(text, true)?;
        Ok((m, if sealed { Seal::Verified } else { Seal::Absent }))
    }

    /// The model and whether the text held a checksum (checked only when `verify`).
    pub(super) fn parse(text: &str, verify: bool) -> Result<(ModelFile, bool), ModelFileError> {
        // Version first, so that a newer file gets "unsupported version", not a field error.
        let version = |v: &serde_json::Value| match v.get("format_version") {
            None => Err(ModelFileError::MissingVersion),
            Some(fv) => match fv.as_u64() {
                Some(n) if SUPPORTED_VERSIONS.contains(&(n as u32)) && n <= u32::MAX as u64 => {
                    Ok(())
                }
                _ => Err(ModelFileError::UnsupportedVersion {
                    found: fv.to_string(),
                }),
            },
        };
        let (m, has_seal): (ModelFile, bool) =
            parse_sealed(text, verify, version).map_err(|e| match e {
                SealedTextError::DuplicateKey(d) => ModelFileError::DuplicateKey(d),
                SealedTextError::NotJson(e) => ModelFileError::NotJson(e),
                SealedTextError::Refused(e) => e,
                SealedTextError::Fields(e) => ModelFileError::Fields(e),
                SealedTextError::Checksum { found, computed } => {
                    ModelFileError::Checksum { found, computed }
                }
            })?;
        m.validate()?;
        Ok((m, has_seal))
    }

    /// Re-seal a model file after a deliberate hand edit: read it without checking its
    /// `content_sha256`, check everything else, and write it back with a new one. Returns
    /// the model and its new digest.
    pub fn seal(path: &Path) -> Result<(ModelFile, String), ModelFileError> {
        let in_file = |e| ModelFileError::InFile {
            path: path.to_path_buf(),
            source: Box::new(e),
        };
        let text = read_capped_to_string(path, InputKind::Model).map_err(|source| {
            ModelFileError::Read {
                path: path.to_path_buf(),
                source,
            }
        })?;
        let (m, _) = Self::parse(&text, false).map_err(in_file)?;
        m.save(path)?;
        let digest = m.content_digest().map_err(in_file)?;
        Ok((m, digest))
    }

    /// Write to `path` atomically (temporary file + rename), after validating.
    pub fn save(&self, path: &Path) -> Result<(), ModelFileError> {
        let mut text = self.to_json().map_err(|e| ModelFileError::InFile {
            path: path.to_path_buf(),
            source: Box::new(ModelFileError::NotSaved(Box::new(e))),
        })?;
        text.push('\n');
        write_bytes_atomically(path, text.as_bytes()).map_err(|source| ModelFileError::Write {
            path: path.to_path_buf(),
            source,
        })
    }

    /// Read and check a model file.
    pub fn load(path: &Path) -> Result<ModelFile, ModelFileError> {
        Self::load_sealed(path).map(|(m, _)| m)
    }

    /// [`load`](Self::load), also saying whether the file was sealed (a caller warns on
    /// [`Seal::Absent`]; see [`Seal::warning`]).
    pub fn load_sealed(path: &Path) -> Result<(ModelFile, Seal), ModelFileError> {
        let text = read_capped_to_string(path, InputKind::Model).map_err(|source| {
            ModelFileError::Read {
                path: path.to_path_buf(),
                source,
            }
        })?;
        Self::from_json_sealed(&text).map_err(|e| ModelFileError::InFile {
            path: path.to_path_buf(),
            source: Box::new(e),
        })
    }
}

impl Seal {
    /// What to tell the user about the model file `path`: nothing when sealed.
    pub fn warning(self, path: &Path) -> Option<String> {
        match self {
            Seal::Verified => None,
            Seal::Absent => Some(format!(
                "{}: no {CHECKSUM_KEY}: the model passed its plausibility checks, but a \
                 corrupted value cannot be told from an intended one; if the content is as \
                 intended, run `gyrotherm model seal {}`",
                path.display(),
                path.display()
            )),
        }
    }
}

/// Why [`parse_sealed`] refused a text (each model kind maps it onto its own error).
#[derive(Debug)]
pub(crate) enum SealedTextError<E> {
    /// An object names a key twice.
    DuplicateKey(DuplicateKey),
    /// The text is not JSON.
    NotJson(serde_json::Error),
    /// The caller's look at the raw value (its version) refused it.
    Refused(E),
    /// A field is missing, unknown or of the wrong type.
    Fields(serde_json::Error),
    /// The checksum does not match the content.
    Checksum { found: String, computed: String },
}

/// SHA-256 of `content`'s compact JSON (fields in declaration order): what
/// [`CHECKSUM_KEY`] seals, for every kind of model file.
pub(crate) fn content_digest_of<T: Serialize>(content: &T) -> Result<String, serde_json::Error> {
    let compact = serde_json::to_string(content)?;
    Ok(sha256_hex(compact.as_bytes()))
}

/// Read a model text sealed with [`CHECKSUM_KEY`], of any model kind `T`: a leading
/// byte-order mark skipped; a key named twice in any object refused before anything reads a
/// value (a repeated key would give the checksum one value and another reader the other);
/// `look` sees the JSON value before its fields are read (a version check); the seal taken
/// out and, when `verify`, compared with [`content_digest_of`] the content read. Returns the
/// content and whether the text held a seal (a file without one, written before files were
/// sealed or by hand, is read on its other checks; the caller tells the user, see
/// [`Seal::warning`]). The content's own checks are the caller's.
pub(crate) fn parse_sealed<T, E>(
    text: &str,
    verify: bool,
    look: impl FnOnce(&serde_json::Value) -> Result<(), E>,
) -> Result<(T, bool), SealedTextError<E>>
where
    T: Serialize + serde::de::DeserializeOwned,
{
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    check_unique_keys(text).map_err(|e| match e {
        KeyCheckError::Duplicate(d) => SealedTextError::DuplicateKey(d),
        KeyCheckError::NotJson(e) => SealedTextError::NotJson(e),
    })?;
    let mut v: serde_json::Value = serde_json::from_str(text).map_err(SealedTextError::NotJson)?;
    look(&v).map_err(SealedTextError::Refused)?;
    let sealed = v.as_object_mut().and_then(|o| o.remove(CHECKSUM_KEY));
    let has_seal = sealed.is_some();
    let m: T = match &sealed {
        // Parsed from the text where possible: its errors give line and column.
        None => serde_json::from_str(text).map_err(SealedTextError::Fields)?,
        Some(_) => serde_json::from_value(v).map_err(SealedTextError::Fields)?,
    };
    if let (Some(found), true) = (sealed, verify) {
        let computed = content_digest_of(&m).map_err(SealedTextError::Fields)?;
        let found = match found {
            serde_json::Value::String(s) => s,
            other => other.to_string(),
        };
        if !found.eq_ignore_ascii_case(&computed) {
            return Err(SealedTextError::Checksum { found, computed });
        }
    }
    Ok((m, has_seal))
}

pub(super) fn supported_list() -> String {
    SUPPORTED_VERSIONS
        .iter()
        .map(|v| v.to_string())
        .collect::<Vec<_>>()
        .join(", ")
}
