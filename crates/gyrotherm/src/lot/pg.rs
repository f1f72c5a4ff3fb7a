//! The lot in PostgreSQL: several stations on separate machines write one lot. The schema is
//! [`PG_V1`] (the SQLite one with an identity column) and its upgrades ([`PG_MIGRATIONS`]);
//! each run is one transaction, and the schema is created or upgraded under an advisory lock
//! so two stations starting at once do not both create it.

use postgres::{Client, NoTls};

use super::schema::{PG_MIGRATIONS, PG_V1, RUN_COLUMNS, SCHEMA_VERSION};
use super::time::{parse_rfc3339_utc, rfc3339_utc};
use super::{
    check_axes, check_known, mark_latest, AxisRecord, FigureRow, Input, LotError, LotStore, Run,
    RunVerdict,
};

/// The advisory-lock key that serialises schema changes (an arbitrary constant, "gyro" in
/// ASCII).
const SCHEMA_LOCK: i64 = 0x6779_726f;

/// A lot in a PostgreSQL database.
pub(crate) struct PgStore {
    client: Client,
    /// The URL without its password, for messages.
    db: String,
}

impl PgStore {
    /// Connect to `url` and, with `create`, make the schema if missing.
    pub fn open(url: &str, create: bool) -> Result<Self, LotError> {
        // Messages must not print secrets.
        let db = super::redact_db(url);
        let client = Client::connect(url, NoTls).map_err(|e| LotError::Database {
            db: db.clone(),
            detail: format!("cannot connect: {e}"),
        })?;
        let mut s = PgStore { client, db };
        s.prepare_schema(create)?;
        Ok(s)
    }

    fn err(&self, e: postgres::Error) -> LotError {
        pg_error(&self.db, e)
    }

    fn prepare_schema(&mut self, create: bool) -> Result<(), LotError> {
        let db = self.db.clone();
        let e = |x| pg_error(&db, x);
        let mut tx = self.client.transaction().map_err(e)?;
        tx.execute("SELECT pg_advisory_xact_lock($1)", &[&SCHEMA_LOCK])
            .map_err(e)?;
        let has: bool = tx
            .query_one("SELECT to_regclass('schema_version') IS NOT NULL", &[])
            .map_err(e)?
            .get(0);
        let from = if has {
            let v: Option<i32> = tx
                .query_one("SELECT max(version) FROM schema_version", &[])
                .map_err(e)?
                .get(0);
            let v = i64::from(v.ok_or(LotError::NotALot { db: db.clone() })?);
            check_known(&db, v)?;
            if v > SCHEMA_VERSION {
                return Err(LotError::NewerSchema {
                    db,
                    found: v,
                    supported: SCHEMA_VERSION,
                });
            }
            if v == SCHEMA_VERSION {
                return tx.commit().map_err(e);
            }
            v
        } else {
            let tables: i64 = tx
                .query_one(
                    "SELECT count(*) FROM information_schema.tables \
                     WHERE table_schema = current_schema() AND table_name IN ('runs', 'figures', 'run_inputs')",
                    &[],
                )
                .map_err(e)?
                .get(0);
            if tables > 0 || !create {
                return Err(LotError::NotALot { db });
            }
            tx.batch_execute(PG_V1).map_err(e)?;
            1
        };
        // `from` is at least 1 here (checked above).
        for (i, step) in PG_MIGRATIONS.iter().enumerate().skip(from as usize - 1) {
            // A failed step drops the transaction, which rolls every step back.
            tx.batch_execute(step)
                .map_err(|x| pg_error(&db, x).in_migration(from, i))?;
        }
        tx.execute(
            "UPDATE schema_version SET version = $1",
            &[&(SCHEMA_VERSION as i32)],
        )
        .map_err(e)?;
        tx.commit().map_err(e)
    }
}

fn pg_error(db: &str, e: postgres::Error) -> LotError {
    LotError::Database {
        db: db.to_string(),
        detail: match e.as_db_error() {
            Some(d) => format!("{}: {}", d.severity(), d.message()),
            None => e.to_string(),
        },
    }
}

impl LotStore for PgStore {
    fn add(&mut self, run: &Run) -> Result<i64, LotError> {
        super::check_unit_name(&run.unit)?;
        let db = self.db.clone();
        let e = |x| pg_error(&db, x);
        let mut tx = self.client.transaction().map_err(e)?;
        let id: i64 = tx
            .query_one(
                "INSERT INTO runs (unit, tested_at, gyrotherm_version, station, model_path, \
                 model_sha256, model_content_sha256, model_method, spec_name, spec_sha256, \
                 spec_toml, verdict) VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12) \
                 RETURNING id",
                &[
                    &run.unit,
                    &rfc3339_utc(run.tested_at_unix_ms),
                    &run.gyrotherm_version,
                    &run.station,
                    &run.model_path,
                    &run.model_sha256,
                    &run.model_content_sha256,
                    &run.model_method,
                    &run.spec_name,
                    &run.spec_sha256,
                    &run.spec_toml,
                    &run.verdict.as_str(),
                ],
            )
            .map_err(e)?
            .get(0);
        let ins = tx
            .prepare(
                "INSERT INTO run_inputs (run_id, position, path, sha256, kind) \
                 VALUES ($1, $2, $3, $4, $5)",
            )
            .map_err(e)?;
        for i in &run.inputs {
            tx.execute(
                &ins,
                &[&id, &(i.position as i32), &i.path, &i.sha256, &i.kind],
            )
            .map_err(e)?;
        }
        let axis = tx
            .prepare(
                "INSERT INTO run_axes (run_id, axis, gyro, temps, verdict) \
                 VALUES ($1, $2, $3, $4, $5)",
            )
            .map_err(e)?;
        for a in &run.axes {
            tx.execute(
                &axis,
                &[
                    &id,
                    &(a.axis as i32),
                    &a.gyro,
                    &a.temps.join(","),
                    &a.verdict.as_str(),
                ],
            )
            .map_err(e)?;
        }
        let fig = tx
            .prepare(
                "INSERT INTO figures (run_id, axis, position, figure, value, limit_min, \
                 limit_max, verdict, margin) VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9)",
            )
            .map_err(e)?;
        for f in &run.figures {
            let v = f.pass.map(|p| if p { "pass" } else { "fail" });
            tx.execute(
                &fig,
                &[
                    &id,
                    &(f.axis.unwrap_or(0) as i32),
                    &(f.position as i32),
                    &f.figure,
                    &f.value,
                    &f.limit_min,
                    &f.limit_max,
                    &v,
                    &f.margin,
                ],
            )
            .map_err(e)?;
        }
        tx.commit().map_err(e)?;
        Ok(id)
    }

    fn runs(&mut self) -> Result<Vec<Run>, LotError> {
        let db = self.db.clone();
        let e = |x| pg_error(&db, x);
        let bad = |detail: String| LotError::BadRow {
            db: db.clone(),
            detail,
        };
        // REPEATABLE READ: the three queries see one snapshot, so a run added meanwhile is
        // wholly in or out.
        let mut tx = self
            .client
            .build_transaction()
            .isolation_level(postgres::IsolationLevel::RepeatableRead)
            .read_only(true)
            .start()
            .map_err(e)?;
        let mut runs = Vec::new();
        for r in tx
            .query(&format!("SELECT {RUN_COLUMNS} FROM runs ORDER BY id"), &[])
            .map_err(e)?
        {
            let id: i64 = r.get(0);
            let at: String = r.get(2);
            let verdict: String = r.get(12);
            runs.push(Run {
                id,
                unit: r.get(1),
                tested_at_unix_ms: parse_rfc3339_utc(&at)
                    .ok_or_else(|| bad(format!("run {id}: tested_at {at:?} is not RFC 3339")))?,
                gyrotherm_version: r.get(3),
                station: r.get(4),
                model_path: r.get(5),
                model_sha256: r.get(6),
                model_content_sha256: r.get(7),
                model_method: r.get(8),
                spec_name: r.get(9),
                spec_sha256: r.get(10),
                spec_toml: r.get(11),
                verdict: RunVerdict::parse(&verdict)
                    .ok_or_else(|| bad(format!("run {id}: verdict {verdict:?}")))?,
                latest: false,
                inputs: Vec::new(),
                axes: Vec::new(),
                figures: Vec::new(),
            });
        }
        let index: std::collections::HashMap<i64, usize> =
            runs.iter().enumerate().map(|(i, r)| (r.id, i)).collect();
        for r in tx
            .query(
                "SELECT run_id, position, path, sha256, kind FROM run_inputs ORDER BY run_id, position",
                &[],
            )
            .map_err(e)?
        {
            let Some(&i) = index.get(&r.get::<_, i64>(0)) else {
                continue;
            };
            let kind: String = r.get(4);
            runs[i].inputs.push(Input {
                position: r.get::<_, i32>(1) as u32,
                path: r.get(2),
                sha256: r.get(3),
                kind: if kind == "static" { "static" } else { "rate_table" },
            });
        }
        for r in tx
            .query(
                "SELECT run_id, axis, gyro, temps, verdict FROM run_axes ORDER BY run_id, axis",
                &[],
            )
            .map_err(e)?
        {
            let id: i64 = r.get(0);
            let Some(&i) = index.get(&id) else {
                continue;
            };
            let temps: String = r.get(3);
            let verdict: String = r.get(4);
            runs[i].axes.push(AxisRecord {
                axis: u32::try_from(r.get::<_, i32>(1))
                    .map_err(|_| bad(format!("run {id}: a negative axis")))?,
                gyro: r.get(2),
                temps: temps.split(',').map(str::to_owned).collect(),
                verdict: RunVerdict::parse(&verdict)
                    .ok_or_else(|| bad(format!("run {id}: axis verdict {verdict:?}")))?,
            });
        }
        // Figure keys in byte order (the order the SQLite store and the judge give), whatever
        // the database's collation.
        for r in tx
            .query(
                "SELECT run_id, position, figure, value, limit_min, limit_max, verdict, margin, \
                 axis FROM figures ORDER BY run_id, axis, position, figure COLLATE \"C\"",
                &[],
            )
            .map_err(e)?
        {
            let id: i64 = r.get(0);
            let Some(&i) = index.get(&id) else {
                continue;
            };
            let v: Option<String> = r.get(6);
            runs[i].figures.push(FigureRow {
                axis: Some(
                    u32::try_from(r.get::<_, i32>(8))
                        .map_err(|_| bad(format!("run {id}: a figure on a negative axis")))?,
                ),
                position: r.get::<_, i32>(1) as u32,
                figure: r.get(2),
                value: r.get(3),
                limit_min: r.get(4),
                limit_max: r.get(5),
                pass: v.map(|v| v == "pass"),
                margin: r.get(7),
            });
        }
        tx.commit().map_err(e)?;
        for r in &mut runs {
            check_axes(r).map_err(bad)?;
        }
        mark_latest(&mut runs);
        Ok(runs)
    }

    fn schema_version(&mut self) -> Result<i64, LotError> {
        let v: Option<i32> = self
            .client
            .query_one("SELECT max(version) FROM schema_version", &[])
            .map_err(|e| self.err(e))?
            .get(0);
        Ok(v.map_or(0, i64::from))
    }
}
