//! The two row sources of the reader: the CSV path (the csv crate) and the switch from the
//! fast path to it, with the helpers both use (header scan, CSV set-up, errors).

use super::*;

/// Where rows come from: the fast path (plain rows in newline-aligned blocks, parsed on two
/// threads, see [`super::chunk`]) until it meets a line it cannot judge, then the CSV path
/// from that line on. Both check numbers, field count and time order.
pub(super) struct Source<R> {
    pub(super) path: PathBuf,
    pub(super) headers: Vec<String>,
    pub(super) header_line: u64,
    pub(super) cols: Columns,
    pub(super) lay: Layout,
    /// Numbers may use a decimal comma (the separator is not a comma).
    pub(super) decimal_comma: bool,
    /// Time and line of the last row read, for the order checks.
    pub(super) last: Option<(f64, u64)>,
    pub(super) rows: u64,
    /// Whether lines end in CRLF (judged by the first line; None: not known yet).
    pub(super) crlf: Option<bool>,
    pub(super) mode: Mode<R>,
    /// Bytes of the log consumed by the fast path, and where the CSV path's byte count
    /// starts (for [`LogReader::bytes_per_row`]).
    pub(super) fast_bytes: u64,
    pub(super) csv_skip: u64,
    /// Scratch record for looking one row ahead after a short row.
    pub(super) peek: ByteRecord,
}

/// The input with the bytes already read in front of it.
pub(super) type Resume<R> = std::io::Chain<std::io::Cursor<Vec<u8>>, R>;

pub(super) enum Mode<R> {
    Fast(Box<Fast<R>>),
    Csv(Box<CsvPart<R>>),
    /// Only while switching.
    Gone,
}

/// The CSV path: the csv crate over the rest of the input; its line numbers are offset by
/// the lines before the point where it took over.
pub(super) struct CsvPart<R> {
    pub(super) csv: csv::Reader<Tail<Resume<R>>>,
    pub(super) line_offset: u64,
    /// The current record.
    pub(super) rec: ByteRecord,
}

impl<R: Read> Source<R> {
    /// Read and check one data row; it becomes the current record.
    #[inline]
    pub(super) fn read(&mut self) -> Result<Option<(Sample, u64)>, Box<LogError>> {
        if let Some(row) = self.fast_row() {
            return Ok(Some((row.sample(self.lay.has_table), row.line)));
        }
        if let Mode::Fast(_) = self.mode {
            return self.refill();
        }
        self.read_csv()
    }

    /// The next row already parsed by the fast path, if there is one; it becomes the
    /// current record.
    #[inline(always)]
    pub(super) fn fast_row(&mut self) -> Option<Row> {
        let Mode::Fast(f) = &mut self.mode else {
            return None;
        };
        let row = *f.parts[f.part].get(f.next)?;
        f.next += 1;
        f.record = OnceCell::new();
        self.last = Some((row.time_s(), row.line));
        self.rows += 1;
        Some(row)
    }

    /// The fast path's rows are all out: go to the second half of the block, parse the
    /// next block, or hand over to the CSV path.
    #[cold]
    pub(super) fn refill(&mut self) -> Result<Option<(Sample, u64)>, Box<LogError>> {
        loop {
            let Mode::Fast(f) = &mut self.mode else {
                return self.read_csv();
            };
            if f.next < f.parts[f.part].len() {
                return self.read();
            }
            if f.part == 0 && !f.parts[1].is_empty() {
                f.part = 1;
                f.next = 0;
                continue;
            }
            if let Some((at, line)) = f.switch_at {
                self.switch_to_csv(at, line);
                continue;
            }
            // Keep the unparsed tail (a partial line), read more behind it.
            f.buf.copy_within(f.parsed_end..f.len, 0);
            f.len -= f.parsed_end;
            self.fast_bytes += f.parsed_end as u64;
            f.parsed_end = 0;
            f.parts[0].clear();
            f.parts[1].clear();
            f.part = 0;
            f.next = 0;
            let end = memchr::memrchr(b'\n', &f.buf[..f.len]).map_or(0, |k| k + 1);
            if end > 0 {
                f.parse(end, self.last.map(|l| l.0), &self.lay);
                continue;
            }
            if f.eof {
                // An unterminated last line (or nothing): the CSV path judges it.
                let line = f.line;
                self.switch_to_csv(0, line);
                continue;
            }
            if f.len == f.buf.len() {
                let n = f.buf.len();
                if 2 * n > MAX_BLOCK_BYTES {
                    // A line of gigabytes: the CSV path judges it.
                    let line = f.line;
                    self.switch_to_csv(0, line);
                    continue;
                }
                f.buf.resize(2 * n, 0);
            }
            let n = read_retry(&mut f.inner, &mut f.buf[f.len..])
                .map_err(|e| Box::new(io_error(&self.path, e)))?;
            f.eof = n == 0;
            f.len += n;
        }
    }

    /// Hand the input from `at` in the block (line `line`) on to the CSV path.
    #[cold]
    pub(super) fn switch_to_csv(&mut self, at: usize, line: u64) {
        let Mode::Fast(f) = std::mem::replace(&mut self.mode, Mode::Gone) else {
            unreachable!("switch_to_csv is only called in fast mode")
        };
        let Fast {
            inner,
            mut buf,
            len,
            ..
        } = *f;
        self.fast_bytes += at as u64;
        buf.truncate(len);
        buf.drain(..at);
        let csv = csv_reader(
            std::io::Cursor::new(buf).chain(inner),
            self.crlf,
            self.lay.delimiter,
        );
        self.csv_skip = 0;
        self.mode = Mode::Csv(Box::new(CsvPart {
            csv,
            line_offset: line - 1,
            rec: ByteRecord::with_capacity(64, self.headers.len()),
        }));
    }

    /// Bytes of data rows consumed so far (after the header).
    pub(super) fn bytes_consumed(&self) -> u64 {
        match &self.mode {
            Mode::Fast(f) => {
                let at = f.parts[f.part]
                    .get(f.next)
                    .map_or(f.parsed_end, |r| r.start as usize);
                self.fast_bytes + at as u64
            }
            Mode::Csv(c) => self.fast_bytes + c.csv.position().byte() - self.csv_skip,
            Mode::Gone => self.fast_bytes,
        }
    }

    /// The current record.
    pub(super) fn record(&self) -> &ByteRecord {
        match &self.mode {
            Mode::Fast(f) => f.record.get_or_init(|| {
                let text = f.current_text();
                let mut rec = ByteRecord::with_capacity(text.len(), self.lay.ncols);
                for field in text.split(|&b| b == self.lay.delimiter) {
                    rec.push_field(field);
                }
                rec
            }),
            Mode::Csv(c) => &c.rec,
            Mode::Gone => unreachable!("no record while switching"),
        }
    }

    /// Field `i` of the current record.
    pub(super) fn field(&self, i: usize) -> &[u8] {
        match &self.mode {
            Mode::Fast(f) => chunk::field(f.current_text(), self.lay.delimiter, i),
            Mode::Csv(c) => &c.rec[i],
            Mode::Gone => unreachable!("no record while switching"),
        }
    }

    /// The CSV path: read and check one row into the current record.
    pub(super) fn read_csv(&mut self) -> Result<Option<(Sample, u64)>, Box<LogError>> {
        let Mode::Csv(c) = &mut self.mode else {
            unreachable!("read_csv is only called in CSV mode")
        };
        let more = c
            .csv
            .read_byte_record(&mut c.rec)
            .map_err(|e| Box::new(csv_error(&self.path, e, c.line_offset)))?;
        if !more {
            return Ok(None);
        }
        let line = record_line(&c.csv, &c.rec) + c.line_offset;
        // Taken out while the checks borrow `self`; put back below (after an error the
        // reader's state does not matter).
        let taken = std::mem::take(&mut c.rec);
        let rec = &taken;
        if rec.len() != self.headers.len() {
            let found = rec.len();
            return Err(Box::new(self.field_count_error(found, line)));
        }
        let time_s = self.number(rec, self.cols.time, line)?;
        let gyro_dps = self.number(rec, self.cols.gyro, line)? * self.lay.gyro_scale;
        if !gyro_dps.is_finite() {
            return Err(Box::new(self.overflow_error(&rec[self.cols.gyro], line)));
        }
        let temp_c = self.number(rec, self.cols.temp, line)?;
        let table_dps = match self.cols.table {
            Some(i) => Some(self.number(rec, i, line)?),
            None => None,
        };
        if let Some((t0, line0)) = self.last {
            // Written so that it holds for the common case; NaN cannot occur (checked above).
            if time_s <= t0 {
                return Err(Box::new(self.order_error(time_s, t0, line, line0)));
            }
        }
        self.last = Some((time_s, line));
        self.rows += 1;
        if let Mode::Csv(c) = &mut self.mode {
            c.rec = taken;
        }
        Ok(Some((
            Sample {
                time_s,
                gyro_dps,
                temp_c,
                table_dps,
            },
            line,
        )))
    }

    #[inline(always)]
    pub(super) fn number(
        &self,
        rec: &ByteRecord,
        i: usize,
        line: u64,
    ) -> Result<f64, Box<LogError>> {
        match parse_number(&rec[i], self.decimal_comma) {
            Some(v) if v.is_finite() => Ok(v),
            _ => Err(Box::new(self.number_error(&rec[i], i, line))),
        }
    }

    /// A gyro field, finite in its unit, beyond f64 once converted to °/s.
    #[cold]
    fn overflow_error(&self, raw: &[u8], line: u64) -> LogError {
        LogError::new(
            Kind::NonFinite,
            &self.path,
            Some(line),
            Some(&self.headers[self.cols.gyro]),
            format!(
                "{} is beyond any number once converted to °/s; check the value and \
                 --gyro-unit, or comment the line out with '#'",
                quoted_field(raw)
            ),
        )
    }

    #[cold]
    pub(super) fn number_error(&self, raw: &[u8], i: usize, line: u64) -> LogError {
        let text = String::from_utf8_lossy(raw);
        let quoted = quoted_field(raw);
        let parses = parse_number(raw, self.decimal_comma).is_some();
        let (kind, message) = if parses {
            (
                Kind::NonFinite,
                format!(
                    "{quoted} is not a finite number (NaN, infinite or out of range); \
                     fix the value or comment the line out with '#'"
                ),
            )
        } else if text.trim().is_empty() {
            (
                Kind::NotANumber,
                "empty field where a number is required; fill in the value or comment the \
                 line out with '#'"
                    .to_owned(),
            )
        } else {
            let hint = if text.contains(',') && !self.decimal_comma {
                " (use '.' as the decimal point)"
            } else {
                ""
            };
            (
                Kind::NotANumber,
                format!(
                    "{quoted} is not a number; fix the value{hint} or comment the line out \
                     with '#'"
                ),
            )
        };
        LogError::new(
            kind,
            &self.path,
            Some(line),
            Some(&self.headers[i]),
            message,
        )
    }

    #[cold]
    pub(super) fn field_count_error(&mut self, found: usize, line: u64) -> LogError {
        let want = self.headers.len();
        // A short row followed by nothing is a file cut mid-write.
        let is_last = found < want
            && match &mut self.mode {
                Mode::Csv(c) => matches!(c.csv.read_byte_record(&mut self.peek), Ok(false)),
                _ => false,
            };
        if is_last {
            LogError::new(
                Kind::TruncatedLine,
                &self.path,
                Some(line),
                Some(&self.headers[found]),
                format!(
                    "truncated last line: {found} of {want} fields (was the file cut while \
                     being written?); delete the incomplete last line or copy the log again"
                ),
            )
        } else {
            LogError::new(
                Kind::FieldCount,
                &self.path,
                Some(line),
                None,
                format!(
                    "{found} fields, but the header (line {}) has {want}; fix the line (a \
                     missing or extra ',') or comment it out with '#'",
                    self.header_line
                ),
            )
        }
    }

    #[cold]
    pub(super) fn order_error(&self, t: f64, t0: f64, line: u64, line0: u64) -> LogError {
        let col = Some(self.headers[self.cols.time].as_str());
        if t == t0 {
            LogError::new(
                Kind::DuplicateTime,
                &self.path,
                Some(line),
                col,
                format!(
                    "duplicate timestamp {t} s (also on line {line0}); remove one of the two \
                     rows"
                ),
            )
        } else {
            LogError::new(
                Kind::TimeNotIncreasing,
                &self.path,
                Some(line),
                col,
                format!(
                    "time is not strictly increasing: {t} s comes after {t0} s (line {line0}); \
                     sort the log by time or remove the out-of-order row"
                ),
            )
        }
    }
}

/// 1-based physical line where `rec`, just read, starts.
///
/// The csv crate stamps a record with the position where reading began, which is before
/// any comment or blank lines it skipped (and, in a CRLF file, before the previous line's
/// LF). So count back from the line after the record: less the newlines inside quoted
/// fields, less one for the record's own LF terminator (a CRLF record ends at its CR, and
/// the last record of a file may have no terminator).
#[inline]
pub(super) fn record_line<R: Read>(csv: &csv::Reader<Tail<R>>, rec: &ByteRecord) -> u64 {
    let start = rec.position().map_or(1, |p| p.line());
    let pos = csv.position();
    let end = pos.line();
    let tail = csv.get_ref();
    let unterminated = pos.byte() == tail.total && tail.last != b'\n';
    let terminator = u64::from(!unterminated && !tail.crlf);
    if end <= start + terminator {
        return start;
    }
    let inside = rec.as_slice().iter().filter(|&&b| b == b'\n').count() as u64;
    end.saturating_sub(inside + terminator).max(start)
}

/// The input, remembering how many bytes were read, the last one (to tell whether the
/// last record ended with a newline) and whether lines end in CRLF (judged by the first
/// line; a file mixing LF and CRLF lines may get line numbers off by one in errors).
pub(super) struct Tail<R> {
    pub(super) inner: R,
    pub(super) total: u64,
    pub(super) last: u8,
    pub(super) crlf: bool,
    pub(super) crlf_known: bool,
}

impl<R: Read> Read for Tail<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        if n > 0 {
            if !self.crlf_known {
                if let Some(k) = buf[..n].iter().position(|&b| b == b'\n') {
                    let before = if k > 0 { buf[k - 1] } else { self.last };
                    self.crlf = before == b'\r';
                    self.crlf_known = true;
                }
            }
            self.total += n as u64;
            self.last = buf[n - 1];
        }
        Ok(n)
    }
}

pub(super) fn csv_error(path: &Path, e: csv::Error, line_offset: u64) -> LogError {
    let line = e.position().map(|p| p.line() + line_offset);
    if let csv::ErrorKind::Io(io) = e.kind() {
        if let Some(long) = LineTooLong::of(io) {
            return LogError::line_too_long(path, long.line);
        }
        LogError::new(Kind::Io, path, line, None, format!("cannot read: {io}"))
    } else {
        LogError::new(Kind::Csv, path, line, None, format!("malformed CSV: {e}"))
    }
}

/// What the start of the input says about the header line.
pub(super) enum HeaderScan {
    /// The header line ends just before this offset (after its newline).
    Found(usize),
    /// Not all of it read yet.
    NeedMore,
    /// Something only the CSV path judges (quote, lone CR).
    Hard,
}

/// Skip comment and blank lines to the header line, as the CSV path does.
pub(super) fn find_header(bytes: &[u8]) -> HeaderScan {
    // A byte-order mark is skipped, as the csv crate does when it reads the header from the
    // block (which holds the mark and at least the newline after it).
    let mut pos = if bytes.starts_with(b"\xEF\xBB\xBF") {
        3
    } else {
        0
    };
    while let Some(k) = memchr::memchr(b'\n', &bytes[pos..]) {
        let nl = pos + k;
        let mut text = &bytes[pos..nl];
        if let [rest @ .., b'\r'] = text {
            text = rest;
        }
        match text.first() {
            None | Some(b'#') => {}
            Some(_) => {
                return if text.iter().any(|&b| b == b'"' || b == b'\r') {
                    HeaderScan::Hard
                } else {
                    HeaderScan::Found(nl + 1)
                };
            }
        }
        pos = nl + 1;
    }
    HeaderScan::NeedMore
}

/// `read`, retried on `Interrupted`.
pub(super) fn read_retry<R: Read>(r: &mut R, buf: &mut [u8]) -> std::io::Result<usize> {
    loop {
        match r.read(buf) {
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            other => return other,
        }
    }
}

pub(super) fn io_error(path: &Path, e: std::io::Error) -> LogError {
    if let Some(long) = LineTooLong::of(&e) {
        return LogError::line_too_long(path, long.line);
    }
    LogError::new(Kind::Io, path, None, None, format!("cannot read: {e}"))
}

/// The csv crate set up as the CSV path reads: no header handling, any field count, `#`
/// comments.
pub(super) fn csv_reader<S: Read>(
    input: S,
    crlf: Option<bool>,
    delimiter: u8,
) -> csv::Reader<Tail<S>> {
    csv::ReaderBuilder::new()
        .delimiter(delimiter)
        .has_headers(false)
        .flexible(true)
        .comment(Some(b'#'))
        .buffer_capacity(64 * 1024)
        .from_reader(Tail {
            inner: input,
            total: 0,
            last: b'\n',
            crlf: crlf.unwrap_or(false),
            crlf_known: crlf.is_some(),
        })
}

/// Read the header record and its line.
pub(super) fn read_header<S: Read>(
    csv: &mut csv::Reader<Tail<S>>,
    path: &Path,
) -> Result<(ByteRecord, u64), LogError> {
    let mut header = ByteRecord::new();
    let got = csv
        .read_byte_record(&mut header)
        .map_err(|e| csv_error(path, e, 0))?;
    if !got {
        return Err(LogError::new(
            Kind::NoHeader,
            path,
            None,
            None,
            "empty file: no header row; the first line that is not a '#' comment must name \
             the columns, e.g. time_s,gyro_dps,temp_c",
        ));
    }
    let line = record_line(csv, &header);
    Ok((header, line))
}

/// The input with its lines capped at [`MAX_LINE_BYTES`]: every line before a longer one is
/// handed on whole, then reading fails with [`LineTooLong`]. So neither path behind it (the
/// fast path's block, the csv crate's record) ever holds more than one capped line: a file
/// without line breaks (`/dev/zero`) is an error after 64 KiB instead of growing memory
/// until the process is killed.
pub(super) struct LineCap<R> {
    inner: R,
    /// Bytes of the current line read so far (since the last line break).
    run: usize,
    /// 1-based physical line now being read.
    line: u64,
    /// A line over the cap was met: every further read fails.
    over: bool,
}

impl<R> LineCap<R> {
    pub(super) fn new(inner: R) -> Self {
        LineCap {
            inner,
            run: 0,
            line: 1,
            over: false,
        }
    }

    fn too_long(&self) -> std::io::Error {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            LineTooLong { line: self.line },
        )
    }
}

impl<R: Read> Read for LineCap<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if self.over {
            return Err(self.too_long());
        }
        let n = self.inner.read(buf)?;
        let mut start = 0;
        // A line with its break may hold MAX_LINE_BYTES bytes: its text at most one less.
        for k in memchr::memchr_iter(b'\n', &buf[..n]) {
            if self.run + (k - start) >= MAX_LINE_BYTES {
                return self.stop(start);
            }
            self.run = 0;
            self.line += 1;
            start = k + 1;
        }
        if self.run + (n - start) >= MAX_LINE_BYTES {
            return self.stop(start);
        }
        self.run += n - start;
        Ok(n)
    }
}

impl<R> LineCap<R> {
    /// The line from `start` in the last read is over the cap: hand on the lines before it
    /// (if any: 0 bytes would read as the end of the input), and fail from then on.
    fn stop(&mut self, start: usize) -> std::io::Result<usize> {
        self.over = true;
        if start == 0 {
            Err(self.too_long())
        } else {
            Ok(start)
        }
    }
}

/// The error [`LineCap`] reads fail with: line `line` is longer than [`MAX_LINE_BYTES`].
#[derive(Debug)]
pub(super) struct LineTooLong {
    pub(super) line: u64,
}

impl LineTooLong {
    /// The over-long line an I/O error stands for, if it is one.
    pub(super) fn of(e: &std::io::Error) -> Option<&LineTooLong> {
        e.get_ref()?.downcast_ref::<LineTooLong>()
    }
}

impl std::fmt::Display for LineTooLong {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "line {} is longer than {MAX_LINE_BYTES} bytes",
            self.line
        )
    }
}

impl std::error::Error for LineTooLong {}
