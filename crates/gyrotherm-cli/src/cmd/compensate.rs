//! `gyrotherm compensate`: apply a fitted model to a log (file to file, or `--stream` on
//! stdin/stdout), with a status per line. Both run the flight compensator of `gyrotherm-core`,
//! so their numbers are identical (see `gyrotherm::compensate_lines`). A single-gyro model and
//! an inertial unit's are read alike (`gyrotherm::unit_model`); a unit's output adds
//! `G_bias`, `G_scale`, `G_comp` and `G_status` for each gyro column G.

use std::process::ExitCode;

use anyhow::Context as _;
use gyrotherm::model::GivenColumns;
use gyrotherm::unit_model::Model;

use super::args::CompensateArgs;
use super::common::tell;
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
    let model = Model::load(&args.model)?;
    if let Some(w) = model.load_warning(&args.model) {
        eprintln!("gyrotherm: warning: {w}");
    }
    model
        .compensate_notes(&args.model, args.log.sample_period_s.is_some())
        .iter()
        .for_each(tell);
    anyhow::ensure!(
        args.log.fill_gaps_max_s.is_none(),
        "--fill-gaps-max-s does not apply to compensate: the compensator bridges time gaps itself and \
         writes one output line per input line"
    );
    let opts = model
        .read_options(&args.log.read_options(), given)
        .with_context(|| format!("cannot use model {}", args.model.display()))?;
    let told = if args.stream {
        let summary = stdio_stream(|input, output| {
            model.compensate_stream(input, "<stdin>".as_ref(), &opts, output)
        })?;
        summary.told(None)
    } else {
        let (Some(input), Some(out)) = (&args.input, &args.out) else {
            anyhow::bail!("give --input FILE and --out FILE, or --stream");
        };
        model.compensate_file(input, out, &opts)?.told(Some(out))
    };
    told.iter().for_each(tell);
    Ok(ExitCode::SUCCESS)
}
