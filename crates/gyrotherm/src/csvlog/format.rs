//! The list of log formats a command reads, and the choice of reader for a file.
//!
//! A format is its name (`--format`, Python's `format=`), its file extensions (how a file
//! is recognised when no format is given; an unknown extension is read as CSV) and its
//! reader. Every command and Python read a log through [`read_log`](super::read_log) (one
//! gyro) or [`read_imu_log`](super::read_imu_log) (a unit), which pick the reader here.

use std::path::Path;

use super::error::{LogError, LogErrorKind as Kind};
use super::{ImuLog, ReadOptions, ReadReport, TestLog, GYRO_COL};
use crate::setting_rule::SettingError;

/// A log's file format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LogFormat {
    /// Text, one row per sample (this module's parent).
    #[default]
    Csv,
    /// PX4 ULog: topic `sensor_gyro`, one three-axis unit per instance.
    Ulog,
    /// ArduPilot DataFlash: message `IMU`, one three-axis unit per instance.
    DataFlash,
}

/// Every format, CSV (the default) first.
pub const LOG_FORMATS: [LogFormat; 3] = [LogFormat::Csv, LogFormat::Ulog, LogFormat::DataFlash];

/// The names of [`LOG_FORMATS`], in their order.
pub const LOG_FORMAT_NAMES: [&str; 3] = ["csv", "ulog", "dataflash"];

impl LogFormat {
    /// The name on the command line and in Python.
    pub fn as_str(self) -> &'static str {
        match self {
            LogFormat::Csv => "csv",
            LogFormat::Ulog => "ulog",
            LogFormat::DataFlash => "dataflash",
        }
    }

    /// One line of help.
    pub fn help(self) -> &'static str {
        match self {
            LogFormat::Csv => "text with a header row (.csv, .txt, any other extension)",
            LogFormat::Ulog => "PX4 ULog (.ulg): topic sensor_gyro",
            LogFormat::DataFlash => "ArduPilot DataFlash (.bin): message IMU",
        }
    }

    /// The file extensions that select the format, lower case, without the dot.
    pub(crate) fn extensions(self) -> &'static [&'static str] {
        match self {
            LogFormat::Csv => &["csv", "txt", "tsv"],
            LogFormat::Ulog => &["ulg"],
            LogFormat::DataFlash => &["bin"],
        }
    }

    /// The format a file's extension names (any case); CSV for any other extension or none,
    /// as every log was read before there was a list of formats.
    pub(crate) fn of_path(path: &Path) -> LogFormat {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        ext.and_then(|e| {
            LOG_FORMATS
                .into_iter()
                .find(|f| f.extensions().contains(&e.as_str()))
        })
        .unwrap_or_default()
    }

    /// Whether a log of this format always holds a unit of several gyro axes (an autopilot's
    /// three-axis sensor) rather than the columns the read options name.
    pub(crate) fn holds_unit(self) -> bool {
        !matches!(self, LogFormat::Csv)
    }
}

impl std::fmt::Display for LogFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl std::str::FromStr for LogFormat {
    type Err = SettingError;
    /// A name of [`LOG_FORMAT_NAMES`].
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        LOG_FORMATS
            .into_iter()
            .find(|f| f.as_str() == s)
            .ok_or_else(|| SettingError::unknown("format", s, &LOG_FORMAT_NAMES))
    }
}

impl ReadOptions {
    /// The format `path` is read in: the one the options name, else the one its extension
    /// names ([`LogFormat::of_path`]).
    pub(crate) fn format_of(&self, path: &Path) -> LogFormat {
        self.format.unwrap_or_else(|| LogFormat::of_path(path))
    }

    /// Whether reading `paths` gives inertial units: the options name several gyro or
    /// temperature columns, or a file's format holds a unit.
    pub fn reads_unit<P: AsRef<Path>>(&self, paths: &[P]) -> bool {
        self.is_multi_column()
            || paths
                .iter()
                .any(|p| self.format_of(p.as_ref()).holds_unit())
    }
}

/// Read a log whose format holds a unit: every gyro axis, or the gyro and temperature
/// columns the options name (a unit model's columns, for example).
pub(crate) fn read_unit(path: &Path, opts: &ReadOptions) -> Result<(ImuLog, ReadReport), LogError> {
    let (mut log, report) = match opts.format_of(path) {
        LogFormat::Ulog => super::ulog::read(path, opts)?,
        LogFormat::DataFlash => super::dataflash::read(path, opts)?,
        // CSV names its columns itself.
        LogFormat::Csv => return super::read_imu_log(path, opts, None),
    };
    let options =
        |e: SettingError| LogError::new(Kind::BadOptions, path, None, None, e.to_string());
    if opts.gyro_col != GYRO_COL {
        let wanted = opts.gyro_cols().map_err(options)?;
        log.gyro = pick(path, std::mem::take(&mut log.gyro), &wanted, "gyro")?;
    }
    let temps = opts.temp_cols().map_err(options)?;
    log.temp = pick(path, std::mem::take(&mut log.temp), &temps, "temperature")?;
    Ok((log, report))
}

/// The columns of `held` named in `wanted`, in that order.
fn pick(
    path: &Path,
    mut held: Vec<super::NamedSeries>,
    wanted: &[String],
    what: &str,
) -> Result<Vec<super::NamedSeries>, LogError> {
    let names: Vec<String> = held.iter().map(|s| s.name.clone()).collect();
    wanted
        .iter()
        .map(|w| {
            let k = held.iter().position(|s| &s.name == w).ok_or_else(|| {
                LogError::new(
                    Kind::MissingColumn,
                    path,
                    None,
                    Some(w),
                    format!("no such {what} in this log; it holds {}", names.join(", ")),
                )
            })?;
            Ok(std::mem::take(&mut held[k]))
        })
        .collect()
}

/// Read an autopilot's log (a format that holds a unit) from any
/// byte source, `source` naming it in messages: as [`read_imu_log`](super::read_imu_log) reads
/// such a file, every axis. A CSV source is read line by line by
/// [`LogReader`](super::LogReader) instead, so it is refused here.
pub fn read_unit_from<R: std::io::Read>(
    src: R,
    source: &Path,
    format: LogFormat,
    instance: u8,
) -> Result<(ImuLog, ReadReport), LogError> {
    match format {
        LogFormat::Ulog => super::ulog::read_from(src, source, instance),
        LogFormat::DataFlash => super::dataflash::read_from(src, source, instance),
        LogFormat::Csv => Err(LogError::new(
            Kind::BadOptions,
            source,
            None,
            None,
            "a CSV source is read line by line with LogReader",
        )),
    }
}

/// Read one gyro axis of a log whose format holds a unit: the gyro column the options name
/// (one of the unit's), with its temperature.
pub(crate) fn read_axis(
    path: &Path,
    opts: &ReadOptions,
) -> Result<(TestLog, ReadReport), LogError> {
    let (log, report) = read_unit(
        path,
        &ReadOptions {
            gyro_col: GYRO_COL.to_owned(),
            ..opts.clone()
        },
    )?;
    let names: Vec<&str> = log.gyro.iter().map(|g| g.name.as_str()).collect();
    let axis = names
        .iter()
        .position(|n| *n == opts.gyro_col)
        .ok_or_else(|| {
            LogError::new(
                Kind::MissingColumn,
                path,
                None,
                Some(&opts.gyro_col),
                format!(
                    "this log holds a unit of gyro axes ({}): read it as a unit by naming them \
                 all (--gyro-col {}), or one axis by its name",
                    names.join(", "),
                    names.join(",")
                ),
            )
        })?;
    Ok((log.axis_log(axis, 0), report))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_list_agree_and_parse_back() {
        for (f, n) in LOG_FORMATS.iter().zip(LOG_FORMAT_NAMES) {
            assert_eq!(f.as_str(), n);
            assert_eq!(n.parse::<LogFormat>().unwrap(), *f);
        }
        let e = "px4".parse::<LogFormat>().unwrap_err();
        assert_eq!(e.setting(), "format");
        assert!(e.to_string().contains("`dataflash`"), "{e}");
    }

    #[test]
    fn extension_picks_the_format_and_anything_else_is_csv() {
        assert_eq!(LogFormat::of_path("a/run.ULG".as_ref()), LogFormat::Ulog);
        assert_eq!(
            LogFormat::of_path("00000042.BIN".as_ref()),
            LogFormat::DataFlash
        );
        assert_eq!(LogFormat::of_path("run.csv".as_ref()), LogFormat::Csv);
        assert_eq!(LogFormat::of_path("run.log".as_ref()), LogFormat::Csv);
        assert_eq!(LogFormat::of_path("run".as_ref()), LogFormat::Csv);
        let given = ReadOptions {
            format: Some(LogFormat::Csv),
            ..ReadOptions::default()
        };
        assert_eq!(given.format_of("x.ulg".as_ref()), LogFormat::Csv);
        assert!(ReadOptions::default().reads_unit(&["x.bin"]));
        assert!(!given.reads_unit(&["x.bin"]));
    }
}
