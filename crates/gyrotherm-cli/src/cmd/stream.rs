//! Stdin and stdout as a live stream (`compensate --stream`, one gyro or an inertial unit).

use std::cell::RefCell;
use std::io::{BufWriter, Read, Write};
use std::rc::Rc;

use anyhow::Context as _;

/// Run `f` on stdin and stdout as a live stream. Rows are handed on as they are made and
/// stdout is flushed whenever the input has to be read again: a live feed gets each line at
/// once, a file is not written one system call per line.
pub fn stdio_stream<T, E>(
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
