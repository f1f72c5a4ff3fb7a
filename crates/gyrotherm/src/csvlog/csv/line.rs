//! Reading a CSV log one line at a time in bounded memory: what the line-by-line compensation
//! (`compensate`, `compensate --stream`) reads its data lines with. The header is the log
//! reader's ([`crate::csvlog::LogReader`]); each data line is read up to a cap on its length,
//! split at the separator (quotes as the log reader reads them), and its numbers parsed as the
//! log reader parses them.

use std::io::BufRead;

/// The fields of one CSV line, as byte ranges: into the line itself when it holds no quote
/// (the usual log line: no copy), else into `buf`, which holds the unquoted fields. Reused
/// from line to line, so a steady stream allocates nothing.
#[derive(Default)]
pub(crate) struct Fields {
    ranges: Vec<std::ops::Range<usize>>,
    buf: Vec<u8>,
    quoted: bool,
}

impl Fields {
    /// Split `line` at `delimiter`; false on a broken quote.
    pub(crate) fn split(&mut self, line: &[u8], delimiter: u8) -> bool {
        self.ranges.clear();
        self.quoted = line.contains(&b'"');
        if !self.quoted {
            let mut start = 0;
            for (i, &b) in line.iter().enumerate() {
                if b == delimiter {
                    self.ranges.push(start..i);
                    start = i + 1;
                }
            }
            self.ranges.push(start..line.len());
            return true;
        }
        self.buf.clear();
        let mut start = 0;
        let mut quoted = false;
        let mut at_start = true;
        let mut i = 0;
        while i < line.len() {
            let b = line[i];
            if quoted {
                if b == b'"' {
                    if line.get(i + 1) == Some(&b'"') {
                        self.buf.push(b'"');
                        i += 1;
                    } else {
                        quoted = false;
                    }
                } else {
                    self.buf.push(b);
                }
            } else if b == delimiter {
                self.ranges.push(start..self.buf.len());
                start = self.buf.len();
                at_start = true;
                i += 1;
                continue;
            } else if b == b'"' && at_start {
                quoted = true;
            } else {
                self.buf.push(b);
            }
            at_start = false;
            i += 1;
        }
        self.ranges.push(start..self.buf.len());
        !quoted
    }

    pub(crate) fn len(&self) -> usize {
        self.ranges.len()
    }

    /// Field `k` of `line` (the line last split), empty past the end.
    pub(crate) fn get<'a>(&'a self, line: &'a [u8], k: usize) -> &'a [u8] {
        let src = if self.quoted { &self.buf[..] } else { line };
        self.ranges
            .get(k)
            .and_then(|r| src.get(r.clone()))
            .unwrap_or(&[])
    }
}

/// What [`read_line_capped`] found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum LineRead {
    /// End of input, nothing read.
    Eof,
    /// A line (in the buffer, its line break included when there was one).
    Line,
    /// A line longer than the cap: its first `cap` bytes are in the buffer, the rest was
    /// read and dropped, up to and including its line break.
    TooLong,
}

/// `read_until(b'\n')` that keeps at most `cap` bytes of a line, so memory stays bounded
/// whatever the input.
pub(crate) fn read_line_capped<R: BufRead>(
    input: &mut R,
    buf: &mut Vec<u8>,
    cap: usize,
) -> std::io::Result<LineRead> {
    buf.clear();
    let mut too_long = false;
    let mut any = false;
    loop {
        let (done, used) = {
            let avail = match input.fill_buf() {
                Ok(a) => a,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(e),
            };
            if avail.is_empty() {
                break;
            }
            any = true;
            let (done, used) = match avail.iter().position(|&b| b == b'\n') {
                Some(i) => (true, i + 1),
                None => (false, avail.len()),
            };
            if !too_long {
                let room = cap - buf.len();
                if used > room {
                    buf.extend_from_slice(&avail[..room]);
                    too_long = true;
                } else {
                    buf.extend_from_slice(&avail[..used]);
                }
            }
            (done, used)
        };
        input.consume(used);
        if done {
            break;
        }
    }
    Ok(if too_long {
        LineRead::TooLong
    } else if any {
        LineRead::Line
    } else {
        LineRead::Eof
    })
}

/// The record a line read into `buf` holds: without its line ending; None for a blank line
/// or a comment (`#` first), which every stream skips.
pub(crate) fn record(buf: &[u8]) -> Option<&[u8]> {
    let line = buf.strip_suffix(b"\n").unwrap_or(buf);
    let line = line.strip_suffix(b"\r").unwrap_or(line);
    let trimmed = line.trim_ascii();
    (!trimmed.is_empty() && !trimmed.starts_with(b"#")).then_some(line)
}

#[cfg(test)]
mod tests {
    use super::Fields;

    #[test]
    fn splits_plain_and_quoted_fields() {
        let mut f = Fields::default();
        let line = br#"1,"a,""b""",,x"#;
        assert!(f.split(line, b','));
        let got: Vec<&[u8]> = (0..f.len()).map(|k| f.get(line, k)).collect();
        assert_eq!(got, [&b"1"[..], b"a,\"b\"", b"", b"x"]);
        let line = b"0.5,1e-3,,NaN";
        assert!(f.split(line, b','));
        let got: Vec<&[u8]> = (0..f.len()).map(|k| f.get(line, k)).collect();
        assert_eq!(got, [&b"0.5"[..], b"1e-3", b"", b"NaN"]);
        assert!(!f.split(br#"1,"open"#, b','));
    }
}
