//! `gyrotherm compensate`: apply a fitted model to a log (file to file, or `--stream` on
//! stdin/stdout). Both run the flight compensator of `gyrotherm-core`, so their numbers are
//! identical.

use std::io::{BufWriter, Write};
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context as _;
use gyrotherm::compensate::compensate_stream;
use gyrotherm::model::ModelFile;

use super::common::LogArgs;

#[derive(Debug, clap::Args)]
pub struct CompensateArgs {
    /// Model file written by `gyrotherm train`.
    #[arg(long)]
    pub model: PathBuf,
    /// Log to compensate (CSV). Not with --stream.
    #[arg(long, required_unless_present = "stream", conflicts_with = "stream")]
    pub input: Option<PathBuf>,
    /// Output CSV: every input column, then bias_dps, scale and gyro_comp_dps (°/s).
    #[arg(long, required_unless_present = "stream", conflicts_with = "stream")]
    pub out: Option<PathBuf>,
    /// Read CSV on stdin and write one output line per input line on stdout, flushed as it
    /// goes (the flight path). Give --sample-period to start output at once; otherwise the
    /// first line comes after 100 input lines (the sample-period estimate).
    #[arg(long)]
    pub stream: bool,
    #[command(flatten)]
    pub log: LogArgs,
}

pub fn run(args: CompensateArgs) -> anyhow::Result<ExitCode> {
    let model = ModelFile::load(&args.model).map_err(anyhow::Error::msg)?;
    let opts = args.log.read_options();
    let summary = if args.stream {
        let stdin = std::io::stdin().lock();
        let stdout = std::io::stdout().lock();
        compensate_stream(&model, stdin, "<stdin>".as_ref(), &opts, stdout, true)
            .map_err(anyhow::Error::msg)?
    } else {
        let (Some(input), Some(out)) = (&args.input, &args.out) else {
            anyhow::bail!("give --input FILE and --out FILE, or --stream");
        };
        let file = std::fs::File::open(input)
            .with_context(|| format!("cannot open {}", input.display()))?;
        let summary =
            gyrotherm::atomic_file::write_atomically(out, |w: &mut BufWriter<std::fs::File>| {
                let s = compensate_stream(
                    &model,
                    std::io::BufReader::new(&file),
                    input,
                    &opts,
                    &mut *w,
                    false,
                )
                .map_err(std::io::Error::other)?;
                w.flush()?;
                Ok::<_, std::io::Error>(s)
            })
            .with_context(|| format!("cannot compensate into {}", out.display()))?;
        eprintln!(
            "gyrotherm: wrote {} ({} rows{})",
            out.display(),
            summary.rows,
            if summary.filled_rows > 0 {
                format!(", {} made by gap filling", summary.filled_rows)
            } else {
                String::new()
            }
        );
        summary
    };
    for w in &summary.warnings {
        eprintln!("gyrotherm: warning: {w}");
    }
    Ok(ExitCode::SUCCESS)
}
