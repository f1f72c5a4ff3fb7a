//! Equivalent degrees of freedom (EDF) and the chi-square quantiles for confidence intervals.
//!
//! EDF: C. A. Greenhall and W. J. Riley, "Uncertainty of stability variances based on finite
//! differences", 35th PTTI Meeting, 2003 (the algorithm Stable32 uses). Chi-square quantiles
//! by inverting the regularized lower incomplete gamma function P(k/2, x/2) (series and
//! continued fraction, Numerical Recipes §6.2) with a safeguarded Newton iteration.

/// 68.27 % = erf(1/√2), the "1σ" confidence level.
pub const ONE_SIGMA_CI: f64 = 0.682_689_492_137_085_9;

/// Generalised autocovariance sw(t) of Greenhall & Riley eq. (7) for noise exponent α.
fn sw(t: f64, alpha: i32) -> f64 {
    let a = t.abs();
    let ln = |t: f64| if t == 0.0 { 0.0 } else { t.abs().ln() };
    match alpha {
        2 => -a,
        1 => t * t * ln(t),
        0 => a * a * a,
        -1 => t.powi(4) * ln(t),
        -2 => a.powi(5),
        -3 => t.powi(6) * ln(t),
        _ => a.powi(7),
    }
}

/// sx(t) of eq. (8): the filter of the averaging factor F (None: F = ∞).
fn sx(t: f64, f: Option<f64>, alpha: i32) -> f64 {
    match f {
        None => sw(t, alpha + 2),
        Some(f) => f * f * (2.0 * sw(t, alpha) - sw(t - 1.0 / f, alpha) - sw(t + 1.0 / f, alpha)),
    }
}

/// sz(t) of eq. (9): the d-th difference, Σ_j (−1)^j C(2d, d+j) sx(t + j).
fn sz(t: f64, f: Option<f64>, alpha: i32, d: u32) -> f64 {
    let coeffs: &[f64] = match d {
        1 => &[2.0, -1.0],
        2 => &[6.0, -4.0, 1.0],
        _ => &[20.0, -15.0, 6.0, -1.0],
    };
    let mut s = coeffs[0] * sx(t, f, alpha);
    for (j, c) in coeffs.iter().enumerate().skip(1) {
        let j = j as f64;
        s += c * (sx(t - j, f, alpha) + sx(t + j, f, alpha));
    }
    s
}

/// The basic sum of eq. (10).
fn basic_sum(j_terms: f64, m_terms: f64, s: f64, f: Option<f64>, alpha: i32, d: u32) -> f64 {
    let first = sz(0.0, f, alpha, d).powi(2);
    let second = (1.0 - j_terms / m_terms) * sz(j_terms / s, f, alpha, d).powi(2);
    let mut third = 0.0;
    let mut j = 1.0;
    while j < j_terms {
        third += 2.0 * (1.0 - j / m_terms) * sz(j / s, f, alpha, d).powi(2);
        j += 1.0;
    }
    first + second + third
}

/// Table 1 (modified variances), (a0, a1) by α = 2..−4 and d = 1..3; None where undefined.
fn table1(alpha: i32, d: u32) -> Option<(f64, f64)> {
    const T: [[(f64, f64); 3]; 7] = [
        [
            (2.0 / 3.0, 1.0 / 3.0),
            (7.0 / 9.0, 0.5),
            (22.0 / 25.0, 2.0 / 3.0),
        ],
        [(0.840, 0.345), (0.997, 0.616), (1.141, 0.843)],
        [(1.079, 0.368), (1.033, 0.607), (1.184, 0.848)],
        [(f64::NAN, 0.0), (1.048, 0.534), (1.180, 0.816)],
        [(f64::NAN, 0.0), (1.302, 0.535), (1.175, 0.777)],
        [(f64::NAN, 0.0), (f64::NAN, 0.0), (1.194, 0.703)],
        [(f64::NAN, 0.0), (f64::NAN, 0.0), (1.489, 0.702)],
    ];
    table_lookup(&T, alpha, d)
}

/// Table 2 (unmodified variances).
fn table2(alpha: i32, d: u32) -> Option<(f64, f64)> {
    const T: [[(f64, f64); 3]; 7] = [
        [(1.5, 0.5), (35.0 / 18.0, 1.0), (231.0 / 100.0, 1.5)],
        [(78.6, 25.2), (790.0, 410.0), (9950.0, 6520.0)],
        [
            (2.0 / 3.0, 1.0 / 6.0),
            (2.0 / 3.0, 1.0 / 3.0),
            (7.0 / 9.0, 0.5),
        ],
        [(f64::NAN, 0.0), (0.852, 0.375), (0.997, 0.617)],
        [(f64::NAN, 0.0), (1.079, 0.368), (1.033, 0.607)],
        [(f64::NAN, 0.0), (f64::NAN, 0.0), (1.053, 0.553)],
        [(f64::NAN, 0.0), (f64::NAN, 0.0), (1.302, 0.535)],
    ];
    table_lookup(&T, alpha, d)
}

fn table_lookup(t: &[[(f64, f64); 3]; 7], alpha: i32, d: u32) -> Option<(f64, f64)> {
    let row = usize::try_from(2 - alpha).ok()?;
    let col = usize::try_from(d.checked_sub(1)?).ok()?;
    let v = *t.get(row)?.get(col)?;
    v.0.is_finite().then_some(v)
}

/// Table 3 (α = 1, unmodified): (b0, b1) by d.
fn table3(d: u32) -> (f64, f64) {
    match d {
        1 => (6.0, 4.0),
        2 => (15.23, 12.0),
        _ => (47.8, 40.0),
    }
}

/// Greenhall & Riley (2003) EDF of a variance of d-th differences (d = 2 Allan, 3 Hadamard)
/// at averaging factor m over `n_phase` phase points (N + 1 for N rate samples), for noise
/// exponent α (S_y(f) ∝ f^α, integer in −4..=2, α + 2d > 1). `overlapping`: OADEV, OHDEV,
/// MDEV; `modified`: MDEV. None where the algorithm is undefined (α + 2d ≤ 1, too few points,
/// or α = 2 with ⌈r⌉ ≤ d).
pub fn edf_greenhall(
    alpha: i32,
    d: u32,
    m: usize,
    n_phase: usize,
    overlapping: bool,
    modified: bool,
) -> Option<f64> {
    if !(1..=3).contains(&d) || !(-4..=2).contains(&alpha) || alpha + 2 * d as i32 <= 1 || m == 0 {
        return None;
    }
    let mf = m as f64;
    let df = d as f64;
    let f = if modified { 1.0 } else { mf };
    let s = if overlapping { mf } else { 1.0 };
    let l = mf / f + mf * df; // filter length in phase samples
    if (n_phase as f64) < l {
        return None;
    }
    let m_terms = 1.0 + (s * (n_phase as f64 - l) / mf).floor();
    let j_terms = m_terms.min((df + 1.0) * s);
    const J_MAX: f64 = 100.0;
    let r = m_terms / s;
    let inv_edf = if modified {
        if j_terms <= J_MAX {
            basic_sum(j_terms, m_terms, s, Some(1.0), alpha, d)
                / (sz(0.0, Some(1.0), alpha, d).powi(2) * m_terms)
        } else if r > df + 1.0 {
            let (a0, a1) = table1(alpha, d)?;
            (a0 - a1 / r) / r
        } else {
            let m_prime = J_MAX / r;
            basic_sum(J_MAX, J_MAX, m_prime, Some(1.0), alpha, d)
                / (sz(0.0, Some(1.0), alpha, d).powi(2) * J_MAX)
        }
    } else if alpha <= 0 {
        if j_terms <= J_MAX {
            let fp = if mf * (df + 1.0) <= J_MAX {
                Some(mf)
            } else {
                None
            };
            basic_sum(j_terms, m_terms, s, fp, alpha, d) / (sz(0.0, fp, alpha, d).powi(2) * m_terms)
        } else if r > df + 1.0 {
            let (a0, a1) = table2(alpha, d)?;
            (a0 - a1 / r) / r
        } else {
            let m_prime = J_MAX / r;
            basic_sum(J_MAX, J_MAX, m_prime, None, alpha, d)
                / (sz(0.0, None, alpha, d).powi(2) * J_MAX)
        }
    } else if alpha == 1 {
        if j_terms <= J_MAX {
            basic_sum(j_terms, m_terms, s, Some(mf), 1, d)
                / (sz(0.0, Some(mf), 1, d).powi(2) * m_terms)
        } else if r > df + 1.0 {
            let (a0, a1) = table2(1, d)?;
            let (b0, b1) = table3(d);
            (a0 - a1 / r) / ((b0 + b1 * mf.ln()).powi(2) * r)
        } else {
            let m_prime = J_MAX / r;
            let (b0, b1) = table3(d);
            basic_sum(J_MAX, J_MAX, m_prime, Some(m_prime), 1, d)
                / ((b0 + b1 * mf.ln()).powi(2) * J_MAX)
        }
    } else {
        // α = 2, unmodified.
        if r.ceil() <= df {
            return None;
        }
        let binom =
            |n: u32, k: u32| (0..k).fold(1.0, |acc, i| acc * f64::from(n - i) / f64::from(i + 1));
        let a0 = binom(4 * d, 2 * d) / binom(2 * d, d).powi(2);
        let a1 = df / 2.0;
        (a0 - a1 / r) / m_terms
    };
    let edf = 1.0 / inv_edf;
    (edf.is_finite() && edf > 0.0).then_some(edf)
}

/// Simple EDF formulas of NIST SP 1065 Table 5 (overlapping Allan variance), for N phase
/// points and α ∈ {2, 1, 0, −1, −2}; None otherwise.
pub fn edf_simple(n_phase: usize, m: usize, alpha: i32) -> Option<f64> {
    let n = n_phase as f64;
    let m = m as f64;
    let edf = match alpha {
        2 => (n + 1.0) * (n - 2.0 * m) / (2.0 * (n - m)),
        1 => {
            let a = (n - 1.0) / (2.0 * m);
            let b = (2.0 * m + 1.0) * (n - 1.0) / 4.0;
            (a.ln() * b.ln()).sqrt().exp()
        }
        0 => {
            (3.0 * (n - 1.0) / (2.0 * m) - 2.0 * (n - 2.0) / n)
                * (4.0 * m * m / (4.0 * m * m + 5.0))
        }
        -1 if m == 1.0 => 2.0 * (n - 2.0) / (2.3 * n - 4.9),
        -1 => 5.0 * n * n / (4.0 * m * (n + 3.0 * m)),
        -2 => {
            (n - 2.0) / (m * (n - 3.0).powi(2))
                * ((n - 1.0).powi(2) - 3.0 * m * (n - 1.0) + 4.0 * m * m)
        }
        _ => return None,
    };
    (edf.is_finite() && edf > 0.0).then_some(edf)
}

/// ln Γ(x) for x > 0 (Lanczos, g = 7, 9 terms; ~1e-15 relative).
fn ln_gamma(x: f64) -> f64 {
    const G: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection: Γ(x)Γ(1−x) = π / sin(πx).
        return (std::f64::consts::PI / (std::f64::consts::PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = G[0];
    let t = x + 7.5;
    for (i, g) in G.iter().enumerate().skip(1) {
        a += g / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// Regularized lower incomplete gamma P(a, x) = γ(a, x)/Γ(a), a > 0, x ≥ 0.
pub(crate) fn regularized_gamma_p(a: f64, x: f64) -> f64 {
    if a.is_nan() || a <= 0.0 || x.is_nan() {
        return f64::NAN;
    }
    if x <= 0.0 {
        return 0.0;
    }
    let log_prefix = -x + a * x.ln() - ln_gamma(a);
    if x < a + 1.0 {
        // Series: γ(a,x) = e^{−x} x^a Σ x^n / (a(a+1)…(a+n)).
        let mut term = 1.0 / a;
        let mut sum = term;
        let mut ap = a;
        for _ in 0..1_000_000 {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        (sum.ln() + log_prefix).exp().min(1.0)
    } else {
        // Continued fraction for Q(a, x) (modified Lentz).
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..1_000_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-16 {
                break;
            }
        }
        (1.0 - (log_prefix.exp() * h)).max(0.0)
    }
}

/// Quantile of the chi-square distribution with `dof` (> 0, may be fractional) degrees of
/// freedom: the x with P(dof/2, x/2) = p, 0 < p < 1. NaN for arguments out of range.
pub fn chi2_inv(p: f64, dof: f64) -> f64 {
    if !(p > 0.0 && p < 1.0 && dof > 0.0 && dof.is_finite()) {
        return f64::NAN;
    }
    let a = dof / 2.0;
    let cdf = |x: f64| regularized_gamma_p(a, x / 2.0);
    let ln_pdf_norm = -a * 2f64.ln() - ln_gamma(a);
    let pdf = |x: f64| ((a - 1.0) * x.ln() - x / 2.0 + ln_pdf_norm).exp();
    let mut lo = 0.0;
    let mut hi = dof + 10.0 * (2.0 * dof).sqrt() + 10.0;
    while cdf(hi) < p {
        lo = hi;
        hi *= 2.0;
    }
    let mut x = dof.max(1e-3).min(hi);
    for _ in 0..200 {
        let fx = cdf(x) - p;
        if fx > 0.0 {
            hi = x;
        } else {
            lo = x;
        }
        let dens = pdf(x);
        let mut next = x - fx / dens;
        if !(next.is_finite() && next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        if (next - x).abs() <= 1e-14 * x.max(1e-300) || hi - lo <= 1e-14 * hi {
            return next;
        }
        x = next;
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Chi-square quantiles from standard tables (Abramowitz & Stegun Table 26.8 / NIST
    /// e-Handbook 1.3.6.7.4).
    #[test]
    fn chi2_quantiles_match_tables() {
        let cases = [
            (0.95, 1.0, 3.841_459),
            (0.05, 1.0, 0.003_932_14),
            (0.95, 10.0, 18.307_038),
            (0.05, 10.0, 3.940_299),
            (0.99, 100.0, 135.806_723),
            (0.01, 100.0, 70.064_895),
            (0.5, 2.0, 1.386_294),
        ];
        const TOL: f64 = 1e-5; // table values are printed to 6-7 digits
        for (p, k, want) in cases {
            let got = chi2_inv(p, k);
            let err = (got - want).abs() / want;
            assert!(
                err < TOL,
                "chi2_inv({p}, {k}): want {want}, got {got}, rel err {err:e}"
            );
        }
    }

    /// ln Γ(n) = ln (n−1)! for integers; Γ(1/2) = √π.
    #[test]
    fn ln_gamma_exact_values() {
        let mut fact = 1.0f64;
        for n in 1..30 {
            let got = ln_gamma(n as f64);
            let want = fact.ln();
            assert!(
                (got - want).abs() < 1e-12 * want.abs().max(1.0),
                "n={n} want {want} got {got}"
            );
            fact *= n as f64;
        }
        let want = std::f64::consts::PI.sqrt().ln();
        assert!((ln_gamma(0.5) - want).abs() < 1e-13);
    }
}
