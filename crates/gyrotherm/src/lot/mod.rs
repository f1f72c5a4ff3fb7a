//! A lot: the test station's record of units judged against their spec sheet.
//!
//! `judge_unit` compensates a unit's held-out logs with its model (the flight compensator,
//! as `gyrotherm compare` does for one model), measures every figure of
//! [`crate::spec::FIGURES`] on each, judges them against the spec sheet when
//! one is given, and returns a [`Run`]: the unit, the time, the gyrotherm version, the
//! SHA-256 of every input and the model's `content_sha256`, each figure and verdict, and
//! the spec. A [`LotStore`] keeps runs: `SqliteStore` (one file, the default) or
//! `PgStore` (PostgreSQL, for several stations on separate machines), with the same schema
//! ([`schema`], docs/lot-schema.md). [`report`] writes the lot's HTML page and CSV.
//!
//! Nothing is lost: each run is written in one transaction; a unit added again keeps both
//! runs, and the `latest_runs` view (and [`Run::latest`]) marks the newer one.

mod pg;
pub mod report;
pub mod schema;
mod sqlite;
mod time;

pub(crate) use pg::PgStore;
pub(crate) use sqlite::SqliteStore;
pub use time::now_unix_ms;
pub(crate) use time::rfc3339_utc;

use std::fmt;
use std::path::{Path, PathBuf};

use serde::Serialize;
use sha2::{Digest, Sha256};

use crate::compensate::compensate_log;
use crate::csvlog::{ImuLog, LogSet, LogSetForm, TestLog};
use crate::fit::NamedLog;
use crate::metrics::EvaluationOptions;
use crate::model::unit::ImuModel;
use crate::model::ModelFile;
use crate::spec::unit::{ImuJudgeError, UnitVerdict};
use crate::spec::{self, MeasureOptions, Spec};
use crate::unit_model::Model;

/// One input file of a run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Input {
    /// Position among the run's held-out logs, from 0.
    pub position: u32,
    /// The path as given.
    pub path: String,
    /// SHA-256 of the file's bytes, hex.
    pub sha256: String,
    /// `static` or `rate_table`.
    pub kind: &'static str,
}

/// One measured figure of one held-out log of a run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FigureRow {
    /// The [`AxisRecord::axis`] it was measured on, for an inertial unit's run (None for a
    /// single-axis run, stored as axis 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axis: Option<u32>,
    /// The [`Input::position`] of the log it was measured on.
    pub position: u32,
    /// The figure's key ([`spec::FIGURES`]).
    pub figure: String,
    pub value: f64,
    /// The spec's limits on it, if any.
    pub limit_min: Option<f64>,
    pub limit_max: Option<f64>,
    /// `Some(true)` pass, `Some(false)` fail, `None` not limited.
    pub pass: Option<bool>,
    /// Distance to the nearest limit (positive inside), when limited.
    pub margin: Option<f64>,
}

/// The verdict of a run: `pass`, `fail`, or `none` (judged without a spec).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum RunVerdict {
    Pass,
    Fail,
    None,
}

impl RunVerdict {
    /// The word stored in the database.
    pub fn as_str(self) -> &'static str {
        match self {
            RunVerdict::Pass => "pass",
            RunVerdict::Fail => "fail",
            RunVerdict::None => "none",
        }
    }

    fn parse(s: &str) -> Option<RunVerdict> {
        match s {
            "pass" => Some(RunVerdict::Pass),
            "fail" => Some(RunVerdict::Fail),
            "none" => Some(RunVerdict::None),
            _ => None,
        }
    }
}

/// One gyro axis of an inertial unit's run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisRecord {
    /// Its position among the unit's axes, from 0 (the model's gyro column order).
    pub axis: u32,
    /// The gyro column.
    pub gyro: String,
    /// The temperature columns the axis's model reads, the first sensor first.
    pub temps: Vec<String>,
    /// The axis's verdict: `pass` when each limited figure passes on every log that gives
    /// it, `none` when judged without a spec.
    pub verdict: RunVerdict,
}

/// One unit judged once: what a lot records.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Run {
    /// Its id in the store (0 before it is stored); ids grow in the order runs are added.
    pub id: i64,
    /// The unit's serial number.
    pub unit: String,
    /// When it was judged, ms since 1970-01-01 UTC.
    pub tested_at_unix_ms: i64,
    /// The gyrotherm version that judged it.
    pub gyrotherm_version: String,
    /// Which station judged it (host name unless given).
    pub station: String,
    pub model_path: String,
    /// SHA-256 of the model file's bytes.
    pub model_sha256: String,
    /// The model's own `content_sha256` (its content, however it is formatted).
    pub model_content_sha256: String,
    pub model_method: String,
    /// The spec sheet's name, SHA-256 and text, when judged against one.
    pub spec_name: Option<String>,
    pub spec_sha256: Option<String>,
    pub spec_toml: Option<String>,
    pub verdict: RunVerdict,
    /// True for the newest run of its unit (set when read back).
    pub latest: bool,
    pub inputs: Vec<Input>,
    /// An inertial unit's axes (empty for a single-axis run); the run's `verdict` is then the
    /// unit's: `pass` only when every axis passes.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub axes: Vec<AxisRecord>,
    pub figures: Vec<FigureRow>,
}

impl Run {
    /// The figure's value on the log where it is worst: the smallest margin when limited,
    /// else the largest magnitude. None when no log of the run gives it.
    pub fn worst(&self, figure: &str) -> Option<&FigureRow> {
        self.figures
            .iter()
            .filter(|f| f.figure == figure)
            .min_by(|a, b| match (a.margin, b.margin) {
                (Some(x), Some(y)) => x.total_cmp(&y),
                _ => b.value.abs().total_cmp(&a.value.abs()),
            })
    }

    /// The test date as RFC 3339 UTC.
    pub fn tested_at(&self) -> String {
        rfc3339_utc(self.tested_at_unix_ms)
    }

    /// Whether this is an inertial unit's run (with axes).
    pub(crate) fn is_unit(&self) -> bool {
        !self.axes.is_empty()
    }

    /// The record of axis `axis` (None: a single-axis run, or no such axis).
    pub fn axis_of(&self, axis: Option<u32>) -> Option<&AxisRecord> {
        let k = axis?;
        self.axes.iter().find(|a| a.axis == k)
    }

    /// The gyro column of axis `axis` (None: a single-axis run, or no such axis).
    pub(crate) fn gyro_of(&self, axis: Option<u32>) -> Option<&str> {
        self.axis_of(axis).map(|a| a.gyro.as_str())
    }
}

/// The unit's verdict from its axes' verdicts: `none` when no axis was judged, else the rule
/// of [`UnitVerdict::from_axes`] (a unit passes only when every axis passes).
pub(crate) fn unit_verdict_of_axes(axes: &[AxisRecord]) -> RunVerdict {
    if axes.iter().all(|a| a.verdict == RunVerdict::None) {
        return RunVerdict::None;
    }
    let v = UnitVerdict::from_axes(
        "",
        "",
        "compensated",
        axes.iter()
            .map(|a| (a.gyro.as_str(), a.verdict != RunVerdict::Fail)),
    );
    RunVerdict::of(Some(v.pass))
}

/// Why a lot could not be read or written, or a unit judged.
#[derive(Debug)]
#[non_exhaustive]
pub enum LotError {
    /// An input file could not be read.
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The model could not be loaded or applied.
    Model {
        path: PathBuf,
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// The figures of a held-out log could not be computed.
    Measure {
        log: String,
        source: crate::metrics::EvaluationError,
    },
    /// The spec could not be applied (a limited figure no log gives).
    Spec(spec::SpecError),
    /// A unit name that cannot name a unit: empty, only white space, white space around it
    /// (`A1` and ` A1` would be two units) or a control character.
    UnitName { name: String, why: &'static str },
    /// The database file does not exist (`lot list`/`lot report` never create one).
    Missing { db: String },
    /// The file is not an SQLite database (or is damaged).
    NotADatabase { db: String, detail: String },
    /// A database without the lot schema (other tables, no `schema_version`).
    NotALot { db: String },
    /// The lot was written by a newer gyrotherm (schema `found` > `supported`).
    NewerSchema {
        db: String,
        found: i64,
        supported: i64,
    },
    /// A schema version below 1, which no gyrotherm writes (edited by hand?): nothing can
    /// tell which upgrades the tables still need.
    InvalidSchema { db: String, found: i64 },
    /// Another writer held the database for longer than the busy timeout.
    Locked { db: String, waited_ms: u64 },
    /// Any other database error.
    Database { db: String, detail: String },
    /// A stored value the schema does not allow (edited by hand?).
    BadRow { db: String, detail: String },
    /// An inertial unit's figures or verdict could not be computed (the message holds the
    /// whole chain of causes).
    Unit(ImuJudgeError),
    /// Upgrading an older lot schema failed; its transaction was rolled back.
    Migration {
        db: String,
        from: i64,
        to: i64,
        detail: String,
    },
}

impl LotError {
    /// A database error met at upgrade step `step` (0: version 1 → 2) from version `from`,
    /// as the failed upgrade it is; any other error as it was.
    pub(crate) fn in_migration(self, from: i64, step: usize) -> LotError {
        match self {
            LotError::Database { db, detail } => LotError::Migration {
                db,
                from,
                to: step as i64 + 2,
                detail,
            },
            other => other,
        }
    }
}

/// `e` and its sources, joined by `: `.
fn write_chain(f: &mut fmt::Formatter<'_>, e: &dyn std::error::Error) -> fmt::Result {
    let mut e: Option<&dyn std::error::Error> = Some(e);
    let mut first = true;
    while let Some(x) = e {
        if !first {
            write!(f, ": ")?;
        }
        write!(f, "{x}")?;
        first = false;
        e = x.source();
    }
    Ok(())
}

impl fmt::Display for LotError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            // The cause follows through `source()`, as `{:#}` and `error_chain` print it.
            LotError::Read { path, .. } => write!(f, "cannot read {}", path.display()),
            LotError::Model { path, .. } => write!(f, "{}", path.display()),
            LotError::Measure { log, source } => {
                write!(f, "{log}: ")?;
                write_chain(f, source)
            }
            LotError::Spec(e) => write!(f, "{e}"),
            LotError::UnitName { name, why } => {
                write!(f, "unit name {name:?} {why}; give the unit's serial number")
            }
            LotError::Missing { db } => write!(
                f,
                "{db}: no such lot database; `gyrotherm lot add --db {db} …` creates it"
            ),
            LotError::NotADatabase { db, detail } => write!(
                f,
                "{db}: not an SQLite database, or damaged ({detail}); nothing was changed: \
                 check the path, or restore the file from a backup"
            ),
            LotError::NotALot { db } => write!(
                f,
                "{db}: a database without the gyrotherm lot schema (no schema_version table); \
                 nothing was changed: give a lot's path or a new file"
            ),
            LotError::NewerSchema {
                db,
                found,
                supported,
            } => write!(
                f,
                "{db}: lot schema version {found} is newer than this gyrotherm reads \
                 ({supported}); nothing was changed: use a newer gyrotherm"
            ),
            LotError::InvalidSchema { db, found } => write!(
                f,
                "{db}: lot schema version {found} is not one gyrotherm writes (versions start \
                 at 1); nothing was changed: the schema_version table was edited outside \
                 gyrotherm; restore the lot from a backup, or set the version its tables match \
                 (docs/lot-schema.md)"
            ),
            LotError::Locked { db, waited_ms } => write!(
                f,
                "{db}: locked by another writer for more than {waited_ms} ms; nothing was \
                 changed: retry, or raise --busy-timeout"
            ),
            LotError::Database { db, detail } => write!(f, "{db}: {detail}"),
            LotError::BadRow { db, detail } => {
                write!(f, "{db}: {detail}; the lot was edited outside gyrotherm")
            }
            LotError::Unit(e) => write_chain(f, e),
            LotError::Migration {
                db,
                from,
                to,
                detail,
            } => write!(
                f,
                "{db}: cannot upgrade the lot schema from version {from} to {to} ({detail}); \
                 nothing was changed and the lot is still version {from}: a table or key the \
                 upgrade adds may already be there (made by hand?); rename it, or upgrade with \
                 the statements in docs/lot-schema.md, then retry"
            ),
        }
    }
}

impl std::error::Error for LotError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            LotError::Read { source, .. } => Some(source),
            LotError::Model { source, .. } => Some(source.as_ref()),
            // Transparent: the spec's message is this error's own.
            LotError::Spec(e) => e.source(),
            _ => None,
        }
    }
}

/// A place runs are kept: the same schema in SQLite or PostgreSQL.
pub trait LotStore {
    /// Record `run` (its `id` and `latest` are ignored) in one transaction; returns its id.
    fn add(&mut self, run: &Run) -> Result<i64, LotError>;
    /// Every run, oldest first, with [`Run::latest`] set.
    fn runs(&mut self) -> Result<Vec<Run>, LotError>;
    /// The schema version the store holds.
    fn schema_version(&mut self) -> Result<i64, LotError>;
}

/// `db` (a lot's `--db`: a URL, a `key=value` connection string or a file path) as a message
/// may show it: every password replaced by `***`. Masked: the URL's `user:PASSWORD@` (the
/// credentials end at the first `@`, as the PostgreSQL URL parser reads them, or at the last
/// one before the query when there are several, so that no part of a password with an `@`
/// shows), URL query parameters and `key=value` settings whose key ends in `password`
/// (`password`, `sslpassword`; any case, percent-encoded or not), quoted values whole.
/// The command line and Python show a lot's name only through this.
pub(crate) fn redact_db(db: &str) -> String {
    let Some((scheme, rest)) = db.split_once("://") else {
        return redact_conninfo(db);
    };
    let before_query = rest.split('?').next().unwrap_or(rest);
    let at = before_query.rfind('@').or_else(|| rest.find('@'));
    let (auth, tail) = match at {
        Some(k) => (Some(&rest[..k]), &rest[k + 1..]),
        None => (None, rest),
    };
    let mut out = format!("{scheme}://");
    if let Some(auth) = auth {
        match auth.split_once(':') {
            Some((user, _)) => out.push_str(&format!("{user}:***@")),
            None => out.push_str(&format!("{auth}@")),
        }
    }
    match tail.split_once('?') {
        Some((path, query)) => {
            out.push_str(path);
            out.push('?');
            let params: Vec<String> = query
                .split('&')
                .map(|p| match p.split_once('=') {
                    Some((k, _)) if is_password_key(&percent_decode(k)) => format!("{k}=***"),
                    _ => p.to_owned(),
                })
                .collect();
            out.push_str(&params.join("&"));
        }
        None => out.push_str(tail),
    }
    out
}

/// A connection setting that holds a secret.
fn is_password_key(key: &str) -> bool {
    key.trim().to_ascii_lowercase().ends_with("password")
}

/// `%XX` escapes decoded (others kept as they are).
fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[i] == b'%' && i + 2 < b.len() {
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// A `key=value` connection string (libpq's form: values bare up to white space, or in
/// single quotes with `\'` escapes) with the values of password keys masked; any other text
/// (a file path) as it is, unless it holds such a setting.
fn redact_conninfo(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut rest = s;
    while let Some(eq) = rest.find('=') {
        let (head, after) = rest.split_at(eq);
        // The key: the word just before `=` (white space allowed around it).
        let key = head.trim_end();
        let key_start = key.rfind(|c: char| c.is_whitespace()).map_or(0, |k| k + 1);
        let is_secret = is_password_key(&key[key_start..]);
        out.push_str(head);
        out.push('=');
        let after = &after[1..];
        let value_start = after.len() - after.trim_start().len();
        out.push_str(&after[..value_start]);
        let value = &after[value_start..];
        let value_len = if let Some(quoted) = value.strip_prefix('\'') {
            let mut escaped = false;
            let end = quoted
                .char_indices()
                .find(|&(_, c)| {
                    let close = c == '\'' && !escaped;
                    escaped = c == '\\' && !escaped;
                    close
                })
                .map_or(quoted.len(), |(k, _)| k + 1);
            1 + end
        } else {
            value.find(char::is_whitespace).unwrap_or(value.len())
        };
        if is_secret {
            out.push_str("***");
        } else {
            out.push_str(&value[..value_len]);
        }
        rest = &value[value_len..];
    }
    out.push_str(rest);
    out
}

/// A stored schema version below 1 is refused before anything is written: upgrades run from
/// the version found, and below 1 there is none to run from (the tables would be stamped
/// current without them, and the lot unusable for good).
pub(crate) fn check_known(db: &str, version: i64) -> Result<(), LotError> {
    if version < 1 {
        return Err(LotError::InvalidSchema {
            db: db.to_string(),
            found: version,
        });
    }
    Ok(())
}

/// Open the lot at `db`: a `postgres://` or `postgresql://` URL, else an SQLite file path.
/// `create`: make the file and the schema if missing (`lot add`); otherwise a missing file is
/// [`LotError::Missing`]. `busy_timeout_ms`: how long a writer waits for another (SQLite).
pub fn open_store(
    db: &str,
    create: bool,
    busy_timeout_ms: u64,
) -> Result<Box<dyn LotStore>, LotError> {
    if db.starts_with("postgres://") || db.starts_with("postgresql://") {
        Ok(Box::new(PgStore::open(db, create)?))
    } else {
        Ok(Box::new(SqliteStore::open(
            Path::new(db),
            create,
            busy_timeout_ms,
        )?))
    }
}

/// What `judge_unit` needs besides the logs; for an inertial unit (several gyro axes,
/// `judge_imu_unit`) the same with its logs (`ImuUnitInputs`).
#[derive(Debug, Clone)]
pub struct UnitInputs<'a, L = (String, TestLog)> {
    pub unit: &'a str,
    pub station: &'a str,
    pub model_path: &'a Path,
    /// The held-out logs, already read, with the paths they were read from, as given (an
    /// inertial unit's read with the model's columns, [`ImuModel::read_options`]).
    pub tests: &'a [L],
    pub spec: Option<&'a Spec>,
    /// Bias-stability τ, s (None: `compare`'s default for these logs; for an inertial unit
    /// `crate::compare::unit::default_tau_s`).
    pub tau_s: Option<f64>,
    /// Settle time at each table segment start, s.
    pub settle_s: f64,
}

/// `name` if it can name a unit in a lot: not empty, no white space around it, no control
/// character. The stores check every run they record; the judging functions trim the name
/// first, so ` A1 ` and `A1` are one unit.
pub fn check_unit_name(name: &str) -> Result<&str, LotError> {
    let bad = |why| {
        Err(LotError::UnitName {
            name: name.to_owned(),
            why,
        })
    };
    if name.trim().is_empty() {
        bad("is empty")
    } else if name.chars().any(char::is_control) {
        bad("holds a control character")
    } else if name.trim() != name {
        bad("has white space before or after it")
    } else {
        Ok(name)
    }
}

/// SHA-256 of a file's bytes, hex.
pub(crate) fn file_sha256(path: &Path) -> Result<String, LotError> {
    let bytes = std::fs::read(path).map_err(|source| LotError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(format!("{:x}", Sha256::digest(&bytes)))
}

/// Judge one unit: compensate each held-out log with its model, measure every figure, judge
/// against the spec; the [`Run`] to record (dated now), and the spec's verdict when given.
pub(crate) fn judge_unit(u: &UnitInputs) -> Result<(Run, Option<spec::Verdict>), LotError> {
    check_unit_name(u.unit.trim())?;
    let (text, model_sha256) = u.model_text()?;
    let (model, _) = ModelFile::from_json_sealed(&text).map_err(|e| u.model_err(e.into()))?;
    let content = model.content_digest().map_err(|e| u.model_err(e.into()))?;
    let named: Vec<NamedLog> = u
        .tests
        .iter()
        .map(|(p, l)| NamedLog { name: p, log: l })
        .collect();
    let opts = u.measure_options(|| crate::compare::default_tau_s(&named).0);
    let mut inputs = Vec::new();
    let mut measured = Vec::new();
    for (i, (name, log)) in u.tests.iter().enumerate() {
        inputs.push(Input {
            position: i as u32,
            path: name.clone(),
            sha256: file_sha256(Path::new(name))?,
            kind: if log.is_static() {
                "static"
            } else {
                "rate_table"
            },
        });
        let comp = compensate_log(&model, log).map_err(|e| u.model_err(e.into()))?;
        let f =
            spec::measure(log, &comp.gyro_comp_dps, &opts).map_err(|source| LotError::Measure {
                log: name.clone(),
                source,
            })?;
        measured.push((name.clone(), f));
    }
    let verdict = match u.spec {
        Some(s) => Some(spec::judge(s, &measured).map_err(LotError::Spec)?),
        None => None,
    };
    let mut figures = Vec::new();
    for (i, (_, f)) in measured.iter().enumerate() {
        for (&key, &value) in f {
            figures.push(u.figure_row(None, i, key, value));
        }
    }
    let run = u.run(
        model_sha256,
        content,
        model.method.as_str().to_string(),
        RunVerdict::of(verdict.as_ref().map(|v| v.pass)),
        inputs,
        Vec::new(),
        figures,
    );
    Ok((run, verdict))
}

/// What [`judge_imu_unit`] needs besides the logs: an inertial unit's [`UnitInputs`].
pub(crate) type ImuUnitInputs<'a> = UnitInputs<'a, (String, ImuLog)>;

impl<L> UnitInputs<'_, L> {
    /// A model error in [`UnitInputs::model_path`].
    fn model_err(&self, source: Box<dyn std::error::Error + Send + Sync>) -> LotError {
        LotError::Model {
            path: self.model_path.to_path_buf(),
            source,
        }
    }

    /// The model file's text and the SHA-256 of its bytes.
    fn model_text(&self) -> Result<(String, String), LotError> {
        let text = crate::input_file::read_capped_to_string(
            self.model_path,
            crate::input_file::InputKind::Model,
        )
        .map_err(|source| LotError::Read {
            path: self.model_path.to_path_buf(),
            source,
        })?;
        let sha = format!("{:x}", Sha256::digest(text.as_bytes()));
        Ok((text, sha))
    }

    /// How each figure is measured: τ (`tau_s` when given, else the default for the logs)
    /// and the settle time.
    fn measure_options(&self, default_tau_s: impl FnOnce() -> f64) -> MeasureOptions {
        MeasureOptions {
            evaluation: EvaluationOptions {
                tau_s: self.tau_s.unwrap_or_else(default_tau_s),
                settle_s: self.settle_s,
                reference_scale: None,
            },
            noise_terms: true,
        }
    }

    /// A figure's row, with the spec's limit for it and its verdict when a spec is given.
    fn figure_row(&self, axis: Option<u32>, position: usize, key: &str, value: f64) -> FigureRow {
        let limit = self.spec.and_then(|s| s.limit(key));
        FigureRow {
            axis,
            position: position as u32,
            figure: key.to_string(),
            value,
            limit_min: limit.and_then(|l| l.min),
            limit_max: limit.and_then(|l| l.max),
            pass: limit.map(|l| l.passes(value)),
            margin: limit.map(|l| l.margin(value)),
        }
    }

    /// The [`Run`] of this unit, dated now, with what the judging found.
    #[allow(clippy::too_many_arguments)]
    fn run(
        &self,
        model_sha256: String,
        model_content_sha256: String,
        model_method: String,
        verdict: RunVerdict,
        inputs: Vec<Input>,
        axes: Vec<AxisRecord>,
        figures: Vec<FigureRow>,
    ) -> Run {
        Run {
            id: 0,
            unit: self.unit.trim().to_string(),
            tested_at_unix_ms: now_unix_ms(),
            gyrotherm_version: env!("CARGO_PKG_VERSION").to_string(),
            station: self.station.to_string(),
            model_path: self.model_path.display().to_string(),
            model_sha256,
            model_content_sha256,
            model_method,
            spec_name: self.spec.map(|s| s.name.clone()),
            spec_sha256: self.spec.map(|s| s.sha256.clone()),
            spec_toml: self.spec.map(|s| s.text.clone()),
            verdict,
            latest: false,
            inputs,
            axes,
            figures,
        }
    }
}

impl RunVerdict {
    /// Pass or fail as judged, none without a spec.
    fn of(pass: Option<bool>) -> RunVerdict {
        match pass {
            Some(true) => RunVerdict::Pass,
            Some(false) => RunVerdict::Fail,
            None => RunVerdict::None,
        }
    }
}

/// The verdict of an inertial unit's run: each axis's (in the model's order, with its gyro
/// column) and the unit's.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ImuRunVerdict {
    pub axes: Vec<(String, spec::Verdict)>,
    pub unit: UnitVerdict,
}

/// Judge an inertial unit: compensate each held-out log with the unit's model, measure every
/// figure of each axis (`crate::spec::unit::measure_unit`, as `evaluate --model` measures
/// it), judge each axis and the unit against the spec
/// (`crate::spec::unit::judge_unit_figures`); the [`Run`] to record (dated now, a row per
/// axis in [`Run::axes`], each figure with its axis) and the verdicts when a spec is given.
pub(crate) fn judge_imu_unit(u: &ImuUnitInputs) -> Result<(Run, Option<ImuRunVerdict>), LotError> {
    check_unit_name(u.unit.trim())?;
    let (text, model_sha256) = u.model_text()?;
    let model = ImuModel::from_json(&text).map_err(|e| u.model_err(e.into()))?;
    let content = model.content_digest().map_err(|e| u.model_err(e.into()))?;
    let opts = u.measure_options(|| crate::compare::unit::default_tau_s(u.tests).0);
    let mut inputs = Vec::with_capacity(u.tests.len());
    for (i, (path, log)) in u.tests.iter().enumerate() {
        inputs.push(Input {
            position: i as u32,
            path: path.clone(),
            sha256: file_sha256(Path::new(path))?,
            kind: if log.table.is_none() {
                "static"
            } else {
                "rate_table"
            },
        });
    }
    let measured =
        crate::spec::unit::measure_unit(&model, u.tests, &opts).map_err(LotError::Unit)?;
    let verdict = match u.spec {
        Some(s) => {
            let (axes, unit) =
                crate::spec::unit::judge_unit_figures(s, &measured).map_err(LotError::Unit)?;
            Some(ImuRunVerdict {
                axes: measured.iter().map(|a| a.gyro.clone()).zip(axes).collect(),
                unit,
            })
        }
        None => None,
    };
    let mut figures = Vec::new();
    let mut axes = Vec::with_capacity(measured.len());
    for (k, a) in measured.iter().enumerate() {
        for (i, (_, f)) in a.measured.iter().enumerate() {
            for (&key, &value) in f {
                figures.push(u.figure_row(Some(k as u32), i, key, value));
            }
        }
        axes.push(AxisRecord {
            axis: k as u32,
            gyro: a.gyro.clone(),
            temps: a.temps.clone(),
            verdict: RunVerdict::of(verdict.as_ref().map(|v| v.axes[k].1.pass)),
        });
    }
    let mut methods: Vec<&str> = Vec::new();
    for a in &model.axes {
        let m = a.model.method.as_str();
        if !methods.contains(&m) {
            methods.push(m);
        }
    }
    let run = u.run(
        model_sha256,
        content,
        methods.join(","),
        RunVerdict::of(verdict.as_ref().map(|v| v.unit.pass)),
        inputs,
        axes,
        figures,
    );
    Ok((run, verdict))
}

/// Check a run read back against the rules of its axes and make its figures' axes what the
/// reader expects: a single-axis run has every figure on axis 0 (read back as None); a unit's
/// figures name one of its axes, and its verdict is its axes' ([`unit_verdict_of_axes`]).
pub(crate) fn check_axes(r: &mut Run) -> Result<(), String> {
    let id = r.id;
    if r.axes.is_empty() {
        for f in &mut r.figures {
            if f.axis.is_some_and(|a| a != 0) {
                return Err(format!(
                    "run {id}: figure {} on axis {:?} of a run without axes",
                    f.figure, f.axis
                ));
            }
            f.axis = None;
        }
        return Ok(());
    }
    for f in &r.figures {
        let k = f.axis.unwrap_or(0);
        if !r.axes.iter().any(|a| a.axis == k) {
            return Err(format!(
                "run {id}: figure {} on axis {k}, which the run does not have",
                f.figure
            ));
        }
    }
    let want = unit_verdict_of_axes(&r.axes);
    if r.verdict != want {
        return Err(format!(
            "run {id}: unit verdict {} but its axes give {}",
            r.verdict.as_str(),
            want.as_str()
        ));
    }
    Ok(())
}

/// Mark the newest run of each unit (highest id) as [`Run::latest`].
pub(crate) fn mark_latest(runs: &mut [Run]) {
    let mut newest: std::collections::HashMap<&str, i64> = Default::default();
    for r in runs.iter() {
        let e = newest.entry(r.unit.as_str()).or_insert(r.id);
        *e = (*e).max(r.id);
    }
    let newest: std::collections::HashMap<String, i64> = newest
        .into_iter()
        .map(|(k, v)| (k.to_string(), v))
        .collect();
    for r in runs.iter_mut() {
        r.latest = newest.get(&r.unit) == Some(&r.id);
    }
}

#[cfg(test)]
mod tests;

/// A run with made-up figures, for benchmarks and tests of the stores and the report (no
/// log is read): unit `unit`, dated `tested_at_unix_ms`, a static and a rate-table input, and
/// the bias stability, ARW and thermal scale-factor error drawn from `seed` around typical
/// values, judged against `bias_stability_dph <= 0.02`, `arw_deg_rt_h <= 0.005` and
/// `sf_thermal_error_ppm <= 30`.
pub fn synthetic_run(unit: &str, seed: u64, tested_at_unix_ms: i64) -> Run {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let limits = [
        (0u32, "bias_stability_dph", 0.012, 0.005, 0.02),
        (0, "arw_deg_rt_h", 0.003, 0.001, 0.005),
        (1, "sf_thermal_error_ppm", 18.0, 8.0, 30.0),
    ];
    let mut figures = Vec::new();
    for (position, key, mean, sd, max) in limits {
        let value: f64 = (mean + sd * (rng.gen::<f64>() * 2.0 - 1.0) * 1.7).max(0.0);
        let limit = crate::spec::Limit {
            min: None,
            max: Some(max),
        };
        figures.push(FigureRow {
            axis: None,
            position,
            figure: key.to_string(),
            value,
            limit_min: None,
            limit_max: Some(max),
            pass: Some(limit.passes(value)),
            margin: Some(limit.margin(value)),
        });
    }
    figures.push(FigureRow {
        axis: None,
        position: 0,
        figure: "bias_dph".into(),
        value: rng.gen::<f64>() * 0.2 - 0.1,
        limit_min: None,
        limit_max: None,
        pass: None,
        margin: None,
    });
    // The order the stores read back: by log, then by figure key.
    figures.sort_by(|a, b| (a.position, &a.figure).cmp(&(b.position, &b.figure)));
    let pass = figures.iter().all(|f| f.pass != Some(false));
    let digest = |s: &str| format!("{:x}", Sha256::digest(s.as_bytes()));
    Run {
        id: 0,
        unit: unit.to_string(),
        tested_at_unix_ms,
        gyrotherm_version: env!("CARGO_PKG_VERSION").to_string(),
        station: "synthetic".into(),
        model_path: format!("{unit}/model.json"),
        model_sha256: digest(&format!("{unit}/model")),
        model_content_sha256: digest(&format!("{unit}/content")),
        model_method: "lstm".into(),
        spec_name: Some("synthetic".into()),
        spec_sha256: Some(digest("synthetic spec")),
        spec_toml: Some("[limits]\nbias_stability_dph = { max = 0.02 }\n".into()),
        verdict: if pass {
            RunVerdict::Pass
        } else {
            RunVerdict::Fail
        },
        latest: false,
        inputs: vec![
            Input {
                position: 0,
                path: format!("{unit}/static.csv"),
                sha256: digest(&format!("{unit}/static")),
                kind: "static",
            },
            Input {
                position: 1,
                path: format!("{unit}/table.csv"),
                sha256: digest(&format!("{unit}/table")),
                kind: "rate_table",
            },
        ],
        axes: Vec::new(),
        figures,
    }
}

/// This machine's host name (the default station name), or `unknown`.
pub fn default_station() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .or_else(|_| std::fs::read_to_string("/etc/hostname"))
        .ok()
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty())
        .or_else(|| std::env::var("HOSTNAME").ok().filter(|s| !s.is_empty()))
        .unwrap_or_else(|| "unknown".into())
}

/// The verdict of a run judged through [`judge_model`], in the shape its model gives it.
#[derive(Debug, Clone, PartialEq)]
pub enum ModelRunVerdict {
    /// A single-gyro model's one verdict.
    Axis(spec::Verdict),
    /// An inertial unit's verdicts, per axis and the unit's.
    Unit(ImuRunVerdict),
}

impl ModelRunVerdict {
    /// The verdicts to print, each under its heading when the run has axes of its own
    /// (`axis K (GYRO) against the spec:`), then the unit's line when it has one.
    pub fn parts(&self) -> (Vec<(Option<String>, &spec::Verdict)>, Option<String>) {
        match self {
            ModelRunVerdict::Axis(v) => (vec![(None, v)], None),
            ModelRunVerdict::Unit(v) => (
                v.axes
                    .iter()
                    .enumerate()
                    .map(|(k, (gyro, axis))| {
                        (
                            Some(format!("axis {} ({gyro}) against the spec:", k + 1)),
                            axis,
                        )
                    })
                    .collect(),
                Some(v.unit.line(v.axes.len())),
            ),
        }
    }
}

/// Judge one unit with its model of either form (`judge_unit` for a single-gyro model,
/// `judge_imu_unit` for an inertial unit's) on its held-out logs (read in the model's form,
/// [`Model::read_logs`]); `u` says the rest (its `tests` are not read).
pub fn judge_model(
    model: &Model,
    u: &UnitInputs<'_, ()>,
    logs: &LogSet,
) -> Result<(Run, Option<ModelRunVerdict>), LotError> {
    fn with<'a, L>(u: &UnitInputs<'a, ()>, tests: &'a [L]) -> UnitInputs<'a, L> {
        UnitInputs {
            unit: u.unit,
            station: u.station,
            model_path: u.model_path,
            tests,
            spec: u.spec,
            tau_s: u.tau_s,
            settle_s: u.settle_s,
        }
    }
    match (model.is_unit(), logs.form()) {
        (true, LogSetForm::Unit(tests)) => {
            let (run, v) = judge_imu_unit(&with(u, tests))?;
            Ok((run, v.map(ModelRunVerdict::Unit)))
        }
        (false, LogSetForm::Single(tests)) => {
            let (run, v) = judge_unit(&with(u, tests))?;
            Ok((run, v.map(ModelRunVerdict::Axis)))
        }
        (unit, _) => Err(LotError::Model {
            path: u.model_path.to_path_buf(),
            source: if unit {
                "an inertial unit's model judges a unit's logs, read with its columns".into()
            } else {
                "a single-axis model; --gyro-col/--temp-col lists need an inertial unit's \
                 model (`gyrotherm train` with the same lists), whose columns lot add then reads"
                    .into()
            },
        }),
    }
}
