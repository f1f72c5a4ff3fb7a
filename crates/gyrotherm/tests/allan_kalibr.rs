//! Kalibr's noise figures from an Allan deviation curve (`gyrotherm::allan::kalibr`), checked
//! against
//! - the closed form for synthetic white rate noise N plus rate random walk K:
//!   σ²(τ) = N²/τ + K²·τ/3 (IEEE Std 952-1997 annex C), so the figures must be N and K;
//! - allan_variance_ros's method on the same data, re-implemented here from its source:
//!   `src/AllanVarianceComputor.cpp` (non-overlapping Allan deviation at τ = 0.1·k s,
//!   k = 1..9999, bins of `int(τ·rate)` samples, the last partial bin dropped) and
//!   `scripts/analysis.py` (`get_intercept`: `curve_fit` of `ln σ = m·ln τ + b` with m bounded
//!   to [slope, slope + 0.001], over τ < 10 s for the slope −½ line read at τ = 1 s, over every
//!   τ for the slope +½ line read at τ = 3 s).

use gyrotherm::allan::kalibr::{kalibr_noise, kalibr_yaml, random_walk};
use gyrotherm::allan::NoiseTerms;
use gyrotherm::settings::AllanSettings;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

const RAD: f64 = std::f64::consts::PI / 180.0;

/// Rate samples (°/s) every `tau0` s, each the mean over its interval of a continuous rate:
/// white noise of density `n` (°/s·√s) plus a random walk `k·W(t)` (°/s/√s), so that the Allan
/// deviation is σ²(τ) = n²/τ + k²·τ/3 at every τ = m·τ0, not only for large m. The mean of
/// W over an interval is the mean of its ends plus the mean of a Brownian bridge, whose
/// variance is τ0/12.
fn white_plus_walk(len: usize, tau0: f64, n: f64, k: f64, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut w_start = 0.0;
    (0..len)
        .map(|_| {
            let white: f64 = StandardNormal.sample(&mut rng);
            let step: f64 = StandardNormal.sample(&mut rng);
            let bridge: f64 = StandardNormal.sample(&mut rng);
            let w_end = w_start + tau0.sqrt() * step;
            let mean_w = 0.5 * (w_start + w_end) + (tau0 / 12.0).sqrt() * bridge;
            w_start = w_end;
            n / tau0.sqrt() * white + k * mean_w
        })
        .collect()
}

/// allan_variance_ros's curve: (τ, σ) at τ = 0.1·k s (AllanVarianceComputor.cpp), σ in the
/// unit of `y`. Bin means by prefix sums (the same means as its running sums).
fn ros_curve(y: &[f64], rate: f64) -> Vec<(f64, f64)> {
    let mut s = vec![0.0];
    for v in y {
        s.push(s.last().unwrap() + v);
    }
    (1..10000)
        .map(|period: i32| {
            let period_time = f64::from(period) * 0.1;
            // `int max_bin_size = period_time * measure_rate_;` (truncation), and a bin
            // closes when `bin_size >= max_bin_size`: at least one sample.
            let bin = ((period_time * rate) as i64).max(1) as usize;
            let m = y.len() / bin;
            let means: Vec<f64> = (0..m)
                .map(|j| (s[(j + 1) * bin] - s[j * bin]) / bin as f64)
                .collect();
            let sum: f64 = means.windows(2).map(|w| (w[1] - w[0]).powi(2)).sum();
            (period_time, (sum / (2.0 * (m as f64 - 1.0))).sqrt())
        })
        .collect()
}

/// analysis.py's `get_intercept(x, y, m, b)`: least squares of ln y on ln x with the slope
/// bounded to [m, m + 0.001], read at x = b. The objective is quadratic, so the bounded
/// optimum is the unbounded slope clamped, with the intercept refitted.
fn ros_intercept(pts: &[(f64, f64)], m: f64, at: f64) -> f64 {
    let lx: Vec<f64> = pts.iter().map(|p| p.0.ln()).collect();
    let ly: Vec<f64> = pts.iter().map(|p| p.1.ln()).collect();
    let n = lx.len() as f64;
    let (mx, my) = (lx.iter().sum::<f64>() / n, ly.iter().sum::<f64>() / n);
    let sxy: f64 = lx.iter().zip(&ly).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = lx.iter().map(|x| (x - mx).powi(2)).sum();
    let slope = (sxy / sxx).clamp(m, m + 0.001);
    let b = my - slope * mx;
    (slope * at.ln() + b).exp()
}

/// OADEV curve (octave τ, identified noise) and noise terms as `gyrotherm allan` makes them.
fn gyrotherm_curve(y: Vec<f64>, tau0: f64) -> (Vec<gyrotherm::allan::AllanPoint>, NoiseTerms) {
    let a = AllanSettings::default().analyse(y, tau0).unwrap();
    (a.points, a.noise.unwrap())
}

#[test]
fn white_noise_plus_rate_walk_gives_n_and_k_and_agrees_with_allan_variance_ros() {
    let (tau0, rate) = (0.1, 10.0);
    // N = 0.01 °/s·√s (36 °/h/√Hz); the lines cross at τ = √3·N/K = 100 s.
    let n = 0.01;
    let k = 3f64.sqrt() * n / 100.0;
    let y = white_plus_walk(2_000_000, tau0, n, k, 7);
    let ros = ros_curve(&y, rate);
    let (points, terms) = gyrotherm_curve(y, tau0);
    let kal = kalibr_noise(&points, &terms, tau0).unwrap();
    let (nd, rw) = (kal.noise_density, kal.random_walk);
    eprintln!("noise density {nd:?}\nrandom walk {rw:?}");
    assert_eq!(kal.update_rate_hz, rate);

    // Closed form: within the 68.3 % bounds widened to about 3σ (a fixed seed: one draw).
    let within = |t: &gyrotherm::allan::kalibr::KalibrTerm, want: f64, what: &str| {
        let half = (t.hi - t.lo) / 2.0;
        assert!(t.lo < t.value && t.value < t.hi, "{what}: bounds {t:?}");
        assert!(
            (t.value - want).abs() <= 3.0 * half,
            "{what}: {} vs {want}, ±{half}",
            t.value
        );
    };
    within(&nd, n * RAD, "noise density");
    within(&rw, k * RAD, "random walk");
    // The white line is pinned by millions of samples; the walk by a few long τ.
    assert!((nd.value / (n * RAD) - 1.0).abs() < 0.02, "{nd:?}");
    assert!((rw.value / (k * RAD) - 1.0).abs() < 0.35, "{rw:?}");

    // allan_variance_ros: its white line over τ < 10 s agrees with gyrotherm's.
    let below_10: Vec<(f64, f64)> = ros.iter().copied().take_while(|p| p.0 != 10.0).collect();
    assert_eq!(below_10.len(), 99);
    let ros_n = ros_intercept(&below_10, -0.5, 1.0) * RAD;
    assert!(
        (ros_n / nd.value - 1.0).abs() < 0.02,
        "ros {ros_n}, gyrotherm {}",
        nd.value
    );
    // Its slope +½ line through every τ, the white-noise part included, reads K further from
    // the truth than gyrotherm's line through the run of points on the +½ slope.
    let ros_k = ros_intercept(&ros, 0.5, 3.0) * RAD;
    eprintln!("ros random walk {ros_k}, closed form {}", k * RAD);
    assert!(
        (ros_k - k * RAD).abs() > (rw.value - k * RAD).abs(),
        "ros {ros_k}, gyrotherm {}, closed form {}",
        rw.value,
        k * RAD
    );
}

#[test]
fn a_pure_rate_walk_gives_the_random_walk_allan_variance_ros_gives() {
    // No white noise: the whole curve is the +½ line, where allan_variance_ros's fit over
    // every τ is the right one, so both must read the same K.
    let (tau0, rate) = (0.1, 10.0);
    let k = 1e-3;
    let y = white_plus_walk(1_000_000, tau0, 0.0, k, 11);
    let ros = ros_curve(&y, rate);
    let (points, terms) = gyrotherm_curve(y, tau0);
    let rw = random_walk(&points, &terms).unwrap();
    let ros_k = ros_intercept(&ros, 0.5, 3.0) * RAD;
    eprintln!("random walk {rw:?}, ros {ros_k}, closed form {}", k * RAD);
    assert!(
        (rw.value / ros_k - 1.0).abs() < 0.25,
        "gyrotherm {}, ros {ros_k}",
        rw.value
    );
    let half = (rw.hi - rw.lo) / 2.0;
    assert!(
        (rw.value - k * RAD).abs() <= 3.0 * half,
        "{rw:?} vs {}",
        k * RAD
    );
    // No −½ region: the file cannot be written, and says which figure is missing.
    let err = kalibr_noise(&points, &terms, tau0).unwrap_err();
    assert!(err.to_string().contains("gyroscope_noise_density"), "{err}");
}

#[test]
fn the_file_states_its_units_and_holds_the_figures() {
    let tau0 = 0.01;
    let n = 0.002;
    let k = 3f64.sqrt() * n / 20.0;
    let y = white_plus_walk(400_000, tau0, n, k, 3);
    let (points, terms) = gyrotherm_curve(y, tau0);
    let kal = kalibr_noise(&points, &terms, tau0).unwrap();
    let text = kalibr_yaml(&kal, "/imu1");
    let value = |key: &str| {
        text.lines()
            .find_map(|l| l.strip_prefix(&format!("{key}: ")))
            .unwrap_or_else(|| panic!("{key} missing:\n{text}"))
            .to_owned()
    };
    assert_eq!(
        value("gyroscope_noise_density").parse::<f64>().unwrap(),
        kal.noise_density.value
    );
    assert_eq!(
        value("gyroscope_random_walk").parse::<f64>().unwrap(),
        kal.random_walk.value
    );
    assert_eq!(value("update_rate"), "1.0e+2");
    assert_eq!(value("rostopic"), "/imu1");
    for unit in ["rad/s/sqrt(Hz)", "rad/s^2/sqrt(Hz)", "update_rate: Hz"] {
        assert!(text.contains(unit), "{unit}:\n{text}");
    }
    // The accelerometer keys are absent and said to be not measured.
    assert!(
        !text.lines().any(|l| l.starts_with("accelerometer")),
        "{text}"
    );
    assert!(text.contains("not measured"));
    assert!(text.is_ascii());
}
