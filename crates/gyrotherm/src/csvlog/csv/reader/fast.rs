//! The fast path: plain rows in newline-aligned blocks, parsed on two threads.

use super::*;

/// The fast path's block and the rows parsed from it.
pub(super) struct Fast<R> {
    pub(super) inner: R,
    /// The block (its length is its capacity; `len` bytes are valid).
    pub(super) buf: Vec<u8>,
    pub(super) len: usize,
    /// Offset after the last complete line parsed, and its line number.
    pub(super) parsed_end: usize,
    pub(super) line: u64,
    pub(super) eof: bool,
    /// Rows of the two halves of the block, and the next one to hand out.
    pub(super) parts: [Vec<Row>; 2],
    pub(super) part: usize,
    pub(super) next: usize,
    /// Where the CSV path takes over once the parsed rows are out (offset, line).
    pub(super) switch_at: Option<(usize, u64)>,
    /// The current row's record, built on demand.
    pub(super) record: OnceCell<ByteRecord>,
    pub(super) threads: bool,
}

/// Block size of the fast path.
pub(super) const BLOCK_BYTES: usize = 2 << 20;

impl<R: Read> Fast<R> {
    /// Parse the complete lines `buf[..end]` (`end` just after a newline), in two parts
    /// on two threads when the block is long; `prev_time` is the time of the row before.
    pub(super) fn parse(&mut self, end: usize, prev_time: Option<f64>, lay: &Layout) {
        let buf = &self.buf[..end];
        let split = if self.threads && end >= PARALLEL_MIN_BYTES {
            // Halves: the other thread runs only while this one parses its half (reading
            // and handing rows out happen between blocks, on this thread alone), so equal
            // halves finish together. (Shifting work to the other thread to cover this
            // thread's reading measured slower: that work does not overlap.)
            let mid = end / 2;
            memchr::memchr(b'\n', &buf[mid..end]).map_or(end, |k| mid + k + 1)
        } else {
            end
        };
        let [rows_a, rows_b] = &mut self.parts;
        let (a, b) = if split < end {
            let (a, b) = std::thread::scope(|s| {
                let hb = s.spawn(|| parse_lines(buf, split, end, 0, None, lay, rows_b));
                let a = parse_lines(buf, 0, split, self.line, prev_time, lay, rows_a);
                (
                    a,
                    hb.join().unwrap_or_else(|p| std::panic::resume_unwind(p)),
                )
            });
            (a, Some(b))
        } else {
            (
                parse_lines(buf, 0, end, self.line, prev_time, lay, rows_a),
                None,
            )
        };
        if a.stopped {
            rows_b.clear();
            self.switch_at = Some((a.stop, a.stop_line));
            self.parsed_end = a.stop;
            return;
        }
        let Some(b) = b else {
            self.parsed_end = end;
            self.line = a.stop_line;
            return;
        };
        // The second half counted lines from 0: shift them, and check the order across
        // the split (the first half's last row, or the row before the block).
        let base = a.stop_line;
        for r in rows_b.iter_mut() {
            r.line += base;
        }
        let before = rows_a.last().map(Row::time_s).or(prev_time);
        if let (Some(t0), Some(first)) = (before, rows_b.first()) {
            if first.time_s() <= t0 {
                self.switch_at = Some((first.start as usize, first.line));
                self.parsed_end = first.start as usize;
                rows_b.clear();
                return;
            }
        }
        if b.stopped {
            self.switch_at = Some((b.stop, b.stop_line + base));
            self.parsed_end = b.stop;
            return;
        }
        self.parsed_end = end;
        self.line = b.stop_line + base;
    }

    /// Text of the current row (the last one handed out).
    pub(super) fn current_text(&self) -> &[u8] {
        match self.next.checked_sub(1) {
            Some(k) => {
                let r = &self.parts[self.part][k];
                &self.buf[r.start as usize..r.end as usize]
            }
            // Before the first row.
            None => b"",
        }
    }
}
