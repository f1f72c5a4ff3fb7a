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
//! `gt_step` with `gyro[i]` and the temperature of the sensor it reads. So each axis computes
//! exactly what a one-axis export of its model computes, and what the core's
//! [`Unit`](gyrotherm_core::unit::Unit) computes: `compensate --stream` to the last bit.
//!
//! **Rust.** `gyrotherm_model.rs` holds `AXES`, `TEMPS`, `CHANNELS` (the sensor each axis
//! reads) and `MODELS` (one [`StaticModel`] per
//! axis), for [`Unit::from_static`](gyrotherm_core::unit::Unit::from_static).
//!
//! **Column names.** Generated source holds only generator text and numbers: the column
//! names, which come from the model file, are never written into it (a name could close a
//! comment and add code). The files give the order by index (`gyro[i]` is the model's i-th
//! gyro column, `temp[j]` its j-th temperature column, and which `temp[]` each axis reads)
//! with the model's content hash; [`column_map`] gives the names for that order, which
//! `gyrotherm export` prints on stderr.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use gyrotherm_core::features::HISTORY_STEPS;
use gyrotherm_core::static_model::StaticModel;

use super::{c, describe, rust, static_model, write_files, ExportError, Lang};
use crate::imu_model::{ImuError, ImuModel};
use crate::model::CHECKSUM_KEY;

/// The model-independent helpers of the C port, written once for the unit: the text from
/// the first of them up to (not including) the first model-dependent function.
const SHARED_FROM: &str = "static double d_from_bits(";
const SHARED_TO: &str = "/* One LSTM step";
/// Their names (kept unsuffixed).
const SHARED: [&str; 7] = [
    "d_from_bits",
    "d_to_bits",
    "f_from_bits",
    "f_to_bits",
    "gt_expm1",
    "gt_exp",
    "gt_sigmoid",
];
/// Names of the single-axis header that each axis gets its own of.
const PER_AXIS_HEADER: [&str; 6] = [
    "gt_state",
    "gt_init",
    "gt_step",
    "gt_coverage_of",
    "GT_N_FEATURES",
    "GT_LAG_SLOTS",
];

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
pub fn column_map(model: &ImuModel) -> Vec<String> {
    let idx = model.sensor_index();
    let mut out = Vec::new();
    for (i, g) in model.gyro_cols.iter().enumerate() {
        out.push(format!(
            "gyro[{i}] = {g} (axis {i}, reads temp[{}])",
            idx.get(i).copied().unwrap_or(0)
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
    // The generated code runs one sensor per axis; exporting only an axis's first sensor
    // would silently drop the further sensors' parts.
    if let Some(a) = model.axes.iter().find(|a| !a.more.is_empty()) {
        return Err(ExportError::Unit(ImuError::Layout(format!(
            "axis {} reads {} temperature sensors; the C and Rust export runs one sensor per \
             axis so far (the multi-sensor port is not written yet)",
            a.gyro,
            a.temps.len()
        ))));
    }
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
        axes.push((
            static_model(&a.model).map_err(err)?,
            describe(&a.model).map_err(err)?,
        ));
    }
    let channels = model.sensor_index();
    let layout = Layout {
        n_temps: model.temp_cols.len(),
        channels: &channels,
        digest: &digest,
    };
    Ok(match lang {
        Lang::C => {
            let (h, c) = generate_c(&axes, &layout);
            vec![("gyrotherm_model.h", h), ("gyrotherm_model.c", c)]
        }
        Lang::Rust => vec![("gyrotherm_model.rs", generate_rust(&axes, &layout))],
    })
}

/// Write the export of a unit model for `lang` into `dir` (created if missing), each file
/// atomically; returns the files written.
pub fn export_imu(model: &ImuModel, lang: Lang, dir: &Path) -> Result<Vec<PathBuf>, ExportError> {
    write_files(generate_imu(model, lang)?, dir)
}

/// What the files say about the unit besides the axes' models.
struct Layout<'a> {
    n_temps: usize,
    channels: &'a [usize],
    digest: &'a str,
}

impl Layout<'_> {
    /// The comment lines (without comment markers) on the model and the column order.
    fn about(&self, axes: &[(StaticModel, String)], gyro: &str, temp: &str) -> Vec<String> {
        let n = axes.len();
        let mut out = vec![
            format!(
                "Unit model: {n} gyro axes, {} temperature columns;",
                self.n_temps
            ),
            format!("{CHECKSUM_KEY} {}.", self.digest),
        ];
        for (i, (_, about)) in axes.iter().enumerate() {
            out.push(format!("Axis {i}: {about}."));
        }
        out.push(
            "Column order. The model's column names are not copied into generated source;".into(),
        );
        out.push(
            "`gyrotherm export` prints them on stderr, and the model file lists them \
             (gyro_cols, temp_cols):"
                .into(),
        );
        for i in 0..n {
            out.push(format!(
                "  {gyro}[{i}] is the model's {} gyro column; axis {i} reads {temp}[{}];",
                ordinal(i + 1),
                self.channels[i]
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

/// Whether `b` may continue an identifier.
fn ident_byte(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b == b'_'
}

/// `text` with every identifier in `names` suffixed `suffix`, outside comments; numbers
/// (`1e0`, `2u`, `0.5f`) are left alone.
fn rename(text: &str, names: &[String], suffix: &str) -> String {
    let b = text.as_bytes();
    let mut out: Vec<u8> = Vec::with_capacity(b.len() + b.len() / 16);
    let mut i = 0;
    while i < b.len() {
        if b[i..].starts_with(b"/*") {
            let end = text[i + 2..].find("*/").map_or(b.len(), |k| i + 2 + k + 2);
            out.extend_from_slice(&b[i..end]);
            i = end;
        } else if (b[i].is_ascii_alphabetic() || b[i] == b'_')
            && (i == 0 || !(ident_byte(b[i - 1]) || b[i - 1] == b'.'))
        {
            let end = (i..b.len()).find(|&k| !ident_byte(b[k])).unwrap_or(b.len());
            let word = &text[i..end];
            out.extend_from_slice(word.as_bytes());
            if names.iter().any(|n| n == word) {
                out.extend_from_slice(suffix.as_bytes());
            }
            i = end;
        } else {
            // Between tokens, or inside a number: one byte as it is.
            out.push(b[i]);
            i += 1;
        }
    }
    // Only ASCII was inserted, at identifier boundaries.
    String::from_utf8(out).unwrap_or_default()
}

/// The file-scope names a single-axis C source defines: `#define` macros, `static`
/// functions and constants, and typedef names (`} name;`), as written at the start of a line.
fn file_scope_names(source: &str) -> Vec<String> {
    let first_ident = |s: &str| -> Option<String> {
        let s = s.trim_start();
        let end = s.find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))?;
        (end > 0).then(|| s[..end].to_owned())
    };
    let mut names = Vec::new();
    for line in source.lines() {
        if let Some(rest) = line.strip_prefix("#define ") {
            names.extend(first_ident(rest));
        } else if line.starts_with("static ") {
            let head = &line[..line.find(['(', '[', '=']).unwrap_or(line.len())];
            let head = head.trim_end();
            let start = head
                .rfind(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .map_or(0, |k| k + 1);
            names.push(head[start..].to_owned());
        } else if let Some(rest) = line.strip_prefix("} ") {
            if rest.ends_with(';') {
                names.extend(first_ident(rest));
            }
        }
    }
    names.retain(|n| !n.is_empty() && !SHARED.contains(&n.as_str()));
    names.extend(PER_AXIS_HEADER.iter().map(|s| (*s).to_owned()));
    names.sort();
    names.dedup();
    names
}

/// `(header, source)` of the unit.
fn generate_c(axes: &[(StaticModel, String)], layout: &Layout) -> (String, String) {
    let n = axes.len();
    let mut h = String::new();
    h.push_str(
        "/* gyrotherm_model.h: FOG thermal compensation for an inertial unit, generated by\n \
         * `gyrotherm export --lang c`.\n",
    );
    for line in layout.about(axes, "gyro", "temp") {
        let _ = writeln!(h, " * {line}");
    }
    h.push_str(UNIT_HEADER_DOC);
    h.push_str(
        "#ifndef GYROTHERM_MODEL_H\n#define GYROTHERM_MODEL_H\n\n#include <stdint.h>\n\n\
         #ifdef __cplusplus\nextern \"C\" {\n#endif\n\n",
    );
    let _ = writeln!(h, "#define GT_AXES {n}");
    let _ = writeln!(h, "#define GT_TEMPS {}", layout.n_temps);
    let _ = writeln!(h, "#define GT_HISTORY_STEPS {HISTORY_STEPS}");
    h.push_str("#define GT_HIDDEN 8\n\n");
    let mut src = String::new();
    src.push_str(
        "/* gyrotherm_model.c: generated by `gyrotherm export --lang c` for an inertial unit.\n \
         * Per axis, the single-axis port of gyrotherm-core (the text of a one-axis export of\n \
         * that axis's model, its file-scope names suffixed _a<axis>), the model-independent\n \
         * helpers once; then the unit's functions. Do not edit: re-export instead. */\n\
         #include \"gyrotherm_model.h\"\n\n#include <math.h>\n#include <string.h>\n",
    );
    let mut states = String::new();
    for (i, (m, about)) in axes.iter().enumerate() {
        let (ah, asrc) = c::generate(m, about);
        let suffix = format!("_a{i}");
        // The axis's own sizes and state, from its single-axis header.
        let nf = m.spec.n_features();
        let lag_slots = m.spec.lags().len().max(1);
        let _ = writeln!(h, "#define GT_N_FEATURES{suffix} {nf}");
        let _ = writeln!(h, "#define GT_LAG_SLOTS{suffix} {lag_slots}");
        let from = ah.find("struct gt_state {").unwrap_or(0);
        let to = ah[from..].find("\n};\n").map_or(ah.len(), |k| from + k + 4);
        let names = file_scope_names(&asrc);
        let _ = writeln!(h, "typedef struct gt_state{suffix} gt_state{suffix};");
        h.push_str(&rename(&ah[from..to], &names, &suffix));
        h.push('\n');
        let _ = writeln!(states, "    gt_state{suffix} a{i};");
        // The port without its file comment and includes; the shared helpers only once.
        let body_at = asrc.find("#include <string.h>\n").map_or(0, |k| k + 20);
        let mut body = asrc[body_at..].to_owned();
        if i > 0 {
            if let (Some(a), Some(b)) = (body.find(SHARED_FROM), body.find(SHARED_TO)) {
                body.replace_range(a..b, "");
            }
        }
        let _ = write!(
            src,
            "\n/* ---- axis {i}: {about} ---- */\n\
             static void gt_init{suffix}(gt_state{suffix} *s);\n\
             static gt_status gt_step{suffix}(gt_state{suffix} *s, double time_s, double gyro_dps,\n    \
             double temp_c, double *rate_dps, double *bias_dps, double *scale);\n\
             static gt_coverage gt_coverage_of{suffix}(const gt_state{suffix} *s, double *sigma_dph);\n"
        );
        src.push_str(&rename(&body, &names, &suffix));
    }
    h.push_str(
        "typedef struct gt_state gt_state;\n\n\
         /* Complete type, fixed size: allocate it statically or on the stack; fields are\n \
         * private (one compensator state per axis). */\nstruct gt_state {\n",
    );
    h.push_str(&states);
    h.push_str("};\n\n");
    h.push_str(UNIT_HEADER_API);
    // The unit's functions.
    src.push_str("\n/* ---- the unit ---- */\nvoid gt_init(gt_state *s)\n{\n");
    for i in 0..n {
        let _ = writeln!(src, "    gt_init_a{i}(&s->a{i});");
    }
    src.push_str(
        "}\n\nvoid gt_step_imu_bk(gt_state *s, double t, const double gyro[GT_AXES],\n    \
         const double temp[GT_TEMPS], double rate[GT_AXES], gt_status status[GT_AXES],\n    \
         double bias[GT_AXES], double scale[GT_AXES])\n{\n",
    );
    for i in 0..n {
        let _ = writeln!(
            src,
            "    status[{i}] = gt_step_a{i}(&s->a{i}, t, gyro[{i}], temp[{}], &rate[{i}], &bias[{i}], &scale[{i}]);",
            layout.channels[i]
        );
    }
    src.push_str(
        "}\n\nvoid gt_step_imu(gt_state *s, double t, const double gyro[GT_AXES],\n    \
         const double temp[GT_TEMPS], double rate[GT_AXES], gt_status status[GT_AXES])\n{\n    \
         double bias[GT_AXES], scale[GT_AXES];\n    \
         gt_step_imu_bk(s, t, gyro, temp, rate, status, bias, scale);\n}\n\n\
         gt_coverage gt_coverage_of_axis(const gt_state *s, int axis, double *sigma_dph)\n{\n    \
         switch (axis) {\n",
    );
    for i in 0..n {
        let _ = writeln!(
            src,
            "    case {i}:\n        return gt_coverage_of_a{i}(&s->a{i}, sigma_dph);"
        );
    }
    src.push_str(
        "    default:\n        if (sigma_dph != 0) {\n            *sigma_dph = NAN;\n        }\n        \
         return GT_NO_VERDICT;\n    }\n}\n",
    );
    (h, src)
}

const UNIT_HEADER_DOC: &str =
    " * C99, no heap, no global mutable state. Do not edit: re-export instead.
 *
 * Use: one gt_state for the unit; gt_init once, then gt_step_imu once per sample with the
 * time (s, increasing), every gyro output (deg/s, gyro[]) and every temperature (deg C,
 * temp[]; NaN if unread). For each axis i it gives status[i] and the compensated rate
 * rate[i] = (gyro[i] - B) / K (0 when status[i] is GT_INVALID); gt_step_imu_bk gives each
 * axis's B (deg/s) and K too. Each axis runs the single-axis compensator (gt_step of a
 * one-axis export of its model: the same statuses GT_OK, GT_HELD, GT_DEGRADED, GT_INVALID,
 * the same time axis and degraded clock, see gyrotherm-core's compensator module) on its
 * gyro and the one temperature it reads, so a fault in one temperature sensor holds only the
 * axes that read it, a bad time stamp reaches every axis alike, and a non-finite gyro sample
 * makes only its own axis GT_INVALID. gt_coverage_of_axis(s, i, &sigma_dph) is gt_coverage_of
 * for axis i (GT_NO_VERDICT and NaN for an axis out of range).
 * The numbers equal gyrotherm-core's (and `gyrotherm compensate --stream`'s) to the last bit
 * when compiled with -ffp-contract=off on IEEE 754 hardware with FLT_EVAL_METHOD == 0. */
";

const UNIT_HEADER_API: &str =
    "typedef enum { GT_OK = 0, GT_HELD = 1, GT_DEGRADED = 2, GT_INVALID = 3 } gt_status;
typedef enum {
    GT_INSIDE = 0,
    GT_EDGE = 1,
    GT_OUTSIDE = 2,
    GT_NO_VERDICT = 3,
    GT_NO_MAP = 4
} gt_coverage;

void gt_init(gt_state *s);
void gt_step_imu(gt_state *s, double t, const double gyro[GT_AXES], const double temp[GT_TEMPS],
                 double rate[GT_AXES], gt_status status[GT_AXES]);
void gt_step_imu_bk(gt_state *s, double t, const double gyro[GT_AXES],
                    const double temp[GT_TEMPS], double rate[GT_AXES], gt_status status[GT_AXES],
                    double bias[GT_AXES], double scale[GT_AXES]);
gt_coverage gt_coverage_of_axis(const gt_state *s, int axis, double *sigma_dph);

#ifdef __cplusplus
}
#endif

#endif /* GYROTHERM_MODEL_H */
";

/// The Rust module of the unit.
fn generate_rust(axes: &[(StaticModel, String)], layout: &Layout) -> String {
    let n = axes.len();
    let mut out = String::from(
        "//! Inertial-unit compensation model for gyrotherm-core, generated by\n\
         //! `gyrotherm export --lang rust`.\n",
    );
    for line in layout.about(axes, "gyro", "temps") {
        let _ = writeln!(out, "//! {line}");
    }
    out.push_str(
        "//! Use: `let mut unit = gyrotherm_core::unit::Unit::<AXES>::from_static(&MODELS, \
         &CHANNELS, TEMPS)?;`\n\
         //! then `unit.step(time_s, &gyro, &temps)` per sample: entry i is axis i's corrected\n\
         //! sample (axis i runs MODELS[i] on temps[CHANNELS[i]]).\n\
         //! Do not edit: re-export instead.\n\n\
         use gyrotherm_core::compensator::TempLimits;\n\
         #[allow(unused_imports)]\n\
         use gyrotherm_core::coverage::Grid;\n\
         use gyrotherm_core::features::{FeatureSpec, LagOutputs};\n\
         #[allow(unused_imports)]\n\
         use gyrotherm_core::static_model::{\n    \
         StaticBaseline, StaticCoverage, StaticLstm, StaticModel, StaticTarget,\n\
         };\n\n",
    );
    let _ = writeln!(
        out,
        "/// Gyro axes (gyro[] entries).\npub const AXES: usize = {n};"
    );
    let _ = writeln!(
        out,
        "/// Temperature columns (temps[] entries).\npub const TEMPS: usize = {};",
        layout.n_temps
    );
    let _ = writeln!(
        out,
        "/// The temps[] entry each axis reads.\npub static CHANNELS: [u8; AXES] = [{}];\n",
        layout
            .channels
            .iter()
            .map(|c| c.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    out.push_str("/// Each axis's model, in axis order.\n");
    out.push_str("#[rustfmt::skip]\n#[allow(clippy::excessive_precision, clippy::unreadable_literal, clippy::approx_constant)]\n");
    out.push_str("pub static MODELS: [StaticModel; AXES] = [\n");
    for (m, _) in axes {
        out.push_str(&rust::model_expr(m));
        out.push_str(",\n");
    }
    out.push_str("];\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renames_identifiers_but_not_numbers_or_comments() {
        let names = vec!["emit".to_owned(), "e0".to_owned(), "STEP_P".to_owned()];
        let text = "/* emit */ emit(s, 1e0, 2.5e-3f, STEP_P); x_emit = emit_x + e0;";
        assert_eq!(
            rename(text, &names, "_a1"),
            "/* emit */ emit_a1(s, 1e0, 2.5e-3f, STEP_P_a1); x_emit = emit_x + e0_a1;"
        );
    }

    #[test]
    fn ordinals() {
        let got: Vec<String> = [1, 2, 3, 4, 11, 12, 13, 21, 22].map(ordinal).to_vec();
        assert_eq!(
            got,
            ["1st", "2nd", "3rd", "4th", "11th", "12th", "13th", "21st", "22nd"]
        );
    }
}
