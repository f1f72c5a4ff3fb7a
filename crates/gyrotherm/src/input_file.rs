//! Reading the small input files (models, spec sheets, chamber profiles, simulated-unit
//! parameters) with a size limit suited to each kind, before any check of their content: a
//! wrong path (`/dev/zero`, a log given as the model) is an error after a few megabytes
//! instead of a process that grows until it is killed.

use std::fmt;
use std::io::{self, Read};
use std::path::Path;

/// A kind of small input file, with the most bytes one may hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum InputKind {
    /// A model file (single-axis or inertial unit, JSON from `gyrotherm train`). The largest
    /// written are an inertial unit's LSTM models with their coverage maps, a few MB.
    Model,
    /// A spec sheet (TOML): a few limits.
    Spec,
    /// A chamber profile (`simulate --profile-file`, as `plan --out` writes it): a line per
    /// segment.
    Profile,
    /// A simulated unit's parameters (`simulate --unit`, JSON): a few dozen numbers.
    SimUnit,
}

impl InputKind {
    /// The most bytes a file of this kind may hold.
    pub const fn limit_bytes(self) -> u64 {
        match self {
            InputKind::Model => 64 << 20,
            InputKind::Spec => 1 << 20,
            InputKind::Profile => 16 << 20,
            InputKind::SimUnit => 1 << 20,
        }
    }

    /// What the file is, in a message.
    pub fn name(self) -> &'static str {
        match self {
            InputKind::Model => "model file",
            InputKind::Spec => "spec sheet",
            InputKind::Profile => "chamber profile",
            InputKind::SimUnit => "unit parameter file",
        }
    }

    /// What to give instead.
    fn remedy(self) -> &'static str {
        match self {
            InputKind::Model => "give the JSON file `gyrotherm train` wrote",
            InputKind::Spec => "give the spec sheet (TOML with a [limits] table)",
            InputKind::Profile => {
                "give the profile file (`duration_s,target_c` lines, as `gyrotherm plan --out` \
                 writes it)"
            }
            InputKind::SimUnit => {
                "give the unit's JSON parameters (as `gyrotherm simulate --print-unit` prints them)"
            }
        }
    }
}

/// A file larger than its kind may be (the source of the `io::Error` `read_capped`
/// returns).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TooLarge {
    pub kind: InputKind,
}

impl fmt::Display for TooLarge {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "larger than {} MiB, the most a {} holds; nothing was read: {}",
            self.kind.limit_bytes() >> 20,
            self.kind.name(),
            self.kind.remedy()
        )
    }
}

impl std::error::Error for TooLarge {}

/// The bytes of `path`, a file of kind `kind`: an error of kind
/// [`io::ErrorKind::FileTooLarge`] (source [`TooLarge`], naming the limit and what to do)
/// when it holds more than [`InputKind::limit_bytes`]. A device or pipe is read up to one
/// byte past the limit, never further. The caller's error names the file.
pub(crate) fn read_capped(path: &Path, kind: InputKind) -> io::Result<Vec<u8>> {
    let limit = kind.limit_bytes();
    let file = std::fs::File::open(path)?;
    let too_large = || io::Error::new(io::ErrorKind::FileTooLarge, TooLarge { kind });
    // A regular file's size is known: refused before reading it.
    if file
        .metadata()
        .is_ok_and(|m| m.is_file() && m.len() > limit)
    {
        return Err(too_large());
    }
    let mut bytes = Vec::new();
    file.take(limit + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(too_large());
    }
    Ok(bytes)
}

/// `read_capped` as UTF-8 text (an error of kind [`io::ErrorKind::InvalidData`] when it is
/// not, as [`std::fs::read_to_string`] says).
pub fn read_capped_to_string(path: &Path, kind: InputKind) -> io::Result<String> {
    String::from_utf8(read_capped(path, kind)?).map_err(|_| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            "stream did not contain valid UTF-8",
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_at_the_limit_is_read_and_one_byte_more_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("spec.toml");
        let limit = InputKind::Spec.limit_bytes() as usize;
        std::fs::write(&path, vec![b'#'; limit]).unwrap();
        assert_eq!(read_capped(&path, InputKind::Spec).unwrap().len(), limit);
        std::fs::write(&path, vec![b'#'; limit + 1]).unwrap();
        let err = read_capped(&path, InputKind::Spec).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::FileTooLarge);
        let msg = err.to_string();
        assert!(
            msg.contains("larger than 1 MiB, the most a spec sheet holds")
                && msg.contains("give the spec sheet"),
            "{msg}"
        );
    }

    /// An endless device is read one byte past the limit, then refused (it was read whole
    /// before: memory grew until the process was killed).
    #[cfg(unix)]
    #[test]
    fn an_endless_device_is_refused_after_the_limit() {
        for kind in [
            InputKind::Model,
            InputKind::Spec,
            InputKind::Profile,
            InputKind::SimUnit,
        ] {
            let err = read_capped_to_string(Path::new("/dev/zero"), kind).unwrap_err();
            assert_eq!(err.kind(), io::ErrorKind::FileTooLarge, "{kind:?}");
            let source = err.get_ref().and_then(|e| e.downcast_ref::<TooLarge>());
            assert_eq!(source, Some(&TooLarge { kind }));
        }
    }

    #[test]
    fn text_that_is_not_utf8_is_invalid_data() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.json");
        std::fs::write(&path, b"{\xff}").unwrap();
        let err = read_capped_to_string(&path, InputKind::Model).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidData);
    }
}
