//! `gyrotherm compensate`: apply a fitted model to a log (file to file, or `--stream` on
//! stdin/stdout), with a status per line. Both run the flight compensator of `gyrotherm-core`,
//! so their numbers are identical (see `gyrotherm::compensate_lines`).

use std::process::ExitCode;

use anyhow::Context as _;
use gyrotherm::compensate_lines::{compensate_file, compensate_lines, Mode};
use gyrotherm::model::{GivenColumns, ModelFile};

use super::args::CompensateArgs;
use super::stream::stdio_stream;

/// `given`: the column options named on the command line; the others come from the model
/// (the columns it was trained on), where it has them.
pub fn run(args: CompensateArgs, given: GivenColumns) -> anyhow::Result<ExitCode> {
    super::common::refuse_outputs_over_inputs(
        args.out.as_deref(),
        [Some(args.model.as_path()), args.input.as_deref()]
            .into_iter()
            .flatten(),
    )?;
    if super::imu::is_imu_model(&args.model)? {
        return super::imu::compensate(args);
    }
    let (model, seal) = ModelFile::load_sealed(&args.model)?;
    if let Some(w) = seal.warning(&args.model) {
        eprintln!("gyrotherm: warning: {w}");
    }
    if let Some(n) = gyrotherm::coverage::missing_note(&model) {
        eprintln!("gyrotherm: note: {}: {n}", args.model.display());
    }
    anyhow::ensure!(
        args.log.fill_gaps_max_s.is_none(),
        "--fill-gaps-max-s does not apply to compensate: the compensator bridges time gaps itself and \
         writes one output line per input line"
    );
    if args.log.sample_period_s.is_some() {
        eprintln!(
            "gyrotherm: note: --sample-period-s is not needed by compensate (output starts with \
             the first line); ignored"
        );
    }
    let opts = model
        .read_options(&args.log.read_options(), given)
        .with_context(|| format!("cannot use model {}", args.model.display()))?;
    let summary = if args.stream {
        let summary = stdio_stream(|input, output| {
            compensate_lines(
                &model,
                input,
                "<stdin>".as_ref(),
                &opts,
                output,
                Mode::Stream,
                true,
            )
        })?;
        eprintln!("gyrotherm: {}", summary.describe());
        summary
    } else {
        let (Some(input), Some(out)) = (&args.input, &args.out) else {
            anyhow::bail!("give --input FILE and --out FILE, or --stream");
        };
        let summary = compensate_file(&model, input, out, &opts)?;
        eprintln!(
            "gyrotherm: wrote {} ({})",
            out.display(),
            summary.describe()
        );
        summary
    };
    if summary.held + summary.degraded + summary.invalid > 0 {
        eprintln!(
            "gyrotherm: temperature faults ridden through: {} held, {} degraded; {} invalid \
             (no rate: gyro not finite{})",
            summary.held,
            summary.degraded,
            summary.invalid,
            if summary.malformed > 0 {
                " or malformed line"
            } else {
                ""
            }
        );
    }
    for w in &summary.warnings {
        eprintln!("gyrotherm: warning: {w}");
    }
    Ok(ExitCode::SUCCESS)
}
