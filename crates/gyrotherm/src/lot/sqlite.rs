//! The lot in one SQLite file (the default store: nothing to install).
//!
//! Several stations may write one file at once (on one machine or a shared disk with working
//! locks): the file is in WAL mode, each run is one `BEGIN IMMEDIATE` transaction, and a
//! writer waits up to the busy timeout for another before giving up with
//! [`LotError::Locked`]. Opening checks the file before writing anything: a file that is not
//! SQLite, a database without the lot schema, or a newer schema is refused untouched.

use std::path::{Path, PathBuf};

use rusqlite::{params, Connection, ErrorCode, OpenFlags, TransactionBehavior};

use super::schema::{RUN_COLUMNS, SCHEMA_VERSION, SQLITE_MIGRATIONS, SQLITE_V1};
use super::time::{parse_rfc3339_utc, rfc3339_utc};
use super::{
    check_axes, check_known, mark_latest, AxisRecord, FigureRow, Input, LotError, LotStore, Run,
    RunVerdict,
};

/// A lot in an SQLite file.
pub(crate) struct SqliteStore {
    conn: Connection,
    path: PathBuf,
    busy_timeout_ms: u64,
}

impl SqliteStore {
    /// Open (and with `create`, make) the lot at `path`.
    pub fn open(path: &Path, create: bool, busy_timeout_ms: u64) -> Result<Self, LotError> {
        let db = super::redact_db(&path.display().to_string());
        if !create && !path.exists() {
            return Err(LotError::Missing { db });
        }
        let mut flags = OpenFlags::SQLITE_OPEN_READ_WRITE | OpenFlags::SQLITE_OPEN_NO_MUTEX;
        if create {
            flags |= OpenFlags::SQLITE_OPEN_CREATE;
        }
        let conn = Connection::open_with_flags(path, flags).map_err(|e| db_error(&db, e, 0))?;
        conn.busy_timeout(std::time::Duration::from_millis(busy_timeout_ms))
            .map_err(|e| db_error(&db, e, 0))?;
        let mut store = SqliteStore {
            conn,
            path: path.to_path_buf(),
            busy_timeout_ms,
        };
        // SQLite answers "busy" at once, without waiting, where waiting could deadlock: when
        // stations open a new file together and one switches it to WAL while another reads
        // its version. Preparing the schema is safe to repeat (it reads the version again
        // and creates only inside an IMMEDIATE transaction), so it is retried up to the busy
        // timeout.
        let started = std::time::Instant::now();
        loop {
            match store.prepare_schema(create) {
                Err(LotError::Locked { .. })
                    if started.elapsed().as_millis() < u128::from(busy_timeout_ms) =>
                {
                    std::thread::sleep(std::time::Duration::from_millis(20));
                }
                other => return other.map(|()| store),
            }
        }
    }

    /// The lot's name in messages (a password in a mistyped URL masked).
    fn db(&self) -> String {
        super::redact_db(&self.path.display().to_string())
    }

    fn err(&self, e: rusqlite::Error) -> LotError {
        db_error(&self.db(), e, self.busy_timeout_ms)
    }

    /// The lot's schema version; None for an empty database (no table at all).
    fn read_version(&self) -> Result<Option<i64>, LotError> {
        let tables: i64 = self
            .conn
            .query_row("SELECT count(*) FROM sqlite_master", [], |r| r.get(0))
            .map_err(|e| self.err(e))?;
        if tables == 0 {
            return Ok(None);
        }
        let has: i64 = self
            .conn
            .query_row(
                "SELECT count(*) FROM sqlite_master WHERE type = 'table' AND name = 'schema_version'",
                [],
                |r| r.get(0),
            )
            .map_err(|e| self.err(e))?;
        if has == 0 {
            return Err(LotError::NotALot { db: self.db() });
        }
        let v: Option<i64> = self
            .conn
            .query_row("SELECT max(version) FROM schema_version", [], |r| r.get(0))
            .map_err(|e| self.err(e))?;
        v.map(Some).ok_or(LotError::NotALot { db: self.db() })
    }

    fn check_not_newer(&self, v: i64) -> Result<(), LotError> {
        check_known(&self.db(), v)?;
        if v > SCHEMA_VERSION {
            return Err(LotError::NewerSchema {
                db: self.db(),
                found: v,
                supported: SCHEMA_VERSION,
            });
        }
        Ok(())
    }

    fn prepare_schema(&mut self, create: bool) -> Result<(), LotError> {
        // Read first: nothing is written to a file that is not a lot of this or an older
        // version.
        match self.read_version()? {
            Some(v) if v == SCHEMA_VERSION => return Ok(()),
            Some(v) => self.check_not_newer(v)?,
            None if !create => return Err(LotError::NotALot { db: self.db() }),
            None => {
                // WAL lets readers go on while a station writes; it is a property of the file,
                // set once before the first table (it cannot change inside a transaction).
                self.conn
                    .query_row("PRAGMA journal_mode = WAL", [], |_| Ok(()))
                    .map_err(|e| self.err(e))?;
            }
        }
        let db = self.db();
        let tx = self
            .conn
            .transaction_with_behavior(TransactionBehavior::Immediate)
            .map_err(|e| db_error(&db, e, self.busy_timeout_ms))?;
        // Another station may have created or upgraded it while this one waited.
        let now: Option<i64> = {
            let n: i64 = tx
                .query_row(
                    "SELECT count(*) FROM sqlite_master WHERE name = 'schema_version'",
                    [],
                    |r| r.get(0),
                )
                .map_err(|e| db_error(&db, e, self.busy_timeout_ms))?;
            if n == 0 {
                None
            } else {
                tx.query_row("SELECT max(version) FROM schema_version", [], |r| r.get(0))
                    .map_err(|e| db_error(&db, e, self.busy_timeout_ms))?
            }
        };
        let from = match now {
            None => {
                tx.execute_batch(SQLITE_V1)
                    .map_err(|e| db_error(&db, e, self.busy_timeout_ms))?;
                1
            }
            Some(v) if v > SCHEMA_VERSION => {
                return Err(LotError::NewerSchema {
                    db,
                    found: v,
                    supported: SCHEMA_VERSION,
                })
            }
            Some(v) => {
                check_known(&db, v)?;
                v
            }
        };
        // `from` is at least 1 here (checked above).
        for (i, step) in SQLITE_MIGRATIONS.iter().enumerate().skip(from as usize - 1) {
            // A failed step drops the transaction, which rolls every step back.
            tx.execute_batch(step)
                .map_err(|e| db_error(&db, e, self.busy_timeout_ms).in_migration(from, i))?;
        }
        tx.execute(
            "UPDATE schema_version SET version = ?1",
            params![SCHEMA_VERSION],
        )
        .map_err(|e| db_error(&db, e, self.busy_timeout_ms))?;
        tx.commit()
            .map_err(|e| db_error(&db, e, self.busy_timeout_ms))
    }
}

/// A rusqlite error in terms of what to do about it.
fn db_error(db: &str, e: rusqlite::Error, busy_timeout_ms: u64) -> LotError {
    match e.sqlite_error_code() {
        Some(ErrorCode::DatabaseBusy) | Some(ErrorCode::DatabaseLocked) => LotError::Locked {
            db: db.to_string(),
            waited_ms: busy_timeout_ms,
        },
        Some(ErrorCode::NotADatabase) | Some(ErrorCode::DatabaseCorrupt) => {
            LotError::NotADatabase {
                db: db.to_string(),
                detail: e.to_string(),
            }
        }
        _ => LotError::Database {
            db: db.to_string(),
            detail: e.to_string(),
        },
    }
}

impl LotStore for SqliteStore {
    fn add(&mut self, run: &Run) -> Result<i64, LotError> {
        super::check_unit_name(&run.unit)?;
        let db = self.db();
        let wait = self.busy_timeout_ms;
        let e = |x| db_error(&db, x, wait);
        // IMMEDIATE takes the write lock first, so two stations never both read and then
        // fail to upgrade (the deadlock a deferred transaction can meet).
        let tx = self
            .conn
            .transaction_with_behavior(TransactionBehavior::Immediate)
            .map_err(e)?;
        tx.execute(
            "INSERT INTO runs (unit, tested_at, gyrotherm_version, station, model_path, \
             model_sha256, model_content_sha256, model_method, spec_name, spec_sha256, \
             spec_toml, verdict) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12)",
            params![
                run.unit,
                rfc3339_utc(run.tested_at_unix_ms),
                run.gyrotherm_version,
                run.station,
                run.model_path,
                run.model_sha256,
                run.model_content_sha256,
                run.model_method,
                run.spec_name,
                run.spec_sha256,
                run.spec_toml,
                run.verdict.as_str()
            ],
        )
        .map_err(e)?;
        let id = tx.last_insert_rowid();
        {
            let mut ins = tx
                .prepare_cached(
                    "INSERT INTO run_inputs (run_id, position, path, sha256, kind) \
                     VALUES (?1, ?2, ?3, ?4, ?5)",
                )
                .map_err(e)?;
            for i in &run.inputs {
                ins.execute(params![id, i.position, i.path, i.sha256, i.kind])
                    .map_err(e)?;
            }
            let mut axis = tx
                .prepare_cached(
                    "INSERT INTO run_axes (run_id, axis, gyro, temps, verdict) \
                     VALUES (?1, ?2, ?3, ?4, ?5)",
                )
                .map_err(e)?;
            for a in &run.axes {
                axis.execute(params![
                    id,
                    a.axis,
                    a.gyro,
                    a.temps.join(","),
                    a.verdict.as_str()
                ])
                .map_err(e)?;
            }
            let mut fig = tx
                .prepare_cached(
                    "INSERT INTO figures (run_id, axis, position, figure, value, limit_min, \
                     limit_max, verdict, margin) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9)",
                )
                .map_err(e)?;
            for f in &run.figures {
                fig.execute(params![
                    id,
                    f.axis.unwrap_or(0),
                    f.position,
                    f.figure,
                    f.value,
                    f.limit_min,
                    f.limit_max,
                    f.pass.map(|p| if p { "pass" } else { "fail" }),
                    f.margin
                ])
                .map_err(e)?;
            }
        }
        tx.commit().map_err(e)?;
        Ok(id)
    }

    fn runs(&mut self) -> Result<Vec<Run>, LotError> {
        let db = self.db();
        let wait = self.busy_timeout_ms;
        let e = |x| db_error(&db, x, wait);
        let bad = |detail: String| LotError::BadRow {
            db: db.clone(),
            detail,
        };
        // One read transaction: a writer adding a run meanwhile is either wholly in or out.
        let tx = self.conn.transaction().map_err(e)?;
        let mut runs = Vec::new();
        {
            let mut q = tx
                .prepare(&format!("SELECT {RUN_COLUMNS} FROM runs ORDER BY id"))
                .map_err(e)?;
            let mut rows = q.query([]).map_err(e)?;
            while let Some(r) = rows.next().map_err(e)? {
                let id: i64 = r.get(0).map_err(e)?;
                let at: String = r.get(2).map_err(e)?;
                let verdict: String = r.get(12).map_err(e)?;
                runs.push(Run {
                    id,
                    unit: r.get(1).map_err(e)?,
                    tested_at_unix_ms: parse_rfc3339_utc(&at).ok_or_else(|| {
                        bad(format!("run {id}: tested_at {at:?} is not RFC 3339"))
                    })?,
                    gyrotherm_version: r.get(3).map_err(e)?,
                    station: r.get(4).map_err(e)?,
                    model_path: r.get(5).map_err(e)?,
                    model_sha256: r.get(6).map_err(e)?,
                    model_content_sha256: r.get(7).map_err(e)?,
                    model_method: r.get(8).map_err(e)?,
                    spec_name: r.get(9).map_err(e)?,
                    spec_sha256: r.get(10).map_err(e)?,
                    spec_toml: r.get(11).map_err(e)?,
                    verdict: RunVerdict::parse(&verdict)
                        .ok_or_else(|| bad(format!("run {id}: verdict {verdict:?}")))?,
                    latest: false,
                    inputs: Vec::new(),
                    axes: Vec::new(),
                    figures: Vec::new(),
                });
            }
        }
        let index: std::collections::HashMap<i64, usize> =
            runs.iter().enumerate().map(|(i, r)| (r.id, i)).collect();
        {
            let mut q = tx
                .prepare("SELECT run_id, position, path, sha256, kind FROM run_inputs ORDER BY run_id, position")
                .map_err(e)?;
            let mut rows = q.query([]).map_err(e)?;
            while let Some(r) = rows.next().map_err(e)? {
                let id: i64 = r.get(0).map_err(e)?;
                let kind: String = r.get(4).map_err(e)?;
                let Some(&i) = index.get(&id) else { continue };
                runs[i].inputs.push(Input {
                    position: r.get(1).map_err(e)?,
                    path: r.get(2).map_err(e)?,
                    sha256: r.get(3).map_err(e)?,
                    kind: if kind == "static" {
                        "static"
                    } else {
                        "rate_table"
                    },
                });
            }
        }
        {
            let mut q = tx
                .prepare(
                    "SELECT run_id, axis, gyro, temps, verdict FROM run_axes \
                     ORDER BY run_id, axis",
                )
                .map_err(e)?;
            let mut rows = q.query([]).map_err(e)?;
            while let Some(r) = rows.next().map_err(e)? {
                let id: i64 = r.get(0).map_err(e)?;
                let Some(&i) = index.get(&id) else { continue };
                let temps: String = r.get(3).map_err(e)?;
                let verdict: String = r.get(4).map_err(e)?;
                runs[i].axes.push(AxisRecord {
                    axis: r.get(1).map_err(e)?,
                    gyro: r.get(2).map_err(e)?,
                    temps: temps.split(',').map(str::to_owned).collect(),
                    verdict: RunVerdict::parse(&verdict)
                        .ok_or_else(|| bad(format!("run {id}: axis verdict {verdict:?}")))?,
                });
            }
        }
        {
            let mut q = tx
                .prepare(
                    "SELECT run_id, position, figure, value, limit_min, limit_max, verdict, \
                     margin, axis FROM figures ORDER BY run_id, axis, position, figure",
                )
                .map_err(e)?;
            let mut rows = q.query([]).map_err(e)?;
            while let Some(r) = rows.next().map_err(e)? {
                let id: i64 = r.get(0).map_err(e)?;
                let Some(&i) = index.get(&id) else { continue };
                let v: Option<String> = r.get(6).map_err(e)?;
                runs[i].figures.push(FigureRow {
                    axis: Some(r.get(8).map_err(e)?),
                    position: r.get(1).map_err(e)?,
                    figure: r.get(2).map_err(e)?,
                    value: r.get(3).map_err(e)?,
                    limit_min: r.get(4).map_err(e)?,
                    limit_max: r.get(5).map_err(e)?,
                    pass: v.map(|v| v == "pass"),
                    margin: r.get(7).map_err(e)?,
                });
            }
        }
        tx.commit().map_err(e)?;
        for r in &mut runs {
            check_axes(r).map_err(bad)?;
        }
        mark_latest(&mut runs);
        Ok(runs)
    }

    fn schema_version(&mut self) -> Result<i64, LotError> {
        Ok(self.read_version()?.unwrap_or(0))
    }
}
