//! Streaming OADEV equals the in-memory estimator (and so the NIST values) whatever the
//! chunking.

use gyrotherm::allan::{deviation, DevKind, NoiseModel, StreamingOadev, TauSet};

mod common;
use common::nbs_data;

/// Both are sums of the same terms; only rounding differs.
const SAME_SUM_TOL: f64 = 1e-12;

#[test]
fn streaming_equals_batch_for_any_chunking() {
    let y = nbs_data();
    let batch = deviation(
        &y,
        1.0,
        DevKind::Oadev,
        &TauSet::Octave,
        NoiseModel::Alpha(0),
    )
    .unwrap();
    for chunk in [1usize, 7, 64, 1000] {
        let mut s = StreamingOadev::octave(250, 1.0).unwrap();
        for c in y.chunks(chunk) {
            s.push(c).unwrap();
        }
        let pts = s.points(Some(0));
        assert_eq!(pts.len(), batch.len(), "chunk {chunk}");
        for (p, b) in pts.iter().zip(&batch) {
            assert_eq!((p.m, p.n), (b.m, b.n));
            let e = (p.dev - b.dev).abs() / b.dev;
            assert!(
                e < SAME_SUM_TOL,
                "chunk {chunk} m={}: batch {} stream {} err {e:e}",
                p.m,
                b.dev,
                p.dev
            );
            assert!((p.lo - b.lo).abs() / b.lo < 1e-9 && (p.hi - b.hi).abs() / b.hi < 1e-9);
        }
    }
    // NIST SP 1065: OADEV at τ = 10 is 9.159953e-02 (explicit factor set).
    let mut s = StreamingOadev::new(&[10], 1.0).unwrap();
    s.push(&y).unwrap();
    let p = s.points(None);
    assert!(
        (p[0].dev - 9.159953e-02).abs() / 9.159953e-02 < 1e-6,
        "{}",
        p[0].dev
    );
    assert!(p[0].lo.is_nan());
}

#[test]
fn streaming_rejects_bad_input() {
    assert!(StreamingOadev::new(&[0, 1], 1.0).is_err());
    assert!(StreamingOadev::new(&[1], 0.0).is_err());
    let mut s = StreamingOadev::octave(4, 1.0).unwrap();
    s.push(&[1.0, 2.0]).unwrap();
    let e = s.push(&[3.0, f64::INFINITY]).unwrap_err();
    assert!(e.to_string().contains("sample 3"), "{e}");
}
