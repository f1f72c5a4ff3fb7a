//! `gyrotherm compensate`: apply a fitted model to a log (file to file, or `--stream` on
//! stdin/stdout). Both run the flight compensator of `gyrotherm-core`, so their numbers are
//! identical.

use std::cell::RefCell;
use std::io::{BufWriter, Read, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::rc::Rc;

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
    let model = ModelFile::load(&args.model)?;
    let opts = args.log.read_options();
    let summary = if args.stream {
        // Rows are handed on as they are made and stdout is flushed whenever the input has
        // to be read again: a live feed gets each line at once, a file is not written one
        // system call per line.
        let out = Rc::new(RefCell::new(BufWriter::with_capacity(
            64 * 1024,
            std::io::stdout().lock(),
        )));
        let write_error = Rc::new(RefCell::new(None));
        let input = FlushBeforeRead {
            inner: std::io::stdin().lock(),
            out: Rc::clone(&out),
            write_error: Rc::clone(&write_error),
        };
        let result = compensate_stream(
            &model,
            input,
            "<stdin>".as_ref(),
            &opts,
            DeferredFlush(Rc::clone(&out)),
            true,
        );
        // A failed flush ends the input (see FlushBeforeRead): that error, not the input's
        // state at that moment, is what went wrong.
        if let Some(e) = write_error.borrow_mut().take() {
            return Err(anyhow::Error::new(e).context("writing standard output"));
        }
        let summary = result?;
        out.borrow_mut()
            .flush()
            .context("writing standard output")?;
        summary
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
                )?;
                w.flush()?;
                Ok::<_, anyhow::Error>(s)
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
