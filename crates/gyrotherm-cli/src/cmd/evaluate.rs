//! `gyrotherm evaluate`: bias, bias stability and, for rate-table logs, the scale-factor
//! figures (IEEE Std 952 / GJB 2426A definitions).

use std::io::Write;
use std::process::ExitCode;

use gyrotherm::settings::EvaluateSettings;

use super::allan::{read_column, ReadColumn};
use super::args::EvaluateArgs;
use super::print::print_evaluation;

pub fn run(args: EvaluateArgs) -> anyhow::Result<ExitCode> {
    if args.model.is_some() || args.log.read_options().reads_unit(&[&args.input]) {
        return super::imu_judge::evaluate(args);
    }
    let mut w = std::io::stdout().lock();
    let spec = super::verdict::load(args.spec.as_deref())?;
    let ReadColumn {
        log,
        values,
        tau0_s,
        log_name,
        name,
    } = read_column(&args.input, &args.column, &args.log)?;
    let settings = EvaluateSettings {
        column: log_name,
        tau_s: args.tau_s,
        settle_s: args.settle_s,
        reference_scale: args.reference_scale,
    };
    let (mut e, tau) = settings.evaluate(&log, &values, tau0_s)?;
    // Named as in the file (the user's --gyro-col, not the standard `gyro_dps`).
    e.column = name;
    if let Some(note) = tau.note(tau0_s) {
        eprintln!("gyrotherm: {note}");
    }
    let verdict = match &spec {
        Some(s) => {
            let (rate_dps, opts, _) = settings.prepare(&values, tau0_s)?;
            Some(super::verdict::judge_log(
                s,
                &log,
                &rate_dps,
                &opts,
                &args.input,
            )?)
        }
        None => None,
    };
    let code = super::verdict::exit_code(verdict.as_ref().is_none_or(|v| v.pass));
    if args.json {
        let mut j = serde_json::to_value(&e)?;
        if let (Some(v), Some(o)) = (&verdict, j.as_object_mut()) {
            o.insert("verdict".into(), serde_json::to_value(v)?);
        }
        writeln!(w, "{}", serde_json::to_string_pretty(&j)?)?;
        return Ok(code);
    }
    print_evaluation(&mut w, &e)?;
    if let Some(v) = &verdict {
        writeln!(w)?;
        super::verdict::print(&mut w, v)?;
    }
    Ok(code)
}
