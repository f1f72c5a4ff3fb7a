//! `evaluate`, `compare` and `report` for an inertial unit (`--gyro-col`/`--temp-col`
//! lists, or `evaluate --model UNIT.json`): the figures per axis and the table across axes
//! (`gyrotherm::imu_judge`, `gyrotherm::report::unit`).

use std::io::Write;
use std::process::ExitCode;

use anyhow::Context as _;
use gyrotherm::csvlog;
use gyrotherm::imu_judge;
use gyrotherm::settings::EvaluateSettings;
use gyrotherm::unit_model::Model;

use super::args::EvaluateArgs;
use super::print::print_evaluation;

/// `evaluate` on a unit log: each gyro column's figures; with `--model`, also each axis's
/// compensated output.
pub fn evaluate(args: EvaluateArgs) -> anyhow::Result<ExitCode> {
    // The sheet first: a bad sheet fails before the log is read.
    let spec = super::verdict::load(args.spec.as_deref())?;
    // A single-gyro model is the unit of its one axis.
    let model = args.model.as_deref().map(Model::load).transpose()?;
    let base = args.log.read_options();
    let model = model.as_ref().map(|m| m.to_unit(&base));
    let opts = match &model {
        Some(m) => m.read_options(&base),
        None => base,
    };
    let (log, report) = csvlog::read_imu_log(&args.input, &opts, args.log.table_axis.as_deref())
        .with_context(|| format!("cannot use log {}", args.input.display()))?;
    if report.filled_gaps > 0 {
        eprintln!(
            "gyrotherm: {}: filled {} gap(s) with {} interpolated sample(s) (--fill-gaps-max-s)",
            args.input.display(),
            report.filled_gaps,
            report.filled_samples
        );
    }
    if let Some(w) = report.truncation_warning(&args.input) {
        eprintln!("gyrotherm: warning: {w}");
    }
    let settings = EvaluateSettings {
        column: args.column.clone(),
        tau_s: args.tau_s,
        settle_s: args.settle_s,
        reference_scale: args.reference_scale,
    };
    let input = args.input.display().to_string();
    let unit =
        imu_judge::evaluate_imu_spec(&log, model.as_deref(), &settings, spec.as_ref(), &input)
            .map_err(anyhow::Error::new)
            .with_context(|| input.clone())?;
    let (axes, tau) = (&unit.axes, &unit.tau);
    if let Some(note) = tau.note(axes[0].raw.sample_period_s) {
        eprintln!("gyrotherm: {note}");
    }
    let code = super::verdict::exit_code(unit.verdict.as_ref().is_none_or(|v| v.pass));
    let mut w = std::io::stdout().lock();
    if args.json {
        // Each axis carries its verdict as the single-axis output does; the unit's verdict
        // sits beside the axes (`UnitEvaluation::to_json`).
        writeln!(w, "{}", serde_json::to_string_pretty(&unit.to_json())?)?;
        return Ok(code);
    }
    for (k, a) in axes.iter().enumerate() {
        if k > 0 {
            writeln!(w)?;
        }
        match &a.compensated {
            Some(c) => {
                writeln!(
                    w,
                    "axis {}: {} (model reads {})",
                    k + 1,
                    a.gyro,
                    a.temps.join(", ")
                )?;
                writeln!(w, "raw:")?;
                print_evaluation(&mut w, &a.raw)?;
                writeln!(w, "compensated:")?;
                print_evaluation(&mut w, c)?;
            }
            None => {
                writeln!(w, "axis {}: {}", k + 1, a.gyro)?;
                print_evaluation(&mut w, &a.raw)?;
            }
        }
        if let Some(v) = &a.verdict {
            writeln!(w)?;
            writeln!(w, "axis {} ({}) against the spec:", k + 1, a.gyro)?;
            super::verdict::print(&mut w, v)?;
        }
    }
    if let Some(v) = &unit.verdict {
        writeln!(w)?;
        writeln!(w, "{}", v.line(axes.len()))?;
    }
    Ok(code)
}
