//! PX4 ULog logs (`.ulg`): topic `sensor_gyro` as a three-axis unit.
//!
//! Of each `sensor_gyro` message of the chosen multi-instance the reader takes `timestamp`
//! (µs), `x`, `y`, `z` (rad/s) and `temperature` (°C), reduced to model steps
//! ([`super::step_means`]). The messages are decoded by the `yule_log` crate (streaming;
//! only `sensor_gyro` is decoded, every other topic is skipped). The bytes it takes are
//! counted on their way in, so that a fault names the offset of the message it is in, and a
//! log cut off mid-message is read to its last whole message
//! ([`ReadReport::truncated_at_byte`]).

use std::cell::Cell;
use std::io::{BufReader, Read};
use std::path::Path;
use std::rc::Rc;

use yule_log::builder::ULogParserBuilder;
use yule_log::model::inst::FieldValue;
use yule_log::model::msg::UlogMessage;

use super::error::{LogError, LogErrorKind as Kind};
use super::step_means::{Refused, StepMeans};
use super::{ImuLog, ReadOptions, ReadReport};

/// The topic of a PX4 gyro's samples.
const TOPIC: &str = "sensor_gyro";

/// A byte source that counts what it hands out and notes when it ran dry mid-read.
struct Counted<R> {
    inner: R,
    taken: Rc<Cell<u64>>,
    ran_dry: Rc<Cell<bool>>,
}

impl<R: Read> Read for Counted<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        if n == 0 && !buf.is_empty() {
            self.ran_dry.set(true);
        }
        self.taken.set(self.taken.get() + n as u64);
        Ok(n)
    }
}

/// Largest number a format definition can hold: an array's length, which a message of at
/// most 65535 bytes bounds.
const MAX_FORMAT_NUMBER: u64 = u16::MAX as u64;

/// Where a byte stands in the ULog framing: the file header, a message's 3-byte header
/// (size, type), or its payload.
#[derive(Debug, Clone, Copy)]
enum Frame {
    FileHeader { left: usize },
    MessageHeader { got: usize, size: [u8; 2] },
    Payload { left: usize, format: bool },
}

impl Frame {
    /// The start of the next message.
    const NEXT_MESSAGE: Frame = Frame::MessageHeader {
        got: 0,
        size: [0; 2],
    };

    /// A payload with `left` bytes still to come (none: the next message starts).
    fn payload(left: usize, format: bool) -> Frame {
        if left == 0 {
            Frame::NEXT_MESSAGE
        } else {
            Frame::Payload { left, format }
        }
    }
}

/// A byte source that refuses a format definition holding a number no message could hold,
/// before the decoder sees it (the decoder's tokenizer unwraps the number as a `usize` and
/// panics on one that overflows). Bytes pass through unchanged otherwise.
struct CheckedFormats<R> {
    inner: R,
    frame: Frame,
    /// Within a format definition: whether the last byte continued an identifier, and the
    /// value of the number being read (None: not in a number).
    in_identifier: bool,
    number: Option<u64>,
    offset: u64,
}

impl<R> CheckedFormats<R> {
    fn new(inner: R) -> Self {
        CheckedFormats {
            inner,
            // Magic (7 bytes), version (1), timestamp (8).
            frame: Frame::FileHeader { left: 16 },
            in_identifier: false,
            number: None,
            offset: 0,
        }
    }

    /// Follow one byte through the framing; an error for a number past any array's length.
    fn step(&mut self, b: u8) -> std::io::Result<()> {
        self.frame = match self.frame {
            Frame::FileHeader { left } if left > 1 => Frame::FileHeader { left: left - 1 },
            Frame::FileHeader { .. } => Frame::NEXT_MESSAGE,
            Frame::MessageHeader { got, mut size } if got < 2 => {
                size[got] = b;
                Frame::MessageHeader { got: got + 1, size }
            }
            Frame::MessageHeader { size, .. } => {
                self.in_identifier = false;
                self.number = None;
                Frame::payload(usize::from(u16::from_le_bytes(size)), b == b'F')
            }
            Frame::Payload { left, format } => {
                if format {
                    self.format_byte(b)?;
                }
                Frame::payload(left - 1, format)
            }
        };
        self.offset += 1;
        Ok(())
    }

    /// A byte of a format definition, tokenized as the decoder does: identifiers
    /// (`[A-Za-z_][A-Za-z0-9_]*`) and numbers (`[0-9]+`).
    fn format_byte(&mut self, b: u8) -> std::io::Result<()> {
        let identifier = b.is_ascii_alphabetic() || b == b'_';
        if self.in_identifier && (identifier || b.is_ascii_digit()) {
            return Ok(());
        }
        self.in_identifier = identifier;
        if !b.is_ascii_digit() {
            self.number = None;
            return Ok(());
        }
        let n = self.number.unwrap_or(0) * 10 + u64::from(b - b'0');
        if n > MAX_FORMAT_NUMBER {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!(
                    "a format definition holds a number over {MAX_FORMAT_NUMBER} at byte {}, \
                     longer than any message",
                    self.offset
                ),
            ));
        }
        self.number = Some(n);
        Ok(())
    }
}

impl<R: Read> Read for CheckedFormats<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        let mut i = 0;
        while i < n {
            // Most bytes are data payloads: passed over in one step.
            if let Frame::Payload {
                left,
                format: false,
            } = self.frame
            {
                let k = left.min(n - i);
                i += k;
                self.offset += k as u64;
                self.frame = Frame::payload(left - k, false);
                continue;
            }
            self.step(buf[i])?;
            i += 1;
        }
        Ok(n)
    }
}

/// Read a ULog's `sensor_gyro` instance `opts.instance` as a unit reduced to model steps.
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<(ImuLog, ReadReport), LogError> {
    let file = std::fs::File::open(path)
        .map_err(|e| LogError::new(Kind::Io, path, None, None, format!("cannot open: {e}")))?;
    read_from(BufReader::with_capacity(1 << 16, file), path, opts.instance)
}

/// [`read`] of any byte source (`path` names it in messages).
pub(crate) fn read_from<R: Read>(
    src: R,
    path: &Path,
    instance: u8,
) -> Result<(ImuLog, ReadReport), LogError> {
    let taken = Rc::new(Cell::new(0));
    let ran_dry = Rc::new(Cell::new(false));
    let counted = Counted {
        inner: CheckedFormats::new(src),
        taken: Rc::clone(&taken),
        ran_dry: Rc::clone(&ran_dry),
    };
    let corrupt = |at: u64, what: String| LogError::corrupt_at(path, at, what);
    let parser = ULogParserBuilder::new(counted)
        .set_subscription_allow_list([TOPIC])
        .build()
        .map_err(|e| corrupt(0, e.to_string()))?;
    let mut means = StepMeans::default();
    let mut instances: Vec<u8> = Vec::new();
    let mut whole: u64 = 0;
    let mut truncated_at = None;
    for item in parser {
        if ran_dry.get() {
            // The source ended inside this message: what the parser made of it is not data.
            truncated_at = Some(whole);
            break;
        }
        let msg = item.map_err(|e| {
            let what = if whole == 0 {
                format!(
                    "not a PX4 ULog ({e}); give --format if the file's extension names the \
                     wrong format"
                )
            } else {
                format!("the log is damaged in the message that starts here ({e})")
            };
            corrupt(whole, what)
        })?;
        let start = whole;
        whole = taken.get();
        let UlogMessage::LoggedData(d) = msg else {
            continue;
        };
        let inst = d.data.multi_id_index.unwrap_or(0);
        if !instances.contains(&inst) {
            instances.push(inst);
        }
        if inst != instance {
            continue;
        }
        let mut v = [f64::NAN; 4];
        for f in &d.data.fields {
            let k = match f.name.as_ref() {
                "x" => 0,
                "y" => 1,
                "z" => 2,
                "temperature" => 3,
                _ => continue,
            };
            v[k] = match f.value {
                FieldValue::ScalarF32(x) => x as f64,
                FieldValue::ScalarF64(x) => x,
                _ => {
                    return Err(corrupt(
                        start,
                        format!("{TOPIC}.{} is not a floating-point field", f.name),
                    ))
                }
            };
        }
        means
            .push(d.timestamp, [v[0], v[1], v[2]], v[3])
            .map_err(|r| {
                corrupt(
                    start,
                    match r {
                        Refused::Backwards { previous_us } => format!(
                            "{TOPIC} instance {instance}: timestamp {} is not after the \
                             previous message's {previous_us}: the log is damaged here",
                            d.timestamp
                        ),
                        Refused::NotFinite => format!(
                            "{TOPIC} instance {instance}: x, y, z or temperature is missing or \
                             not a finite number (a gyro without a temperature sensor cannot \
                             be compensated for temperature)"
                        ),
                    },
                )
            })?;
    }
    if truncated_at.is_none() && ran_dry.get() && whole < taken.get() {
        truncated_at = Some(whole);
    }
    super::step_means::reduced_log(path, means, instance, &instances, TOPIC, truncated_at)
}
