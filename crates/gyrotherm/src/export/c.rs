//! `--target c`: `gyrotherm_model.h` and `gyrotherm_model.c`, C99, no heap, no global mutable
//! state; weights, scalers and limits as `static const`. The API (the header's complete
//! `gt_state` has a fixed size per model):
//!
//! ```c
//! typedef enum { GT_OK = 0, GT_HELD = 1, GT_DEGRADED = 2, GT_INVALID = 3 } gt_status;
//! void gt_init(gt_state *s);
//! gt_status gt_step(gt_state *s, double time_s, double gyro_dps, double temp_c,
//!                   double *rate_dps, double *bias_dps, double *scale);
//! typedef enum { GT_INSIDE = 0, GT_EDGE = 1, GT_OUTSIDE = 2, GT_NO_VERDICT = 3,
//!                GT_NO_MAP = 4 } gt_coverage;
//! gt_coverage gt_coverage_of(const gt_state *s, double *sigma_dph);
//! ```
//!
//! `gt_step` is a line-by-line port of `gyrotherm_core::Compensator::step` (see the parent
//! module for what makes the numbers equal). On `GT_INVALID` `*rate_dps` is 0.
//! `gt_coverage_of` is a port of `gyrotherm_core::coverage::CoverageMap::verdict_of` on the
//! compensator's latest features, the model's coverage map held as `static const` data;
//! `GT_NO_MAP` for a model without one.

use std::fmt::Write as _;

use gyrotherm_core::compensator::REBASE_AFTER;
use gyrotherm_core::features::{LagOutputs, HISTORY_STEPS, MAX_STEP_INDEX};
use gyrotherm_core::static_model::{StaticModel, StaticTarget};

use super::{f32_lit, f64_lit};

/// An f64 constant as C source (exact: shortest round-trip decimal).
fn d(v: f64) -> String {
    // `1e0` is a valid C floating constant.
    f64_lit(v)
}

/// An f32 constant as C source.
fn f(v: f32) -> String {
    format!("{}f", f32_lit(v))
}

fn join(v: impl IntoIterator<Item = String>) -> String {
    v.into_iter().collect::<Vec<_>>().join(", ")
}

/// The C source of one target's static data and its `target_def`.
fn target<const H: usize>(out: &mut String, name: &str, t: &StaticTarget<H>, nf: usize) {
    let mut base_ptr = "0".to_owned();
    let mut lstm_ptr = "0".to_owned();
    if let Some(b) = &t.baseline {
        let n = b.n_terms.max(1) as usize;
        let rows: Vec<String> = (0..n)
            .map(|j| {
                format!(
                    "{{{}}}",
                    join((0..nf).map(|i| if j < b.n_terms as usize {
                        b.powers[j][i].to_string()
                    } else {
                        "0".into()
                    }))
                )
            })
            .collect();
        let _ = writeln!(
            out,
            "static const unsigned char {name}_pow[{n}][GT_N_FEATURES] = {{\n    {}\n}};",
            rows.join(",\n    ")
        );
        let _ = writeln!(
            out,
            "static const double {name}_coef[{n}] = {{{}}};",
            join((0..n).map(|j| d(b.coefficients[j])))
        );
        let _ = writeln!(
            out,
            "static const base_def {name}_base = {{{}, {name}_pow, {name}_coef}};",
            b.n_terms
        );
        base_ptr = format!("&{name}_base");
    }
    if let Some(l) = &t.lstm {
        let ni = l.n_inputs as usize;
        // w_x[k][g*H+j] = w_ih[g][j][k]; w_h[m][g*H+j] = w_hh[g][j][m]; b = b_ih + b_hh (f32,
        // as Lstm::new adds them).
        let wx: Vec<String> = (0..ni)
            .map(|k| {
                format!(
                    "{{{}}}",
                    join(
                        (0..4)
                            .flat_map(|g| (0..H).map(move |j| (g, j)))
                            .map(|(g, j)| f(l.w_ih[g][j][k]))
                    )
                )
            })
            .collect();
        let wh: Vec<String> = (0..H)
            .map(|m| {
                format!(
                    "{{{}}}",
                    join(
                        (0..4)
                            .flat_map(|g| (0..H).map(move |j| (g, j)))
                            .map(|(g, j)| f(l.w_hh[g][j][m]))
                    )
                )
            })
            .collect();
        let b: Vec<String> = (0..4)
            .flat_map(|g| (0..H).map(move |j| (g, j)))
            .map(|(g, j)| f(l.b_ih[g][j] + l.b_hh[g][j]))
            .collect();
        let _ = writeln!(
            out,
            "static const float {name}_wx[{ni}][{}] = {{\n    {}\n}};",
            4 * H,
            wx.join(",\n    ")
        );
        let _ = writeln!(
            out,
            "static const float {name}_wh[{H}][{}] = {{\n    {}\n}};",
            4 * H,
            wh.join(",\n    ")
        );
        let _ = writeln!(
            out,
            "static const float {name}_b[{}] = {{{}}};",
            4 * H,
            b.join(", ")
        );
        let _ = writeln!(
            out,
            "static const float {name}_wout[{H}] = {{{}}};",
            join(l.w_out.iter().map(|v| f(*v)))
        );
        let _ = writeln!(
            out,
            "static const double {name}_mean[{ni}] = {{{}}};",
            join(l.input_mean[..ni].iter().map(|v| d(*v)))
        );
        let _ = writeln!(
            out,
            "static const double {name}_std[{ni}] = {{{}}};",
            join(l.input_std[..ni].iter().map(|v| d(*v)))
        );
        let _ = writeln!(
            out,
            "static const lstm_def {name}_lstm = {{{ni}, {name}_wx, {name}_wh, {name}_b, {name}_wout, {}, {name}_mean, {name}_std, {}, {}}};",
            f(l.b_out),
            d(l.target_mean),
            d(l.target_std)
        );
        lstm_ptr = format!("&{name}_lstm");
    }
    let _ = writeln!(
        out,
        "static const target_def {name}_target = {{{}, {base_ptr}, {lstm_ptr}, {}}};\n",
        d(t.offset),
        u8::from(t.lstm_reads_base && t.baseline.is_some() && t.lstm.is_some())
    );
}

/// The C source of the coverage map's static data (empty without a map).
fn coverage<const H: usize>(m: &StaticModel<H>) -> String {
    let Some(c) = &m.coverage else {
        return String::new();
    };
    let g = &c.grid;
    let rows: Vec<String> = (0..g.n_temp)
        .map(|i| {
            format!(
                "{{{}}}",
                join((0..g.n_rate).map(|j| d(c.sigma_dph[i * g.n_rate + j])))
            )
        })
        .collect();
    format!(
        "static const double COV_TEMP_MIN = {};\n\
         static const double COV_TEMP_CELL = {};\n\
         static const double COV_RATE_MIN = {};\n\
         static const double COV_RATE_CELL = {};\n\
         static const double COV_GROWTH = {};\n\
         #define COV_N_TEMP {}\n\
         #define COV_N_RATE {}\n\
         static const double COV_SIGMA[COV_N_TEMP][COV_N_RATE] = {{\n    {}\n}};\n\n",
        d(g.temp_min_c),
        d(g.temp_cell_c),
        d(g.rate_min_c_per_s),
        d(g.rate_cell_c_per_s),
        d(c.growth_per_cell),
        g.n_temp,
        g.n_rate,
        rows.join(",\n    ")
    )
}

/// What an axis that reads further sensors adds to the single-axis port (see
/// [`super::unit`]): text for the `@MORE_*@` places of the templates, each a whole line or
/// lines (or, for `plausible`, a condition to append); all empty for a one-sensor model, which
/// leaves the port as it is.
#[derive(Debug, Clone, Default)]
pub(crate) struct Hooks {
    /// Fields appended to `struct gt_state`.
    pub state: String,
    /// `&& ...`: the further sensors' readings are believed.
    pub plausible: String,
    /// Statements at the end of `rebase`.
    pub rebase: String,
    /// Statements after the first pipeline's push (`r` its result).
    pub push: String,
    /// Statements where a pushed sample is accepted.
    pub accepted: String,
    /// Statements after both models were evaluated (`vb`, `vk`).
    pub add: String,
}

/// `(header, source)`.
pub fn generate<const H: usize>(m: &StaticModel<H>, about: &str) -> (String, String) {
    generate_with(m, about, &Hooks::default())
}

/// [`generate`] with an axis's further sensors' hooks.
pub(crate) fn generate_with<const H: usize>(
    m: &StaticModel<H>,
    about: &str,
    hooks: &Hooks,
) -> (String, String) {
    let spec = &m.spec;
    let nf = spec.n_features();
    let n_lags = spec.lags().len();
    let lag_slots = n_lags.max(1);
    let p = spec.step_period_s;
    let rate_lag_steps = (spec.rate_lag_s / p).round() as u64;
    let window_steps = if spec.smoothing_window_s != 0.0 {
        (spec.smoothing_window_s / p).round() as u64
    } else {
        0
    };
    let taus: Vec<f64> = (0..lag_slots)
        .map(|j| spec.lags().get(j).copied().unwrap_or(1.0))
        .collect();
    // As FeaturePipeline::new: 1 - exp(-P/τ) = -expm1(-P/τ).
    let gains: Vec<f64> = taus.iter().map(|tau| -libm::expm1(-p / tau)).collect();
    let (levels, diffs) = match spec.lag_outputs {
        LagOutputs::Level => (1, 0),
        LagOutputs::DiffFromT => (0, 1),
        LagOutputs::Both => (1, 1),
    };
    let l = &m.limits;
    let header = HEADER
        .replace("@ABOUT@", about)
        .replace("@DEGRADED_S@", &l.degraded_after_s.to_string())
        .replace("@REBASE_AFTER@", &REBASE_AFTER.to_string())
        .replace("@SETTLE_S@", &spec.settle_s().to_string())
        .replace("@STEP_S@", &p.to_string())
        .replace("@NF@", &nf.to_string())
        .replace("@LAGS@", &lag_slots.to_string())
        .replace("@HIST@", &HISTORY_STEPS.to_string())
        .replace("@HIDDEN@", &H.to_string())
        .replace("@MORE_STATE@", &hooks.state)
        .replace(
            "@COVERAGE_NOTE@",
            &match &m.coverage {
                Some(c) => format!("a map of {} x {} cells", c.grid.n_temp, c.grid.n_rate),
                None => "none, so always GT_NO_MAP".to_owned(),
            },
        );
    let mut data = String::new();
    target(&mut data, "bias", &m.bias, nf);
    target(&mut data, "scale", &m.scale, nf);
    // The core's e^x constants (gyrotherm_core::lstm::exp), as the same f32 values.
    let poly: [f32; 7] = [
        1.0 / 720.0,
        1.0 / 120.0,
        1.0 / 24.0,
        1.0 / 6.0,
        0.5,
        1.0,
        1.0,
    ];
    let p7: f32 = 1.0 / 5_040.0;
    let source = SOURCE
        .replace("@ABOUT@", about)
        .replace("@N_LAGS@", &n_lags.to_string())
        .replace("@GATES@", &(4 * H).to_string())
        .replace("@GATE_F@", &H.to_string())
        .replace("@GATE_G@", &(2 * H).to_string())
        .replace("@GATE_O@", &(3 * H).to_string())
        .replace("@STEP_P@", &d(p))
        .replace(
            "@BOUNDARY_TOL@",
            &d(gyrotherm_core::features::BOUNDARY_TOL_STEPS),
        )
        .replace("@RATE_LAG_STEPS@", &rate_lag_steps.to_string())
        .replace("@WINDOW_STEPS@", &window_steps.to_string())
        .replace("@LAG_TAU@", &join(taus.iter().map(|v| d(*v))))
        .replace("@LAG_GAIN@", &join(gains.iter().map(|v| d(*v))))
        .replace("@LEVELS@", &levels.to_string())
        .replace("@DIFFS@", &diffs.to_string())
        .replace("@T_MIN@", &d(l.min_c))
        .replace("@T_MAX@", &d(l.max_c))
        .replace("@RATE_MAX@", &d(l.max_rate_c_per_s))
        .replace("@ALLOW@", &d(l.step_allowance_c))
        .replace("@DEGRADED@", &d(l.degraded_after_s))
        .replace("@SETTLE@", &d(spec.settle_s()))
        .replace("@MAX_STEP@", &d(MAX_STEP_INDEX as f64))
        .replace("@REBASE_AFTER@", &REBASE_AFTER.to_string())
        .replace("@LOG2E@", &f(core::f32::consts::LOG2_E))
        .replace("@LN2_HI@", &f(0.693_145_75))
        .replace("@LN2_LO@", &f(1.428_606_8e-6))
        .replace("@SHIFT@", &f(12_582_912.0))
        .replace("@P7@", &f(p7))
        .replace("@POLY@", &join(poly.iter().map(|v| f(*v))))
        .replace(
            "@HAS_COVERAGE@",
            &u8::from(m.coverage.is_some()).to_string(),
        )
        .replace("@MORE_REBASE@", &hooks.rebase)
        .replace("@MORE_PLAUSIBLE@", &hooks.plausible)
        .replace("@MORE_PUSH@", &hooks.push)
        .replace("@MORE_ACCEPTED@", &hooks.accepted)
        .replace("@MORE_ADD@", &hooks.add)
        .replace("@DATA@", &data)
        .replace("@COVERAGE@", &coverage(m));
    (header, source)
}

// The C port, kept as C files with `@NAME@` placeholders that `generate` fills with numbers
// and the generator's own words (so the port reads, and diffs, as C).
const HEADER: &str = include_str!("templates/gyrotherm_model.h.in");

const SOURCE: &str = include_str!("templates/gyrotherm_model.c.in");
