//! Kalibr's IMU noise file (`imu.yaml`, the `--imu` file of `kalibr_calibrate_imu_camera`):
//! the gyro's continuous-time noise figures read from its Allan deviation curve, as the
//! Kalibr wiki ("IMU Noise Model") and IEEE Std 952-1997 annex C define them.
//!
//! - `gyroscope_noise_density`, rad/s/√Hz: the white rate noise N, σ(τ) = N/√τ, so N is the
//!   value at τ = 1 s of the slope −½ line ([`super::noise_terms`]'s angle random walk).
//! - `gyroscope_random_walk`, rad/s²/√Hz: the rate random walk K, σ(τ) = K·√(τ/3), so K is the
//!   value at τ = 3 s of the slope +½ line (its rate random walk).
//! - `update_rate`, Hz: the log's sample rate, 1/τ0, to six significant digits.
//! - `rostopic`: the IMU topic Kalibr reads from the bag (a setting).
//!
//! Each line is fitted with its slope fixed over the run of points that lie on it (see
//! [`super::noise_terms`]), not over a fixed τ range: a slope-½ line fitted through the
//! white-noise part too would read K too high. The accelerometer's keys are absent: a gyro
//! log measures no accelerometer; the file says so in a comment.
//!
//! **Bounds.** Each figure is `exp(c)` read off a line `ln σ = slope·ln τ + c`, with c the
//! EDF-weighted mean of `ln σ_i − slope·ln τ_i` over the line's points. From the χ² law of
//! σ², `ln σ_i` has standard deviation `1/√(2·EDF_i)`; the points of one curve are correlated
//! (they share samples), and the standard deviation of a weighted mean of correlated values
//! is at most the weighted mean of theirs (equality when fully correlated). That bound,
//! `s_c`, gives the line an EDF of `1/(2·s_c²)`, never more than its best point's, and the
//! 68.3 % bounds follow from χ² with that EDF as for any single point
//! ([`super::confidence`]).

use super::{chi2_inv, AllanPoint, NoiseTerm, NoiseTerms, ONE_SIGMA_CI};

/// °/h to rad/s.
const RAD_S_PER_DPH: f64 = std::f64::consts::PI / 180.0 / 3600.0;

/// One figure of the file, with its 68.3 % bounds.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct KalibrTerm {
    /// The figure (rad/s/√Hz for the noise density, rad/s²/√Hz for the random walk).
    pub value: f64,
    /// Lower and upper 68.3 % bounds, same unit (NaN when the line's points have no EDF).
    pub lo: f64,
    pub hi: f64,
    /// The line's EDF (see the module doc; NaN when its points have none).
    pub edf: f64,
    /// τ the line is read at, s.
    pub tau_read_s: f64,
    /// τ range of the points the line was fitted to, s.
    pub fit_tau_min_s: f64,
    pub fit_tau_max_s: f64,
}

/// The figures of the file.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct KalibrNoise {
    /// `gyroscope_noise_density`, rad/s/√Hz.
    pub noise_density: KalibrTerm,
    /// `gyroscope_random_walk`, rad/s²/√Hz.
    pub random_walk: KalibrTerm,
    /// `update_rate`, Hz.
    pub update_rate_hz: f64,
}

/// Why the file cannot be written.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum KalibrError {
    /// The curve has no run of points of this slope, so the figure cannot be read.
    NoRegion {
        key: &'static str,
        slope: &'static str,
    },
    /// The sample period gives no rate.
    SamplePeriod(f64),
}

impl std::fmt::Display for KalibrError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            KalibrError::NoRegion { key, slope } => write!(
                f,
                "{key}: the Allan deviation curve has no region of slope {slope} to read it \
                 from (for the noise density, a finer τ0; for the random walk, a longer log)"
            ),
            KalibrError::SamplePeriod(p) => {
                write!(f, "sample period {p} s gives no update rate")
            }
        }
    }
}

impl std::error::Error for KalibrError {}

/// The line's EDF and bounds for a figure read off `term` (its value already converted to
/// `value`), from the curve's points in the term's fitted τ range.
fn bounded(points: &[AllanPoint], term: &NoiseTerm, value: f64) -> KalibrTerm {
    let on_line: Vec<&AllanPoint> = points
        .iter()
        .filter(|p| {
            p.dev.is_finite()
                && p.dev > 0.0
                && p.tau_s >= term.fit_tau_min_s
                && p.tau_s <= term.fit_tau_max_s
        })
        .collect();
    let has_edf = !on_line.is_empty() && on_line.iter().all(|p| p.edf.is_finite() && p.edf > 0.0);
    let edf = if has_edf {
        let w: f64 = on_line.iter().map(|p| p.edf).sum();
        let s_c = on_line
            .iter()
            .map(|p| p.edf * (1.0 / (2.0 * p.edf)).sqrt())
            .sum::<f64>()
            / w;
        1.0 / (2.0 * s_c * s_c)
    } else {
        f64::NAN
    };
    let (lo, hi) = if edf.is_finite() && edf > 0.0 {
        let lo_q = (1.0 - ONE_SIGMA_CI) / 2.0;
        (
            value * (edf / chi2_inv(1.0 - lo_q, edf)).sqrt(),
            value * (edf / chi2_inv(lo_q, edf)).sqrt(),
        )
    } else {
        (f64::NAN, f64::NAN)
    };
    KalibrTerm {
        value,
        lo,
        hi,
        edf,
        tau_read_s: term.tau_read_s,
        fit_tau_min_s: term.fit_tau_min_s,
        fit_tau_max_s: term.fit_tau_max_s,
    }
}

/// `gyroscope_noise_density` (rad/s/√Hz) from the curve `points` and its noise terms (None:
/// no slope −½ region).
pub fn noise_density(points: &[AllanPoint], terms: &NoiseTerms) -> Option<KalibrTerm> {
    // ARW N[°/√h] = σ[°/h at 1 s]/60.
    let t = terms.arw_deg_rt_h?;
    Some(bounded(points, &t, t.value * 60.0 * RAD_S_PER_DPH))
}

/// `gyroscope_random_walk` (rad/s²/√Hz) from the curve `points` and its noise terms (None:
/// no slope +½ region).
pub fn random_walk(points: &[AllanPoint], terms: &NoiseTerms) -> Option<KalibrTerm> {
    // RRW K[°/h/√h] = 60·σ[°/h at 3 s].
    let t = terms.rrw_deg_h_rt_h?;
    Some(bounded(points, &t, t.value / 60.0 * RAD_S_PER_DPH))
}

/// The figures of a rate log's Allan deviation curve (ADEV or OADEV) `points`, its noise
/// terms `terms` (from [`super::noise_terms`]), and its sample period `tau0_s`.
pub fn kalibr_noise(
    points: &[AllanPoint],
    terms: &NoiseTerms,
    tau0_s: f64,
) -> Result<KalibrNoise, KalibrError> {
    // Six significant digits: time stamps such as i·0.01 give τ0 a round-off in the 13th
    // digit that would otherwise show as 100.00000000000909 Hz.
    let update_rate_hz: f64 = format!("{:.5e}", 1.0 / tau0_s).parse().unwrap_or(f64::NAN);
    if !(update_rate_hz.is_finite() && update_rate_hz > 0.0) {
        return Err(KalibrError::SamplePeriod(tau0_s));
    }
    let noise_density = noise_density(points, terms).ok_or(KalibrError::NoRegion {
        key: "gyroscope_noise_density",
        slope: "-1/2",
    })?;
    let random_walk = random_walk(points, terms).ok_or(KalibrError::NoRegion {
        key: "gyroscope_random_walk",
        slope: "+1/2",
    })?;
    Ok(KalibrNoise {
        noise_density,
        random_walk,
        update_rate_hz,
    })
}

/// A number as a YAML float every YAML reader takes as one: the shortest round-trip digits,
/// with a `.` in the mantissa and a signed exponent (YAML 1.1, which PyYAML and so Kalibr
/// follow, reads `1e-5` as a string).
pub(crate) fn yaml_float(v: f64) -> String {
    let s = format!("{v:e}");
    let (mant, exp) = s.split_once('e').unwrap_or((&s, "0"));
    let mant = if mant.contains('.') {
        mant.to_owned()
    } else {
        format!("{mant}.0")
    };
    let exp = if exp.starts_with('-') {
        exp.to_owned()
    } else {
        format!("+{exp}")
    };
    format!("{mant}e{exp}")
}

/// A bound for a comment: the number, or words when there is none.
fn bound_text(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.4e}")
    } else {
        "not available (no EDF)".to_owned()
    }
}

/// The file's text: comments stating every unit and how each figure was read, the gyro keys,
/// `update_rate` and `rostopic` (a name checked by
/// [`crate::settings::kalibr::parse_rostopic`]). Only the generator's words and numbers
/// besides the topic.
pub fn kalibr_yaml(n: &KalibrNoise, rostopic: &str) -> String {
    let nd = &n.noise_density;
    let rw = &n.random_walk;
    let mut t = String::new();
    t.push_str(
        "# Kalibr IMU noise model, written by gyrotherm allan --kalibr\n\
         # Read from the gyro's Allan deviation curve (IEEE Std 952-1997 annex C; Kalibr wiki,\n\
         # IMU Noise Model): continuous-time figures.\n",
    );
    t.push_str(&format!(
        "# gyroscope_noise_density: rad/s/sqrt(Hz), white rate noise N = Allan deviation at\n\
         #   tau = 1 s on the slope -1/2 line fitted over tau {} .. {} s;\n\
         #   68.3 % bounds {} .. {} (Greenhall EDF {:.1})\n",
        nd.fit_tau_min_s,
        nd.fit_tau_max_s,
        bound_text(nd.lo),
        bound_text(nd.hi),
        nd.edf
    ));
    t.push_str(&format!(
        "# gyroscope_random_walk: rad/s^2/sqrt(Hz), rate random walk K = Allan deviation at\n\
         #   tau = 3 s on the slope +1/2 line fitted over tau {} .. {} s;\n\
         #   68.3 % bounds {} .. {} (Greenhall EDF {:.1})\n",
        rw.fit_tau_min_s,
        rw.fit_tau_max_s,
        bound_text(rw.lo),
        bound_text(rw.hi),
        rw.edf
    ));
    t.push_str(
        "# update_rate: Hz, the log's sample rate\n\
         # rostopic: the IMU topic in the bag\n\
         # accelerometer_noise_density and accelerometer_random_walk: not measured (a gyro log);\n\
         #   Kalibr needs them: add them from the accelerometer's own Allan deviation curve\n",
    );
    t.push_str(&format!(
        "gyroscope_noise_density: {}\n",
        yaml_float(nd.value)
    ));
    t.push_str(&format!(
        "gyroscope_random_walk: {}\n",
        yaml_float(rw.value)
    ));
    t.push_str(&format!("update_rate: {}\n", yaml_float(n.update_rate_hz)));
    t.push_str(&format!("rostopic: {rostopic}\n"));
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn yaml_floats_have_a_dot_and_a_signed_exponent() {
        assert_eq!(yaml_float(1e-5), "1.0e-5");
        assert_eq!(yaml_float(1.25e-7), "1.25e-7");
        assert_eq!(yaml_float(100.0), "1.0e+2");
        assert_eq!(yaml_float(0.5), "5.0e-1");
        assert_eq!(yaml_float(1.0), "1.0e+0");
        for v in [1e-5, 1.25e-7, 100.0, 2.0 / 3.0, 400.0] {
            assert_eq!(yaml_float(v).parse::<f64>().unwrap(), v);
        }
    }
}
