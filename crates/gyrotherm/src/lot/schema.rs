//! The lot schema, version by version. docs/lot-schema.md prints the same statements (a test
//! keeps them in step) so a lab can create the tables in its own database.
//!
//! A store holds one row in `schema_version`. Opening a store with an older version runs the
//! steps after it ([`SQLITE_MIGRATIONS`], [`PG_MIGRATIONS`], index i upgrades version i to
//! i + 1) in the same transaction as the check; a newer version is refused and nothing is
//! written.

/// The schema version this gyrotherm writes and reads.
pub const SCHEMA_VERSION: i64 = 1;

/// Version 1 in SQLite.
pub const SQLITE_V1: &str = "\
CREATE TABLE schema_version (version INTEGER NOT NULL);
CREATE TABLE runs (
    id                   INTEGER PRIMARY KEY AUTOINCREMENT,
    unit                 TEXT NOT NULL,
    tested_at            TEXT NOT NULL,
    gyrotherm_version    TEXT NOT NULL,
    station              TEXT NOT NULL,
    model_path           TEXT NOT NULL,
    model_sha256         TEXT NOT NULL,
    model_content_sha256 TEXT NOT NULL,
    model_method         TEXT NOT NULL,
    spec_name            TEXT,
    spec_sha256          TEXT,
    spec_toml            TEXT,
    verdict              TEXT NOT NULL CHECK (verdict IN ('pass', 'fail', 'none'))
);
CREATE INDEX runs_unit ON runs (unit, id);
CREATE TABLE run_inputs (
    run_id   INTEGER NOT NULL REFERENCES runs (id),
    position INTEGER NOT NULL,
    path     TEXT NOT NULL,
    sha256   TEXT NOT NULL,
    kind     TEXT NOT NULL CHECK (kind IN ('static', 'rate_table')),
    PRIMARY KEY (run_id, position)
);
CREATE TABLE figures (
    run_id    INTEGER NOT NULL REFERENCES runs (id),
    position  INTEGER NOT NULL,
    figure    TEXT NOT NULL,
    value     DOUBLE PRECISION NOT NULL,
    limit_min DOUBLE PRECISION,
    limit_max DOUBLE PRECISION,
    verdict   TEXT CHECK (verdict IN ('pass', 'fail')),
    margin    DOUBLE PRECISION,
    PRIMARY KEY (run_id, position, figure),
    FOREIGN KEY (run_id, position) REFERENCES run_inputs (run_id, position)
);
CREATE VIEW latest_runs AS
    SELECT * FROM runs r WHERE r.id = (SELECT MAX(id) FROM runs WHERE unit = r.unit);
INSERT INTO schema_version (version) VALUES (1);
";

/// Version 1 in PostgreSQL: the same tables; ids from an identity column.
pub const PG_V1: &str = "\
CREATE TABLE schema_version (version INTEGER NOT NULL);
CREATE TABLE runs (
    id                   BIGINT GENERATED ALWAYS AS IDENTITY PRIMARY KEY,
    unit                 TEXT NOT NULL,
    tested_at            TEXT NOT NULL,
    gyrotherm_version    TEXT NOT NULL,
    station              TEXT NOT NULL,
    model_path           TEXT NOT NULL,
    model_sha256         TEXT NOT NULL,
    model_content_sha256 TEXT NOT NULL,
    model_method         TEXT NOT NULL,
    spec_name            TEXT,
    spec_sha256          TEXT,
    spec_toml            TEXT,
    verdict              TEXT NOT NULL CHECK (verdict IN ('pass', 'fail', 'none'))
);
CREATE INDEX runs_unit ON runs (unit, id);
CREATE TABLE run_inputs (
    run_id   BIGINT NOT NULL REFERENCES runs (id),
    position INTEGER NOT NULL,
    path     TEXT NOT NULL,
    sha256   TEXT NOT NULL,
    kind     TEXT NOT NULL CHECK (kind IN ('static', 'rate_table')),
    PRIMARY KEY (run_id, position)
);
CREATE TABLE figures (
    run_id    BIGINT NOT NULL REFERENCES runs (id),
    position  INTEGER NOT NULL,
    figure    TEXT NOT NULL,
    value     DOUBLE PRECISION NOT NULL,
    limit_min DOUBLE PRECISION,
    limit_max DOUBLE PRECISION,
    verdict   TEXT CHECK (verdict IN ('pass', 'fail')),
    margin    DOUBLE PRECISION,
    PRIMARY KEY (run_id, position, figure),
    FOREIGN KEY (run_id, position) REFERENCES run_inputs (run_id, position)
);
CREATE VIEW latest_runs AS
    SELECT * FROM runs r WHERE r.id = (SELECT MAX(id) FROM runs WHERE unit = r.unit);
INSERT INTO schema_version (version) VALUES (1);
";

/// Upgrades of an SQLite lot: index i takes version i + 1 to i + 2 (none yet: version 1 is
/// the first).
pub const SQLITE_MIGRATIONS: &[&str] = &[];

/// Upgrades of a PostgreSQL lot, as [`SQLITE_MIGRATIONS`].
pub const PG_MIGRATIONS: &[&str] = &[];

/// The columns every reader selects, in this order (both stores).
pub(crate) const RUN_COLUMNS: &str = "id, unit, tested_at, gyrotherm_version, station, \
model_path, model_sha256, model_content_sha256, model_method, spec_name, spec_sha256, \
spec_toml, verdict";

#[cfg(test)]
mod tests {
    #[test]
    fn docs_print_the_schema() {
        // docs/lot-schema.md is the copy a lab reads: it must hold both scripts verbatim.
        let doc = include_str!("../../../../docs/lot-schema.md");
        assert!(doc.contains(super::SQLITE_V1.trim_end()), "SQLite schema");
        assert!(doc.contains(super::PG_V1.trim_end()), "PostgreSQL schema");
    }
}
