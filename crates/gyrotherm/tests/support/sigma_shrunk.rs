//! The check that a model with a residual LSTM carries its least-squares base's coverage map
//! with σ shrunk by the ratio its held-out blocks measured.

use gyrotherm::model::CoverageDef;

/// `kept`'s map is `base`'s with every cell's σ multiplied by `ratio` (the counts and RMS
/// left as they are).
pub fn assert_sigma_shrunk(kept: &CoverageDef, base: &CoverageDef, ratio: f64) {
    assert!(
        ratio < 1.0,
        "the LSTM helped nothing on the held-out blocks"
    );
    assert_eq!(kept.rms_dph, base.rms_dph);
    assert_eq!(kept.sigma_dph.len(), base.sigma_dph.len());
    for (k, p) in kept.sigma_dph.iter().zip(&base.sigma_dph) {
        assert!(
            (k - p * ratio).abs() <= 1e-12 * p.abs(),
            "{k} against {p} × {ratio}"
        );
    }
}
