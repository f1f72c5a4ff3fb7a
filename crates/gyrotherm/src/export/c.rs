//! `--lang c`: `gyrotherm_model.h` and `gyrotherm_model.c`, C99, no heap, no global mutable
//! state; weights, scalers and limits as `static const`. The API (the header's complete
//! `gt_state` has a fixed size per model):
//!
//! ```c
//! typedef enum { GT_OK = 0, GT_HELD = 1, GT_DEGRADED = 2, GT_INVALID = 3 } gt_status;
//! void gt_init(gt_state *s);
//! gt_status gt_step(gt_state *s, double time_s, double gyro_dps, double temp_c,
//!                   double *rate_dps, double *bias_dps, double *scale);
//! ```
//!
//! `gt_step` is a line-by-line port of `gyrotherm_core::Compensator::step` (see the parent
//! module for what makes the numbers equal). On `GT_INVALID` `*rate_dps` is 0.

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
fn target(out: &mut String, name: &str, t: &StaticTarget, nf: usize) {
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
        // w_x[k][g*8+j] = w_ih[g][j][k]; w_h[m][g*8+j] = w_hh[g][j][m]; b = b_ih + b_hh (f32,
        // as Lstm::new adds them).
        let wx: Vec<String> = (0..ni)
            .map(|k| {
                format!(
                    "{{{}}}",
                    join(
                        (0..4)
                            .flat_map(|g| (0..8).map(move |j| (g, j)))
                            .map(|(g, j)| f(l.w_ih[g][j][k]))
                    )
                )
            })
            .collect();
        let wh: Vec<String> = (0..8)
            .map(|m| {
                format!(
                    "{{{}}}",
                    join(
                        (0..4)
                            .flat_map(|g| (0..8).map(move |j| (g, j)))
                            .map(|(g, j)| f(l.w_hh[g][j][m]))
                    )
                )
            })
            .collect();
        let b: Vec<String> = (0..4)
            .flat_map(|g| (0..8).map(move |j| (g, j)))
            .map(|(g, j)| f(l.b_ih[g][j] + l.b_hh[g][j]))
            .collect();
        let _ = writeln!(
            out,
            "static const float {name}_wx[{ni}][32] = {{\n    {}\n}};",
            wx.join(",\n    ")
        );
        let _ = writeln!(
            out,
            "static const float {name}_wh[8][32] = {{\n    {}\n}};",
            wh.join(",\n    ")
        );
        let _ = writeln!(
            out,
            "static const float {name}_b[32] = {{{}}};",
            b.join(", ")
        );
        let _ = writeln!(
            out,
            "static const float {name}_wout[8] = {{{}}};",
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

/// `(header, source)`.
pub fn generate(m: &StaticModel, about: &str) -> (String, String) {
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
        .replace("@HIST@", &HISTORY_STEPS.to_string());
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
        .replace("@DATA@", &data);
    (header, source)
}

const HEADER: &str = r#"/* gyrotherm_model.h: FOG thermal compensation, generated by `gyrotherm export --lang c`.
 * Model: @ABOUT@.
 * C99, no heap, no global mutable state. Do not edit: re-export instead.
 *
 * Use: one gt_state per gyro axis; gt_init once, then gt_step once per sample with the time
 * (s, increasing), the gyro output (deg/s) and the temperature (deg C, NaN if unread). It
 * always returns B (deg/s), K and, unless the status is GT_INVALID, the compensated rate
 * G = (gyro - B) / K:
 *   GT_OK       temperature accepted, B and K current;
 *   GT_HELD     this temperature sample was rejected (not finite, outside the plausible
 *               range, or changing faster than the rate limit) or its time stamp was not
 *               placed (below): features and LSTM states held, B and K last good;
 *   GT_DEGRADED held for longer than the limit on the degraded clock (or no good temperature
 *               yet: B = 0, K = 1), or settling on a new time base (B and K current);
 *   GT_INVALID  the gyro sample is not finite, or (gyro - B) / K is not: no rate
 *               (*rate_dps = 0).
 * Time axis (as gyrotherm-core's compensator module doc), with D = @DEGRADED_S@ s:
 *   placed      t finite and 0 < t - t_base <= D (or the first finite time): t_base = t, the
 *               candidate is dropped, the temperature is judged and used;
 *   not placed  t NaN or infinite, repeated, backward or more than D ahead: held (degraded
 *               below), temperature unused, B and K held; a finite t becomes the candidate
 *               (count 1, or one more when 0 < t - t_cand <= D); a non-finite t drops it;
 *   new base    when the candidate count reaches @REBASE_AFTER@: features, lags and LSTM states
 *               restart at this sample, the temperature history is forgotten, and the status
 *               is degraded for @SETTLE_S@ s from the new first step, then ok.
 *   A single bad time among good ones never re-bases. Degraded clock: degraded when
 *   (t_base - t_ok) + @STEP_S@ s * (samples since the last placed one) > D.
 * The numbers equal gyrotherm-core's (and `gyrotherm compensate --stream`'s) to the last bit
 * when compiled with -ffp-contract=off on IEEE 754 hardware with FLT_EVAL_METHOD == 0. */
#ifndef GYROTHERM_MODEL_H
#define GYROTHERM_MODEL_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define GT_N_FEATURES @NF@
#define GT_LAG_SLOTS @LAGS@
#define GT_HISTORY_STEPS @HIST@
#define GT_HIDDEN 8

typedef struct gt_state gt_state;

/* Complete type, fixed size: allocate it statically or on the stack; fields are private. */
struct gt_state {
    uint64_t hist_k[GT_HISTORY_STEPS]; /* feature steps kept (step index, temperature) */
    double hist_t[GT_HISTORY_STEPS];
    double lag_c[GT_LAG_SLOTS];        /* first-order thermal lags, deg C */
    double t0_s;                       /* first accepted sample's time */
    double pipe_last_s;                /* last accepted sample's time */
    uint64_t last_step;
    uint32_t hist_head;
    uint32_t hist_len;
    float lstm_h[2][GT_HIDDEN];        /* bias, scale LSTM states */
    float lstm_c[2][GT_HIDDEN];
    double held_bias;
    double held_scale;
    double base_s;                     /* time base: latest placed time stamp */
    double cand_s;                     /* candidate base: latest unplaced finite time */
    double settle_end_s;               /* after a new base: degraded before this time */
    double good_time_s;                /* latest accepted temperature and its time */
    double good_temp_c;
    double ok_time_s;                  /* latest sample with fresh B and K on this base */
    uint32_t unplaced;                 /* samples since the latest placed one */
    uint8_t cand_n;                    /* samples agreeing on the candidate */
    uint8_t started, has_held, current, has_base, has_cand, rebased, has_settle, has_good,
        has_ok;
};

typedef enum { GT_OK = 0, GT_HELD = 1, GT_DEGRADED = 2, GT_INVALID = 3 } gt_status;

void gt_init(gt_state *s);
gt_status gt_step(gt_state *s, double time_s, double gyro_dps, double temp_c,
                  double *rate_dps, double *bias_dps, double *scale);

#ifdef __cplusplus
}
#endif

#endif /* GYROTHERM_MODEL_H */
"#;

const SOURCE: &str = r#"/* gyrotherm_model.c: generated by `gyrotherm export --lang c`. Model: @ABOUT@.
 * A line-by-line port of gyrotherm-core (features.rs, baseline.rs, lstm.rs, compensator.rs):
 * same operations in the same order, so the same numbers. Do not edit: re-export instead. */
#include "gyrotherm_model.h"

#include <math.h>
#include <string.h>

#define N_LAGS @N_LAGS@
#define LAG_LEVELS @LEVELS@
#define LAG_DIFFS @DIFFS@

static const double STEP_P = @STEP_P@;
static const double BOUNDARY_TOL = @BOUNDARY_TOL@;
static const uint64_t RATE_LAG_STEPS = @RATE_LAG_STEPS@u;
static const uint64_t WINDOW_STEPS = @WINDOW_STEPS@u;
static const double LAG_TAU[GT_LAG_SLOTS] = {@LAG_TAU@};
static const double LAG_GAIN[GT_LAG_SLOTS] = {@LAG_GAIN@};
static const double T_MIN = @T_MIN@;
static const double T_MAX = @T_MAX@;
static const double RATE_MAX = @RATE_MAX@;
static const double STEP_ALLOWANCE = @ALLOW@;
static const double DEGRADED_AFTER = @DEGRADED@;
static const double SETTLE_S = @SETTLE@;
static const double MAX_STEP_INDEX = @MAX_STEP@;
#define REBASE_AFTER @REBASE_AFTER@u

typedef struct {
    int n_terms;
    const unsigned char (*pow)[GT_N_FEATURES];
    const double *coef;
} base_def;

typedef struct {
    int n_inputs;
    const float (*w_x)[32];
    const float (*w_h)[32];
    const float *b;
    const float *w_out;
    float b_out;
    const double *mean;
    const double *std;
    double t_mean;
    double t_std;
} lstm_def;

typedef struct {
    double offset;
    const base_def *base;
    const lstm_def *lstm;
    int reads_base;
} target_def;

@DATA@
static double d_from_bits(uint64_t u) { double v; memcpy(&v, &u, sizeof v); return v; }
static uint64_t d_to_bits(double v) { uint64_t u; memcpy(&u, &v, sizeof u); return u; }
static float f_from_bits(uint32_t u) { float v; memcpy(&v, &u, sizeof v); return v; }
static uint32_t f_to_bits(float v) { uint32_t u; memcpy(&u, &v, sizeof u); return u; }

/* expm1, ported from the libm crate (FreeBSD s_expm1.c), for bit-equal lag gains. */
static double gt_expm1(double x)
{
    const double O_THRESHOLD = 7.09782712893383973096e+02;
    const double LN2_HI = 6.93147180369123816490e-01;
    const double LN2_LO = 1.90821492927058770002e-10;
    const double INVLN2 = 1.44269504088896338700e+00;
    const double Q1 = -3.33333333333331316428e-02;
    const double Q2 = 1.58730158725481460165e-03;
    const double Q3 = -7.93650757867487942473e-05;
    const double Q4 = 4.00821782732936239552e-06;
    const double Q5 = -2.01099218183624371326e-07;
    double hi, lo, c, t, y, e, hfx, hxs, r1, twopk, uf;
    int32_t k;
    uint64_t ui = d_to_bits(x);
    uint32_t hx = (uint32_t)((ui >> 32) & 0x7fffffffu);
    int sign = (int)(ui >> 63);
    if (hx >= 0x4043687Au) {
        if (x != x) {
            return x;
        }
        if (sign != 0) {
            return -1.0;
        }
        if (x > O_THRESHOLD) {
            x *= d_from_bits(0x7fe0000000000000u);
            return x;
        }
    }
    if (hx > 0x3fd62e42u) {
        if (hx < 0x3FF0A2B2u) {
            if (sign == 0) {
                hi = x - LN2_HI;
                lo = LN2_LO;
                k = 1;
            } else {
                hi = x + LN2_HI;
                lo = -LN2_LO;
                k = -1;
            }
        } else {
            k = (int32_t)(INVLN2 * x + (sign != 0 ? -0.5 : 0.5));
            t = (double)k;
            hi = x - t * LN2_HI;
            lo = t * LN2_LO;
        }
        x = hi - lo;
        c = (hi - x) - lo;
    } else if (hx < 0x3c900000u) {
        return x;
    } else {
        c = 0.0;
        k = 0;
    }
    hfx = 0.5 * x;
    hxs = x * hfx;
    r1 = 1.0 + hxs * (Q1 + hxs * (Q2 + hxs * (Q3 + hxs * (Q4 + hxs * Q5))));
    t = 3.0 - r1 * hfx;
    e = hxs * ((r1 - t) / (6.0 - x * t));
    if (k == 0) {
        return x - (x * e - hxs);
    }
    e = x * (e - c) - c;
    e -= hxs;
    if (k == -1) {
        return 0.5 * (x - e) - 0.5;
    }
    if (k == 1) {
        if (x < -0.25) {
            return -2.0 * (e - (x + 0.5));
        }
        return 1.0 + 2.0 * (x - e);
    }
    twopk = d_from_bits((uint64_t)(0x3ff + k) << 52);
    if (k < 0 || k > 56) {
        y = x - e + 1.0;
        if (k == 1024) {
            y = y * 2.0 * d_from_bits(0x7fe0000000000000u);
        } else {
            y = y * twopk;
        }
        return y - 1.0;
    }
    uf = d_from_bits((uint64_t)(0x3ff - k) << 52);
    if (k < 20) {
        y = (x - e + (1.0 - uf)) * twopk;
    } else {
        y = (x - (e + uf) + 1.0) * twopk;
    }
    return y;
}

/* e^x in f32 as gyrotherm_core::lstm::exp: clamp, Cody-Waite reduction, degree-7 Taylor. */
static float gt_exp(float x)
{
    const float LOG2E = @LOG2E@;
    const float LN2_HI = @LN2_HI@;
    const float LN2_LO = @LN2_LO@;
    const float SHIFT = @SHIFT@;
    static const float POLY[7] = {@POLY@};
    float t, n, r, p;
    uint32_t bits;
    int i;
    if (x < -87.0f) {
        x = -87.0f;
    }
    if (x > 88.0f) {
        x = 88.0f;
    }
    t = x * LOG2E + SHIFT;
    n = t - SHIFT;
    r = (x - n * LN2_HI) - n * LN2_LO;
    p = @P7@;
    for (i = 0; i < 7; i++) {
        p = p * r + POLY[i];
    }
    bits = (f_to_bits(t) - f_to_bits(SHIFT) + 127u) << 23;
    return p * f_from_bits(bits);
}

static float gt_sigmoid(float z) { return 1.0f / (1.0f + gt_exp(-z)); }

/* One LSTM step (gyrotherm_core::lstm::Lstm::step); state untouched on failure. */
static int lstm_step(const lstm_def *d, float *h, float *c, const float *x, float *y_out)
{
    float z[32], cn[GT_HIDDEN], tc[GT_HIDDEN], hn[GT_HIDDEN], y;
    int i, j, k;
    for (k = 0; k < d->n_inputs; k++) {
        if (!isfinite(x[k])) {
            return 0;
        }
    }
    for (i = 0; i < 32; i++) {
        z[i] = d->b[i];
    }
    for (k = 0; k < d->n_inputs; k++) {
        for (i = 0; i < 32; i++) {
            z[i] += d->w_x[k][i] * x[k];
        }
    }
    for (k = 0; k < GT_HIDDEN; k++) {
        for (i = 0; i < 32; i++) {
            z[i] += d->w_h[k][i] * h[k];
        }
    }
    for (j = 0; j < GT_HIDDEN; j++) {
        z[16 + j] *= 2.0f;
    }
    for (i = 0; i < 32; i++) {
        z[i] = gt_sigmoid(z[i]);
    }
    for (j = 0; j < GT_HIDDEN; j++) {
        cn[j] = z[8 + j] * c[j] + z[j] * (2.0f * z[16 + j] - 1.0f);
        tc[j] = 2.0f * cn[j];
    }
    for (j = 0; j < GT_HIDDEN; j++) {
        tc[j] = gt_sigmoid(tc[j]);
    }
    y = d->b_out;
    for (j = 0; j < GT_HIDDEN; j++) {
        hn[j] = z[24 + j] * (2.0f * tc[j] - 1.0f);
        y += d->w_out[j] * hn[j];
    }
    if (!isfinite(y)) {
        return 0;
    }
    memcpy(h, hn, sizeof hn);
    memcpy(c, cn, sizeof cn);
    *y_out = y;
    return 1;
}

/* NormalisedLstm::step. */
static int norm_lstm(const lstm_def *d, float *h, float *c, const double *f, double *out)
{
    float x[GT_N_FEATURES + 1], y;
    int k;
    for (k = 0; k < d->n_inputs; k++) {
        double z = (f[k] - d->mean[k]) / d->std[k];
        if (!isfinite(z)) {
            return 0;
        }
        x[k] = (float)z;
    }
    if (!lstm_step(d, h, c, x, &y)) {
        return 0;
    }
    *out = d->t_mean + d->t_std * (double)y;
    return 1;
}

/* BaselineModel::eval. */
static int base_eval(const base_def *b, const double *x, double *out)
{
    double y = 0.0, m;
    int i, j, p;
    for (i = 0; i < GT_N_FEATURES; i++) {
        if (!isfinite(x[i])) {
            return 0;
        }
    }
    for (j = 0; j < b->n_terms; j++) {
        m = b->coef[j];
        for (i = 0; i < GT_N_FEATURES; i++) {
            for (p = 0; p < b->pow[j][i]; p++) {
                m *= x[i];
            }
        }
        y += m;
    }
    if (!isfinite(y)) {
        return 0;
    }
    *out = y;
    return 1;
}

/* TargetModel::eval. */
static int target_eval(const target_def *t, float *h, float *c, const double *f, double *out)
{
    double y = t->offset, base = 0.0, l;
    if (t->base != 0) {
        if (!base_eval(t->base, f, &base)) {
            return 0;
        }
        y += base;
    }
    if (t->lstm != 0) {
        if (t->reads_base) {
            double xb[GT_N_FEATURES + 1];
            int i;
            for (i = 0; i < GT_N_FEATURES; i++) {
                xb[i] = f[i];
            }
            xb[GT_N_FEATURES] = base;
            if (!norm_lstm(t->lstm, h, c, xb, &l)) {
                return 0;
            }
        } else if (!norm_lstm(t->lstm, h, c, f, &l)) {
            return 0;
        }
        y += l;
    }
    if (!isfinite(y)) {
        return 0;
    }
    *out = y;
    return 1;
}

/* The i-th newest stored step (FeaturePipeline::hist_back). */
static uint32_t hist_back(const gt_state *s, uint32_t i)
{
    uint32_t back = s->hist_head + GT_HISTORY_STEPS - 1u - (i < GT_HISTORY_STEPS - 1u ? i : GT_HISTORY_STEPS - 1u);
    return back >= GT_HISTORY_STEPS ? back - GT_HISTORY_STEPS : back;
}

/* FeaturePipeline::emit: advance to step k, n steps after the previous one, value t. */
static void emit(gt_state *s, uint64_t k, uint64_t n, double t, double *feat)
{
    uint32_t e, i;
    int j, at = 0;
    double rate;
    for (j = 0; j < N_LAGS; j++) {
        double gain;
        if (n == 1u) {
            gain = LAG_GAIN[j];
        } else if (n == 0u) {
            gain = 0.0;
        } else {
            gain = -gt_expm1(-(double)n * STEP_P / LAG_TAU[j]);
        }
        s->lag_c[j] += gain * (t - s->lag_c[j]);
    }
    s->hist_k[s->hist_head] = k;
    s->hist_t[s->hist_head] = t;
    s->hist_head = s->hist_head + 1u == GT_HISTORY_STEPS ? 0u : s->hist_head + 1u;
    s->hist_len = s->hist_len + 1u < GT_HISTORY_STEPS ? s->hist_len + 1u : GT_HISTORY_STEPS;
    e = hist_back(s, s->hist_len - 1u);
    if (k >= RATE_LAG_STEPS) {
        uint64_t target = k - RATE_LAG_STEPS;
        uint32_t l = (uint32_t)RATE_LAG_STEPS;
        uint32_t direct = hist_back(s, l);
        if (l < s->hist_len && s->hist_k[direct] == target) {
            e = direct;
        } else {
            for (i = 1u; i < s->hist_len; i++) {
                uint32_t c = hist_back(s, i);
                if (s->hist_k[c] <= target) {
                    e = c;
                    break;
                }
            }
        }
    }
    if (s->hist_k[e] < k) {
        rate = (t - s->hist_t[e]) / ((double)(k - s->hist_k[e]) * STEP_P);
    } else {
        rate = 0.0;
    }
    feat[at++] = t;
    feat[at++] = rate;
    if (WINDOW_STEPS > 0u) {
        double sum = 0.0;
        uint32_t count = 0u;
        for (i = 0u; i < s->hist_len; i++) {
            uint32_t c = hist_back(s, i);
            if (k - s->hist_k[c] >= WINDOW_STEPS) {
                break;
            }
            sum += s->hist_t[c];
            count++;
        }
        feat[at++] = sum / (double)(count > 0u ? count : 1u);
    }
    if (LAG_LEVELS) {
        for (j = 0; j < N_LAGS; j++) {
            feat[at++] = s->lag_c[j];
        }
    }
    if (LAG_DIFFS) {
        for (j = 0; j < N_LAGS; j++) {
            feat[at++] = t - s->lag_c[j];
        }
    }
}

/* FeaturePipeline::push: 1 new step (features in feat), 0 holding, -1 refused, -2 time out
 * of range (the step index would reach MAX_STEP_INDEX). */
static int pipe_push(gt_state *s, double time_s, double temp_c, double *feat)
{
    uint64_t k, n;
    double q;
    int j;
    if (!isfinite(time_s) || !isfinite(temp_c)) {
        return -1;
    }
    if (!s->started) {
        s->started = 1u;
        s->t0_s = time_s;
        s->pipe_last_s = time_s;
        s->last_step = 0u;
        for (j = 0; j < GT_LAG_SLOTS; j++) {
            s->lag_c[j] = temp_c;
        }
        s->hist_len = 0u;
        s->hist_head = 0u;
        emit(s, 0u, 0u, temp_c, feat);
        return 1;
    }
    if (time_s <= s->pipe_last_s) {
        return -1;
    }
    q = (time_s - s->t0_s) / STEP_P + BOUNDARY_TOL;
    if (q >= MAX_STEP_INDEX) {
        return -2;
    }
    k = (uint64_t)floor(q);
    s->pipe_last_s = time_s;
    if (k <= s->last_step) {
        return 0;
    }
    n = k - s->last_step;
    s->last_step = k;
    emit(s, k, n, temp_c, feat);
    return 1;
}

/* Compensator::rebase: restart the pipeline and the LSTM states, forget the temperature
 * history; B and K stay held until the new pipeline's first step. */
static void rebase(gt_state *s)
{
    int j;
    s->hist_head = 0u;
    s->hist_len = 0u;
    for (j = 0; j < GT_LAG_SLOTS; j++) {
        s->lag_c[j] = 0.0;
    }
    s->started = 0u;
    s->last_step = 0u;
    memset(s->lstm_h, 0, sizeof s->lstm_h);
    memset(s->lstm_c, 0, sizeof s->lstm_c);
    s->current = 0u;
    s->has_good = 0u;
    s->has_ok = 0u;
    s->rebased = 1u;
    s->has_settle = 0u;
}

/* Compensator::place: whether time_s is placed on the time base (the time axis in the
 * header), re-basing when the candidate has gathered REBASE_AFTER samples. */
static int place(gt_state *s, double time_s)
{
    uint8_t n = 1u;
    if (!isfinite(time_s)) {
        s->has_cand = 0u;
        if (s->unplaced < UINT32_MAX) {
            s->unplaced++;
        }
        return 0;
    }
    if (!s->has_base || (time_s > s->base_s && time_s - s->base_s <= DEGRADED_AFTER)) {
        s->has_base = 1u;
        s->base_s = time_s;
        s->unplaced = 0u;
        s->has_cand = 0u;
        return 1;
    }
    if (s->has_cand && time_s > s->cand_s && time_s - s->cand_s <= DEGRADED_AFTER) {
        n = s->cand_n < 255u ? (uint8_t)(s->cand_n + 1u) : 255u;
    }
    if (n >= REBASE_AFTER) {
        rebase(s);
        s->has_base = 1u;
        s->base_s = time_s;
        s->unplaced = 0u;
        s->has_cand = 0u;
        return 1;
    }
    s->has_cand = 1u;
    s->cand_s = time_s;
    s->cand_n = n;
    if (s->unplaced < UINT32_MAX) {
        s->unplaced++;
    }
    return 0;
}

/* Compensator::plausible. */
static int plausible(const gt_state *s, double time_s, double temp_c)
{
    if (!(temp_c >= T_MIN && temp_c <= T_MAX)) {
        return 0;
    }
    if (s->has_good) {
        double allowed = RATE_MAX * (time_s - s->good_time_s) + STEP_ALLOWANCE;
        return fabs(temp_c - s->good_temp_c) <= allowed;
    }
    return 1;
}

/* Compensator::eval: both models on a new step; keep B and K only if both are usable. */
static int eval(gt_state *s, const double *feat)
{
    int ok_b, ok_k;
    double vb = 0.0, vk = 0.0;
    s->current = 0u;
    ok_b = target_eval(&bias_target, s->lstm_h[0], s->lstm_c[0], feat, &vb);
    ok_k = target_eval(&scale_target, s->lstm_h[1], s->lstm_c[1], feat, &vk);
    if (!(ok_b && ok_k)) {
        return 0;
    }
    if (!(vk > 0.0 && isfinite(vb) && isfinite(vk))) {
        return 0;
    }
    s->held_bias = vb;
    s->held_scale = vk;
    s->has_held = 1u;
    s->current = 1u;
    return 1;
}

/* Compensator::push: a placed, believed sample into the pipeline; 1 when B and K are fresh. */
static int push(gt_state *s, double time_s, double temp_c)
{
    double feat[GT_N_FEATURES];
    int r = pipe_push(s, time_s, temp_c, feat);
    if (r == -2) {
        /* Steps can no longer be counted exactly on this base: start a new one here. */
        rebase(s);
        r = pipe_push(s, time_s, temp_c, feat);
    }
    if (r == 1) {
        s->has_good = 1u;
        s->good_time_s = time_s;
        s->good_temp_c = temp_c;
        if (s->rebased) {
            s->rebased = 0u;
            s->has_settle = 1u;
            s->settle_end_s = time_s + SETTLE_S;
        }
        return eval(s, feat);
    }
    if (r == 0) {
        s->has_good = 1u;
        s->good_time_s = time_s;
        s->good_temp_c = temp_c;
        return s->current;
    }
    return 0;
}

void gt_init(gt_state *s)
{
    memset(s, 0, sizeof *s);
}

gt_status gt_step(gt_state *s, double time_s, double gyro_dps, double temp_c,
                  double *rate_dps, double *bias_dps, double *scale)
{
    double b = 0.0, k = 1.0;
    int fresh = 0, settling = 0;
    gt_status status;
    if (place(s, time_s) && plausible(s, time_s, temp_c)) {
        fresh = push(s, time_s, temp_c);
    }
    if (fresh) {
        s->has_ok = 1u;
        s->ok_time_s = s->base_s;
    }
    if (s->has_held) {
        b = s->held_bias;
        k = s->held_scale;
    }
    if (s->has_settle && s->has_base) {
        settling = s->base_s < s->settle_end_s;
    }
    /* A finite sample so large that (gyro - B) / K overflows has no rate either. */
    if (!(isfinite(gyro_dps) && isfinite((gyro_dps - b) / k))) {
        status = GT_INVALID;
    } else if (settling) {
        status = GT_DEGRADED;
    } else if (fresh) {
        status = GT_OK;
    } else {
        double unplaced_s = STEP_P * (double)s->unplaced;
        if (s->has_ok && s->has_base
            && (s->base_s - s->ok_time_s) + unplaced_s <= DEGRADED_AFTER) {
            status = GT_HELD;
        } else {
            status = GT_DEGRADED;
        }
    }
    *bias_dps = b;
    *scale = k;
    *rate_dps = status == GT_INVALID ? 0.0 : (gyro_dps - b) / k;
    return status;
}
"#;
