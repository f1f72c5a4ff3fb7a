//! Export a model file for flight code: a C99 source pair ([`c`]) or a Rust module for
//! `gyrotherm-core` ([`rust`]), both from the same static form of the model
//! ([`static_model`]), so that no JSON is parsed in flight.
//!
//! The C code computes exactly what `gyrotherm-core` computes: the same operations in the same
//! order, f64 for features, baselines and the compensator, f32 for the LSTM with the core's
//! activation approximations, and a port of the `libm` crate's `expm1` (FreeBSD `s_expm1.c`)
//! for lag filters across gaps. Compiled with `-std=c99 -ffp-contract=off` (no fused
//! multiply-add, as Rust never contracts) on an IEEE 754 target with single-precision `float`
//! arithmetic (`FLT_EVAL_METHOD == 0`: x86-64 SSE, Cortex-M4F), its outputs equal
//! `gyrotherm compensate --stream` to the last bit.

pub mod ardupilot;
pub mod autopilot;
pub mod c;
pub mod px4;
pub mod rust;
pub mod steady_bias;
pub mod target;
pub mod unit;

pub use target::{ExportTarget, EXPORT_TARGETS};

use std::path::{Path, PathBuf};

use gyrotherm_core::compensator::LSTM_INPUTS;
use gyrotherm_core::coverage::{MAX_RATE_CELLS, MAX_TEMP_CELLS};
use gyrotherm_core::features::MAX_FEATURES;
use gyrotherm_core::static_model::{StaticCoverage, StaticModel};

use crate::compensate::CompensateError;
pub(crate) use crate::model::static_baseline;
use crate::model::{static_target, ModelFile, ModelFileError, SubModel, Target, CHECKSUM_KEY};

/// Why a model cannot be exported.
#[derive(Debug)]
#[non_exhaustive]
pub enum ExportError {
    /// The model file fails its checks.
    Model(ModelFileError),
    /// The model cannot be turned into flight form.
    Flight(CompensateError),
    /// An inertial-unit model fails its checks, or one of its axes cannot be exported.
    Unit(crate::model::unit::ImuError),
    /// The model cannot be written as autopilot parameters.
    Autopilot(autopilot::AutopilotError),
    /// Writing an output file failed.
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
}

impl std::fmt::Display for ExportError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ExportError::Model(_) | ExportError::Flight(_) => {
                f.write_str("model cannot be exported")
            }
            ExportError::Unit(_) => f.write_str("inertial-unit model cannot be exported"),
            ExportError::Autopilot(_) => f.write_str("cannot write autopilot parameters"),
            ExportError::Io { path, .. } => write!(f, "cannot write {}", path.display()),
        }
    }
}

impl std::error::Error for ExportError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ExportError::Io { source, .. } => Some(source),
            ExportError::Model(e) => Some(e),
            ExportError::Flight(e) => Some(e),
            ExportError::Unit(e) => Some(e),
            ExportError::Autopilot(e) => Some(e),
        }
    }
}

/// Target language.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Lang {
    /// `gyrotherm_model.h` + `gyrotherm_model.c`, C99.
    C,
    /// `gyrotherm_model.rs`, a module for `gyrotherm-core`.
    Rust,
}

/// Names of the export languages.
pub(crate) const LANG_NAMES: [&str; 2] = ["c", "rust"];

impl Lang {
    /// The name on the command line (`--target`).
    pub fn as_str(&self) -> &'static str {
        match self {
            Lang::C => "c",
            Lang::Rust => "rust",
        }
    }

    /// One line on what is written (the `--help` text of the value).
    pub fn help(&self) -> &'static str {
        ExportTarget::from(*self).help()
    }
}

impl std::fmt::Display for Lang {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl std::str::FromStr for Lang {
    type Err = crate::settings::SettingError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        [Lang::C, Lang::Rust]
            .into_iter()
            .find(|l| l.as_str() == s)
            .ok_or_else(|| crate::settings::SettingError::unknown("lang", s, &LANG_NAMES))
    }
}

/// The static (flight) form of a model file: the numbers the core's compensator is built
/// from, after the same conversions (`f64` LSTM weights to `f32`, inputs padded to
/// `LSTM_INPUTS` slots), for a model whose LSTMs (if any) have 8 hidden units; see
/// [`sized_static_model`] for the others.
pub fn static_model(model: &ModelFile) -> Result<StaticModel, ExportError> {
    sized_static_model::<{ gyrotherm_core::compensator::HIDDEN }>(model)
}

/// The flight size of a model file's LSTMs ([`crate::compensate::hidden_size`]).
pub(crate) fn model_hidden_size(
    model: &ModelFile,
) -> Result<crate::flight_size::HiddenSize, ExportError> {
    crate::compensate::hidden_size([model.bias.as_ref(), model.scale.as_ref()])
        .map_err(ExportError::Flight)
}

/// [`static_model`] at `H` hidden units (smaller LSTMs widened with zero units, larger ones
/// refused).
pub fn sized_static_model<const H: usize>(
    model: &ModelFile,
) -> Result<StaticModel<H>, ExportError> {
    let err = ExportError::Model;
    model.validate().map_err(err)?;
    let spec = model.feature_spec().map_err(err)?;
    let limits = model.features.temp_sensor.to_core().map_err(err)?;
    let target = |sub: Option<&SubModel>, absent: f64, target: Target| {
        static_target(sub, absent).map_err(|e| {
            ExportError::Flight(CompensateError::InTarget {
                target,
                source: Box::new(e),
            })
        })
    };
    Ok(StaticModel {
        spec,
        limits,
        bias: target(model.bias.as_ref(), 0.0, Target::Bias)?,
        scale: target(model.scale.as_ref(), 1.0, Target::Scale)?,
        coverage: static_coverage(model)?,
    })
}

/// The model's coverage map as static data, checked as `compensate` checks it (the core map
/// is built from it, so a map the core refuses is refused here rather than in flight).
fn static_coverage(model: &ModelFile) -> Result<Option<StaticCoverage>, ExportError> {
    let Some(def) = &model.coverage else {
        return Ok(None);
    };
    let map = def
        .to_core()
        .map_err(|e| ExportError::Model(ModelFileError::invalid("coverage", e.to_string())))?;
    let grid = *map.grid();
    let mut sigma_dph = [0.0; MAX_TEMP_CELLS * MAX_RATE_CELLS];
    for i in 0..grid.n_temp {
        for j in 0..grid.n_rate {
            sigma_dph[i * grid.n_rate + j] = map.sigma_dph(i, j).unwrap_or(0.0);
        }
    }
    Ok(Some(StaticCoverage {
        grid,
        sigma_dph,
        growth_per_cell: map.growth_per_cell(),
    }))
}

// The generators index the core's arrays by these sizes.
const _: () = assert!(LSTM_INPUTS == MAX_FEATURES);

/// The generated files of `model` for `lang`, as `(file name, text)`, without writing
/// anything. Every byte of the text is one the generator chose: its templates, numbers it
/// formatted and fixed words; no string of the model file (who created it, the training
/// files' names) is copied into it, so a model cannot inject code or directives into flight
/// source. See [`is_generated_text`].
pub fn generate(model: &ModelFile, lang: Lang) -> Result<Vec<(&'static str, String)>, ExportError> {
    let size = model_hidden_size(model)?;
    crate::flight_size::with_hidden!(size, H => generate_sized::<H>(model, lang))
}

/// [`generate`] with the LSTMs at `H` hidden units.
fn generate_sized<const H: usize>(
    model: &ModelFile,
    lang: Lang,
) -> Result<Vec<(&'static str, String)>, ExportError> {
    let m = sized_static_model::<H>(model)?;
    let about = describe(model)?;
    let files = match lang {
        Lang::C => {
            let (h, c) = c::generate(&m, &about);
            vec![("gyrotherm_model.h", h), ("gyrotherm_model.c", c)]
        }
        Lang::Rust => vec![("gyrotherm_model.rs", rust::generate(&m, &about))],
    };
    Ok(files)
}

/// Write the export of `model` for `lang` into `dir` (created if missing), each file
/// atomically; returns the files written.
pub fn export(model: &ModelFile, lang: Lang, dir: &Path) -> Result<Vec<PathBuf>, ExportError> {
    write_files(generate(model, lang)?, dir)
}

/// Write generated `files` into `dir` (created if missing), each atomically.
pub(crate) fn write_files(
    files: Vec<(&'static str, String)>,
    dir: &Path,
) -> Result<Vec<PathBuf>, ExportError> {
    std::fs::create_dir_all(dir).map_err(|source| ExportError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    // Every destination is checked before any is written, so a refused one (a link planted
    // in the folder) leaves no partial export behind.
    for (name, _) in &files {
        let path = dir.join(name);
        crate::atomic_file::destination(&path)
            .map_err(|source| ExportError::Io { path, source })?;
    }
    let mut out = Vec::new();
    for (name, text) in files {
        let path = dir.join(name);
        crate::atomic_file::write_bytes_atomically(&path, text.as_bytes()).map_err(|source| {
            ExportError::Io {
                path: path.clone(),
                source,
            }
        })?;
        out.push(path);
    }
    Ok(out)
}

/// Whether `text` holds only what the generator writes: printable ASCII (0x20 to 0x7E) and
/// `\n`, and no `??` (the start of every C trigraph, which `-std=c99` would translate).
/// Control characters, bidirectional overrides and other non-ASCII text can only come
/// from outside the generator, so their absence is checked in the tests and the fuzz target.
pub fn is_generated_text(text: &str) -> bool {
    text.bytes()
        .all(|b| b == b'\n' || (0x20..=0x7e).contains(&b))
        && !text.contains("??")
}

/// One line saying what the model is, for the generated files' headers: only the
/// generator's own words for the method and the sub-model kinds, and the model's content
/// hash (hex), by which the model file can be found again. The file's free-text fields
/// (`training.created_by`, `training.inputs`) are left out: they are whatever the file
/// says, and in a comment of generated source they could close the comment and add code.
pub(crate) fn describe(model: &ModelFile) -> Result<String, ExportError> {
    // The enum's own fixed name, never the file's text.
    let method: &'static str = model.method.as_str();
    let kind = |s: &Option<SubModel>| match s {
        None => "none",
        Some(SubModel::Lstm { .. }) => "lstm",
        Some(SubModel::Baseline { .. }) => "least squares",
        Some(SubModel::Residual { .. }) => "least squares + lstm",
    };
    // SHA-256 computed here, as lower-case hex (`sha256_hex`), not read from the file.
    let digest = model.content_digest().map_err(ExportError::Model)?;
    Ok(format!(
        "method {method}, bias: {}, scale factor: {}; {CHECKSUM_KEY} {digest}",
        kind(&model.bias),
        kind(&model.scale),
    ))
}

/// Shortest round-trip text of an f64, valid as a C and a Rust literal (`1e0`, `-2.5e-3`).
pub(crate) fn f64_lit(v: f64) -> String {
    format!("{v:e}")
}

/// Shortest round-trip text of an f32 (no suffix).
pub(crate) fn f32_lit(v: f32) -> String {
    format!("{v:e}")
}
