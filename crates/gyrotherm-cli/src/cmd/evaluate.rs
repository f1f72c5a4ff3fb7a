//! `gyrotherm evaluate`: bias, bias stability and, for rate-table logs, the scale-factor
//! figures (IEEE Std 952 / GJB 2426A definitions); for a unit's log, per axis, with a model's
//! compensated output beside the raw one.

use std::io::Write;
use std::process::ExitCode;

use gyrotherm::evaluate::{evaluate, EvaluateJob};
use gyrotherm::settings::EvaluateSettings;
use gyrotherm::unit_model::Model;

use super::args::EvaluateArgs;
use super::common::tell;

pub fn run(args: EvaluateArgs) -> anyhow::Result<ExitCode> {
    // The sheet and the model first: a bad one fails before the log is read.
    let spec = super::verdict::load(args.spec.as_deref())?;
    let model = args.model.as_deref().map(Model::load).transpose()?;
    let settings = EvaluateSettings {
        column: args.column.clone(),
        tau_s: args.tau_s,
        settle_s: args.settle_s,
        reference_scale: args.reference_scale,
    };
    let read = args.log.read_options();
    let evaluated = evaluate(&EvaluateJob {
        input: &args.input,
        read: &read,
        table_axis: args.log.table_axis.as_deref(),
        model: model.as_ref(),
        settings: &settings,
        spec: spec.as_ref(),
    });
    let evaluated = evaluated?;
    evaluated.told.iter().for_each(tell);
    let mut w = std::io::stdout().lock();
    if args.json {
        writeln!(
            w,
            "{}",
            serde_json::to_string_pretty(&evaluated.to_json()?)?
        )?;
    } else {
        evaluated.write_text(&mut w)?;
    }
    Ok(super::verdict::exit_code(evaluated.pass()))
}
