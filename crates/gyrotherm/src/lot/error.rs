//! Why a lot cannot be read, written or judged.

use std::fmt;
use std::path::PathBuf;

use crate::spec;
use crate::spec::unit::ImuJudgeError;

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
