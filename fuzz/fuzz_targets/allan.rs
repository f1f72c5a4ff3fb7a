//! The Allan functions on arbitrary data: every deviation kind over the octave τ set, the
//! streaming OADEV, and the noise-term read-out.
//!
//! Holds: no panic; on finite samples every deviation it gives is finite and ≥ 0 (no
//! overflow to ∞ for any finite input), the streaming OADEV agrees with the batch one (or refuses a sample too large for it), and
//! bounds are finite or NaN together with their EDF; non-finite samples are refused with
//! their index.

#![no_main]

use arbitrary::{Result, Unstructured};
use gyrotherm::allan::{
    deviation, noise_terms, AllanError, DevKind, NoiseModel, StreamingOadev, TauSet,
};
use libfuzzer_sys::fuzz_target;

/// Samples per case at most (each kind is O(N log N) over the octave set).
const MAX_SAMPLES: usize = 2048;

const KINDS: [DevKind; 5] = [
    DevKind::Adev,
    DevKind::Oadev,
    DevKind::Mdev,
    DevKind::Hdev,
    DevKind::Ohdev,
];

fn samples(u: &mut Unstructured) -> Result<Vec<f64>> {
    // One scale for the whole run (any finite magnitude), then either small integer
    // multiples of it or any bit pattern.
    let scale = f64::from_bits(u.arbitrary()?);
    let raw = u.ratio(1, 4)?;
    let mut v = Vec::new();
    while !u.is_empty() && v.len() < MAX_SAMPLES {
        v.push(if raw {
            f64::from_bits(u.arbitrary()?)
        } else {
            f64::from(u.arbitrary::<i8>()?) * scale
        });
    }
    Ok(v)
}

fn run(data: &[u8]) -> Result<()> {
    let mut u = Unstructured::new(data);
    let tau0 = if u.ratio(1, 8)? {
        f64::from_bits(u.arbitrary()?)
    } else {
        f64::from(u.int_in_range(1u16..=1000)?) * 0.01
    };
    let noise = if u.arbitrary()? {
        NoiseModel::Identify
    } else {
        NoiseModel::Alpha(u.int_in_range(-3..=3)?)
    };
    let x = samples(&mut u)?;
    let finite = x.iter().all(|v| v.is_finite());
    let first_bad = x.iter().position(|v| !v.is_finite());
    for kind in KINDS {
        match deviation(&x, tau0, kind, &TauSet::Octave, noise) {
            Ok(points) => {
                assert!(finite && tau0.is_finite() && tau0 > 0.0);
                for p in &points {
                    assert!(p.dev.is_finite() && p.dev >= 0.0, "{kind:?} {p:?}");
                    assert!(p.tau_s.is_finite() && p.tau_s > 0.0, "{kind:?} {p:?}");
                    if p.edf.is_finite() {
                        assert!(p.lo.is_finite() && p.hi.is_finite(), "{kind:?} {p:?}");
                        assert!(p.lo <= p.dev && p.dev <= p.hi, "{kind:?} {p:?}");
                    }
                }
                let terms = noise_terms(&points, 3600.0);
                for t in [
                    terms.arw_deg_rt_h,
                    terms.bias_instability_dph,
                    terms.rrw_deg_h_rt_h,
                    terms.quantization_arcsec,
                    terms.rate_ramp_deg_h2,
                ]
                .into_iter()
                .flatten()
                {
                    assert!(t.value.is_finite(), "{kind:?} {t:?}");
                }
                // Streaming offsets by the first sample, batch by the mean: they agree
                // unless the variation is lost in the offset's rounding.
                let x0 = x.first().copied().unwrap_or(0.0);
                let amax = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                let spread = x
                    .iter()
                    .fold(0.0f64, |m, v| m.max((v / 2.0 - x0 / 2.0).abs()));
                if kind == DevKind::Oadev && spread >= 1e-6 * amax {
                    let ms: Vec<usize> = points.iter().map(|p| p.m).collect();
                    let mut s = StreamingOadev::new(&ms, tau0).expect("same factors");
                    // Streaming cannot rescale ahead: past ~1e150 it may refuse instead.
                    if let Err(e) = s.push(&x) {
                        assert!(matches!(e, AllanError::TooLarge { .. }), "{e}");
                        continue;
                    }
                    for (a, b) in s.points(None).iter().zip(&points) {
                        assert_eq!(a.m, b.m);
                        let tol = 1e-6 * b.dev.max(f64::MIN_POSITIVE) + 1e-300;
                        assert!(
                            (a.dev - b.dev).abs() <= tol * 1e3,
                            "streaming {a:?} batch {b:?}"
                        );
                    }
                }
            }
            Err(AllanError::NonFinite { index }) => {
                assert_eq!(Some(index), first_bad);
            }
            Err(_) => {}
        }
    }
    Ok(())
}

fuzz_target!(|data: &[u8]| {
    let _ = run(data);
});
