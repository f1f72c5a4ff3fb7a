//! Gyro noise terms read from an Allan deviation curve (IEEE Std 952-1997 Annex C).
//!
//! On a log-log plot each term shows as a straight line of known slope:
//! - angle random walk N: σ = N/√τ (slope −1/2), N = σ(τ = 1 s); in °/√h,
//!   N = σ[°/h at 1 s]/60.
//! - bias instability B: flat part, σ_min = B·√(2 ln 2/π) = 0.6643·B (°/h).
//! - rate random walk K: σ = K·√(τ/3) (slope +1/2), K = σ(τ = 3 s) in °/s/√s; in °/h/√h,
//!   K = 60·σ[°/h at 3 s].
//! - quantization Q: σ = √3·Q/τ (slope −1), Q = σ(τ = √3 s) in °; reported in arcsec.
//! - rate ramp R: σ = R·τ/√2 (slope +1), R = σ(τ = √2 s) in °/s²; reported in °/h².
//!
//! Each line is fitted with its slope fixed (least squares in log σ, weighted by each point's
//! EDF) over the contiguous run of points whose local slope (mean of the two neighbouring
//! segments) is within ±[`SLOPE_TOL`] of the term's slope; of several runs the one with the
//! largest total EDF is used. B is read at the lowest point of the flat region (every point
//! whose local slope is within the tolerance of 0), wherever it lies. A term with no such
//! point is None.

use super::AllanPoint;

/// How far the local log-log slope may be from a term's slope for a point to be used.
pub(crate) const SLOPE_TOL: f64 = 0.2;

/// One noise term.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct NoiseTerm {
    /// The coefficient, in the unit named by the field holding it.
    pub value: f64,
    /// τ the coefficient is read at on the fitted line (or the τ of σ_min), s.
    pub tau_read_s: f64,
    /// τ range of the points the line was fitted to, s.
    pub fit_tau_min_s: f64,
    pub fit_tau_max_s: f64,
}

/// All five terms; None where the curve shows no region of that slope.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct NoiseTerms {
    /// Angle random walk, °/√h.
    pub arw_deg_rt_h: Option<NoiseTerm>,
    /// Bias instability, °/h.
    pub bias_instability_dph: Option<NoiseTerm>,
    /// Rate random walk, °/h/√h.
    pub rrw_deg_h_rt_h: Option<NoiseTerm>,
    /// Quantization noise, arcsec.
    pub quantization_arcsec: Option<NoiseTerm>,
    /// Rate ramp, °/h².
    pub rate_ramp_deg_h2: Option<NoiseTerm>,
}

/// Local slope at each point: mean of the slopes of the segments touching it.
fn local_slopes(pts: &[LogPoint]) -> Vec<f64> {
    let seg: Vec<f64> = pts
        .windows(2)
        .map(|w| (w[1].ln_sigma - w[0].ln_sigma) / (w[1].ln_tau - w[0].ln_tau))
        .collect();
    (0..pts.len())
        .map(|i| {
            let left = i.checked_sub(1).and_then(|j| seg.get(j));
            let right = seg.get(i);
            match (left, right) {
                (Some(a), Some(b)) => 0.5 * (a + b),
                (Some(a), None) | (None, Some(a)) => *a,
                (None, None) => f64::NAN,
            }
        })
        .collect()
}

/// A point of the curve in natural logs, with its fit weight (EDF, or terms when no EDF).
#[derive(Debug, Clone, Copy)]
struct LogPoint {
    ln_tau: f64,
    ln_sigma: f64,
    weight: f64,
}

/// Contiguous runs of points whose local slope is near `slope`; the heaviest run (largest
/// total weight, i.e. the best-determined part of the curve) is kept.
fn best_run(pts: &[LogPoint], local: &[f64], slope: f64) -> Option<std::ops::Range<usize>> {
    let mut best: Option<(f64, std::ops::Range<usize>)> = None;
    let mut i = 0;
    // A NaN local slope is near nothing (and must not stop the scan).
    let near = |i: usize| (local[i] - slope).abs() <= SLOPE_TOL;
    while i < pts.len() {
        if !near(i) {
            i += 1;
            continue;
        }
        let start = i;
        while i < pts.len() && near(i) {
            i += 1;
        }
        let w: f64 = pts[start..i].iter().map(|p| p.weight).sum();
        if best.as_ref().is_none_or(|(bw, _)| w > *bw) {
            best = Some((w, start..i));
        }
    }
    best.map(|(_, r)| r)
}

/// Fits log σ = slope·log τ + c (weighted least squares with the slope fixed) over the best
/// run of points near `slope`; returns σ at `tau_read_s` on that line and the fitted τ range.
fn fixed_slope_read(
    pts: &[LogPoint],
    local: &[f64],
    slope: f64,
    tau_read_s: f64,
) -> Option<(f64, f64, f64)> {
    let run = best_run(pts, local, slope)?;
    let sel = &pts[run];
    let wsum: f64 = sel.iter().map(|p| p.weight).sum();
    let c = sel
        .iter()
        .map(|p| p.weight * (p.ln_sigma - slope * p.ln_tau))
        .sum::<f64>()
        / wsum;
    let sigma = (c + slope * tau_read_s.ln()).exp();
    Some((sigma, sel[0].ln_tau.exp(), sel[sel.len() - 1].ln_tau.exp()))
}

/// Bias instability: the lowest σ of the flat region, i.e. of every point whose local slope
/// is within ±[`SLOPE_TOL`] of 0 (IEEE Std 952 reads B at the curve's flat minimum). Not the
/// heaviest flat run: at short τ the points carry the most EDF, so a short bump there (a
/// local maximum, slope 0) would outweigh the floor at long τ and be read as B. The fit
/// range is the flat run holding that point.
fn bias_instability(pts: &[LogPoint], local: &[f64]) -> Option<NoiseTerm> {
    let flat = |i: usize| (local[i] - 0.0).abs() <= SLOPE_TOL;
    let min = (0..pts.len())
        .filter(|&i| flat(i))
        .min_by(|&a, &b| pts[a].ln_sigma.total_cmp(&pts[b].ln_sigma))?;
    let (mut lo, mut hi) = (min, min);
    while lo > 0 && flat(lo - 1) {
        lo -= 1;
    }
    while hi + 1 < pts.len() && flat(hi + 1) {
        hi += 1;
    }
    Some(NoiseTerm {
        value: pts[min].ln_sigma.exp()
            / (2.0 * std::f64::consts::LN_2 / std::f64::consts::PI).sqrt(),
        tau_read_s: pts[min].ln_tau.exp(),
        fit_tau_min_s: pts[lo].ln_tau.exp(),
        fit_tau_max_s: pts[hi].ln_tau.exp(),
    })
    .filter(|t| t.value.is_finite())
}

/// Noise terms from an ADEV/OADEV curve. `to_dph` converts the curve's unit to °/h
/// (3600 for °/s, 1 for °/h, 3600·180/π for rad/s). Points with non-finite or non-positive
/// σ are ignored.
pub fn noise_terms(points: &[AllanPoint], to_dph: f64) -> NoiseTerms {
    let mut pts: Vec<LogPoint> = points
        .iter()
        .filter(|p| p.dev.is_finite() && p.dev > 0.0 && p.tau_s.is_finite() && p.tau_s > 0.0)
        .map(|p| LogPoint {
            ln_tau: p.tau_s.ln(),
            ln_sigma: (p.dev * to_dph).ln(),
            weight: if p.edf.is_finite() && p.edf > 0.0 {
                p.edf
            } else {
                p.n.max(1) as f64
            },
        })
        .collect();
    pts.sort_by(|a, b| a.ln_tau.total_cmp(&b.ln_tau));
    pts.dedup_by(|a, b| a.ln_tau == b.ln_tau);
    if pts.len() < 2 {
        return NoiseTerms::default();
    }
    let local = local_slopes(&pts);
    // A term read off so far along its line that it is beyond f64 is not reported.
    let term = |slope: f64, tau: f64, scale: f64| {
        fixed_slope_read(&pts, &local, slope, tau)
            .map(|(s, lo, hi)| NoiseTerm {
                value: s * scale,
                tau_read_s: tau,
                fit_tau_min_s: lo,
                fit_tau_max_s: hi,
            })
            .filter(|t| t.value.is_finite())
    };
    // σ in °/h throughout.
    let arw = term(-0.5, 1.0, 1.0 / 60.0);
    let rrw = term(0.5, 3.0, 60.0);
    let quant = term(-1.0, 3f64.sqrt(), 1.0); // σ[°/h at √3 s] = Q[°]·3600 = Q[arcsec]
    let ramp = term(1.0, 2f64.sqrt(), 3600.0); // R[°/h²] = σ[°/s²]·3600² = σ[°/h]·3600
    let bias = bias_instability(&pts, &local);
    NoiseTerms {
        arw_deg_rt_h: arw,
        bias_instability_dph: bias,
        rrw_deg_h_rt_h: rrw,
        quantization_arcsec: quant,
        rate_ramp_deg_h2: ramp,
    }
}
