//! The SQLite store's promises: round trip, nothing lost under parallel writers, both runs of
//! a unit kept with the newer marked, and a locked, damaged, foreign or newer-schema file
//! refused unchanged. `exercise_store` is shared with the PostgreSQL test
//! (tests/lot_postgres.rs) through [`super::LotStore`].

use std::path::Path;

use super::time::rfc3339_utc;
use super::*;

fn bytes(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap()
}

#[test]
fn store_round_trip_and_latest() {
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("lot.sqlite");
    let mut s = SqliteStore::open(&db, true, 5000).unwrap();
    exercise_store(&mut s);
    // Reopened, the same runs come back (the file is the record).
    let mut s = SqliteStore::open(&db, false, 5000).unwrap();
    assert_eq!(s.runs().unwrap().len(), 3);
    assert_eq!(s.schema_version().unwrap(), schema::SCHEMA_VERSION);
}

/// Add three runs (unit A twice) and check what comes back; the store must be empty.
pub(crate) fn exercise_store(s: &mut dyn LotStore) {
    let a1 = synthetic_run("A-001", 1, 1_700_000_000_000);
    let b = synthetic_run("B-002", 2, 1_700_000_100_000);
    let a2 = synthetic_run("A-001", 3, 1_700_000_200_000);
    let ids: Vec<i64> = [&a1, &b, &a2].iter().map(|r| s.add(r).unwrap()).collect();
    assert!(ids[0] < ids[1] && ids[1] < ids[2], "ids grow: {ids:?}");
    let runs = s.runs().unwrap();
    assert_eq!(runs.len(), 3);
    let latest: Vec<(&str, bool)> = runs.iter().map(|r| (r.unit.as_str(), r.latest)).collect();
    assert_eq!(latest, [("A-001", false), ("B-002", true), ("A-001", true)]);
    // Everything recorded comes back as it went in (id and latest are the store's).
    for (got, want) in runs.iter().zip([&a1, &b, &a2]) {
        let mut g = got.clone();
        g.id = 0;
        g.latest = false;
        assert_eq!(&g, want);
    }
}

#[test]
fn parallel_writers_lose_nothing() {
    // Four stations, each its own connection, 25 runs each into one file at once.
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("lot.sqlite");
    drop(SqliteStore::open(&db, true, 5000).unwrap());
    let threads: Vec<_> = (0..4)
        .map(|t| {
            let db = db.clone();
            std::thread::spawn(move || {
                let mut s = SqliteStore::open(&db, true, 30_000).unwrap();
                for i in 0..25 {
                    let unit = format!("S{t}-{i:03}");
                    s.add(&synthetic_run(&unit, (t * 100 + i) as u64, 0))
                        .unwrap();
                }
            })
        })
        .collect();
    for t in threads {
        t.join().unwrap();
    }
    let runs = SqliteStore::open(&db, false, 5000).unwrap().runs().unwrap();
    assert_eq!(runs.len(), 100);
    let mut ids: Vec<i64> = runs.iter().map(|r| r.id).collect();
    ids.dedup();
    assert_eq!(ids.len(), 100);
    assert!(runs
        .iter()
        .all(|r| r.figures.len() == 4 && r.inputs.len() == 2));
}

#[test]
fn parallel_creators_make_one_schema() {
    // Several stations opening a new file at the same moment: one creates, none fails.
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("new.sqlite");
    let threads: Vec<_> = (0..4)
        .map(|t| {
            let db = db.clone();
            std::thread::spawn(move || {
                let mut s = SqliteStore::open(&db, true, 30_000).unwrap();
                s.add(&synthetic_run(&format!("U{t}"), t, 0)).unwrap();
            })
        })
        .collect();
    for t in threads {
        t.join().unwrap();
    }
    let mut s = SqliteStore::open(&db, false, 5000).unwrap();
    assert_eq!(s.runs().unwrap().len(), 4);
}

#[test]
fn locked_file_is_an_error_and_changes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("lot.sqlite");
    let mut s = SqliteStore::open(&db, true, 100).unwrap();
    s.add(&synthetic_run("A", 1, 0)).unwrap();
    let other = rusqlite::Connection::open(&db).unwrap();
    other.execute_batch("BEGIN EXCLUSIVE").unwrap();
    let e = s.add(&synthetic_run("B", 2, 0)).unwrap_err();
    assert!(
        matches!(e, LotError::Locked { waited_ms: 100, .. }),
        "{e:?}"
    );
    assert!(e.to_string().contains("nothing was changed"), "{e}");
    other.execute_batch("ROLLBACK").unwrap();
    assert_eq!(s.runs().unwrap().len(), 1);
}

#[test]
fn damaged_file_is_refused_unchanged() {
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("lot.sqlite");
    let junk: Vec<u8> = (0..8192u32).map(|i| (i * 7 + 3) as u8).collect();
    std::fs::write(&db, &junk).unwrap();
    let e = SqliteStore::open(&db, true, 100).err().unwrap();
    assert!(matches!(e, LotError::NotADatabase { .. }), "{e:?}");
    assert_eq!(bytes(&db), junk);

    // A real lot whose header page was overwritten halfway: refused the same way.
    let db2 = dir.path().join("torn.sqlite");
    let mut s = SqliteStore::open(&db2, true, 100).unwrap();
    s.add(&synthetic_run("A", 1, 0)).unwrap();
    drop(s);
    let mut b = bytes(&db2);
    for x in &mut b[0..100] {
        *x = 0xAA;
    }
    std::fs::write(&db2, &b).unwrap();
    let e = SqliteStore::open(&db2, true, 100).err().unwrap();
    assert!(matches!(e, LotError::NotADatabase { .. }), "{e:?}");
    assert_eq!(bytes(&db2), b);
}

#[test]
fn newer_schema_and_foreign_database_are_refused_unchanged() {
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("lot.sqlite");
    let mut s = SqliteStore::open(&db, true, 100).unwrap();
    s.add(&synthetic_run("A", 1, 0)).unwrap();
    drop(s);
    {
        let c = rusqlite::Connection::open(&db).unwrap();
        c.execute("UPDATE schema_version SET version = 99", [])
            .unwrap();
        // Fold the WAL into the file so the bytes compared below are the whole database.
        c.query_row("PRAGMA wal_checkpoint(TRUNCATE)", [], |_| Ok(()))
            .unwrap();
    }
    let before = bytes(&db);
    let e = SqliteStore::open(&db, true, 100).err().unwrap();
    assert!(
        matches!(
            e,
            LotError::NewerSchema {
                found: 99,
                supported: 2,
                ..
            }
        ),
        "{e:?}"
    );
    assert!(e.to_string().contains("use a newer gyrotherm"), "{e}");
    assert_eq!(bytes(&db), before);

    let other = dir.path().join("other.sqlite");
    {
        let c = rusqlite::Connection::open(&other).unwrap();
        c.execute_batch("CREATE TABLE t (x INTEGER); INSERT INTO t VALUES (1);")
            .unwrap();
    }
    let before = bytes(&other);
    let e = SqliteStore::open(&other, true, 100).err().unwrap();
    assert!(matches!(e, LotError::NotALot { .. }), "{e:?}");
    assert_eq!(bytes(&other), before);
}

#[test]
fn missing_file_is_not_created_by_readers() {
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("none.sqlite");
    let e = SqliteStore::open(&db, false, 100).err().unwrap();
    assert!(matches!(e, LotError::Missing { .. }), "{e:?}");
    assert!(!db.exists());
}

#[test]
fn report_of_a_synthetic_lot() {
    let runs: Vec<Run> = {
        let mut v: Vec<Run> = (0..40)
            .map(|i| {
                let mut r =
                    synthetic_run(&format!("<U{i}>"), i, 1_700_000_000_000 + i as i64 * 60_000);
                r.id = i as i64 + 1;
                r
            })
            .collect();
        mark_latest(&mut v);
        v
    };
    let y = report::lot_yield(&runs);
    let passed = runs
        .iter()
        .filter(|r| r.verdict == RunVerdict::Pass)
        .count();
    assert_eq!((y.units, y.passed), (40, passed));
    let dir = tempfile::tempdir().unwrap();
    let page = report::write_lot_report(dir.path(), "lot <1>", &runs).unwrap();
    let html = std::fs::read_to_string(&page).unwrap();
    // Serials come from the database: escaped on the page.
    assert!(
        html.contains("&lt;U") && !html.contains("<U"),
        "unescaped serial"
    );
    assert!(html.contains("lot &lt;1&gt;"));
    for key in [
        "bias_stability_dph",
        "arw_deg_rt_h",
        "sf_thermal_error_ppm",
        "bias_dph",
    ] {
        assert!(
            dir.path().join(format!("dist_{key}.png")).is_file(),
            "{key}"
        );
        assert!(
            dir.path().join(format!("date_{key}.svg")).is_file(),
            "{key}"
        );
    }
    let csv = std::fs::read_to_string(dir.path().join("lot.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 40 * 4);
}

/// A throwaway PostgreSQL server from the Debian package (`initdb`, `pg_ctl`), on a free
/// loopback port, data in a temp dir; stopped on drop. None (and a note) when the package is
/// missing, unless `CI=true`, where that is a failure.
struct PgServer {
    dir: tempfile::TempDir,
    bin: std::path::PathBuf,
    port: u16,
}

impl PgServer {
    fn start() -> Option<PgServer> {
        let bin = std::fs::read_dir("/usr/lib/postgresql").ok().and_then(|d| {
            d.filter_map(|e| e.ok())
                .map(|e| e.path().join("bin"))
                .find(|b| b.join("initdb").is_file())
        });
        let Some(bin) = bin else {
            assert!(
                std::env::var("CI").as_deref() != Ok("true"),
                "CI=true but PostgreSQL is not installed (apt-get install postgresql)"
            );
            eprintln!("SKIPPED: PostgreSQL store tests (no /usr/lib/postgresql/*/bin/initdb)");
            return None;
        };
        let dir = tempfile::tempdir().unwrap();
        let data = dir.path().join("data");
        let port = std::net::TcpListener::bind("127.0.0.1:0")
            .unwrap()
            .local_addr()
            .unwrap()
            .port();
        // The server refuses to run as root: the data dir belongs to `postgres`, and the
        // commands run as that user when we are root.
        let as_pg = |prog: &str| {
            let is_root = std::process::Command::new("id")
                .arg("-u")
                .output()
                .map(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
                .unwrap_or(false);
            let mut c = if is_root {
                let mut c = std::process::Command::new("runuser");
                c.args(["-u", "postgres", "--"]).arg(bin.join(prog));
                c
            } else {
                std::process::Command::new(bin.join(prog))
            };
            c.stdout(std::process::Stdio::null());
            c
        };
        let ok = |mut c: std::process::Command| {
            let s = c.status().unwrap();
            assert!(s.success(), "{c:?}: {s}");
        };
        ok({
            let mut c = std::process::Command::new("chown");
            c.args(["-R", "postgres"]).arg(dir.path());
            c
        });
        ok({
            let mut c = as_pg("initdb");
            c.args(["-A", "trust", "-U", "postgres", "-D"]).arg(&data);
            c
        });
        ok({
            let mut c = as_pg("pg_ctl");
            c.arg("-D").arg(&data).arg("-o").arg(format!(
                "-p {port} -k {} -c listen_addresses=127.0.0.1",
                dir.path().display()
            ));
            c.args(["-l"])
                .arg(dir.path().join("log"))
                .args(["-w", "start"]);
            c
        });
        Some(PgServer { dir, bin, port })
    }

    fn url(&self, db: &str) -> String {
        format!("postgres://postgres@127.0.0.1:{}/{db}", self.port)
    }

    fn create_db(&self, name: &str) -> String {
        let mut c = postgres::Client::connect(&self.url("postgres"), postgres::NoTls).unwrap();
        c.batch_execute(&format!("CREATE DATABASE {name}")).unwrap();
        self.url(name)
    }
}

impl Drop for PgServer {
    fn drop(&mut self) {
        let _ = std::process::Command::new("runuser")
            .args(["-u", "postgres", "--"])
            .arg(self.bin.join("pg_ctl"))
            .arg("-D")
            .arg(self.dir.path().join("data"))
            .args(["-m", "fast", "-w", "stop"])
            .stdout(std::process::Stdio::null())
            .status();
    }
}

#[test]
fn postgres_store_same_promises() {
    let Some(pg) = PgServer::start() else { return };
    // The same checks as the SQLite store, through the same trait.
    let url = pg.create_db("lot_a");
    let mut s = open_store(&url, true, 0).unwrap();
    exercise_store(s.as_mut());
    assert_eq!(s.schema_version().unwrap(), schema::SCHEMA_VERSION);
    drop(s);

    // Stations on separate machines: four clients adding at once lose nothing.
    let url = pg.create_db("lot_b");
    let threads: Vec<_> = (0..4)
        .map(|t| {
            let url = url.clone();
            std::thread::spawn(move || {
                let mut s = open_store(&url, true, 0).unwrap();
                for i in 0..10 {
                    s.add(&synthetic_run(&format!("S{t}-{i}"), t * 100 + i, 0))
                        .unwrap();
                }
            })
        })
        .collect();
    for t in threads {
        t.join().unwrap();
    }
    assert_eq!(
        open_store(&url, false, 0).unwrap().runs().unwrap().len(),
        40
    );

    // A newer schema is refused and left as it was.
    let mut c = postgres::Client::connect(&url, postgres::NoTls).unwrap();
    c.batch_execute("UPDATE schema_version SET version = 7")
        .unwrap();
    let e = open_store(&url, true, 0).err().unwrap();
    assert!(matches!(e, LotError::NewerSchema { found: 7, .. }), "{e:?}");
    let v: i32 = c
        .query_one("SELECT version FROM schema_version", &[])
        .unwrap()
        .get(0);
    let n: i64 = c
        .query_one("SELECT count(*) FROM runs", &[])
        .unwrap()
        .get(0);
    assert_eq!((v, n), (7, 40));
    // A database that is not a lot, and a reader on an empty one, are refused.
    let url = pg.create_db("lot_c");
    let e = open_store(&url, false, 0).err().unwrap();
    assert!(matches!(e, LotError::NotALot { .. }), "{e:?}");
}

/// A three-axis unit's run with made-up figures (each axis: the figures of
/// [`synthetic_run`]), every limited figure set to half its limit (so it passes) except the
/// bias stability of `fail_axis`, set to twice its limit. The verdicts are set by hand from
/// those values: an axis fails only when one of its figures is above its limit, and the unit
/// only when an axis fails.
fn synthetic_unit(unit: &str, seed: u64, at: i64, fail_axis: Option<u32>) -> Run {
    let mut run = synthetic_run(unit, seed, at);
    let base = std::mem::take(&mut run.figures);
    let gyros = ["gyro_x_dps", "gyro_y_dps", "gyro_z_dps"];
    for (k, g) in gyros.iter().enumerate() {
        let k = k as u32;
        let fails = fail_axis == Some(k);
        for f in &base {
            let mut f = f.clone();
            f.axis = Some(k);
            if let Some(max) = f.limit_max {
                let bad = fails && f.figure == "bias_stability_dph";
                f.value = if bad { 2.0 * max } else { 0.5 * max };
                f.pass = Some(!bad);
                f.margin = Some(max - f.value);
            } else {
                f.value += k as f64;
            }
            run.figures.push(f);
        }
        run.axes.push(AxisRecord {
            axis: k,
            gyro: g.to_string(),
            temps: vec!["temp_case_c".into(), format!("temp_{}_c", &g[5..6])],
            verdict: if fails {
                RunVerdict::Fail
            } else {
                RunVerdict::Pass
            },
        });
    }
    run.verdict = if fail_axis.is_some() {
        RunVerdict::Fail
    } else {
        RunVerdict::Pass
    };
    run.model_method = "thermal".into();
    run
}

/// Add two units (one failing on axis y) beside a single-axis run and check the round trip,
/// the yield and what the report shows; the store must be empty.
pub(crate) fn exercise_unit_store(s: &mut dyn LotStore) {
    let single = synthetic_run("S-1", 7, 1_700_000_000_000);
    let good = synthetic_unit("IMU-1", 8, 1_700_000_100_000, None);
    let bad = synthetic_unit("IMU-2", 9, 1_700_000_200_000, Some(1));
    for r in [&single, &good, &bad] {
        s.add(r).unwrap();
    }
    let runs = s.runs().unwrap();
    assert_eq!(runs.len(), 3);
    for (got, want) in runs.iter().zip([&single, &good, &bad]) {
        let mut g = got.clone();
        g.id = 0;
        g.latest = false;
        assert_eq!(&g, want, "{}", want.unit);
    }
    // A row per axis per figure: 3 axes × 4 figures.
    assert_eq!(runs[1].figures.len(), 12);
    assert!(runs[0].axes.is_empty() && runs[0].figures.iter().all(|f| f.axis.is_none()));
    // The single-axis run is judged as before; the units by every axis.
    let single_pass = usize::from(single.verdict == RunVerdict::Pass);
    let y = report::lot_yield(&runs);
    assert_eq!(
        (y.units, y.passed, y.failed),
        (3, 1 + single_pass, 2 - single_pass)
    );
    let dir = tempfile::tempdir().unwrap();
    let page = report::write_lot_report(dir.path(), "units", &runs).unwrap();
    let html = std::fs::read_to_string(page).unwrap();
    assert!(html.contains("<table id=\"axes\">"), "{html}");
    assert!(
        html.contains(
            "<tr><td>IMU-2</td><td>fail</td><td>gyro_y_dps</td><td>temp_case_c, temp_y_c</td>\
             <td>fail</td><td>bias_stability_dph</td>"
        ),
        "{html}"
    );
    // The worst units table names the axis of a unit's worst figure.
    assert!(
        html.contains("<td>bias_stability_dph (gyro_y_dps)</td>"),
        "{html}"
    );
    let csv = String::from_utf8(report::lot_csv(&runs).unwrap()).unwrap();
    assert_eq!(csv.lines().count(), 1 + 4 + 12 + 12);
    assert!(csv
        .lines()
        .next()
        .unwrap()
        .ends_with(",margin,axis,axis_verdict"));
    assert!(
        csv.lines().any(|l| l.starts_with("3,IMU-2,")
            && l.contains(",bias_stability_dph,")
            && l.ends_with(",gyro_y_dps,fail")),
        "{csv}"
    );
    // Single-axis rows leave the axis columns empty.
    assert!(csv.lines().nth(1).unwrap().ends_with(",,"), "{csv}");
}

#[test]
fn sqlite_store_holds_inertial_units() {
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("lot.sqlite");
    let mut s = SqliteStore::open(&db, true, 5000).unwrap();
    exercise_unit_store(&mut s);
    // A unit's verdict that its axes do not give (edited by hand) is refused on reading.
    drop(s);
    let c = rusqlite::Connection::open(&db).unwrap();
    c.execute("UPDATE runs SET verdict = 'pass' WHERE unit = 'IMU-2'", [])
        .unwrap();
    drop(c);
    let e = SqliteStore::open(&db, false, 5000)
        .unwrap()
        .runs()
        .unwrap_err();
    assert!(matches!(e, LotError::BadRow { .. }), "{e:?}");
    assert!(e.to_string().contains("its axes give fail"), "{e}");
}

/// Write `run` as gyrotherm 1 wrote it into a version 1 lot (the statements of the version 1
/// `add`, kept here as they were: the test's fixture of the old code path).
const V1_INSERT_RUN: &str = "INSERT INTO runs (unit, tested_at, gyrotherm_version, station, \
model_path, model_sha256, model_content_sha256, model_method, spec_name, spec_sha256, \
spec_toml, verdict) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12)";
const V1_INSERT_INPUT: &str =
    "INSERT INTO run_inputs (run_id, position, path, sha256, kind) VALUES (?1, ?2, ?3, ?4, ?5)";
const V1_INSERT_FIGURE: &str = "INSERT INTO figures (run_id, position, figure, value, \
limit_min, limit_max, verdict, margin) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8)";

/// A version 1 SQLite lot at `db` holding `runs`, made as gyrotherm 1 made it: WAL mode, the
/// version 1 script, each run in its own transaction.
fn write_v1_sqlite(db: &Path, runs: &[Run]) {
    let mut c = rusqlite::Connection::open(db).unwrap();
    c.query_row("PRAGMA journal_mode = WAL", [], |_| Ok(()))
        .unwrap();
    c.execute_batch(&format!("BEGIN; {} COMMIT;", schema::SQLITE_V1))
        .unwrap();
    for r in runs {
        let tx = c.transaction().unwrap();
        tx.execute(
            V1_INSERT_RUN,
            rusqlite::params![
                r.unit,
                rfc3339_utc(r.tested_at_unix_ms),
                r.gyrotherm_version,
                r.station,
                r.model_path,
                r.model_sha256,
                r.model_content_sha256,
                r.model_method,
                r.spec_name,
                r.spec_sha256,
                r.spec_toml,
                r.verdict.as_str()
            ],
        )
        .unwrap();
        let id = tx.last_insert_rowid();
        for i in &r.inputs {
            tx.execute(
                V1_INSERT_INPUT,
                rusqlite::params![id, i.position, i.path, i.sha256, i.kind],
            )
            .unwrap();
        }
        for f in &r.figures {
            tx.execute(
                V1_INSERT_FIGURE,
                rusqlite::params![
                    id,
                    f.position,
                    f.figure,
                    f.value,
                    f.limit_min,
                    f.limit_max,
                    f.pass.map(|p| if p { "pass" } else { "fail" }),
                    f.margin
                ],
            )
            .unwrap();
        }
        tx.commit().unwrap();
    }
}

#[test]
fn sqlite_version_1_lot_is_upgraded_and_keeps_every_run() {
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("v1.sqlite");
    let old = [
        synthetic_run("A-001", 1, 1_700_000_000_000),
        synthetic_run("B-002", 2, 1_700_000_100_000),
    ];
    write_v1_sqlite(&db, &old);
    // The fixture is a version 1 lot: its version row, and figures without an axis.
    {
        let c = rusqlite::Connection::open(&db).unwrap();
        let v: i64 = c
            .query_row("SELECT version FROM schema_version", [], |r| r.get(0))
            .unwrap();
        let cols: Vec<String> = c
            .prepare("SELECT name FROM pragma_table_info('figures')")
            .unwrap()
            .query_map([], |r| r.get(0))
            .unwrap()
            .map(Result::unwrap)
            .collect();
        assert_eq!(v, 1);
        assert!(!cols.iter().any(|c| c == "axis"), "{cols:?}");
    }
    // A reader (lot list, lot report) opens it: upgraded in place.
    let mut s = SqliteStore::open(&db, false, 5000).unwrap();
    assert_eq!(s.schema_version().unwrap(), 2);
    let runs = s.runs().unwrap();
    assert_eq!(runs.len(), 2);
    for (got, want) in runs.iter().zip(&old) {
        let mut g = got.clone();
        g.id = 0;
        g.latest = false;
        assert_eq!(&g, want);
    }
    // The upgraded lot takes a unit beside the old runs.
    s.add(&synthetic_unit("IMU-1", 3, 1_700_000_200_000, Some(2)))
        .unwrap();
    let runs = s.runs().unwrap();
    assert_eq!(runs.len(), 3);
    assert_eq!(runs[2].axes.len(), 3);
    assert_eq!(runs[2].verdict, RunVerdict::Fail);
    // Its figures went in with their axis.
    let c = rusqlite::Connection::open(&db).unwrap();
    let axes: Vec<i64> = c
        .prepare("SELECT DISTINCT axis FROM figures ORDER BY axis")
        .unwrap()
        .query_map([], |r| r.get(0))
        .unwrap()
        .map(Result::unwrap)
        .collect();
    assert_eq!(axes, [0, 1, 2]);
}

#[test]
fn failed_upgrade_changes_nothing_and_says_what_to_do() {
    let dir = tempfile::tempdir().unwrap();
    let db = dir.path().join("v1.sqlite");
    write_v1_sqlite(&db, &[synthetic_run("A-001", 1, 0)]);
    // A table the upgrade would create, made by hand: the upgrade stops at it.
    {
        let c = rusqlite::Connection::open(&db).unwrap();
        c.execute_batch("CREATE TABLE run_axes (note TEXT);")
            .unwrap();
    }
    let e = SqliteStore::open(&db, true, 5000).err().unwrap();
    assert!(
        matches!(e, LotError::Migration { from: 1, to: 2, .. }),
        "{e:?}"
    );
    let m = e.to_string();
    assert!(
        m.contains("nothing was changed") && m.contains("docs/lot-schema.md"),
        "{m}"
    );
    // Still version 1, its figures table as it was (no axis column), the run in it.
    let c = rusqlite::Connection::open(&db).unwrap();
    let v: i64 = c
        .query_row("SELECT version FROM schema_version", [], |r| r.get(0))
        .unwrap();
    let has_axis: i64 = c
        .query_row(
            "SELECT count(*) FROM pragma_table_info('figures') WHERE name = 'axis'",
            [],
            |r| r.get(0),
        )
        .unwrap();
    let n: i64 = c
        .query_row("SELECT count(*) FROM figures", [], |r| r.get(0))
        .unwrap();
    assert_eq!((v, has_axis, n), (1, 0, 4));
}

/// [`write_v1_sqlite`] in PostgreSQL (the same version 1 statements with `$n` parameters).
fn write_v1_pg(url: &str, runs: &[Run]) {
    let mut c = postgres::Client::connect(url, postgres::NoTls).unwrap();
    let mut tx = c.transaction().unwrap();
    tx.batch_execute(schema::PG_V1).unwrap();
    tx.commit().unwrap();
    let pg = |q: &str| {
        let mut out = q.to_string();
        for n in (1..=12).rev() {
            out = out.replace(&format!("?{n}"), &format!("${n}"));
        }
        out
    };
    for r in runs {
        let mut tx = c.transaction().unwrap();
        let id: i64 = tx
            .query_one(
                &format!("{} RETURNING id", pg(V1_INSERT_RUN)),
                &[
                    &r.unit,
                    &rfc3339_utc(r.tested_at_unix_ms),
                    &r.gyrotherm_version,
                    &r.station,
                    &r.model_path,
                    &r.model_sha256,
                    &r.model_content_sha256,
                    &r.model_method,
                    &r.spec_name,
                    &r.spec_sha256,
                    &r.spec_toml,
                    &r.verdict.as_str(),
                ],
            )
            .unwrap()
            .get(0);
        for i in &r.inputs {
            tx.execute(
                &pg(V1_INSERT_INPUT),
                &[&id, &(i.position as i32), &i.path, &i.sha256, &i.kind],
            )
            .unwrap();
        }
        for f in &r.figures {
            let v = f.pass.map(|p| if p { "pass" } else { "fail" });
            tx.execute(
                &pg(V1_INSERT_FIGURE),
                &[
                    &id,
                    &(f.position as i32),
                    &f.figure,
                    &f.value,
                    &f.limit_min,
                    &f.limit_max,
                    &v,
                    &f.margin,
                ],
            )
            .unwrap();
        }
        tx.commit().unwrap();
    }
}

#[test]
fn postgres_store_holds_units_and_upgrades_version_1() {
    let Some(pg) = PgServer::start() else { return };
    let url = pg.create_db("lot_units");
    let mut s = open_store(&url, true, 0).unwrap();
    exercise_unit_store(s.as_mut());
    drop(s);

    // A version 1 lot made by the old statements: upgraded on opening, every run kept.
    let url = pg.create_db("lot_v1");
    let old = [
        synthetic_run("A-001", 1, 1_700_000_000_000),
        synthetic_run("B-002", 2, 1_700_000_100_000),
    ];
    write_v1_pg(&url, &old);
    let mut s = open_store(&url, false, 0).unwrap();
    assert_eq!(s.schema_version().unwrap(), 2);
    let runs = s.runs().unwrap();
    for (got, want) in runs.iter().zip(&old) {
        let mut g = got.clone();
        g.id = 0;
        g.latest = false;
        assert_eq!(&g, want);
    }
    s.add(&synthetic_unit("IMU-1", 3, 1_700_000_200_000, None))
        .unwrap();
    let runs = s.runs().unwrap();
    assert_eq!((runs.len(), runs[2].axes.len()), (3, 3));
    assert_eq!(report::lot_yield(&runs).units, 3);
    drop(s);

    // A failed upgrade is rolled back whole: still version 1, figures without an axis.
    let url = pg.create_db("lot_v1_blocked");
    write_v1_pg(&url, &old[..1]);
    let mut c = postgres::Client::connect(&url, postgres::NoTls).unwrap();
    c.batch_execute("CREATE TABLE run_axes (note TEXT)")
        .unwrap();
    let e = open_store(&url, true, 0).err().unwrap();
    assert!(
        matches!(e, LotError::Migration { from: 1, to: 2, .. }),
        "{e:?}"
    );
    assert!(e.to_string().contains("nothing was changed"), "{e}");
    let v: i32 = c
        .query_one("SELECT version FROM schema_version", &[])
        .unwrap()
        .get(0);
    let has_axis: i64 = c
        .query_one(
            "SELECT count(*) FROM information_schema.columns \
             WHERE table_name = 'figures' AND column_name = 'axis'",
            &[],
        )
        .unwrap()
        .get(0);
    assert_eq!((v, has_axis), (1, 0));
}

/// A stored schema version below 1 (no gyrotherm writes one) is refused by readers and
/// writers alike, and the lot is left as it was: before, `from as usize - 1` wrapped, the
/// upgrade steps were skipped and the version set to the current one, and every later open
/// failed with "no such table: run_axes".
#[test]
fn sqlite_schema_version_below_1_is_refused_unchanged() {
    for bad in [0i64, -1, i64::MIN] {
        let dir = tempfile::tempdir().unwrap();
        let db = dir.path().join("v1.sqlite");
        write_v1_sqlite(&db, &[synthetic_run("A-001", 1, 0)]);
        {
            let c = rusqlite::Connection::open(&db).unwrap();
            c.execute("UPDATE schema_version SET version = ?1", [bad])
                .unwrap();
        }
        for create in [false, true] {
            let e = SqliteStore::open(&db, create, 5000).err().unwrap();
            assert!(
                matches!(e, LotError::InvalidSchema { found, .. } if found == bad),
                "{e:?}"
            );
            let m = e.to_string();
            assert!(
                m.contains(&format!(
                    "lot schema version {bad} is not one gyrotherm writes"
                )) && m.contains("nothing was changed"),
                "{m}"
            );
        }
        let c = rusqlite::Connection::open(&db).unwrap();
        let v: i64 = c
            .query_row("SELECT version FROM schema_version", [], |r| r.get(0))
            .unwrap();
        let tables: i64 = c
            .query_row(
                "SELECT count(*) FROM sqlite_master WHERE name = 'run_axes'",
                [],
                |r| r.get(0),
            )
            .unwrap();
        assert_eq!((v, tables), (bad, 0));
    }
}

/// The same in PostgreSQL.
#[test]
fn postgres_schema_version_below_1_is_refused_unchanged() {
    let Some(pg) = PgServer::start() else { return };
    let url = pg.create_db("lot_v0");
    write_v1_pg(&url, &[synthetic_run("A-001", 1, 0)]);
    let mut c = postgres::Client::connect(&url, postgres::NoTls).unwrap();
    c.batch_execute("UPDATE schema_version SET version = 0")
        .unwrap();
    for create in [false, true] {
        let e = open_store(&url, create, 0).err().unwrap();
        assert!(
            matches!(e, LotError::InvalidSchema { found: 0, .. }),
            "{e:?}"
        );
    }
    let v: i32 = c
        .query_one("SELECT version FROM schema_version", &[])
        .unwrap()
        .get(0);
    let axes: bool = c
        .query_one("SELECT to_regclass('run_axes') IS NOT NULL", &[])
        .unwrap()
        .get(0);
    assert_eq!((v, axes), (0, false));
}

/// Every way a PostgreSQL password can be written is masked in a lot's name as messages show
/// it (the forms of the PostgreSQL manual, "Connection Strings": URL credentials, URL query
/// parameters, `key=value` settings, quoted or not); nothing else changes.
#[test]
fn every_form_of_a_password_is_masked() {
    for (db, want) in [
        (
            "postgres://gyro:s3cret@db.lab:5432/lot",
            "postgres://gyro:***@db.lab:5432/lot",
        ),
        (
            "postgresql://gyro@db.lab/lot?password=s3cret",
            "postgresql://gyro@db.lab/lot?password=***",
        ),
        (
            "postgres://db.lab/lot?user=gyro&password=s3cret&sslmode=disable",
            "postgres://db.lab/lot?user=gyro&password=***&sslmode=disable",
        ),
        (
            "postgres://db.lab/lot?PassWord=s3cret&sslpassword=k3y",
            "postgres://db.lab/lot?PassWord=***&sslpassword=***",
        ),
        (
            "postgres://db.lab/lot?pass%77ord=s3cret",
            "postgres://db.lab/lot?pass%77ord=***",
        ),
        (
            "postgres://gyro:s3@cret@db.lab/lot",
            "postgres://gyro:***@db.lab/lot",
        ),
        (
            "host=db.lab user=gyro password=s3cret dbname=lot",
            "host=db.lab user=gyro password=*** dbname=lot",
        ),
        (
            "host=db.lab password = 's3 c\\'ret' dbname=lot",
            "host=db.lab password = *** dbname=lot",
        ),
        ("postgres://gyro@db.lab/lot", "postgres://gyro@db.lab/lot"),
        ("/data/lot.sqlite", "/data/lot.sqlite"),
        ("lot=2024.sqlite", "lot=2024.sqlite"),
    ] {
        let got = redact_db(db);
        assert_eq!(got, want, "{db}");
        assert!(!got.contains("s3") && !got.contains("k3y"), "{got}");
    }
}
