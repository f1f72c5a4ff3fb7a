//! Figure 8 and the Allan curve and noise-term lines that `gyrotherm allan --plot` reuses.

use super::{compensated_result, sig, Builder};
use crate::allan::{self, AllanPoint, DevKind, NoiseModel, NoiseTerms, TauSet};
use crate::compare::TestResult;
use crate::fit::NamedLog;
use crate::metrics::DPS_TO_DPH;
use crate::report::figures::{allan_figure, AllanCurve, AllanPointPlot, NoiseLine, NoiseTerm};
use crate::report::ReportError;

/// Figure 8: OADEV (octave τ) of the raw and compensated output of a static log.
pub(super) fn allan_report_figure(
    b: &mut Builder,
    l: &NamedLog,
    r: &TestResult,
) -> Result<(), ReportError> {
    let tau0 = l.log.sample_period_s();
    let oadev = |v: &[f64]| {
        allan::deviation(
            v,
            tau0,
            DevKind::Oadev,
            &TauSet::Octave,
            NoiseModel::Identify,
        )
    };
    let raw = match oadev(&l.log.gyro_dps) {
        Ok(p) => p,
        Err(e) => {
            b.note(8, &format!("{}: {e}", l.name));
            return Ok(());
        }
    };
    let mut curves = vec![allan_curve("raw", &raw, DPS_TO_DPH)];
    let mut lines = noise_lines(&allan::noise_terms(&raw, DPS_TO_DPH), "raw");
    let mut terms_from = "raw";
    // Figure 8 is drawn without the compensated curve when that one cannot be computed: its
    // caption says so (a "not drawn" note would name a figure the page shows).
    let mut left_out = String::new();
    if let Some(m) = compensated_result(r) {
        match oadev(&m.compensated.gyro_comp_dps) {
            Ok(p) => {
                let label = m.label;
                curves.push(allan_curve(&format!("{label} compensated"), &p, DPS_TO_DPH));
                lines = noise_lines(&allan::noise_terms(&p, DPS_TO_DPH), label);
                terms_from = label;
            }
            Err(e) => left_out = format!(" The {} compensated curve is left out: {e}.", m.label),
        }
    }
    let files = allan_figure(&b.path(7), &curves, &lines, "°/h")?;
    b.add(
        &files,
        format!(
            "Overlapping Allan deviation (octave τ) of {} (°/h), 68.3 % confidence bars; dashed \
             lines: noise terms identified on the {terms_from} curve (IEEE Std 952 annex C).\
             {left_out}",
            l.name
        ),
    );
    Ok(())
}

/// An Allan curve for [`allan_figure`], each σ and bound multiplied by `to_unit` (3600 for
/// °/s samples drawn in °/h).
pub fn allan_curve(label: &str, points: &[AllanPoint], to_unit: f64) -> AllanCurve {
    AllanCurve {
        label: label.to_owned(),
        points: points
            .iter()
            .map(|p| AllanPointPlot {
                tau_s: p.tau_s,
                dev: p.dev * to_unit,
                lo: p.lo * to_unit,
                hi: p.hi * to_unit,
            })
            .collect(),
    }
}

/// Slope lines (in °/h, τ in s) of the noise terms read by [`allan::noise_terms`], labelled
/// with their values and `source` (e.g. "raw"). Conversions (IEEE Std 952 annex C):
/// N[°/h·√s] = 60·N[°/√h]; B in °/h as is; K[°/h/√s] = K[°/h/√h] / 60;
/// Q\[°/h·s\] = Q\[arcsec\] (σ = √3·Q/τ). The rate ramp has no line.
pub fn noise_lines(terms: &NoiseTerms, source: &str) -> Vec<NoiseLine> {
    let suffix = if source.is_empty() {
        String::new()
    } else {
        format!(" ({source})")
    };
    let mut out = Vec::new();
    if let Some(t) = terms.arw_deg_rt_h {
        out.push(NoiseLine {
            label: format!("ARW N = {} °/√h{suffix}", sig(t.value)),
            term: NoiseTerm::AngleRandomWalk { n: 60.0 * t.value },
        });
    }
    if let Some(t) = terms.bias_instability_dph {
        out.push(NoiseLine {
            label: format!("bias instability B = {} °/h{suffix}", sig(t.value)),
            term: NoiseTerm::BiasInstability { b: t.value },
        });
    }
    if let Some(t) = terms.rrw_deg_h_rt_h {
        out.push(NoiseLine {
            label: format!("RRW K = {} °/h/√h{suffix}", sig(t.value)),
            term: NoiseTerm::RateRandomWalk { k: t.value / 60.0 },
        });
    }
    if let Some(t) = terms.quantization_arcsec {
        out.push(NoiseLine {
            label: format!("quantization Q = {} arcsec{suffix}", sig(t.value)),
            term: NoiseTerm::Quantization { q: t.value },
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan;

    #[test]
    fn noise_line_units_follow_ieee952() {
        // IEEE Std 952 annex C: σ(1 s) = N[°/h·√s] = 60·N[°/√h]; σ(3 s) = K[°/h/√s]
        // = K[°/h/√h] / 60; σ(√3 s) = Q\[°/h·s\] = Q\[arcsec\]; flat 0.6643·B.
        let term = |value| allan::NoiseTerm {
            value,
            tau_read_s: 1.0,
            fit_tau_min_s: 1.0,
            fit_tau_max_s: 2.0,
        };
        let terms = NoiseTerms {
            arw_deg_rt_h: Some(term(0.01)),
            bias_instability_dph: Some(term(0.02)),
            rrw_deg_h_rt_h: Some(term(0.6)),
            quantization_arcsec: Some(term(0.5)),
            rate_ramp_deg_h2: None,
        };
        let lines = noise_lines(&terms, "raw");
        assert_eq!(lines.len(), 4);
        let want = [
            (1.0, 0.6),
            (10.0, 0.6643 * 0.02),
            (3.0, 0.01),
            (3f64.sqrt(), 0.5),
        ];
        for (l, (tau, sigma)) in lines.iter().zip(want) {
            let got = l.term.sigma(tau);
            // 0.6643 is rounded to 4 digits in the standard: 1e-4 relative.
            assert!(
                (got - sigma).abs() <= 1e-4 * sigma,
                "{}: want σ({tau} s) = {sigma} got {got}",
                l.label
            );
        }
        assert!(lines[0].label.contains("0.0100 °/√h"), "{}", lines[0].label);
    }
}
