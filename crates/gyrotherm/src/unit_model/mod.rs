//! The model of a unit of N gyro axes, read from either file form through one entry point
//! ([`Model::load`]): a single-gyro file ([`ModelFile`], `format_version`) is a unit of one
//! axis; an inertial unit's file ([`ImuModel`], `imu_format_version`) one of its axes. The
//! model remembers the form it was read from, so that checking, sealing, compensating and
//! exporting write exactly what each form's own code writes; callers never ask which form a
//! file holds.

use std::borrow::Cow;
use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};

use crate::compensate_lines::unit::{compensate_imu_file, compensate_imu_lines, ImuLinesSummary};
use crate::compensate_lines::{
    compensate_file, compensate_lines, FileError, LinesError, LinesSummary, Mode,
};
use crate::csvlog::ReadOptions;
use crate::export::autopilot::{self, AutopilotExport, ModelRef};
use crate::export::unit::{column_map, export_imu};
use crate::export::{export, ExportError, ExportTarget, Lang};
use crate::input_file::{read_capped_to_string, InputKind};
use crate::model::unit::{
    is_imu_model_text, ImuAxis, ImuError, ImuModel, SensorScore, IMU_FORMAT_VERSION_ONE_SENSOR,
};
use crate::model::{GivenColumns, ModelFile, ModelFileError, Seal};
use crate::settings::autopilot::AutopilotSettings;
pub use crate::told::Told;
pub use samples::{AxisCoverage, SamplesError, NO_COVERAGE};

mod samples;
mod summary;

/// A model file of either form, as read.
#[derive(Debug, Clone)]
pub struct Model {
    form: Form,
    seal: Seal,
}

/// The file form a [`Model`] was read from and is written back in: the two wire formats of
/// one model (a single gyro's file is a unit of one axis). Only the library's own code
/// chooses between them (for the bytes each form writes); callers see [`Model`].
#[derive(Debug, Clone)]
pub(crate) enum Form {
    Single(Box<ModelFile>),
    Unit(ImuModel),
}

/// Why a model file cannot be used. A single-gyro file's error names the file itself; an
/// inertial unit's is told as `cannot use model FILE` with its cause.
#[derive(Debug)]
#[non_exhaustive]
pub enum ModelError {
    /// A single-gyro model file (the error is its own message).
    Single(ModelFileError),
    /// An inertial unit's model file at `path`.
    Unit { path: PathBuf, source: ImuError },
    /// An inertial unit's model text, read without a file.
    UnitText(ImuError),
}

impl std::fmt::Display for ModelError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ModelError::Single(e) => e.fmt(f),
            ModelError::Unit { path, .. } => write!(f, "cannot use model {}", path.display()),
            ModelError::UnitText(_) => f.write_str("cannot use the unit model text"),
        }
    }
}

impl std::error::Error for ModelError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            // Transparent: the file's error is this error's own.
            ModelError::Single(e) => e.source(),
            ModelError::Unit { source, .. } | ModelError::UnitText(source) => Some(source),
        }
    }
}

impl From<ModelFileError> for ModelError {
    fn from(e: ModelFileError) -> Self {
        ModelError::Single(e)
    }
}

/// One gyro axis of a [`Model`]: its gyro column, the temperature columns it reads (the first
/// sensor first) and its first sensor's model.
#[derive(Debug, Clone, Copy)]
pub struct Axis<'a> {
    pub gyro: &'a str,
    pub temps: &'a [String],
    pub model: &'a ModelFile,
}

/// What a compensation run counted, in the form of the model that ran.
#[derive(Debug, Clone, PartialEq)]
pub struct Compensation(Counts);

#[derive(Debug, Clone, PartialEq)]
enum Counts {
    Single(LinesSummary),
    /// A unit's counts, with the gyro columns they are per axis of.
    Unit(ImuLinesSummary, Vec<String>),
}

impl Model {
    /// Read and check a model file of either form (the checks of that form, the content
    /// checksum included when present; see [`Model::load_warning`] for a file without one).
    pub fn load(path: &Path) -> Result<Model, ModelError> {
        let text = read_capped_to_string(path, InputKind::Model).map_err(|source| {
            ModelFileError::Read {
                path: path.to_path_buf(),
                source,
            }
        })?;
        Self::from_text(&text).map_err(|e| e.in_file(path))
    }

    fn from_text(text: &str) -> Result<Model, TextError> {
        if is_imu_model_text(text) {
            let (m, seal) = ImuModel::from_json_sealed(text).map_err(TextError::Unit)?;
            return Ok(Model {
                form: Form::Unit(m),
                seal,
            });
        }
        let (m, seal) = ModelFile::from_json_sealed(text).map_err(TextError::Single)?;
        Ok(Model {
            form: Form::Single(Box::new(m)),
            seal,
        })
    }

    /// Parse and check model text of either form, as [`Model::load`] checks a file.
    pub fn from_json(text: &str) -> Result<Model, ModelError> {
        Self::from_text(text).map_err(|e| match e {
            TextError::Single(e) => ModelError::Single(e),
            TextError::Unit(e) => ModelError::UnitText(e),
        })
    }

    /// The file's text: the bytes [`Model::save`] writes, in the form it was read from.
    pub fn to_json(&self) -> Result<String, ModelError> {
        match &self.form {
            Form::Single(m) => {
                let mut text = m.to_json()?;
                text.push('\n');
                Ok(text)
            }
            Form::Unit(m) => m.to_json().map_err(ModelError::UnitText),
        }
    }

    /// A single-gyro model as a one-axis unit (sealed: it was made, not read).
    pub fn from_single(m: ModelFile) -> Model {
        Model {
            form: Form::Single(Box::new(m)),
            seal: Seal::Verified,
        }
    }

    /// An inertial unit's model (sealed: it was made, not read).
    pub fn from_unit(m: ImuModel) -> Model {
        Model {
            form: Form::Unit(m),
            seal: Seal::Verified,
        }
    }

    /// Whether the model has the form of an inertial unit's file (for the library's own
    /// choice between the two forms' code; see the module doc).
    pub(crate) fn is_unit(&self) -> bool {
        matches!(self.form, Form::Unit(_))
    }

    /// Whether the file read held its content checksum.
    pub fn seal(&self) -> Seal {
        self.seal
    }

    /// What to tell the user about the file `path` as read: nothing when sealed.
    pub fn load_warning(&self, path: &Path) -> Option<String> {
        self.seal.warning(path)
    }

    /// Re-seal a hand-edited model file of either form: read it without checking its
    /// `content_sha256`, check everything else, and write it back with a new one. Returns the
    /// new digest.
    pub fn seal_file(path: &Path) -> Result<String, ModelError> {
        let text = read_capped_to_string(path, InputKind::Model).unwrap_or_default();
        if is_imu_model_text(&text) {
            let (_, digest) = ImuModel::seal(path).map_err(|source| ModelError::Unit {
                path: path.to_path_buf(),
                source,
            })?;
            return Ok(digest);
        }
        Ok(ModelFile::seal(path)?.1)
    }

    /// `model check`'s line: whether the file is sealed, its axes when a unit, and its
    /// content digest.
    pub fn check_line(&self, path: &Path) -> Result<String, ModelError> {
        let state = match self.seal {
            Seal::Verified => "ok, sealed",
            Seal::Absent => "ok but not sealed",
        };
        Ok(match &self.form {
            Form::Single(m) => format!(
                "{}: {state}, content_sha256 {}",
                path.display(),
                m.content_digest()?
            ),
            Form::Unit(m) => format!(
                "{}: {state} (inertial unit, {} axes), content_sha256 {}",
                path.display(),
                m.axes.len(),
                m.content_digest().map_err(|source| ModelError::Unit {
                    path: path.to_path_buf(),
                    source,
                })?
            ),
        })
    }

    /// Write the file atomically, in the form it was read from.
    pub fn save(&self, path: &Path) -> Result<(), ModelError> {
        match &self.form {
            Form::Single(m) => Ok(m.save(path)?),
            Form::Unit(m) => m.save(path).map_err(|source| ModelError::Unit {
                path: path.to_path_buf(),
                source,
            }),
        }
    }

    /// The axes, in column order: a single-gyro file's one axis reads the columns it was
    /// trained with, or those of `base` (the command line's, else the standard names) where
    /// the file does not name them.
    pub fn axes<'a>(&'a self, base: &'a ReadOptions) -> Vec<Axis<'a>> {
        match &self.form {
            Form::Single(m) => {
                let (gyro, temp) = match &m.columns {
                    Some(c) => (&c.gyro_col, &c.temp_col),
                    None => (&base.gyro_col, &base.temp_col),
                };
                vec![Axis {
                    gyro,
                    temps: std::slice::from_ref(temp),
                    model: m,
                }]
            }
            Form::Unit(u) => u
                .axes
                .iter()
                .map(|a| Axis {
                    gyro: &a.gyro,
                    temps: &a.temps,
                    model: &a.model,
                })
                .collect(),
        }
    }

    /// The model as an inertial unit's: a single-gyro model is the unit of its one axis
    /// ([`Model::axes`]), its one sensor unscored (it was not chosen among others).
    pub fn to_unit<'a>(&'a self, base: &ReadOptions) -> Cow<'a, ImuModel> {
        match &self.form {
            Form::Unit(m) => Cow::Borrowed(m),
            Form::Single(m) => {
                let axis = &self.axes(base)[0];
                let (gyro, temp) = (axis.gyro.to_owned(), axis.temps[0].clone());
                Cow::Owned(ImuModel {
                    imu_format_version: IMU_FORMAT_VERSION_ONE_SENSOR,
                    gyro_cols: vec![gyro.clone()],
                    temp_cols: vec![temp.clone()],
                    axes: vec![ImuAxis {
                        gyro,
                        temps: vec![temp.clone()],
                        scores: vec![SensorScore { temp, cv_rms: None }],
                        model: ModelFile::clone(m),
                        more: Vec::new(),
                        multi_cv_rms: None,
                        fallback: None,
                    }],
                })
            }
        }
    }

    /// The read options for a log this model runs on: the model's columns where it names
    /// them (a single-gyro file: those `given` on the command line win), the rest of `base`.
    pub fn read_options(
        &self,
        base: &ReadOptions,
        given: GivenColumns,
    ) -> Result<ReadOptions, ModelFileError> {
        match &self.form {
            Form::Single(m) => m.read_options(base, given),
            Form::Unit(m) => Ok(m.read_options(base)),
        }
    }

    /// Read a unit's held-out logs in this model's form, with `opts` (from
    /// [`Model::read_options`]): a unit model's as a unit's, a single-gyro model's as a single
    /// gyro's unless the options name column lists or a file holds a unit (which
    /// [`crate::lot::judge_model`] then refuses with what to do).
    pub fn read_logs(
        &self,
        paths: &[PathBuf],
        opts: &ReadOptions,
        table_axis: Option<&str>,
    ) -> crate::csvlog::SetRead {
        let unit = self.is_unit() || opts.reads_unit(paths);
        crate::csvlog::read_in_form(paths, opts, table_axis, unit)
    }

    /// What to tell before compensating with the model read from `path`: a single-gyro
    /// model's missing coverage map, and a sample period given that compensation does not need.
    pub fn compensate_notes(&self, path: &Path, sample_period_given: bool) -> Vec<Told> {
        let Form::Single(m) = &self.form else {
            return Vec::new();
        };
        let mut told = Vec::new();
        if let Some(n) = crate::coverage::missing_note(m) {
            told.push(Told::Note(format!("{}: {n}", path.display())));
        }
        if sample_period_given {
            told.push(Told::Note(
                "--sample-period-s is not needed by compensate (output starts with the first \
                 line); ignored"
                    .into(),
            ));
        }
        told
    }

    /// Compensate the log `input` into the CSV file `out` ([`Mode::Strict`]), read with
    /// `opts` (from [`Model::read_options`]).
    pub fn compensate_file(
        &self,
        input: &Path,
        out: &Path,
        opts: &ReadOptions,
    ) -> Result<Compensation, FileError> {
        Ok(Compensation(match &self.form {
            Form::Single(m) => Counts::Single(compensate_file(m, input, out, opts)?),
            Form::Unit(m) => Counts::Unit(
                compensate_imu_file(m, input, out, opts)?,
                m.gyro_cols.clone(),
            ),
        }))
    }

    /// Compensate the live stream `input` (named `source` in errors) into `output`
    /// ([`Mode::Stream`], each line flushed).
    pub fn compensate_stream(
        &self,
        input: &mut dyn BufRead,
        source: &Path,
        opts: &ReadOptions,
        output: &mut dyn Write,
    ) -> Result<Compensation, LinesError> {
        Ok(Compensation(match &self.form {
            Form::Single(m) => Counts::Single(compensate_lines(
                m,
                input,
                source,
                opts,
                output,
                Mode::Stream,
                true,
            )?),
            Form::Unit(m) => Counts::Unit(
                compensate_imu_lines(m, input, source, opts, output, Mode::Stream, true)?,
                m.gyro_cols.clone(),
            ),
        }))
    }

    /// Write the model as flight code in `lang` into `dir`: the files written, then what to
    /// tell about them.
    pub fn export(&self, lang: Lang, dir: &Path) -> Result<Vec<Told>, ExportError> {
        let (files, map) = match &self.form {
            Form::Single(m) => (export(m, lang, dir)?, None),
            Form::Unit(m) => (export_imu(m, lang, dir)?, Some(column_map(m))),
        };
        let mut told: Vec<Told> = files
            .iter()
            .map(|f| Told::Line(format!("wrote {}", f.display())))
            .collect();
        if let Some(map) = map {
            // The names stay out of the generated source (they come from the model file):
            // the files list the order by index, and this is the map.
            told.push(Told::Line(
                "column order of the exported unit (names from the model file):".into(),
            ));
            told.extend(map.into_iter().map(Told::Item));
        }
        Ok(told)
    }

    /// Write the model for `target` into `dir`: flight code (C, Rust; [`Model::export`]) or
    /// an autopilot's parameter file (`Model::export_autopilot`), with the polynomial's fit
    /// and what it does not carry. What to tell comes with the outcome, also when it failed
    /// (`axis_given` as for `Model::export_autopilot`).
    pub fn write_export(
        &self,
        target: ExportTarget,
        settings: &AutopilotSettings,
        axis_given: bool,
        dir: &Path,
    ) -> (Vec<Told>, Result<(), ExportError>) {
        if let Some(lang) = target.lang() {
            return match self.export(lang, dir) {
                Ok(told) => (told, Ok(())),
                Err(e) => (Vec::new(), Err(e)),
            };
        }
        let (mut told, export) = self.export_autopilot(target, settings, axis_given);
        let export = match export {
            Ok(e) => e,
            Err(e) => return (told, Err(e)),
        };
        for line in export.summary() {
            told.push(match line.strip_prefix("warning: ") {
                Some(w) => Told::Warning(w.to_owned()),
                None => Told::Line(line),
            });
        }
        match autopilot::write(&export, dir) {
            Ok(path) => {
                told.push(Told::Line(format!("wrote {}", path.display())));
                (told, Ok(()))
            }
            Err(e) => (told, Err(e)),
        }
    }

    /// The autopilot's parameters for the model (see [`autopilot::generate`]), with what to
    /// tell first when the command line named an axis (`axis_given`) that a unit's columns fix.
    pub(crate) fn export_autopilot(
        &self,
        target: ExportTarget,
        settings: &AutopilotSettings,
        axis_given: bool,
    ) -> (Vec<Told>, Result<AutopilotExport, ExportError>) {
        let mut told = Vec::new();
        let model = match &self.form {
            Form::Single(m) => ModelRef::Single(m),
            Form::Unit(m) => {
                if axis_given {
                    told.push(Told::Warning(
                        "--axis is for a single-gyro model; the unit's axes are X, Y, Z in its \
                         column order:"
                            .into(),
                    ));
                    for (axis, gyro) in ["X", "Y", "Z"].iter().zip(&m.gyro_cols) {
                        told.push(Told::Item(format!("{axis} = {gyro}")));
                    }
                }
                ModelRef::Unit(m)
            }
        };
        (told, autopilot::generate(model, target, settings))
    }
}

impl Compensation {
    /// Data lines written (= data lines read).
    pub fn rows(&self) -> u64 {
        match &self.0 {
            Counts::Single(s) => s.rows,
            Counts::Unit(s, _) => s.rows,
        }
    }

    /// Per axis, in column order, the lines per status: ok, held, degraded, invalid (a
    /// malformed line is invalid), fallback.
    pub fn per_axis(&self) -> Vec<[u64; 5]> {
        match &self.0 {
            Counts::Single(s) => vec![[s.ok, s.held, s.degraded, s.invalid, 0]],
            Counts::Unit(s, _) => s.per_axis.clone(),
        }
    }

    /// The warnings of the run: extrapolation (a single-gyro model's) and time steps longer
    /// than the compensator runs at.
    pub fn warnings(&self) -> &[String] {
        match &self.0 {
            Counts::Single(s) => &s.warnings,
            Counts::Unit(s, _) => &s.warnings,
        }
    }

    /// What to tell about the run: a file run writes `wrote OUT (...)`, a stream (`out` None)
    /// its counts; then temperature faults and warnings, as each form tells them.
    pub fn told(&self, out: Option<&Path>) -> Vec<Told> {
        let mut told = Vec::new();
        match &self.0 {
            Counts::Single(s) => {
                told.push(Told::Line(match out {
                    Some(out) => format!("wrote {} ({})", out.display(), s.describe()),
                    None => s.describe(),
                }));
                if s.held + s.degraded + s.invalid > 0 {
                    told.push(Told::Line(format!(
                        "temperature faults ridden through: {} held, {} degraded; {} invalid \
                         (no rate: gyro not finite{})",
                        s.held,
                        s.degraded,
                        s.invalid,
                        if s.malformed > 0 {
                            " or malformed line"
                        } else {
                            ""
                        }
                    )));
                }
                told.extend(s.warnings.iter().cloned().map(Told::Warning));
            }
            Counts::Unit(s, gyro_cols) => match out {
                None => {
                    told.push(Told::Line(s.describe(gyro_cols)));
                    told.extend(s.warnings.iter().cloned().map(Told::Warning));
                }
                Some(out) => {
                    let counts: Vec<String> = gyro_cols
                        .iter()
                        .zip(&s.per_axis)
                        .enumerate()
                        .map(|(k, (g, n))| {
                            let fallback = if n[4] > 0 {
                                format!(", {} fallback", n[4])
                            } else {
                                String::new()
                            };
                            let coverage = s.coverage_counts(k);
                            format!(
                                "{g}: {} ok, {} held, {} degraded, {} invalid{fallback}{coverage}",
                                n[0], n[1], n[2], n[3]
                            )
                        })
                        .collect();
                    told.push(Told::Line(format!(
                        "wrote {} ({} lines; {})",
                        out.display(),
                        s.rows,
                        counts.join("; ")
                    )));
                }
            },
        }
        told
    }
}

/// Why model text could not be used, before the file is named.
enum TextError {
    Single(ModelFileError),
    Unit(ImuError),
}

impl TextError {
    fn in_file(self, path: &Path) -> ModelError {
        match self {
            TextError::Single(e) => ModelError::Single(ModelFileError::InFile {
                path: path.to_path_buf(),
                source: Box::new(e),
            }),
            TextError::Unit(source) => ModelError::Unit {
                path: path.to_path_buf(),
                source,
            },
        }
    }
}
