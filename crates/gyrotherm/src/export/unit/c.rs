//! An inertial unit's C export: per axis, the single-axis port of [`crate::export::c`] with
//! its file-scope names suffixed, the further sensors' pipelines and the unit functions (see
//! the parent module).

use std::fmt::Write as _;

use gyrotherm_core::features::HISTORY_STEPS;

use super::{AxisExport, Layout, SensorExport};
use crate::export::c;

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

/// The fields of the single-axis `struct gt_state` that a further sensor keeps, as the core's
/// further sensor holds them (`FeaturePipeline` and the latest accepted reading): those the
/// pipeline functions of [`sensor_pieces`] and the `more_*` functions use, and no others (no
/// time axis, fault handling, LSTM or coverage state: those are the axis's).
const SENSOR_FIELDS: [&str; 12] = [
    "hist_k",
    "hist_t",
    "lag_c",
    "t0_s",
    "pipe_last_s",
    "last_step",
    "good_time_s",
    "good_temp_c",
    "hist_head",
    "hist_len",
    "started",
    "has_good",
];

/// A further sensor's state: the single-axis header's `struct gt_state` (`header`, as
/// [`c::generate`] writes it) declaring only the [`SENSOR_FIELDS`], each with the type and
/// size that port gives it (one definition: the template's). File-scope names as in the
/// single-axis header, to be suffixed like the sensor's code.
fn sensor_state(header: &str) -> String {
    let body = header
        .find("struct gt_state {")
        .map(|a| &header[a + "struct gt_state {".len()..])
        .and_then(|rest| rest.find("};").map(|b| &rest[..b]))
        .unwrap_or("");
    // The declarations without their comments.
    let mut code = String::new();
    let mut rest = body;
    while let Some(a) = rest.find("/*") {
        code.push_str(&rest[..a]);
        rest = rest[a..].find("*/").map_or("", |b| &rest[a + b + 2..]);
    }
    code.push_str(rest);
    // Each field's type and declarator ("hist_k[GT_HISTORY_STEPS]"), by name.
    let mut fields: Vec<(String, String, String)> = Vec::new();
    for decl in code.split(';') {
        let decl = decl.split_whitespace().collect::<Vec<_>>().join(" ");
        let Some((ty, declarators)) = decl.split_once(' ') else {
            continue;
        };
        for d in declarators.split(',').map(str::trim) {
            let name = d.split('[').next().unwrap_or("").trim();
            fields.push((name.to_owned(), ty.to_owned(), d.to_owned()));
        }
    }
    // In the order of SENSOR_FIELDS (the state's layout); a field the template lost is left
    // out, and the pipeline code that uses it does not compile.
    let mut out = String::from("struct gt_state {\n");
    for f in SENSOR_FIELDS {
        if let Some((_, ty, d)) = fields.iter().find(|(n, _, _)| n == f) {
            out.push_str(&format!("    {ty} {d};\n"));
        }
    }
    out.push_str("};\n");
    out
}

/// The pieces of a further sensor's single-axis port that the axis uses: the constants of
/// its feature pipeline, its baseline type and data (the parts of B and K), the pipeline
/// (`hist_back`, `emit`, `pipe_push`) and `base_eval`. The rest of that port (its compensator,
/// its LSTM code) the axis does not run, so it is left out (C99 warns of unused statics).
fn sensor_pieces(src: &str, parts: bool) -> String {
    const NEEDED: [&str; 10] = [
        "N_LAGS",
        "LAG_LEVELS",
        "LAG_DIFFS",
        "STEP_P",
        "BOUNDARY_TOL",
        "RATE_LAG_STEPS",
        "WINDOW_STEPS",
        "LAG_TAU",
        "LAG_GAIN",
        "MAX_STEP_INDEX",
    ];
    let between = |from: &str, to: &str| -> &str {
        let a = src.find(from).unwrap_or(src.len());
        let b = src[a..].find(to).map_or(src.len(), |k| a + k);
        &src[a..b]
    };
    let mut out = String::new();
    for line in between("#define N_LAGS", "typedef struct {").lines() {
        let name = match line.strip_prefix("#define ") {
            Some(r) => r.split(' ').next(),
            None => line
                .split_once(" = ")
                .and_then(|(h, _)| h.rsplit(' ').next())
                .and_then(|n| n.split('[').next()),
        }
        .unwrap_or("");
        if NEEDED.contains(&name) {
            out.push_str(line);
            out.push('\n');
        }
    }
    out.push('\n');
    if parts {
        let typedef = between(
            "typedef struct {\n    int n_terms;",
            "typedef struct {\n    int n_inputs;",
        );
        out.push_str(typedef);
        let data = between("} target_def;\n", SHARED_FROM);
        for line in data.lines().skip(1) {
            if !line.contains("_target = {") {
                out.push_str(line);
                out.push('\n');
            }
        }
    }
    // The coverage verdict is the first sensor's: a further sensor's pipeline keeps no T and
    // dT for it (its state has no such fields, so a template change that moved these lines
    // fails to compile rather than writing elsewhere).
    out.push_str(
        &between("/* The i-th newest stored step", "/* Compensator::rebase").replace(
            "    s->cov_temp_c = t;\n    s->cov_rate_c_per_s = rate;\n",
            "",
        ),
    );
    if parts {
        out.push_str(between(
            "/* BaselineModel::eval. */",
            "/* TargetModel::eval. */",
        ));
    }
    out
}

/// The C of an axis's further sensors (suffix `_a<i>`): the hooks into its single-axis port,
/// and the functions they call (`more_*`), placed after the port. Each further sensor `j`
/// keeps its pipeline state `m<j>`, its reading of this sample `m<j>_t` and its latest features
/// `m<j>_feat` in the axis's state; the functions are a port of the core's `MoreParts`
/// (gyrotherm-core's multi.rs), in its order.
fn further_sensors<const H: usize>(
    i: usize,
    sensors: &[SensorExport<H>],
) -> (c::Hooks, String, String) {
    if sensors.is_empty() {
        return (c::Hooks::default(), String::new(), String::new());
    }
    let a = format!("_a{i}");
    let mut hooks = c::Hooks::default();
    for (k, s) in sensors.iter().enumerate() {
        let j = k + 1;
        let _ = write!(
            hooks.state,
            "    gt_state{a}s{j} m{j};              /* further sensor {j}: pipeline, latest good reading */\n    \
             double m{j}_t;                   /* its reading of this sample */\n    \
             double m{j}_feat[GT_N_FEATURES{a}s{j}]; /* its latest features */\n"
        );
        let _ = s;
    }
    hooks.plausible = format!(" && more_plausible{a}(s, time_s)");
    hooks.rebase = format!("    more_rebase{a}(s);\n");
    hooks.push = format!(
        "    /* The further pipelines see the same times, so they step when this one does. */\n    \
         if ((r == 1 || r == 0) && !more_push{a}(s, time_s)) {{\n        rebase(s);\n        return 0;\n    }}\n"
    );
    hooks.accepted = format!("        more_accepted{a}(s, time_s);\n");
    hooks.add = format!("    if (!more_add{a}(s, &vb, &vk)) {{\n        return 0;\n    }}\n");
    let protos = format!(
        "static int more_plausible{a}(const gt_state{a} *s, double time_s);\n\
         static void more_rebase{a}(gt_state{a} *s);\n\
         static int more_push{a}(gt_state{a} *s, double time_s);\n\
         static void more_accepted{a}(gt_state{a} *s, double time_s);\n\
         static int more_add{a}(const gt_state{a} *s, double *b, double *k);\n"
    );
    let mut f = String::new();
    let _ = write!(
        f,
        "\n/* Axis {i}'s further sensors (gyrotherm_core::multi): each reading believed as the\n \
         * first sensor's is (Compensator::plausible), against its own latest good reading. */\n\
         static int more_reading{a}(int has_good, double good_time_s, double good_temp_c,\n    \
         double time_s, double temp_c)\n{{\n    \
         if (!(temp_c >= T_MIN{a} && temp_c <= T_MAX{a})) {{\n        return 0;\n    }}\n    \
         if (has_good) {{\n        \
         double allowed = RATE_MAX{a} * (time_s - good_time_s) + STEP_ALLOWANCE{a};\n        \
         return fabs(temp_c - good_temp_c) <= allowed;\n    }}\n    return 1;\n}}\n\n\
         static int more_plausible{a}(const gt_state{a} *s, double time_s)\n{{\n    int ok = 1;\n"
    );
    for j in 1..=sensors.len() {
        let _ = writeln!(
            f,
            "    ok = ok && more_reading{a}(s->m{j}.has_good, s->m{j}.good_time_s, s->m{j}.good_temp_c, time_s, s->m{j}_t);"
        );
    }
    f.push_str("    return ok;\n}\n\n");
    let _ = writeln!(
        f,
        "/* A new time base: restart the pipelines (FeaturePipeline::reset), forget the readings. */\n\
         static void more_rebase{a}(gt_state{a} *s)\n{{"
    );
    for j in 1..=sensors.len() {
        let _ = writeln!(
            f,
            "    s->m{j}.hist_head = 0u;\n    s->m{j}.hist_len = 0u;\n    \
             memset(s->m{j}.lag_c, 0, sizeof s->m{j}.lag_c);\n    s->m{j}.started = 0u;\n    \
             s->m{j}.last_step = 0u;\n    s->m{j}.has_good = 0u;"
        );
    }
    f.push_str("}\n\n");
    let _ = writeln!(
        f,
        "/* Every further pipeline takes the sample; 0 if one refused it. */\n\
         static int more_push{a}(gt_state{a} *s, double time_s)\n{{\n    int ok = 1;"
    );
    for j in 1..=sensors.len() {
        let _ = writeln!(
            f,
            "    ok = pipe_push{a}s{j}(&s->m{j}, time_s, s->m{j}_t, s->m{j}_feat) >= 0 && ok;"
        );
    }
    f.push_str("    return ok;\n}\n\n");
    let _ = writeln!(
        f,
        "/* The sample was used: each reading is its sensor's latest good one. */\n\
         static void more_accepted{a}(gt_state{a} *s, double time_s)\n{{"
    );
    for j in 1..=sensors.len() {
        let _ = writeln!(
            f,
            "    s->m{j}.has_good = 1u;\n    s->m{j}.good_time_s = time_s;\n    s->m{j}.good_temp_c = s->m{j}_t;"
        );
    }
    f.push_str("}\n\n");
    let _ = writeln!(
        f,
        "/* Each further sensor's parts of B and K, added in order; 0 if one gave none. */\n\
         static int more_add{a}(const gt_state{a} *s, double *b, double *k)\n{{"
    );
    if sensors
        .iter()
        .any(|s| s.bias.is_some() || s.scale.is_some())
    {
        f.push_str("    double v;\n");
    }
    f.push_str("    (void)b;\n    (void)k;\n");
    for (k, s) in sensors.iter().enumerate() {
        let j = k + 1;
        let _ = writeln!(f, "    if (!s->m{j}.started) {{\n        return 0;\n    }}");
        for (part, name, acc) in [(&s.bias, "bias", "b"), (&s.scale, "scale", "k")] {
            if part.is_some() {
                let _ = writeln!(
                    f,
                    "    if (!base_eval{a}s{j}(&{name}_base{a}s{j}, s->m{j}_feat, &v)) {{\n        \
                     return 0;\n    }}\n    *{acc} += v;"
                );
            }
        }
    }
    f.push_str("    return 1;\n}\n");
    (hooks, protos, f)
}

/// `(header, source)` of the unit.
pub(super) fn generate_c<const H: usize>(
    axes: &[AxisExport<H>],
    layout: &Layout,
) -> (String, String) {
    let n = axes.len();
    let mut h = String::new();
    h.push_str(
        "/* gyrotherm_model.h: FOG thermal compensation for an inertial unit, generated by\n \
         * `gyrotherm export --target c`.\n",
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
    let _ = write!(h, "#define GT_HIDDEN {H}\n\n");
    let mut src = String::new();
    src.push_str(
        "/* gyrotherm_model.c: generated by `gyrotherm export --target c` for an inertial unit.\n \
         * Per axis, the single-axis port of gyrotherm-core (the text of a one-axis export of\n \
         * that axis's model, its file-scope names suffixed _a<axis>), the model-independent\n \
         * helpers once; for an axis with further sensors, each sensor's feature pipeline and\n \
         * baseline code from the same port (suffixed _a<axis>s<sensor>) and the functions that\n \
         * join them to the axis (more_*); then the unit's functions. Do not edit: re-export\n \
         * instead. */\n\
         #include \"gyrotherm_model.h\"\n\n#include <math.h>\n#include <string.h>\n",
    );
    let mut states = String::new();
    for (i, ax) in axes.iter().enumerate() {
        let (m, about) = (&ax.model, &ax.about);
        let suffix = format!("_a{i}");
        // The further sensors' state types first (the axis's state holds them).
        let mut sensor_src = String::new();
        for (k, se) in ax.sensors.iter().enumerate() {
            let ss = format!("{suffix}s{}", k + 1);
            let (sh, ssrc) = c::generate(&se.model, "a further sensor");
            let names = file_scope_names(&ssrc);
            let _ = writeln!(
                h,
                "#define GT_N_FEATURES{ss} {}",
                se.model.spec.n_features()
            );
            let _ = writeln!(
                h,
                "#define GT_LAG_SLOTS{ss} {}",
                se.model.spec.lags().len().max(1)
            );
            let _ = writeln!(h, "typedef struct gt_state{ss} gt_state{ss};");
            h.push_str(&rename(&sensor_state(&sh), &names, &ss));
            h.push('\n');
            let _ = write!(
                sensor_src,
                "\n/* ---- axis {i}, further sensor {}: its pipeline and parts ---- */\n",
                k + 1
            );
            let parts = se.bias.is_some() || se.scale.is_some();
            sensor_src.push_str(&rename(&sensor_pieces(&ssrc, parts), &names, &ss));
        }
        let (hooks, protos, more_fns) = further_sensors(i, &ax.sensors);
        let (ah, asrc) = c::generate_with(m, about, &hooks);
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
        src.push_str(&protos);
        src.push_str(&rename(&body, &names, &suffix));
        src.push_str(&sensor_src);
        src.push_str(&more_fns);
        if let Some((fm, fabout)) = &ax.fallback {
            // The fallback: the single-axis port of its model, as an axis's, suffixed _a<i>f.
            let fs = format!("{suffix}f");
            let (fh, fsrc) = c::generate(fm, fabout);
            let _ = writeln!(h, "#define GT_N_FEATURES{fs} {}", fm.spec.n_features());
            let _ = writeln!(
                h,
                "#define GT_LAG_SLOTS{fs} {}",
                fm.spec.lags().len().max(1)
            );
            let from = fh.find("struct gt_state {").unwrap_or(0);
            let to = fh[from..].find("\n};\n").map_or(fh.len(), |k| from + k + 4);
            let names = file_scope_names(&fsrc);
            let _ = writeln!(h, "typedef struct gt_state{fs} gt_state{fs};");
            h.push_str(&rename(&fh[from..to], &names, &fs));
            h.push('\n');
            let _ = writeln!(
                states,
                "    gt_state{fs} a{i}f; /* axis {i}'s fallback */\n    \
                 uint8_t fb{i};        /* axis {i} runs on its fallback */"
            );
            // The shared helpers are axis 0's.
            let body_at = fsrc.find("#include <string.h>\n").map_or(0, |k| k + 20);
            let mut body = fsrc[body_at..].to_owned();
            if let (Some(a), Some(b)) = (body.find(SHARED_FROM), body.find(SHARED_TO)) {
                body.replace_range(a..b, "");
            }
            let _ = write!(
                src,
                "\n/* ---- axis {i}'s fallback, on its first sensor alone: {fabout} ---- */\n\
                 static void gt_init{fs}(gt_state{fs} *s);\n\
                 static gt_status gt_step{fs}(gt_state{fs} *s, double time_s, double gyro_dps,\n    \
                 double temp_c, double *rate_dps, double *bias_dps, double *scale);\n\
                 static gt_coverage gt_coverage_of{fs}(const gt_state{fs} *s, double *sigma_dph);\n"
            );
            src.push_str(&rename(&body, &names, &fs));
        }
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
    for (i, ax) in axes.iter().enumerate() {
        let _ = writeln!(src, "    gt_init_a{i}(&s->a{i});");
        if ax.fallback.is_some() {
            let _ = writeln!(src, "    gt_init_a{i}f(&s->a{i}f);\n    s->fb{i} = 0u;");
        }
    }
    src.push_str(
        "}\n\nvoid gt_step_imu_bk(gt_state *s, double t, const double gyro[GT_AXES],\n    \
         const double temp[GT_TEMPS], double rate[GT_AXES], gt_status status[GT_AXES],\n    \
         double bias[GT_AXES], double scale[GT_AXES])\n{\n",
    );
    for (i, ax) in axes.iter().enumerate() {
        for (k, se) in ax.sensors.iter().enumerate() {
            let _ = writeln!(src, "    s->a{i}.m{}_t = temp[{}];", k + 1, se.channel);
        }
        let _ = writeln!(
            src,
            "    status[{i}] = gt_step_a{i}(&s->a{i}, t, gyro[{i}], temp[{}], &rate[{i}], &bias[{i}], &scale[{i}]);",
            ax.channel
        );
        if ax.fallback.is_some() {
            // gyrotherm_core::multi::AxisCompensator::step's choice, on the two outputs.
            let _ = writeln!(
                src,
                "    {{\n        double rf, bf, kf;\n        \
                 gt_status sf = gt_step_a{i}f(&s->a{i}f, t, gyro[{i}], temp[{}], &rf, &bf, &kf);\n        \
                 if (status[{i}] != GT_INVALID && sf != GT_INVALID) {{\n            \
                 s->fb{i} = (uint8_t)(status[{i}] == GT_DEGRADED && sf != GT_DEGRADED);\n        }}\n        \
                 if (s->fb{i}) {{\n            status[{i}] = sf == GT_OK ? GT_FALLBACK : sf;\n            \
                 rate[{i}] = rf;\n            bias[{i}] = bf;\n            scale[{i}] = kf;\n        }}\n    }}",
                ax.channel
            );
        }
    }
    src.push_str(
        "}\n\nvoid gt_step_imu(gt_state *s, double t, const double gyro[GT_AXES],\n    \
         const double temp[GT_TEMPS], double rate[GT_AXES], gt_status status[GT_AXES])\n{\n    \
         double bias[GT_AXES], scale[GT_AXES];\n    \
         gt_step_imu_bk(s, t, gyro, temp, rate, status, bias, scale);\n}\n\n\
         gt_coverage gt_coverage_of_axis(const gt_state *s, int axis, double *sigma_dph)\n{\n    \
         switch (axis) {\n",
    );
    for (i, ax) in axes.iter().enumerate() {
        let _ = writeln!(src, "    case {i}:");
        if ax.fallback.is_some() {
            let _ = writeln!(
                src,
                "        if (s->fb{i}) {{\n            return gt_coverage_of_a{i}f(&s->a{i}f, sigma_dph);\n        }}"
            );
        }
        let _ = writeln!(
            src,
            "        return gt_coverage_of_a{i}(&s->a{i}, sigma_dph);"
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
 * gyro and the first temperature it reads. An axis that reads further sensors (listed above)
 * also runs each one's feature pipeline on the same time axis and adds each one's part of B
 * and K after the first sensor's, in order; it uses a sample only when every sensor it reads
 * is believed, each against its own latest good reading (gyrotherm-core's multi module). So a
 * fault in one temperature sensor holds only the axes that read it, a bad time stamp reaches
 * every axis alike, and a non-finite gyro sample makes only its own axis GT_INVALID. An axis
 * with a fallback (listed above) also runs the single-axis compensator of its fallback model on
 * its first sensor, from the start; while the axis on all its sensors is GT_DEGRADED and the
 * fallback is not, it gives the fallback's output, with status GT_FALLBACK where the
 * fallback's is GT_OK (its GT_HELD otherwise), decided on samples where neither is GT_INVALID.
 * gt_coverage_of_axis(s, i, &sigma_dph) is gt_coverage_of for axis i (its fallback's while
 * it runs on it; GT_NO_VERDICT and NaN for an axis out of range).
 * The numbers equal gyrotherm-core's (and `gyrotherm compensate --stream`'s) to the last bit
 * when compiled with -ffp-contract=off on IEEE 754 hardware with FLT_EVAL_METHOD == 0. */
";

const UNIT_HEADER_API: &str = "typedef enum {
    GT_OK = 0,
    GT_HELD = 1,
    GT_DEGRADED = 2,
    GT_INVALID = 3,
    GT_FALLBACK = 4
} gt_status;
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

    /// A further sensor's state is the single-axis template's `struct gt_state` cut to
    /// [`SENSOR_FIELDS`]: every field once, with the template's own declaration (the
    /// reference: the template text, read here line by line).
    #[test]
    fn a_further_sensors_state_is_the_templates_fields() {
        let template = include_str!("../templates/gyrotherm_model.h.in");
        let header = template.replace("@MORE_STATE@", "");
        let got = sensor_state(&header);
        let decls: Vec<&str> = got.lines().filter(|l| l.ends_with(';')).collect();
        for f in SENSOR_FIELDS {
            let with = |d: &&&str| d.split([' ', ',', ';', '[']).any(|w| w == f);
            assert_eq!(decls.iter().filter(with).count(), 1, "{f} in {got}");
        }
        assert!(got.starts_with("struct gt_state {\n") && got.ends_with("};\n"));
        // The types, as the template declares them.
        for (field, ty) in [
            ("last_step", "uint64_t"),
            ("hist_k", "uint64_t"),
            ("started", "uint8_t"),
        ] {
            let line = template
                .lines()
                .find(|l| l.split([' ', ',', ';', '[']).any(|w| w == field))
                .unwrap();
            assert!(line.trim_start().starts_with(ty), "{line}");
            assert!(decls
                .iter()
                .any(|d| d.trim_start().starts_with(ty) && d.contains(field)));
        }
        // Nothing of the axis's own state (time base, LSTM, coverage) is declared.
        for f in ["base_s", "lstm_h", "cov_temp_c", "has_held", "unplaced"] {
            assert!(!got.contains(f), "{f} in {got}");
        }
    }
}
