//! A two-sensor unit's runs for the inertial-unit tests: unit 1000 of the simulated design
//! family, `seed-shock`.

use gyrotherm::csvlog::ImuLog;
use gyrotherm::sim::imu::{imu_from_family, simulate_imu, ImuConfig};
use gyrotherm::sim::SimConfig;

/// Unit 1000 (design family), `seed-shock`, with only the gyro x and the case and x-coil
/// sensors kept; the table (if any) on axis `table` (a table on y or z leaves a static run
/// for x).
pub fn run(seed: u64, table: Option<usize>) -> ImuLog {
    let mut r = SimConfig::builtin("seed-shock").unwrap();
    r.seed = seed;
    r.table_rate_dps = table.map(|_| 20.0);
    let mut log = simulate_imu(&ImuConfig {
        run: r,
        unit: imu_from_family(1000),
        table_axis: table.unwrap_or(0),
    })
    .unwrap();
    log.gyro.truncate(1);
    log.temp.truncate(2);
    log
}

/// As `gyrotherm train` with a static run (seed 1) and a table run per axis (seed 2).
#[allow(dead_code)] // Not every test that includes this file trains on these runs.
pub fn training() -> Vec<(String, ImuLog)> {
    [(1, None), (2, Some(0)), (2, Some(1)), (2, Some(2))]
        .into_iter()
        .map(|(seed, table)| (format!("{seed} {table:?}"), run(seed, table)))
        .collect()
}
