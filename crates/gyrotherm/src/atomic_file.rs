//! Write outputs so that nothing is lost: into a temporary file in the target folder, then
//! renamed into place. A crash or error mid-write leaves any previous file untouched.
//!
//! Where the output goes decides how it is written ([`destination`]):
//! - a new path or a regular file: temporary file beside it, renamed over it;
//! - a symbolic link (dangling or not): refused, and left as it is. A link planted where an
//!   output goes (say in an export folder) would otherwise make the program write wherever
//!   it points; the message names the link and says what to do;
//! - a FIFO, a character or block device, a socket (such as `/dev/null`): opened and written
//!   straight (without following a link put there in the meantime), nothing renamed or
//!   created beside it;
//! - `-`, `/dev/stdout` (and `/dev/stderr`): the process's own standard output (error),
//!   written straight, sharing its position with the shell's redirection; likewise
//!   `/dev/fd/N` and `/proc/self/fd/N`, the kernel's names for files the shell opened for
//!   the process (links only in name: no one can plant them);
//! - a directory: refused.
//!
//! Only the last component is checked: folders on the way (`/tmp` on some systems, a
//! build folder on another disk) may be links.
//!
//! Temporary files being written are kept in a process-wide list, so that a signal handler
//! (installed by the command-line program) can remove them before the process exits:
//! [`remove_temp_files`].

use std::fs::{File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Component, Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard};

/// How an output path is written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Destination {
    /// The process's standard output (`-`, `/dev/stdout`, `/dev/fd/1`).
    Stdout,
    /// The process's standard error (`/dev/stderr`, `/dev/fd/2`).
    Stderr,
    /// Opened and written in place: a FIFO, device or socket, or a file the process has open
    /// (`/dev/fd/N`).
    Direct(PathBuf),
    /// Written to a temporary file beside this path (a regular file or none yet, never a
    /// link) and renamed over it.
    Replace(PathBuf),
}

/// Decide how `path` is written (see the module documentation). Errors: a symbolic link, a
/// directory, or a path whose kind cannot be read (permission).
pub fn destination(path: &Path) -> io::Result<Destination> {
    if let Some(stream) = standard_stream(path) {
        return Ok(stream);
    }
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_symlink() && !open_file_name(path) => {
            return Err(link_refused(path))
        }
        Ok(_) => {}
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            return Ok(Destination::Replace(path.to_path_buf()))
        }
        Err(e) => return Err(cannot_inspect(path, e)),
    }
    match std::fs::metadata(path) {
        Ok(meta) if meta.is_dir() => Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{} is a directory; give a file name", path.display()),
        )),
        Ok(meta) if meta.is_file() && !under_dev_or_proc(path) => {
            Ok(Destination::Replace(path.to_path_buf()))
        }
        // e.g. /dev/fd/3 opened by the shell onto a file: writing in place keeps the
        // shell's view of it; a rename would put a file into /dev.
        Ok(_) => Ok(Destination::Direct(path.to_path_buf())),
        Err(e) => Err(cannot_inspect(path, e)),
    }
}

fn cannot_inspect(path: &Path, e: io::Error) -> io::Error {
    io::Error::new(e.kind(), format!("cannot inspect {}: {e}", path.display()))
}

fn link_refused(path: &Path) -> io::Error {
    let target = match std::fs::read_link(path) {
        Ok(t) => format!(" (to {})", t.display()),
        Err(_) => String::new(),
    };
    io::Error::new(
        io::ErrorKind::InvalidInput,
        format!(
            "{} is a symbolic link{target}: outputs are never written through links; \
             give the file's real path, or remove the link",
            path.display()
        ),
    )
}

/// `-` and the names of the standard streams.
fn standard_stream(path: &Path) -> Option<Destination> {
    match path.to_str()? {
        "-" | "/dev/stdout" | "/dev/fd/1" | "/proc/self/fd/1" => Some(Destination::Stdout),
        "/dev/stderr" | "/dev/fd/2" | "/proc/self/fd/2" => Some(Destination::Stderr),
        _ => None,
    }
}

/// `/dev/fd/N` or `/proc/self/fd/N` (`/proc/PID/fd/N`): the kernel's link to a file this
/// process already has open, which no one else can put there (unlike a link in a
/// world-writable folder such as `/dev/shm`).
fn open_file_name(path: &Path) -> bool {
    let names: Option<Vec<&str>> = path
        .components()
        .map(|c| match c {
            Component::RootDir => Some("/"),
            Component::Normal(n) => n.to_str(),
            _ => None,
        })
        .collect();
    let number = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    match names.as_deref() {
        Some(["/", "dev", "fd", n]) => number(n),
        Some(["/", "proc", pid, "fd", n]) => (*pid == "self" || number(pid)) && number(n),
        _ => false,
    }
}

fn under_dev_or_proc(path: &Path) -> bool {
    let mut c = path.components();
    c.next() == Some(Component::RootDir)
        && matches!(c.next(), Some(Component::Normal(n)) if n == "dev" || n == "proc")
}

/// Write `path` safely: `write` gets a buffered writer; on success it is flushed. For a file
/// (see [`destination`]) the writer is on a temporary file in the same folder, which is
/// synced and renamed over the file; on error (or a panic) the temporary file is removed
/// and the file is left as it was. FIFOs, devices and standard output are written straight.
pub(crate) fn write_atomically<T, E>(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<T, E>,
) -> Result<T, E>
where
    E: From<io::Error>,
{
    match destination(path)? {
        Destination::Stdout => {
            // Anything printed through `std::io::stdout` must come first.
            io::stdout().flush()?;
            write_straight(clone_stdout()?, write)
        }
        Destination::Stderr => write_straight(clone_stderr()?, write),
        Destination::Direct(p) => {
            let file = open_direct(&p)?;
            write_straight(file, write)
        }
        Destination::Replace(target) => write_replacing(&target, write),
    }
}

/// Open a FIFO, device or socket for writing, in place. A link put there since
/// [`destination`] looked is refused by the open itself (ELOOP), not followed.
fn open_direct(p: &Path) -> io::Result<File> {
    let mut options = OpenOptions::new();
    options.write(true);
    #[cfg(unix)]
    if !open_file_name(p) {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NOFOLLOW);
    }
    options
        .open(p)
        .map_err(|e| io::Error::new(e.kind(), format!("cannot open {}: {e}", p.display())))
}

fn write_straight<T, E>(
    file: File,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<T, E>,
) -> Result<T, E>
where
    E: From<io::Error>,
{
    let mut out = BufWriter::new(file);
    let v = write(&mut out)?;
    out.flush()?;
    Ok(v)
}

fn write_replacing<T, E>(
    target: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<T, E>,
) -> Result<T, E>
where
    E: From<io::Error>,
{
    let old_permissions = std::fs::metadata(target).ok().map(|m| m.permissions());
    let (tmp, file) = create_temp_beside(target)?;
    let guard = TempGuard::new(tmp);
    let mut out = BufWriter::new(file);
    let v = write(&mut out)?;
    out.flush()?;
    if let Some(perm) = old_permissions {
        out.get_ref().set_permissions(perm)?;
    }
    out.get_ref().sync_all()?;
    drop(out);
    guard.rename_to(target)?;
    Ok(v)
}

/// `dir/.name.tmp.<pid>.<n>` beside `path` (so the final rename stays on one file system),
/// created new: never an existing file or a link planted under that name.
fn create_temp_beside(path: &Path) -> io::Result<(PathBuf, File)> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "output".to_owned());
    let dir = match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let mut last_err = None;
    for _ in 0..100 {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let tmp = dir.join(format!(".{name}.tmp.{}.{n}", std::process::id()));
        // Registered before it exists, so a signal arriving in between still removes it.
        register(&tmp);
        match OpenOptions::new().write(true).create_new(true).open(&tmp) {
            Ok(f) => return Ok((tmp, f)),
            Err(e) => {
                unregister(&tmp);
                if e.kind() != io::ErrorKind::AlreadyExists {
                    return Err(io::Error::new(
                        e.kind(),
                        format!("cannot create temporary file {}: {e}", tmp.display()),
                    ));
                }
                last_err = Some(e);
            }
        }
    }
    Err(last_err.unwrap_or_else(|| io::Error::other("no free temporary name")))
}

fn clone_stdout() -> io::Result<File> {
    #[cfg(unix)]
    {
        use std::os::fd::AsFd;
        Ok(File::from(io::stdout().as_fd().try_clone_to_owned()?))
    }
    #[cfg(windows)]
    {
        use std::os::windows::io::AsHandle;
        Ok(File::from(io::stdout().as_handle().try_clone_to_owned()?))
    }
}

fn clone_stderr() -> io::Result<File> {
    #[cfg(unix)]
    {
        use std::os::fd::AsFd;
        Ok(File::from(io::stderr().as_fd().try_clone_to_owned()?))
    }
    #[cfg(windows)]
    {
        use std::os::windows::io::AsHandle;
        Ok(File::from(io::stderr().as_handle().try_clone_to_owned()?))
    }
}

/// Write bytes safely (see `write_atomically`).
pub fn write_bytes_atomically(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_atomically(path, |w| w.write_all(bytes))
}

/// An output path that names one of the same command's inputs: writing it would replace
/// the input (a raw log overwritten by a model, a model by its own output).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OutputIsInput {
    /// The output as given.
    pub output: PathBuf,
    /// The input it names, as given.
    pub input: PathBuf,
}

impl std::fmt::Display for OutputIsInput {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} is also an input of this command ({}); nothing was written: give the output \
             another path",
            self.output.display(),
            self.input.display()
        )
    }
}

impl std::error::Error for OutputIsInput {}

/// Refuse outputs that would replace one of `inputs`, before anything is read or written.
/// Paths are compared canonical (links, `..` and relative paths resolved), so `./a.csv` and
/// `dir/../a.csv` are one file. Only outputs written by replacing a file are checked
/// ([`Destination::Replace`]): standard output, FIFOs and devices replace nothing (`--input
/// /dev/stdin --out -` on a terminal names one device twice, and is fine). An output that does
/// not exist yet is no input; an input that cannot be resolved (missing) is left to its
/// reader to report.
pub fn refuse_outputs_over_inputs(
    outputs: &[&Path],
    inputs: &[&Path],
) -> Result<(), OutputIsInput> {
    let inputs: Vec<(PathBuf, &Path)> = inputs
        .iter()
        .filter_map(|p| Some((std::fs::canonicalize(p).ok()?, *p)))
        .collect();
    for out in outputs {
        if !matches!(destination(out), Ok(Destination::Replace(_))) {
            continue;
        }
        let Ok(canonical) = std::fs::canonicalize(out) else {
            continue;
        };
        if let Some((_, input)) = inputs.iter().find(|(c, _)| *c == canonical) {
            return Err(OutputIsInput {
                output: out.to_path_buf(),
                input: input.to_path_buf(),
            });
        }
    }
    Ok(())
}

/// Temporary files now being written by this process.
static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn live() -> MutexGuard<'static, Vec<PathBuf>> {
    LIVE.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

fn register(tmp: &Path) {
    live().push(tmp.to_path_buf());
}

fn unregister(tmp: &Path) {
    live().retain(|p| p != tmp);
}

/// Remove every temporary file this process is writing and forget them; returns how many
/// were removed. For a signal handler that is about to end the process: a write in progress
/// then fails at its rename instead of leaving a hidden partial file.
pub fn remove_temp_files() -> usize {
    remove_temp_files_where(|_| true)
}

fn remove_temp_files_where(select: impl Fn(&Path) -> bool) -> usize {
    let mut live = live();
    let mut removed = 0;
    live.retain(|p| {
        if !select(p) {
            return true;
        }
        removed += usize::from(std::fs::remove_file(p).is_ok());
        false
    });
    removed
}

/// A registered temporary file, removed when dropped unless renamed into place.
struct TempGuard {
    tmp: Option<PathBuf>,
}

impl TempGuard {
    fn new(tmp: PathBuf) -> Self {
        TempGuard { tmp: Some(tmp) }
    }

    fn rename_to(mut self, target: &Path) -> io::Result<()> {
        let Some(tmp) = self.tmp.take() else {
            return Ok(());
        };
        // Under the list's lock, so that a concurrent remove_temp_files either removes the
        // file before the rename (which then fails) or finds it already in place.
        let mut live = live();
        if !live.contains(&tmp) {
            return Err(io::Error::new(
                io::ErrorKind::Interrupted,
                format!("{} was removed before it was complete", target.display()),
            ));
        }
        let result = std::fs::rename(&tmp, target).map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            io::Error::new(
                e.kind(),
                format!(
                    "cannot rename {} to {}: {e}",
                    tmp.display(),
                    target.display()
                ),
            )
        });
        live.retain(|p| p != &tmp);
        result
    }
}

impl Drop for TempGuard {
    fn drop(&mut self) {
        if let Some(tmp) = self.tmp.take() {
            let _ = std::fs::remove_file(&tmp);
            unregister(&tmp);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entries(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn failed_write_keeps_old_file_and_leaves_no_temp() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.csv");
        std::fs::write(&path, b"old").unwrap();
        let r: Result<(), io::Error> = write_atomically(&path, |w| {
            w.write_all(b"partial")?;
            Err(io::Error::other("boom"))
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        assert_eq!(entries(dir.path()), ["out.csv"]);
    }

    #[test]
    fn panicking_write_leaves_no_temp() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.csv");
        let r = std::panic::catch_unwind(|| {
            let _ = write_atomically(&path, |w| -> io::Result<()> {
                w.write_all(b"partial")?;
                w.flush()?;
                panic!("mid-write");
            });
        });
        assert!(r.is_err());
        assert!(entries(dir.path()).is_empty());
    }

    #[test]
    fn successful_write_replaces_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.csv");
        std::fs::write(&path, b"old").unwrap();
        write_bytes_atomically(&path, b"new").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        assert_eq!(entries(dir.path()), ["out.csv"]);
    }

    #[cfg(unix)]
    #[test]
    fn replacing_keeps_the_old_files_permissions() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.csv");
        std::fs::write(&path, b"old").unwrap();
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o640)).unwrap();
        write_bytes_atomically(&path, b"new").unwrap();
        let mode = std::fs::metadata(&path).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o640);
    }

    #[test]
    fn a_directory_is_refused_and_left_alone() {
        let dir = tempfile::tempdir().unwrap();
        let err = write_bytes_atomically(dir.path(), b"x").unwrap_err();
        assert!(err.to_string().contains("is a directory"), "{err}");
        assert!(dir.path().is_dir());
        assert!(entries(dir.path()).is_empty());
    }

    /// The refusal names the link and what to do, and nothing in `dir` changed.
    #[cfg(unix)]
    fn assert_link_refused(dir: &Path, link: &Path, before: &[String]) {
        let err = write_bytes_atomically(link, b"new").unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput, "{err}");
        let msg = err.to_string();
        assert!(
            msg.contains(&link.display().to_string())
                && msg.contains("is a symbolic link")
                && msg.contains("remove the link"),
            "{msg}"
        );
        assert_eq!(entries(dir), before, "no file was created or removed");
        assert!(std::fs::symlink_metadata(link)
            .unwrap()
            .file_type()
            .is_symlink());
    }

    #[cfg(unix)]
    #[test]
    fn a_symlink_is_refused_and_its_target_left_untouched() {
        let dir = tempfile::tempdir().unwrap();
        let real = dir.path().join("real.csv");
        let link = dir.path().join("link.csv");
        std::fs::write(&real, b"old").unwrap();
        std::os::unix::fs::symlink("real.csv", &link).unwrap();
        assert_link_refused(dir.path(), &link, &["link.csv".into(), "real.csv".into()]);
        assert_eq!(std::fs::read(&real).unwrap(), b"old");
        assert_eq!(std::fs::read_link(&link).unwrap(), Path::new("real.csv"));
    }

    #[cfg(unix)]
    #[test]
    fn a_dangling_symlink_is_refused_and_creates_nothing() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        let a = dir.path().join("a");
        std::os::unix::fs::symlink("b", &a).unwrap();
        std::os::unix::fs::symlink("sub/new.csv", dir.path().join("b")).unwrap();
        assert_link_refused(dir.path(), &a, &["a".into(), "b".into(), "sub".into()]);
        assert!(!dir.path().join("sub/new.csv").exists());
    }

    #[cfg(unix)]
    #[test]
    fn a_symlink_to_a_device_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let sink = dir.path().join("sink");
        std::os::unix::fs::symlink("/dev/null", &sink).unwrap();
        assert_link_refused(dir.path(), &sink, &["sink".into()]);
    }

    #[cfg(unix)]
    #[test]
    fn a_link_loop_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a");
        std::os::unix::fs::symlink("b", &a).unwrap();
        std::os::unix::fs::symlink("a", dir.path().join("b")).unwrap();
        assert_link_refused(dir.path(), &a, &["a".into(), "b".into()]);
    }

    #[cfg(unix)]
    #[test]
    fn a_link_swapped_in_for_a_fifo_is_not_followed() {
        // As if the FIFO `destination` saw was replaced by a link before the open.
        let dir = tempfile::tempdir().unwrap();
        let real = dir.path().join("real.csv");
        std::fs::write(&real, b"old").unwrap();
        let swapped = dir.path().join("pipe");
        std::os::unix::fs::symlink("real.csv", &swapped).unwrap();
        assert!(open_direct(&swapped).is_err(), "opened through the link");
        assert_eq!(std::fs::read(&real).unwrap(), b"old");
    }

    #[cfg(unix)]
    #[test]
    fn only_the_kernels_names_of_open_files_are_exempt() {
        for p in ["/dev/fd/3", "/proc/self/fd/10", "/proc/123/fd/0"] {
            assert!(open_file_name(Path::new(p)), "{p}");
        }
        for p in [
            "/dev/shm/x",
            "/dev/fd/../../tmp/x",
            "/dev/fd/3/x",
            "/proc/self/cwd/x",
            "dev/fd/3",
            "/dev/fd/",
        ] {
            assert!(!open_file_name(Path::new(p)), "{p}");
        }
    }

    #[test]
    fn standard_streams_and_devices_are_written_straight() {
        assert_eq!(destination(Path::new("-")).unwrap(), Destination::Stdout);
        assert_eq!(
            destination(Path::new("/dev/stdout")).unwrap(),
            Destination::Stdout
        );
        assert_eq!(
            destination(Path::new("/dev/stderr")).unwrap(),
            Destination::Stderr
        );
        #[cfg(unix)]
        assert_eq!(
            destination(Path::new("/dev/null")).unwrap(),
            Destination::Direct(PathBuf::from("/dev/null"))
        );
    }

    #[cfg(unix)]
    #[test]
    fn dev_null_stays_a_device() {
        use std::os::unix::fs::FileTypeExt;
        // Guarded: were /dev/null to be taken for a file, writing would replace it.
        assert!(matches!(
            destination(Path::new("/dev/null")).unwrap(),
            Destination::Direct(_)
        ));
        write_bytes_atomically(Path::new("/dev/null"), b"discarded").unwrap();
        let ft = std::fs::metadata("/dev/null").unwrap().file_type();
        assert!(ft.is_char_device());
    }

    #[test]
    fn an_output_that_is_an_input_is_refused_by_its_canonical_path() {
        let dir = tempfile::tempdir().unwrap();
        let log = dir.path().join("static.csv");
        std::fs::write(&log, b"raw").unwrap();
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        let other = dir.path().join("sub/../static.csv");
        let err = refuse_outputs_over_inputs(&[&other], &[Path::new("x.csv"), &log]).unwrap_err();
        assert_eq!(
            (err.output.as_path(), err.input.as_path()),
            (other.as_path(), log.as_path())
        );
        assert!(err.to_string().contains("is also an input"), "{err}");
        assert_eq!(std::fs::read(&log).unwrap(), b"raw");
        // A new file, another file, a device: no input replaced.
        let new = dir.path().join("model.json");
        refuse_outputs_over_inputs(&[&new], &[&log]).unwrap();
        std::fs::write(&new, b"{}").unwrap();
        refuse_outputs_over_inputs(&[&new], &[&log]).unwrap();
        #[cfg(unix)]
        refuse_outputs_over_inputs(&[Path::new("/dev/null")], &[Path::new("/dev/null")]).unwrap();
    }

    #[test]
    fn remove_temp_files_removes_a_write_in_progress() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.csv");
        std::fs::write(&path, b"old").unwrap();
        let r = write_atomically(&path, |w| -> io::Result<()> {
            w.write_all(b"partial")?;
            w.flush()?;
            assert_eq!(entries(dir.path()).len(), 2);
            // As the signal handler would, from another thread (limited to this test's
            // folder: other tests write files at the same time).
            let mine = |p: &Path| p.starts_with(dir.path());
            let removed =
                std::thread::scope(|s| s.spawn(|| remove_temp_files_where(mine)).join().unwrap());
            assert_eq!(removed, 1);
            Ok(())
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read(&path).unwrap(), b"old");
        assert_eq!(entries(dir.path()), ["out.csv"]);
    }
}
