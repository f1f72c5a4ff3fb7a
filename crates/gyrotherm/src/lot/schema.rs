//! The lot schema, version by version. docs/lot-schema.md prints the same statements (a test
//! keeps them in step) so a lab can create the tables in its own database.
//!
//! A store holds one row in `schema_version`. Opening a store with an older version runs the
//! steps after it (`SQLITE_MIGRATIONS`, `PG_MIGRATIONS`, index i upgrades version i + 1
//! to i + 2) in the same transaction as the check; a newer version is refused and nothing is
//! written. A new store is made the same way (version 1, then every step), so the steps run
//! on every new lot, not only on the old ones.
//!
//! Version 2 holds inertial units: a unit's run has a row per axis in `run_axes` (its gyro
//! column, the temperature columns its model reads, its verdict) and its figures carry the
//! axis (`figures.axis`, 0 for a single-axis run, which has no `run_axes` row).

/// The schema version this gyrotherm writes and reads.
pub(crate) const SCHEMA_VERSION: i64 = 2;

/// Version 1 in SQLite.
pub(crate) const SQLITE_V1: &str = "\
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
pub(crate) const PG_V1: &str = "\
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

/// Version 1 to 2 in SQLite: the axes of a unit's run, and the axis of each figure.
/// SQLite cannot change a primary key in place, so `figures` is copied into a new table with
/// the axis in its key (every existing figure on axis 0) and renamed.
pub(crate) const SQLITE_V1_TO_V2: &str = "\
CREATE TABLE run_axes (
    run_id  INTEGER NOT NULL REFERENCES runs (id),
    axis    INTEGER NOT NULL,
    gyro    TEXT NOT NULL,
    temps   TEXT NOT NULL,
    verdict TEXT NOT NULL CHECK (verdict IN ('pass', 'fail', 'none')),
    PRIMARY KEY (run_id, axis)
);
CREATE TABLE figures_v2 (
    run_id    INTEGER NOT NULL REFERENCES runs (id),
    axis      INTEGER NOT NULL DEFAULT 0,
    position  INTEGER NOT NULL,
    figure    TEXT NOT NULL,
    value     DOUBLE PRECISION NOT NULL,
    limit_min DOUBLE PRECISION,
    limit_max DOUBLE PRECISION,
    verdict   TEXT CHECK (verdict IN ('pass', 'fail')),
    margin    DOUBLE PRECISION,
    PRIMARY KEY (run_id, axis, position, figure),
    FOREIGN KEY (run_id, position) REFERENCES run_inputs (run_id, position)
);
INSERT INTO figures_v2 (run_id, axis, position, figure, value, limit_min, limit_max, verdict, margin)
    SELECT run_id, 0, position, figure, value, limit_min, limit_max, verdict, margin FROM figures;
DROP TABLE figures;
ALTER TABLE figures_v2 RENAME TO figures;
UPDATE schema_version SET version = 2;
";

/// Version 1 to 2 in PostgreSQL: as [`SQLITE_V1_TO_V2`]; PostgreSQL changes the key in place.
pub(crate) const PG_V1_TO_V2: &str = "\
CREATE TABLE run_axes (
    run_id  BIGINT NOT NULL REFERENCES runs (id),
    axis    INTEGER NOT NULL,
    gyro    TEXT NOT NULL,
    temps   TEXT NOT NULL,
    verdict TEXT NOT NULL CHECK (verdict IN ('pass', 'fail', 'none')),
    PRIMARY KEY (run_id, axis)
);
ALTER TABLE figures ADD COLUMN axis INTEGER NOT NULL DEFAULT 0;
ALTER TABLE figures DROP CONSTRAINT figures_pkey;
ALTER TABLE figures ADD PRIMARY KEY (run_id, axis, position, figure);
UPDATE schema_version SET version = 2;
";

/// Upgrades of an SQLite lot: index i takes version i + 1 to i + 2.
pub(crate) const SQLITE_MIGRATIONS: &[&str] = &[SQLITE_V1_TO_V2];

/// Upgrades of a PostgreSQL lot, as [`SQLITE_MIGRATIONS`].
pub(crate) const PG_MIGRATIONS: &[&str] = &[PG_V1_TO_V2];

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
        assert!(
            doc.contains(super::SQLITE_V1_TO_V2.trim_end()),
            "SQLite upgrade to version 2"
        );
        assert!(
            doc.contains(super::PG_V1_TO_V2.trim_end()),
            "PostgreSQL upgrade to version 2"
        );
    }
}
