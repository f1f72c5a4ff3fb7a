//! Baseline least-squares fits: recovery of known coefficients, refusals, core = ground.

use gyrotherm::baseline::{fit, fit_rows, LsqError, PolyDegrees, Terms, TermsError};
use gyrotherm::csvlog::TestLog;
use gyrotherm::features::{extract, FeatureSpec, FeatureTable};

/// A chamber-like cycle: 20 °C, cool to -40 at 3 °C/min, soak, heat to 60, soak (°C).
fn chamber(t: f64) -> f64 {
    let seg = [
        (0.0, 20.0),
        (1000.0, 20.0),
        (3000.0, -40.0),
        (5000.0, -40.0),
        (8333.0, 60.0),
        (10000.0, 60.0),
    ];
    for w in seg.windows(2) {
        let ((ta, a), (tb, b)) = (w[0], w[1]);
        if t <= tb {
            return a + (b - a) * ((t - ta) / (tb - ta)).clamp(0.0, 1.0);
        }
    }
    60.0
}

fn table(spec: &FeatureSpec) -> FeatureTable {
    let time_s: Vec<f64> = (0..10_000).map(|i| i as f64).collect();
    // A little wiggle so that T and dT are not piecewise collinear.
    let temp_c: Vec<f64> = time_s
        .iter()
        .map(|&t| chamber(t) + 0.7 * (t / 97.0).sin())
        .collect();
    let log = TestLog {
        gyro_dps: vec![0.0; time_s.len()],
        time_s,
        temp_c,
        ..TestLog::default()
    };
    extract(&log, spec).unwrap()
}

/// Relative tolerance on recovered coefficients from noise-free targets: pure round-off
/// (about 1e-13 measured here); 1e-10 leaves room for other platforms.
const COEF_TOL: f64 = 1e-10;

fn assert_close(want: &[f64], got: &[f64], rel: f64) {
    assert_eq!(want.len(), got.len());
    for (j, (w, g)) in want.iter().zip(got).enumerate() {
        let err = (w - g).abs() / w.abs().max(1e-300);
        assert!(
            err < rel,
            "coefficient {j}: want {w}, got {g}, rel error {err:.2e}"
        );
    }
}

#[test]
fn linear_fit_recovers_the_generating_coefficients() {
    // Target made by the published linear form bias = c0 + c1·T + c2·dT with known c;
    // noise-free, so least squares must return c up to round-off (COEF_TOL).
    let tab = table(&FeatureSpec::PUBLISHED);
    let c = [3.5e-3, -2.0e-5, 0.04];
    let y: Vec<f64> = (0..tab.n_rows())
        .map(|r| c[0] + c[1] * tab.row(r)[0] + c[2] * tab.row(r)[1])
        .collect();
    let terms = Terms::linear(2);
    assert_eq!(terms.powers, vec![vec![0, 0], vec![1, 0], vec![0, 1]]);
    let f = fit(&tab, &y, None, &terms).unwrap();
    assert_close(&c, &f.coefficients, COEF_TOL);
    assert!(f.rms_residual < 1e-15, "rms {}", f.rms_residual);
    assert_eq!(f.n_used, 10_000);
}

#[test]
fn poly_fit_with_cross_term_and_lags_recovers_coefficients() {
    // Cubic in T, quadratic in dT, T·dT, plus three thermal-state features linearly.
    let tab = table(&FeatureSpec::THERMAL_STATE);
    let deg = PolyDegrees {
        temp: 3,
        rate: 2,
        cross: true,
    };
    let terms = Terms::poly(5, deg);
    let names: Vec<String> = (0..terms.len())
        .map(|j| terms.name(j, &tab.names))
        .collect();
    assert_eq!(
        names,
        [
            "1",
            "T",
            "T^2",
            "T^3",
            "dT",
            "dT^2",
            "T·dT",
            "T-T_lag300",
            "T-T_lag1000",
            "T-T_lag3000"
        ]
    );
    let c = [1e-3, 2e-5, -3e-7, 4e-9, 0.05, -0.2, 1e-3, 2e-4, -1e-4, 5e-5];
    let y: Vec<f64> = (0..tab.n_rows())
        .map(|r| {
            let x = tab.row(r);
            let (t, d) = (x[0], x[1]);
            c[0] + c[1] * t
                + c[2] * t * t
                + c[3] * t * t * t
                + c[4] * d
                + c[5] * d * d
                + c[6] * t * d
                + c[7] * x[2]
                + c[8] * x[3]
                + c[9] * x[4]
        })
        .collect();
    let f = fit(&tab, &y, None, &terms).unwrap();
    assert_close(&c, &f.coefficients, COEF_TOL);
    assert!(f.condition_ratio > 1e-6, "ratio {}", f.condition_ratio);
}

#[test]
fn masked_rows_are_left_out() {
    let tab = table(&FeatureSpec::PUBLISHED);
    let c = [1.0, 0.5, -0.25];
    let mut y: Vec<f64> = (0..tab.n_rows())
        .map(|r| c[0] + c[1] * tab.row(r)[0] + c[2] * tab.row(r)[1])
        .collect();
    let mut mask = vec![true; y.len()];
    for r in (0..y.len()).step_by(3) {
        y[r] = f64::NAN; // unlabelled
        mask[r] = false;
    }
    let f = fit(&tab, &y, Some(&mask), &Terms::linear(2)).unwrap();
    assert_close(&c, &f.coefficients, COEF_TOL);
    assert_eq!(f.n_used, 10_000 - 3334);
    // Without the mask the NaN is refused, naming the step.
    let e = fit(&tab, &y, None, &Terms::linear(2)).unwrap_err();
    assert!(e.to_string().contains("step 0"), "{e}");
}

#[test]
fn constant_temperature_is_refused_with_the_reason() {
    let log = TestLog {
        time_s: (0..500).map(|i| i as f64).collect(),
        temp_c: vec![23.0; 500],
        gyro_dps: vec![0.0; 500],
        ..TestLog::default()
    };
    let tab = extract(&log, &FeatureSpec::PUBLISHED).unwrap();
    let e = fit(&tab, &vec![0.01; 500], None, &Terms::linear(2)).unwrap_err();
    assert!(matches!(e, LsqError::ConstantFeature { .. }), "{e:?}");
    let msg = e.to_string();
    for want in [
        "temperature is constant (23.0 °C ± 0)",
        "cannot fit the T coefficient",
        "spans the temperature range",
    ] {
        assert!(msg.contains(want), "want {want:?} in {msg:?}");
    }
}

#[test]
fn dependent_terms_are_refused_naming_them() {
    // Feature 2 = 2·T + 1 exactly: 1, T and x2 are linearly dependent.
    let n = 200;
    let mut rows = Vec::new();
    for i in 0..n {
        let t = i as f64 * 0.37;
        rows.extend_from_slice(&[t, (i as f64).sin(), 2.0 * t + 1.0]);
    }
    let names = vec!["T".to_owned(), "dT".to_owned(), "x".to_owned()];
    let e = fit_rows(
        &rows,
        3,
        &names,
        &["°C", "°C/s", "°C"],
        &vec![1.0; n],
        None,
        &Terms::linear(3),
    )
    .unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains("linearly dependent"), "{msg}");
    for t in ["1", "T", "x"] {
        assert!(
            matches!(&e, LsqError::RankDeficient { terms, .. } if terms.iter().any(|s| s == t)),
            "term {t} should be named: {msg}"
        );
    }
}

#[test]
fn shape_errors() {
    let tab = table(&FeatureSpec::PUBLISHED);
    let e = fit(&tab, &[1.0; 3], None, &Terms::linear(2)).unwrap_err();
    assert!(e.to_string().contains("3 target values"), "{e}");
    let e = fit(&tab, &vec![0.0; tab.n_rows()], None, &Terms::linear(3)).unwrap_err();
    assert!(e.to_string().contains("terms are over 3 features"), "{e}");
    let too_many = Terms::poly(
        2,
        PolyDegrees {
            temp: 9,
            rate: 9,
            cross: true,
        },
    );
    assert!(matches!(
        too_many.validate().unwrap_err(),
        TermsError::TermCount { .. }
    ));
    let e = fit(&tab, &[0.0; 2], Some(&[true, false]), &Terms::linear(2)).unwrap_err();
    assert!(matches!(e, LsqError::Shape(_)));
}

#[test]
fn core_evaluation_equals_ground_evaluation() {
    // The flight evaluator (repeated multiplication, no_std) against the ground one (powi
    // over the design row): the same polynomial, so equal up to a few ulp of the largest term.
    let tab = table(&FeatureSpec::THERMAL_STATE);
    let terms = Terms::poly(5, PolyDegrees::default());
    let y: Vec<f64> = (0..tab.n_rows())
        .map(|r| 1e-3 * (tab.row(r)[0] / 30.0).tanh() + 0.02 * tab.row(r)[1])
        .collect();
    let f = fit(&tab, &y, None, &terms).unwrap();
    let core = f.to_core().unwrap();
    let ground = f.predict(&tab);
    let mut worst: f64 = 0.0;
    for (r, g) in ground.iter().enumerate() {
        let c = core.eval(tab.row(r)).unwrap();
        let scale: f64 = terms
            .design_row(tab.row(r))
            .iter()
            .zip(&f.coefficients)
            .map(|(a, b)| (a * b).abs())
            .sum();
        worst = worst.max((c - g).abs() / scale);
    }
    assert!(worst < 1e-14, "worst relative difference {worst:.2e}");
    // And the fit is useful: the residual is far below the target's spread.
    assert!(f.rms_residual < 1e-4, "rms {}", f.rms_residual);
}

/// `extend_design_row` (and its sparse form) appends `design_row`'s values to the bit (the reference: `design_row`
/// itself, `powi` on every factor), at powers 0 to 4 and at zero, negative and tiny values.
#[test]
fn extend_design_row_is_design_row_to_the_bit() {
    let terms = gyrotherm::fit::thermal::basis(gyrotherm::fit::thermal::Basis::Full, 3);
    let mut t = terms.clone();
    t.powers.push(vec![4, 0, 1, 0, 2]);
    // Three chosen rows, then a sweep of values over many magnitudes and both signs (the
    // sparse form squares and multiplies low powers itself instead of calling `powi`).
    let mut rows = vec![
        [21.3125, 1e-3, -0.4, 2.75, -7.0],
        [-38.0625, -0.06, 0.0, -1e-300, 3.5],
        [0.0, 0.0, 1e-5, -0.0, 1.0 / 3.0],
    ];
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut draw = || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        let mantissa = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
        mantissa * 10f64.powi(((state >> 3) % 40) as i32 - 20)
    };
    for _ in 0..2000 {
        rows.push([draw(), draw(), draw(), draw(), draw()]);
    }
    for x in rows {
        let want: Vec<u64> = t.design_row(&x).iter().map(|v| v.to_bits()).collect();
        for from in [0, 1] {
            let mut out = vec![9.0];
            t.extend_design_row(&x, from, &mut out);
            let got: Vec<u64> = out[1..].iter().map(|v| v.to_bits()).collect();
            assert_eq!(got, want[from..], "{x:?}");
            // The sparse form the fits build their designs with: the same bits.
            let mut out = vec![9.0];
            t.sparse().extend_design_row(&x, from, &mut out);
            let got: Vec<u64> = out[1..].iter().map(|v| v.to_bits()).collect();
            assert_eq!(got, want[from..], "sparse, {x:?}");
        }
    }
}
