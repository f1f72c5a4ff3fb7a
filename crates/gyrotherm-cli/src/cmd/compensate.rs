//! `gyrotherm compensate`: apply a fitted model to a log (file to file, or `--stream` on
//! stdin/stdout), with a status per line. Both run the flight compensator of `gyrotherm-core`,
//! so their numbers are identical (see `gyrotherm::compensate_lines`).

use std::cell::RefCell;
use std::io::{BufWriter, Read, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::rc::Rc;

use anyhow::Context as _;
use gyrotherm::compensate_lines::{compensate_file, compensate_lines, Mode};
use gyrotherm::model::{GivenColumns, ModelFile, TempSensorDef};
use gyrotherm_core::TempLimits;

use super::common::LogArgs;

#[derive(Debug, clap::Args)]
pub struct CompensateArgs {
    /// Model file written by `gyrotherm train`.
    #[arg(long)]
    pub model: PathBuf,
    /// Log to compensate (CSV). Not with --stream.
    #[arg(long, required_unless_present = "stream", conflicts_with = "stream")]
    pub input: Option<PathBuf>,
    /// Output CSV: every input column, then bias_dps, scale, gyro_comp_dps (°/s), status
    /// (ok, held, degraded, invalid), coverage (inside, edge, outside the training region)
    /// and sigma_dph (1σ estimate of the residual bias error, °/h). With an inertial-unit
    /// model: every input column, then G_bias, G_scale, G_comp, G_status per gyro column G.
    #[arg(long, required_unless_present = "stream", conflicts_with = "stream")]
    pub out: Option<PathBuf>,
    /// Read CSV on stdin and write one output line per input line on stdout, flushed as it
    /// goes (the flight path), with the columns of --out (single-axis or inertial-unit model).
    /// A malformed line is written as `invalid` and the stream goes on.
    #[arg(long)]
    pub stream: bool,
    #[command(flatten)]
    pub log: LogArgs,
}

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

/// Run `f` on stdin and stdout as a live stream. Rows are handed on as they are made and
/// stdout is flushed whenever the input has to be read again: a live feed gets each line at
/// once, a file is not written one system call per line.
pub(super) fn stdio_stream<T, E>(
    f: impl FnOnce(&mut dyn std::io::BufRead, &mut dyn Write) -> Result<T, E>,
) -> anyhow::Result<T>
where
    E: std::error::Error + Send + Sync + 'static,
{
    let out = Rc::new(RefCell::new(BufWriter::with_capacity(
        64 * 1024,
        std::io::stdout().lock(),
    )));
    let write_error = Rc::new(RefCell::new(None));
    let mut input = std::io::BufReader::new(FlushBeforeRead {
        inner: std::io::stdin().lock(),
        out: Rc::clone(&out),
        write_error: Rc::clone(&write_error),
    });
    let result = f(&mut input, &mut DeferredFlush(Rc::clone(&out)));
    // A failed flush ends the input (see FlushBeforeRead): that error, not the input's
    // state at that moment, is what went wrong.
    if let Some(e) = write_error.borrow_mut().take() {
        return Err(anyhow::Error::new(e).context("writing standard output"));
    }
    let value = result?;
    out.borrow_mut()
        .flush()
        .context("writing standard output")?;
    Ok(value)
}

type SharedOut<'a> = Rc<RefCell<BufWriter<std::io::StdoutLock<'a>>>>;

/// Stdin that flushes stdout before every read, so no output line waits on more input. A
/// flush that fails (e.g. the reader of a pipe went away) is kept for the caller and ends the
/// input, so it is not reported as a read error of stdin.
struct FlushBeforeRead<'a, R> {
    inner: R,
    out: SharedOut<'a>,
    write_error: Rc<RefCell<Option<std::io::Error>>>,
}

impl<R: Read> Read for FlushBeforeRead<'_, R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if self.write_error.borrow().is_some() {
            return Ok(0);
        }
        if let Err(e) = self.out.borrow_mut().flush() {
            *self.write_error.borrow_mut() = Some(e);
            return Ok(0);
        }
        self.inner.read(buf)
    }
}

/// Stdout whose `flush` waits for [`FlushBeforeRead`] (the real flush happens before the next
/// read and at the end).
struct DeferredFlush<'a>(SharedOut<'a>);

impl Write for DeferredFlush<'_> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.borrow_mut().write(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// Temperature-sensor fault limits stored in the model at `train` (see `gyrotherm compensate`:
/// a reading outside the range or changing faster than the rate limit is held).
#[derive(Debug, Clone, clap::Args)]
pub struct TempSensorArgs {
    /// Lowest plausible temperature reading, °C.
    #[arg(long, value_name = "C", allow_negative_numbers = true, default_value_t = TempLimits::DEFAULT.min_c)]
    pub temp_min_c: f64,
    /// Highest plausible temperature reading, °C.
    #[arg(long, value_name = "C", allow_negative_numbers = true, default_value_t = TempLimits::DEFAULT.max_c)]
    pub temp_max_c: f64,
    /// Fastest plausible temperature change, °C/s.
    #[arg(long, value_name = "C_PER_S", default_value_t = TempLimits::DEFAULT.max_rate_c_per_s)]
    pub temp_max_rate_c_per_s: f64,
    /// Temperature change always allowed between two readings (noise, resolution), °C.
    #[arg(long, value_name = "C", default_value_t = TempLimits::DEFAULT.step_allowance_c)]
    pub temp_step_allowance_c: f64,
    /// Seconds without a good temperature before the output is `degraded` instead of `held`.
    #[arg(long, value_name = "S", default_value_t = TempLimits::DEFAULT.degraded_after_s)]
    pub degraded_after_s: f64,
}

impl TempSensorArgs {
    /// The model-file form, checked.
    pub fn to_def(&self) -> anyhow::Result<TempSensorDef> {
        let def = TempSensorDef {
            min_c: self.temp_min_c,
            max_c: self.temp_max_c,
            max_rate_c_per_s: self.temp_max_rate_c_per_s,
            step_allowance_c: self.temp_step_allowance_c,
            degraded_after_s: self.degraded_after_s,
        };
        def.to_core().map_err(|e| {
            anyhow::anyhow!(
                "temperature-sensor limits (--temp-min-c, --temp-max-c, --temp-max-rate-c-per-s, \
                 --temp-step-allowance-c, --degraded-after-s): {e}"
            )
        })?;
        Ok(def)
    }
}
