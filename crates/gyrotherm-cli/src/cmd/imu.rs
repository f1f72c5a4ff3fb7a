//! `train` for an inertial unit: several gyro and temperature columns (`--gyro-col`/`--temp-col`
//! lists), one model file for the unit (`gyrotherm::imu_model`), and the reading of such logs.

use std::path::PathBuf;

use anyhow::Context as _;
use gyrotherm::csvlog::{self, ImuLog};
use gyrotherm::imu_model::ImuFitEvent;

use super::common::{error_message, LogArgs};

/// Read every log with the column lists, reporting each failure, then stop if any failed.
pub fn read_imu_logs(paths: &[PathBuf], args: &LogArgs) -> anyhow::Result<Vec<(String, ImuLog)>> {
    read_imu_logs_with(paths, args, &args.read_options())
}

/// [`read_imu_logs`] with the columns of `opts` (a unit model's, [`ImuModel::read_options`]).
pub fn read_imu_logs_with(
    paths: &[PathBuf],
    args: &LogArgs,
    opts: &csvlog::ReadOptions,
) -> anyhow::Result<Vec<(String, ImuLog)>> {
    let mut out = Vec::new();
    let mut failed = 0;
    // The files are read at once, each on its own thread; what each gave is told in order.
    let read = csvlog::read_imu_logs(paths, opts, args.table_axis.as_deref());
    for (p, r) in paths.iter().zip(read) {
        match r.with_context(|| format!("cannot use log {}", p.display())) {
            Ok((log, report)) => {
                if report.filled_gaps > 0 {
                    eprintln!(
                        "gyrotherm: {}: filled {} gap(s) with {} interpolated sample(s) \
                         (--fill-gaps-max-s)",
                        p.display(),
                        report.filled_gaps,
                        report.filled_samples
                    );
                }
                if let Some(w) = report.truncation_warning(p) {
                    eprintln!("gyrotherm: warning: {w}");
                }
                if report.zero_table {
                    eprintln!(
                        "gyrotherm: {}: the table-rate column {} is all zeros: read as a \
                         static run",
                        p.display(),
                        opts.table_col
                    );
                }
                out.push((p.display().to_string(), log));
            }
            Err(e) => {
                eprintln!("gyrotherm: {}", error_message(&e));
                failed += 1;
            }
        }
    }
    anyhow::ensure!(
        failed == 0,
        "{failed} of {} input logs could not be read (see above)",
        paths.len()
    );
    Ok(out)
}

/// Live lines on stderr for each step of a unit fit ([`ImuFitEvent`]): the axis and sensor
/// with the seconds since `started` (the axes run on threads, so lines of several axes
/// interleave; each line names its axis).
pub fn fit_event_printer(
    started: std::time::Instant,
    logs: &[(String, ImuLog)],
) -> impl Fn(ImuFitEvent) + Sync {
    let gyro: Vec<String> = logs
        .first()
        .map(|(_, l)| l.gyro.iter().map(|s| s.name.clone()).collect())
        .unwrap_or_default();
    let temp: Vec<String> = logs
        .first()
        .map(|(_, l)| l.temp.iter().map(|s| s.name.clone()).collect())
        .unwrap_or_default();
    move |e: ImuFitEvent| {
        let at = started.elapsed().as_secs_f64();
        let g = |k: usize| gyro.get(k).map_or("?", String::as_str);
        let t = |j: usize| temp.get(j).map_or("?", String::as_str);
        match e {
            ImuFitEvent::AxisStarted { axis } => eprintln!(
                "gyrotherm: [{at:6.1} s] {}: axis starts ({} sensor(s) to try)",
                g(axis),
                temp.len()
            ),
            ImuFitEvent::SensorStarted { axis, sensor } => eprintln!(
                "gyrotherm: [{at:6.1} s] {}: fitting on {} (sensor {} of {})",
                g(axis),
                t(sensor),
                sensor + 1,
                temp.len()
            ),
            ImuFitEvent::SensorFinished {
                axis,
                sensor,
                cv_rms,
            } => eprintln!(
                "gyrotherm: [{at:6.1} s] {}: {} done (cross-validated RMS {})",
                g(axis),
                t(sensor),
                cv_rms.map_or("-".to_owned(), |r| format!("{r:.3e}"))
            ),
            ImuFitEvent::AxisFinished { axis, sensor } => {
                eprintln!(
                    "gyrotherm: [{at:6.1} s] {}: axis done, reads {}",
                    g(axis),
                    t(sensor)
                )
            }
            _ => {}
        }
    }
}
