//! Tests of the streaming reader.

use super::*;
use crate::csvlog::GyroUnit;
use proptest::prelude::*;

/// One sample as handed out: the bits of time, gyro, temperature, table rate; line;
/// whether filled; the raw record.
type Out = (u64, u64, u64, Option<u64>, u64, bool, Vec<Vec<u8>>);

/// The report at the end: rows, period bits, filled samples and gaps, jitter bits and
/// line.
type End = (u64, Option<u64>, usize, usize, u64, Option<u64>);

/// Everything a reader hands out, and how it ends.
#[derive(Debug, PartialEq)]
struct Run {
    samples: Vec<Out>,
    end: Result<End, String>,
}

fn run<R: Read>(input: R, opts: &ReadOptions, fast: bool) -> Run {
    let mut samples = Vec::new();
    let mut rdr = match LogReader::with_path(input, "<t>".into(), opts, fast) {
        Ok(r) => r,
        Err(e) => {
            return Run {
                samples,
                end: Err(e.to_string()),
            }
        }
    };
    let end = loop {
        match rdr.next_sample() {
            Ok(Some(s)) => samples.push((
                s.time_s.to_bits(),
                s.gyro_dps.to_bits(),
                s.temp_c.to_bits(),
                s.table_dps.map(f64::to_bits),
                rdr.line(),
                rdr.is_filled(),
                rdr.record()
                    .map(|r| r.iter().map(<[u8]>::to_vec).collect())
                    .unwrap_or_default(),
            )),
            Ok(None) => {
                let r = rdr.report();
                break Ok((
                    r.rows,
                    r.sample_period_s.map(f64::to_bits),
                    r.filled_samples,
                    r.filled_gaps,
                    r.max_step_jitter.to_bits(),
                    r.max_jitter_line,
                ));
            }
            Err(e) => break Err(e.to_string()),
        }
    };
    Run { samples, end }
}

/// A reader that hands out at most `step` bytes per call (block edges everywhere).
struct Dribble<'a> {
    data: &'a [u8],
    step: usize,
}

impl Read for Dribble<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.step.min(buf.len()).min(self.data.len());
        buf[..n].copy_from_slice(&self.data[..n]);
        self.data = &self.data[n..];
        Ok(n)
    }
}

/// Whether the last record of `text` runs inside an open quote to the end of the input
/// (csv-core's quoting: a quote opens only at a field's start, `""` inside is a quote,
/// `#` at a record's start is a comment line). There the CSV path's line number is
/// approximate (`record_line` cannot tell the file's last newline, inside the quote,
/// from a terminator); from a later starting point, as after the fast path hands over,
/// it comes out right. The comparisons close such a quote first.
fn ends_in_open_quote(text: &[u8], d: u8) -> bool {
    let (mut i, mut record_start, mut field_start, mut quoted) = (0, true, true, false);
    while i < text.len() {
        let b = text[i];
        i += 1;
        if quoted {
            if b == b'"' {
                if text.get(i) == Some(&b'"') {
                    i += 1;
                } else {
                    quoted = false;
                }
            }
        } else if record_start && b == b'#' {
            i = memchr::memchr(b'\n', &text[i..]).map_or(text.len(), |k| i + k + 1);
        } else if b == b'\n' || b == b'\r' {
            (record_start, field_start) = (true, true);
        } else {
            record_start = false;
            quoted = field_start && b == b'"';
            field_start = b == d;
        }
    }
    quoted
}

/// The fast path (whole input, and in small pieces) gives what the CSV path gives.
fn same_as_csv(text: &[u8], opts: &ReadOptions) {
    let want = run(text, opts, false);
    assert_eq!(
        run(text, opts, true),
        want,
        "fast path, {:?}",
        String::from_utf8_lossy(text)
    );
    for step in [1, 7] {
        let got = run(Dribble { data: text, step }, opts, true);
        assert_eq!(
            got,
            want,
            "fast path in {step}-byte reads, {:?}",
            String::from_utf8_lossy(text)
        );
    }
}

fn log(rows: usize, table: bool) -> String {
    let mut s = String::from("# bench\ntime_s,gyro_dps,temp_c");
    s += if table { ",table_dps,id\n" } else { ",id\n" };
    for i in 0..rows {
        let gyro = 0.0012 + 1e-7 * ((i * 7919) % 1000) as f64;
        s += &format!(
            "{:.3},{gyro:.13},{}",
            i as f64 * 0.01,
            20.0 + (i % 16) as f64 * 0.0625
        );
        if table {
            s += ",20";
        }
        s += &format!(",r{i}\n");
    }
    s
}

#[test]
fn fast_path_matches_csv_path_on_edge_cases() {
    let opts = ReadOptions::default();
    let gaps = ReadOptions {
        fill_gaps_max_s: Some(10.0),
        ..ReadOptions::default()
    };
    for text in [
        "time_s,gyro_dps,temp_c\n0,1,2\n1,1,2\n",
        "time_s,gyro_dps,temp_c\r\n0,1,2\r\n\r\n# c\r\n1,1,2\r\n2,1,2",
        "time_s,gyro_dps,temp_c\n0,1,2\n1,1\n",
        "time_s,gyro_dps,temp_c\n0,1,2\n1,1,2,3\n2,1,2\n",
        "time_s,gyro_dps,temp_c\n0,1,2\n\"1\",1,2\n2,\"1\n\",2\n3,x,2\n",
        "time_s,gyro_dps,temp_c\n0,1,2\n1\r,1,2\n",
        "time_s,gyro_dps,temp_c\n0,1,2\n0,1,2\n",
        "time_s,gyro_dps,temp_c\n0,1,2\n 1 , 1e0 ,2\n2,nan,2\n",
        "time_s,gyro_dps,temp_c\n0,1,2\n1,1,2\n5,1,2\n6,1,2\n",
        "\u{feff}time_s,gyro_dps,temp_c\n0,1,2\n",
        "\u{feff}# c\ntime_s,gyro_dps,temp_c\n0,1,2\n1,1,2\n",
        "\u{feff}\r\n\r\ntime_s,gyro_dps,temp_c\r\n0,1,2\r\n",
        "time_s,gyro_dps,temp_c\n0,1.5,2\n1,-.5,2.\n2,+1.25,2\n3,1.2.3,2\n",
        "time_s,gyro_dps,temp_c\n0,1,2\n1.25,1,2\n2,1,2\n3,1,2\n3.5,1,2\n",
        "# only\n",
        "time_s,gyro_dps,temp_c\n",
        "time_s,gyro_dps,temp_c\n#0,1,2\n 1,1,2\n",
    ] {
        same_as_csv(text.as_bytes(), &opts);
        same_as_csv(text.as_bytes(), &gaps);
        same_in_every_layout(text);
    }
}

/// `text` (written with commas and decimal points) read with `;` and tab separators,
/// with decimal points and with decimal commas, and with a given sample period: the
/// fast path gives what the CSV path gives; and with the gyro in °/h.
fn same_in_every_layout(text: &str) {
    let semicolon = ReadOptions {
        delimiter: b';',
        ..ReadOptions::default()
    };
    let tab = ReadOptions {
        delimiter: b'\t',
        ..ReadOptions::default()
    };
    let given = ReadOptions {
        sample_period_s: Some(1.0),
        fill_gaps_max_s: Some(10.0),
        ..ReadOptions::default()
    };
    same_as_csv(text.replace(',', ";").as_bytes(), &semicolon);
    same_as_csv(
        text.replace(',', ";").replace('.', ",").as_bytes(),
        &semicolon,
    );
    same_as_csv(text.replace(',', "\t").replace('.', ",").as_bytes(), &tab);
    same_as_csv(text.as_bytes(), &given);
    let dph = ReadOptions {
        gyro_unit: GyroUnit::Dph,
        ..ReadOptions::default()
    };
    same_as_csv(text.as_bytes(), &dph);
}

#[test]
fn fast_path_matches_csv_path_across_the_parallel_split() {
    let opts = ReadOptions::default();
    let text = log(20_000, true);
    assert!(text.len() > PARALLEL_MIN_BYTES, "the log must be split");
    let want = run(text.as_bytes(), &opts, false);
    assert_eq!(want.samples.len(), 20_000);
    assert_eq!(run(text.as_bytes(), &opts, true), want);
    // An error in each half, near the split, and an order break across it.
    let lines: Vec<&str> = text.lines().collect();
    for (at, bad) in [
        (3_000, "x"),
        (10_000, "1,2"),
        (10_003, "\"5\",1,2,3,4"),
        (15_000, "1e9,1,2,3,4"),
        (19_999, "1,1,1,1,1"),
    ] {
        let mut l = lines.clone();
        l[at] = bad;
        let t = l.join("\n") + "\n";
        let want = run(t.as_bytes(), &opts, false);
        assert_eq!(run(t.as_bytes(), &opts, true), want, "bad line {at}");
    }
    for k in 9_990..10_010 {
        let mut l = lines.clone();
        l.swap(k, k + 1);
        let t = l.join("\n") + "\n";
        assert_eq!(
            run(t.as_bytes(), &opts, true),
            run(t.as_bytes(), &opts, false)
        );
    }
}

proptest! {
    // No lone CR here: the CSV path's line numbers are approximate in a file that mixes
    // line endings (see `Tail`), the fast path's count newlines.
    #[test]
    fn fast_path_matches_csv_path_on_any_input(
        body in prop::collection::vec(
            prop::sample::select(b"0123456789.,-e#\n\" ".to_vec()), 0..200),
    ) {
        let mut text = b"time_s,gyro_dps,temp_c\n".to_vec();
        text.extend(body);
        if ends_in_open_quote(&text, b',') {
            text.push(b'"');
        }
        same_as_csv(&text, &ReadOptions::default());
    }

    #[test]
    fn fast_path_matches_csv_path_on_any_input_with_decimal_commas(
        body in prop::collection::vec(
            prop::sample::select(b"0123456789.,;-+e#\n\" ".to_vec()), 0..200),
    ) {
        let mut text = b"time_s;gyro_dps;temp_c\n".to_vec();
        text.extend(body);
        if ends_in_open_quote(&text, b';') {
            text.push(b'"');
        }
        let opts = ReadOptions { delimiter: b';', ..ReadOptions::default() };
        same_as_csv(&text, &opts);
    }

    #[test]
    fn fast_path_matches_csv_path_on_logs_with_a_fault(
        at in 0usize..60,
        fault in prop::sample::select(vec!["", "x", ",", "\r", "\"", "#", "\n", "1e999", "-"]),
    ) {
        let mut text = log(60, false).into_bytes();
        let pos = (at * text.len() / 60).min(text.len());
        text.splice(pos..pos, fault.bytes());
        same_as_csv(&text, &ReadOptions::default());
    }
}
