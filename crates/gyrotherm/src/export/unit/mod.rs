//! Export an inertial-unit model ([`ImuModel`]): the unit's flight code, in C or Rust.
//!
//! **C.** `gyrotherm_model.h` defines `GT_AXES` and `GT_TEMPS` and declares
//!
//! ```c
//! void gt_init(gt_state *s);
//! void gt_step_imu(gt_state *s, double t, const double gyro[GT_AXES],
//!                  const double temp[GT_TEMPS], double rate[GT_AXES],
//!                  gt_status status[GT_AXES]);
//! void gt_step_imu_bk(gt_state *s, double t, const double gyro[GT_AXES],
//!                     const double temp[GT_TEMPS], double rate[GT_AXES],
//!                     gt_status status[GT_AXES], double bias[GT_AXES], double scale[GT_AXES]);
//! gt_coverage gt_coverage_of_axis(const gt_state *s, int axis, double *sigma_dph);
//! ```
//!
//! `gyrotherm_model.c` holds, per axis, the single-axis port of [`super::c`] for that axis's
//! model, its file-scope names suffixed `_a<i>` (comments untouched), the model-independent
//! helpers (`expm1`, `exp`, bit casts) once; then the unit functions, which call axis `i`'s
//! `gt_step` with `gyro[i]` and the temperature of the first sensor it reads. An axis that
//! reads further sensors ([`gyrotherm_core::multi`]) gets, per further sensor, the feature
//! pipeline and baseline code of the same port (the port of a model on that sensor's features
//! whose B and K are its parts), suffixed `_a<i>s<j>`, with a state of only what the core's
//! further sensor holds (that pipeline and its latest accepted reading, not a whole
//! single-axis state), and the port's hooks (`@MORE_*@`) call the `more_*` functions, a port
//! of the core's further-sensor handling: plausibility against each sensor's own last good
//! reading, the pipelines pushed together, the parts added in order, every pipeline restarted
//! on a new time base. So each axis computes exactly what the
//! core's [`Unit`](gyrotherm_core::unit::Unit) computes: `compensate --stream` to the last
//! bit. An axis with a fallback model ([`crate::model::unit::ImuAxis::fallback`]) also gets the
//! single-axis port of that model, suffixed `_a<i>f`, stepped on its first sensor alongside,
//! and the unit function makes the core's choice between the two outputs
//! ([`gyrotherm_core::multi`]: status `GT_FALLBACK`).
//!
//! **Rust.** `gyrotherm_model.rs` holds `AXES`, `TEMPS`, `CHANNELS` (the first sensor each
//! axis reads), `MODELS` (one [`StaticModel`] per axis), `SENSORS` (each axis's further
//! sensors) and `FALLBACKS` (each axis's fallback model, if any), for
//! [`Unit::from_static_fallbacks`](gyrotherm_core::unit::Unit::from_static_fallbacks).
//!
//! **Column names.** Generated source holds only generator text and numbers: the column
//! names, which come from the model file, are never written into it (a name could close a
//! comment and add code). The files give the order by index (`gyro[i]` is the model's i-th
//! gyro column, `temp[j]` its j-th temperature column, and which `temp[]` each axis reads)
//! with the model's content hash; `column_map` gives the names for that order, which
//! `gyrotherm export` prints on stderr.

mod c;
mod rust;

use std::path::{Path, PathBuf};

use gyrotherm_core::static_model::{StaticBaseline, StaticModel, StaticTarget};

use super::{describe, sized_static_model, static_baseline, write_files, ExportError, Lang};
use crate::model::unit::{ImuError, ImuModel};
use crate::model::CHECKSUM_KEY;
/// `1st`, `2nd`, `3rd`, `4th`, ...
fn ordinal(n: usize) -> String {
    let suffix = match (n % 10, n % 100) {
        (_, 11..=13) => "th",
        (1, _) => "st",
        (2, _) => "nd",
        (3, _) => "rd",
        _ => "th",
    };
    format!("{n}{suffix}")
}

/// The unit's name-to-index map, one line each, for the user (stderr): the names come from
/// the model file and go nowhere into generated source.
pub(crate) fn column_map(model: &ImuModel) -> Vec<String> {
    let mut out = Vec::new();
    for (i, (g, a)) in model.gyro_cols.iter().zip(&model.axes).enumerate() {
        let reads: Vec<String> = a
            .temps
            .iter()
            .map(|t| {
                let j = model.temp_cols.iter().position(|c| c == t).unwrap_or(0);
                format!("temp[{j}]")
            })
            .collect();
        out.push(format!(
            "gyro[{i}] = {g} (axis {i}, reads {})",
            reads.join(", ")
        ));
    }
    for (j, t) in model.temp_cols.iter().enumerate() {
        out.push(format!("temp[{j}] = {t}"));
    }
    out
}

/// The generated files of a unit model for `lang`, as `(file name, text)`, without writing
/// anything; like [`super::generate`], every byte is the generator's.
pub fn generate_imu(
    model: &ImuModel,
    lang: Lang,
) -> Result<Vec<(&'static str, String)>, ExportError> {
    model.validate().map_err(ExportError::Unit)?;
    let size = model.hidden_size().map_err(ExportError::Unit)?;
    crate::flight_size::with_hidden!(size, H => generate_imu_sized::<H>(model, lang))
}

/// [`generate_imu`] with every axis's LSTMs at `H` hidden units.
fn generate_imu_sized<const H: usize>(
    model: &ImuModel,
    lang: Lang,
) -> Result<Vec<(&'static str, String)>, ExportError> {
    let compact = serde_json::to_string(model).map_err(|e| ExportError::Unit(ImuError::Json(e)))?;
    let digest = crate::model::sha256_hex(compact.as_bytes());
    let mut axes = Vec::with_capacity(model.axes.len());
    for a in &model.axes {
        let err = |e: ExportError| match e {
            ExportError::Model(source) => ExportError::Unit(ImuError::Axis {
                gyro: a.gyro.clone(),
                source: Box::new(source),
            }),
            other => other,
        };
        let first = sized_static_model::<H>(&a.model).map_err(err)?;
        // The further sensors as the core axis holds them (what the stream runs).
        let core = model.axis_compensator(a).map_err(ExportError::Unit)?;
        let sensors = core
            .further()
            .into_iter()
            .map(|(channel, spec, bias, scale)| {
                let bias = bias.map(static_baseline);
                let scale = scale.map(static_baseline);
                let part = |b: &Option<StaticBaseline>| StaticTarget {
                    offset: 0.0,
                    baseline: *b,
                    lstm: None,
                    lstm_reads_base: false,
                };
                SensorExport {
                    channel,
                    model: StaticModel {
                        spec: *spec,
                        limits: first.limits,
                        bias: part(&bias),
                        scale: part(&scale),
                        coverage: None,
                    },
                    bias,
                    scale,
                }
            })
            .collect();
        let fallback = match &a.fallback {
            Some(f) => Some((
                sized_static_model::<H>(f).map_err(err)?,
                describe(f).map_err(err)?,
            )),
            None => None,
        };
        axes.push(AxisExport {
            channel: core.first().channel(),
            about: describe(&a.model).map_err(err)?,
            model: first,
            sensors,
            fallback,
        });
    }
    let layout = Layout {
        n_temps: model.temp_cols.len(),
        digest: &digest,
    };
    Ok(match lang {
        Lang::C => {
            let (h, c) = c::generate_c(&axes, &layout);
            vec![("gyrotherm_model.h", h), ("gyrotherm_model.c", c)]
        }
        Lang::Rust => vec![("gyrotherm_model.rs", rust::generate_rust(&axes, &layout))],
    })
}

/// One axis to export: its first sensor's model and channel, its further sensors, and its
/// fallback model on the first sensor alone (with its description).
struct AxisExport<const H: usize> {
    model: StaticModel<H>,
    about: String,
    channel: usize,
    sensors: Vec<SensorExport<H>>,
    fallback: Option<(StaticModel<H>, String)>,
}

impl<const H: usize> AxisExport<H> {
    /// The `temp[]` entries the axis reads, first sensor first.
    fn channels(&self) -> Vec<usize> {
        std::iter::once(self.channel)
            .chain(self.sensors.iter().map(|s| s.channel))
            .collect()
    }
}

/// A further sensor of an axis: its `temp[]` entry, its features, its parts of B and K, and
/// the single-axis model whose port gives its pipeline and baseline code (the axis's limits,
/// the parts as baselines without offset).
struct SensorExport<const H: usize> {
    channel: usize,
    model: StaticModel<H>,
    bias: Option<StaticBaseline>,
    scale: Option<StaticBaseline>,
}

/// Write the export of a unit model for `lang` into `dir` (created if missing), each file
/// atomically; returns the files written.
pub fn export_imu(model: &ImuModel, lang: Lang, dir: &Path) -> Result<Vec<PathBuf>, ExportError> {
    write_files(generate_imu(model, lang)?, dir)
}

/// What the files say about the unit besides the axes' models.
struct Layout<'a> {
    n_temps: usize,
    digest: &'a str,
}

impl Layout<'_> {
    /// The comment lines (without comment markers) on the model and the column order.
    fn about<const H: usize>(&self, axes: &[AxisExport<H>], gyro: &str, temp: &str) -> Vec<String> {
        let n = axes.len();
        let mut out = vec![
            format!(
                "Unit model: {n} gyro axes, {} temperature columns;",
                self.n_temps
            ),
            format!("{CHECKSUM_KEY} {}.", self.digest),
        ];
        for (i, a) in axes.iter().enumerate() {
            out.push(format!("Axis {i}: {}.", a.about));
            for (j, s) in a.sensors.iter().enumerate() {
                let spec = &s.model.spec;
                let lags: Vec<String> = spec.lags().iter().map(|t| format!("{t} s")).collect();
                out.push(format!(
                    "  further sensor {}: {temp}[{}], lags [{}] (T - lag outputs), parts of {};",
                    j + 1,
                    s.channel,
                    lags.join(", "),
                    match (s.bias.is_some(), s.scale.is_some()) {
                        (true, true) => "B and K",
                        (true, false) => "B",
                        (false, true) => "K",
                        (false, false) => "neither B nor K",
                    }
                ));
            }
            if let Some((_, about)) = &a.fallback {
                out.push(format!(
                    "  fallback on {temp}[{}] alone, while a further sensor is given up on: {about};",
                    a.channel
                ));
            }
        }
        out.push(
            "Column order. The model's column names are not copied into generated source;".into(),
        );
        out.push(
            "`gyrotherm export` prints them on stderr, and the model file lists them \
             (gyro_cols, temp_cols):"
                .into(),
        );
        for (i, a) in axes.iter().enumerate() {
            let reads: Vec<String> = a
                .channels()
                .iter()
                .map(|c| format!("{temp}[{c}]"))
                .collect();
            out.push(format!(
                "  {gyro}[{i}] is the model's {} gyro column; axis {i} reads {}{};",
                ordinal(i + 1),
                reads.join(", "),
                if reads.len() > 1 {
                    " (first sensor first)"
                } else {
                    ""
                }
            ));
        }
        for j in 0..self.n_temps {
            out.push(format!(
                "  {temp}[{j}] is the model's {} temperature column.",
                ordinal(j + 1)
            ));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ordinals() {
        let got: Vec<String> = [1, 2, 3, 4, 11, 12, 13, 21, 22].map(ordinal).to_vec();
        assert_eq!(
            got,
            ["1st", "2nd", "3rd", "4th", "11th", "12th", "13th", "21st", "22nd"]
        );
    }
}
