//! `train` and `compensate` for an inertial unit: several gyro and temperature columns
//! (`--gyro-col`/`--temp-col` lists), one model file for the unit (`gyrotherm::imu_model`).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context as _;
use gyrotherm::csvlog::{self, ImuLog, LogWriter};
use gyrotherm::imu_model::{self, ImuFitEvent, ImuModel};

use super::common::{error_message, LogArgs};
use super::compensate::CompensateArgs;
use super::train::TrainArgs;

/// Whether `path` holds an inertial-unit model (an unreadable file is left to the
/// single-axis path, which names the problem).
pub fn is_imu_model(path: &Path) -> anyhow::Result<bool> {
    Ok(std::fs::read_to_string(path).is_ok_and(|t| imu_model::is_imu_model_text(&t)))
}

/// Read every log with the column lists, reporting each failure, then stop if any failed.
pub fn read_imu_logs(paths: &[PathBuf], args: &LogArgs) -> anyhow::Result<Vec<(String, ImuLog)>> {
    let opts = args.read_options();
    let mut out = Vec::new();
    let mut failed = 0;
    for p in paths {
        match csvlog::read_imu_log(p, &opts, args.table_axis.as_deref())
            .with_context(|| format!("cannot use log {}", p.display()))
        {
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

/// `train` with several gyro or temperature columns: one model for the unit.
pub fn train(args: TrainArgs) -> anyhow::Result<ExitCode> {
    let logs = read_imu_logs(&args.input, &args.log)?;
    for (name, l) in &logs {
        let what = l
            .table_axis
            .as_deref()
            .map_or("static".to_owned(), |a| format!("rate table on {a}"));
        eprintln!("gyrotherm: {name}: {what}");
    }
    let cfg = args.fit.fit_config(args.method)?;
    let temp_sensor = args.sensor.to_def()?;
    let started = std::time::Instant::now();
    let axes = logs.first().map_or(0, |(_, l)| l.gyro.len());
    let sensors = logs.first().map_or(0, |(_, l)| l.temp.len());
    eprintln!(
        "gyrotherm: fitting {axes} axes on their own threads, each on {sensors} sensor(s) in turn"
    );
    let events = fit_event_printer(started, &logs);
    let model =
        imu_model::fit_imu_with_events(&logs, &cfg, &temp_sensor, &|_, _, _, _, _| {}, &events)
            .map_err(anyhow::Error::new)
            .context("training failed")?;
    model
        .save(&args.out)
        .map_err(anyhow::Error::new)
        .context("cannot write the model")?;
    eprintln!(
        "gyrotherm: wrote {} ({} model for {axes} axes) in {:.1} s",
        args.out.display(),
        cfg.model_method().as_str(),
        started.elapsed().as_secs_f64()
    );
    for a in &model.axes {
        let scores: Vec<String> = a
            .scores
            .iter()
            .map(|s| match s.cv_rms {
                Some(r) => format!("{} {r:.3e}", s.temp),
                None => format!("{} -", s.temp),
            })
            .collect();
        eprintln!(
            "  {}: reads {} (bias: {}, scale factor: {}); cross-validated RMS per sensor: {}",
            a.gyro,
            a.temps.join(", "),
            if a.model.bias.is_some() {
                "fitted"
            } else {
                "none"
            },
            if a.model.scale.is_some() {
                "fitted"
            } else {
                "none"
            },
            scores.join(", ")
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// `compensate` with an inertial-unit model: for each gyro column G the output adds
/// `G_bias`, `G_scale`, `G_comp` and `G_status`.
pub fn compensate(args: CompensateArgs) -> anyhow::Result<ExitCode> {
    let model = ImuModel::load(&args.model)
        .map_err(anyhow::Error::new)
        .with_context(|| format!("cannot use model {}", args.model.display()))?;
    anyhow::ensure!(
        !args.stream,
        "--stream with an inertial-unit model is not implemented yet; use --input and --out"
    );
    let (Some(input), Some(out)) = (&args.input, &args.out) else {
        anyhow::bail!("give --input FILE and --out FILE");
    };
    let opts = model.read_options(&args.log.read_options());
    let (log, _) = csvlog::read_imu_log(input, &opts, args.log.table_axis.as_deref())
        .with_context(|| format!("cannot use log {}", input.display()))?;
    let comp = imu_model::compensate_imu(&model, &log).map_err(anyhow::Error::new)?;
    write_compensated(out, &log, &model, &comp)
        .with_context(|| format!("cannot write {}", out.display()))?;
    let mut counts = Vec::new();
    for (a, c) in model.axes.iter().zip(&comp) {
        let mut n = [0usize; 4];
        for s in &c.status {
            n[*s as usize] += 1;
        }
        counts.push(format!(
            "{}: {} ok, {} held, {} degraded, {} invalid",
            a.gyro, n[0], n[1], n[2], n[3]
        ));
    }
    eprintln!(
        "gyrotherm: wrote {} ({} lines; {})",
        out.display(),
        log.len(),
        counts.join("; ")
    );
    Ok(ExitCode::SUCCESS)
}

fn write_compensated(
    path: &Path,
    log: &ImuLog,
    model: &ImuModel,
    comp: &[imu_model::AxisCompensated],
) -> std::io::Result<()> {
    gyrotherm::atomic_file::write_atomically(path, |w| -> std::io::Result<()> {
        let numeric: Vec<&csvlog::NamedSeries> =
            log.gyro.iter().chain(&log.temp).chain(&log.table).collect();
        let mut header: Vec<String> = std::iter::once(csvlog::TIME_COL.to_owned())
            .chain(numeric.iter().map(|s| s.name.clone()))
            .chain(log.extra.iter().map(|c| c.name.clone()))
            .collect();
        for a in &model.axes {
            for suffix in ["bias", "scale", "comp", "status"] {
                header.push(format!("{}_{suffix}", a.gyro));
            }
        }
        let mut out = LogWriter::new(w, header)?;
        for i in 0..log.len() {
            out.push_f64(log.time_s[i]);
            for s in &numeric {
                out.push_f64(s.values[i]);
            }
            for c in &log.extra {
                out.push_raw(c.values[i].as_bytes());
            }
            for c in comp {
                out.push_f64(c.bias_dps[i]);
                out.push_f64(c.scale[i]);
                out.push_f64(c.gyro_comp_dps[i]);
                out.push_raw(c.status[i].as_str().as_bytes());
            }
            out.end_row()?;
        }
        out.flush()
    })
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
