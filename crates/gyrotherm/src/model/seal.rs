//! Model-file text: JSON in and out, the `content_sha256` seal, and files on disk.

use super::*;
use crate::input_file::{read_capped_to_string, InputKind};

impl ModelFile {
    /// SHA-256 of the model's content (its compact JSON, fields in declaration order):
    /// layout and key order of the file do not change it, any value does.
    pub fn content_digest(&self) -> Result<String, ModelFileError> {
        let compact = serde_json::to_string(self).map_err(ModelFileError::Fields)?;
        Ok(sha256_hex(compact.as_bytes()))
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
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        // Before anything reads a value: a repeated key would give the checksum one value
        // and another reader the other.
        check_unique_keys(text).map_err(|e| match e {
            KeyCheckError::Duplicate(d) => ModelFileError::DuplicateKey(d),
            KeyCheckError::NotJson(e) => ModelFileError::NotJson(e),
        })?;
        // Version first, so that a newer file gets "unsupported version", not a field error.
        let mut v: serde_json::Value =
            serde_json::from_str(text).map_err(ModelFileError::NotJson)?;
        match v.get("format_version") {
            None => return Err(ModelFileError::MissingVersion),
            Some(fv) => match fv.as_u64() {
                Some(n) if SUPPORTED_VERSIONS.contains(&(n as u32)) && n <= u32::MAX as u64 => {}
                _ => {
                    return Err(ModelFileError::UnsupportedVersion {
                        found: fv.to_string(),
                    })
                }
            },
        }
        let sealed = v.as_object_mut().and_then(|o| o.remove(CHECKSUM_KEY));
        let has_seal = sealed.is_some();
        let m: ModelFile = match &sealed {
            // Parsed from the text where possible: its errors give line and column.
            None => serde_json::from_str(text).map_err(ModelFileError::Fields)?,
            Some(_) => serde_json::from_value(v).map_err(ModelFileError::Fields)?,
        };
        if let (Some(found), true) = (sealed, verify) {
            let computed = m.content_digest()?;
            let found = match found {
                serde_json::Value::String(s) => s,
                other => other.to_string(),
            };
            if !found.eq_ignore_ascii_case(&computed) {
                return Err(ModelFileError::Checksum { found, computed });
            }
        }
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

pub(super) fn supported_list() -> String {
    SUPPORTED_VERSIONS
        .iter()
        .map(|v| v.to_string())
        .collect::<Vec<_>>()
        .join(", ")
}
