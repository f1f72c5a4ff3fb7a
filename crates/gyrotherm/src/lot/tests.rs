//! The SQLite store's promises: round trip, nothing lost under parallel writers, both runs of
//! a unit kept with the newer marked, and a locked, damaged, foreign or newer-schema file
//! refused unchanged. `exercise_store` is shared with the PostgreSQL test
//! (tests/lot_postgres.rs) through [`super::LotStore`].

use std::path::Path;

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
                supported: 1,
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
