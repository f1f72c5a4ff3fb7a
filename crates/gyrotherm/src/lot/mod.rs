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

mod error;
mod judge;
mod pg;
pub mod report;
mod run;
pub mod schema;
mod sqlite;
mod store;
mod time;

pub use error::LotError;
pub use judge::{check_unit_name, judge_model, ImuRunVerdict, ModelRunVerdict, UnitInputs};
pub(crate) use pg::PgStore;
pub(crate) use run::{check_axes, mark_latest};
pub use run::{default_station, synthetic_run, AxisRecord, FigureRow, Input, Run, RunVerdict};
pub(crate) use sqlite::SqliteStore;
pub(crate) use store::{check_known, redact_db};
pub use store::{open_store, LotStore};
pub use time::now_unix_ms;
pub(crate) use time::rfc3339_utc;

#[cfg(test)]
mod tests;
