//! ArduPilot DataFlash logs (`.bin`): the gyro of message `IMU` as a three-axis unit.
//!
//! A DataFlash log is a stream of messages, each `A3 95`, a type byte and a payload whose
//! layout an earlier `FMT` message (type 128) defines: its length, name, one character per
//! field and the field labels. Of message `IMU` the reader takes `TimeUS` (µs), `I` (the
//! sensor instance; logs without it name the second and third sensor `IMU2`, `IMU3`),
//! `GyrX`, `GyrY`, `GyrZ` (rad/s) and `T` (°C), reduced to model steps
//! ([`super::step_means`]).
//!
//! The parser is written here rather than taken from a crate: the DataFlash crate on
//! crates.io panics on a `FMT` message declaring a length under 3 bytes, and on damaged data
//! it skips bytes silently, so it can name neither the offset of a fault nor a cut-off end.
//! Here a fault is a [`LogError`] naming the byte offset; a log cut off mid-message is read
//! to its last whole message and [`ReadReport::truncated_at_byte`] says where it ends.

use std::io::{BufReader, Read};
use std::path::Path;

use super::error::{LogError, LogErrorKind as Kind};
use super::step_means::{Refused, StepMeans};
use super::{ImuLog, ReadReport};

const HEAD: [u8; 2] = [0xA3, 0x95];
const FMT_TYPE: u8 = 0x80;
/// Length of a `FMT` message, header included.
const FMT_LEN: usize = 89;

/// Bytes of a field of type character `c` (None: not a DataFlash type).
fn field_size(c: u8) -> Option<usize> {
    Some(match c {
        b'b' | b'B' | b'M' => 1,
        b'h' | b'H' | b'c' | b'C' => 2,
        b'i' | b'I' | b'f' | b'n' | b'e' | b'E' | b'L' => 4,
        b'd' | b'q' | b'Q' => 8,
        b'N' => 16,
        b'Z' | b'a' => 64,
        _ => return None,
    })
}

/// A field's value as a number (None: a text or array field).
fn number(c: u8, b: &[u8]) -> Option<f64> {
    let a2 = || [b[0], b[1]];
    let a4 = || [b[0], b[1], b[2], b[3]];
    let a8 = || [b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]];
    Some(match c {
        b'b' => b[0] as i8 as f64,
        b'B' | b'M' => b[0] as f64,
        b'h' => i16::from_le_bytes(a2()) as f64,
        b'H' => u16::from_le_bytes(a2()) as f64,
        b'c' => i16::from_le_bytes(a2()) as f64 / 100.0,
        b'C' => u16::from_le_bytes(a2()) as f64 / 100.0,
        b'i' | b'L' => i32::from_le_bytes(a4()) as f64,
        b'I' => u32::from_le_bytes(a4()) as f64,
        b'e' => i32::from_le_bytes(a4()) as f64 / 100.0,
        b'E' => u32::from_le_bytes(a4()) as f64 / 100.0,
        b'f' => f32::from_le_bytes(a4()) as f64,
        b'd' => f64::from_le_bytes(a8()),
        b'q' => i64::from_le_bytes(a8()) as f64,
        b'Q' => u64::from_le_bytes(a8()) as f64,
        _ => return None,
    })
}

/// Where a field sits in a payload: its offset and type character.
#[derive(Debug, Clone, Copy)]
struct Field {
    at: usize,
    kind: u8,
}

/// The fields of an `IMU` message the reader takes.
#[derive(Debug, Clone, Copy)]
struct ImuFields {
    time: Field,
    instance: Option<Field>,
    gyro: [Field; 3],
    temp: Field,
}

/// One message type: its length (header included) and, for the gyro messages, its fields
/// and the instance it is when it has no `I` field.
#[derive(Debug, Clone, Copy, Default)]
struct Type {
    len: usize,
    imu: Option<(ImuFields, u8)>,
}

/// Read a DataFlash log's gyro instance `opts.instance` as a unit reduced to model steps.
pub(crate) fn read(
    path: &Path,
    opts: &super::ReadOptions,
) -> Result<(ImuLog, ReadReport), LogError> {
    let file = std::fs::File::open(path)
        .map_err(|e| LogError::new(Kind::Io, path, None, None, format!("cannot open: {e}")))?;
    read_from(BufReader::with_capacity(1 << 16, file), path, opts.instance)
}

/// [`read`] of any byte source (`path` names it in messages).
pub(crate) fn read_from<R: Read>(
    mut src: R,
    path: &Path,
    instance: u8,
) -> Result<(ImuLog, ReadReport), LogError> {
    let corrupt = |at: u64, what: String| LogError::corrupt_at(path, at, what);
    let mut types: Vec<Type> = vec![Type::default(); 256];
    types[FMT_TYPE as usize].len = FMT_LEN;
    let mut at: u64 = 0;
    let mut payload = vec![0u8; 256];
    let mut means = StepMeans::default();
    let mut instances: Vec<u8> = Vec::new();
    let mut truncated_at = None;
    loop {
        let mut head = [0u8; 3];
        match fill(&mut src, &mut head).map_err(|e| io_error(path, at, e))? {
            0 => break,
            3 => {}
            _ => {
                truncated_at = Some(at);
                break;
            }
        }
        if head[..2] != HEAD {
            let what = if at == 0 {
                format!(
                    "not an ArduPilot DataFlash log: it starts with {:02X} {:02X}, not A3 95 \
                     (give --format if the file's extension names the wrong format)",
                    head[0], head[1]
                )
            } else {
                format!(
                    "no message header (A3 95) where a message starts: the log is damaged \
                     here (found {:02X} {:02X}); cut the file before this byte to read the \
                     part before it",
                    head[0], head[1]
                )
            };
            return Err(corrupt(at, what));
        }
        let ty = types[head[2] as usize];
        if ty.len < 3 {
            return Err(corrupt(
                at,
                format!(
                    "message type {} has no FMT definition before it: the log is damaged or \
                     not a DataFlash log",
                    head[2]
                ),
            ));
        }
        let body = &mut payload[..ty.len - 3];
        let got = fill(&mut src, body).map_err(|e| io_error(path, at, e))?;
        if got < body.len() {
            truncated_at = Some(at);
            break;
        }
        if head[2] == FMT_TYPE {
            define(&mut types, body).map_err(|what| corrupt(at, what))?;
        } else if let Some((f, own)) = ty.imu {
            let get = |f: Field| number(f.kind, &body[f.at..]).unwrap_or(f64::NAN);
            let inst = f.instance.map_or(own, |i| get(i) as u8);
            if !instances.contains(&inst) {
                instances.push(inst);
            }
            if inst == instance {
                let t = get(f.time);
                let rates = f.gyro.map(get);
                let temp = get(f.temp);
                if !(t >= 0.0 && t < u64::MAX as f64) {
                    return Err(corrupt(at, format!("IMU TimeUS {t} is not a time")));
                }
                means.push(t as u64, rates, temp).map_err(|r| {
                    corrupt(
                        at,
                        match r {
                            Refused::Backwards { previous_us } => format!(
                                "IMU instance {instance}: TimeUS {t} is not after the previous \
                                 message's {previous_us}: the log is damaged here"
                            ),
                            Refused::NotFinite => format!(
                                "IMU instance {instance}: a gyro rate or the temperature is \
                                 not a finite number"
                            ),
                        },
                    )
                })?;
            }
        }
        at += ty.len as u64;
    }
    super::step_means::reduced_log(path, means, instance, &instances, "IMU", truncated_at)
}

/// Record a `FMT` message's type; an `IMU` type's fields are found by their labels.
fn define(types: &mut [Type], body: &[u8]) -> Result<(), String> {
    let text = |b: &[u8]| {
        let end = b.iter().position(|c| *c == 0).unwrap_or(b.len());
        String::from_utf8_lossy(&b[..end]).into_owned()
    };
    let (ty, len) = (body[0], body[1] as usize);
    let name = text(&body[2..6]);
    let kinds = text(&body[6..22]);
    let labels = text(&body[22..86]);
    if ty == FMT_TYPE {
        // The FMT message defining itself: its layout is fixed.
        return (len == FMT_LEN)
            .then_some(())
            .ok_or_else(|| format!("FMT defines itself with length {len}, not {FMT_LEN}"));
    }
    if len < 3 {
        return Err(format!(
            "FMT of message {name:?} (type {ty}) gives length {len}, under the 3-byte header"
        ));
    }
    let mut imu = None;
    let own = match name.as_str() {
        "IMU" => Some(0),
        "IMU2" => Some(1),
        "IMU3" => Some(2),
        _ => None,
    };
    if let Some(own) = own {
        let mut at = 0;
        let mut fields: Vec<(&str, Field)> = Vec::new();
        for (k, label) in kinds.bytes().zip(labels.split(',')) {
            let size = field_size(k)
                .ok_or_else(|| format!("FMT of {name}: unknown field type {:?}", k as char))?;
            fields.push((label, Field { at, kind: k }));
            at += size;
        }
        if at + 3 > len {
            return Err(format!(
                "FMT of {name}: its fields take {} bytes, more than its length {len}",
                at + 3
            ));
        }
        let find = |l: &str| {
            fields
                .iter()
                .find(|(n, f)| *n == l && number(f.kind, &[0; 8]).is_some())
                .map(|(_, f)| *f)
        };
        let need = |l: &str| find(l).ok_or_else(|| format!("FMT of {name}: no numeric field {l}"));
        imu = Some((
            ImuFields {
                time: need("TimeUS")?,
                instance: find("I"),
                gyro: [need("GyrX")?, need("GyrY")?, need("GyrZ")?],
                temp: need("T")?,
            },
            own,
        ));
    }
    types[ty as usize] = Type { len, imu };
    Ok(())
}

/// Read until `buf` is full or the source ends: the bytes read.
fn fill<R: Read>(src: &mut R, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut n = 0;
    while n < buf.len() {
        match src.read(&mut buf[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(n)
}

fn io_error(path: &Path, at: u64, e: std::io::Error) -> LogError {
    LogError::new(
        Kind::Io,
        path,
        None,
        None,
        format!("byte {at}: cannot read: {e}"),
    )
}
