//! θ (the phase: the cumulative sum of the rate) and the difference sums over it that every
//! deviation kind is made of.

use super::DevKind;

/// One step of Neumaier's compensated sum: adds v to the sum s with compensation c. The
/// larger-magnitude operand is chosen by a select, not a branch (the comparison is
/// unpredictable on noise), with the same operations as the textbook form.
#[inline(always)]
pub(super) fn neumaier_add(s: &mut f64, c: &mut f64, v: f64) {
    let t = *s + v;
    let (big, small) = if s.abs() >= v.abs() { (*s, v) } else { (v, *s) };
    *c += (big - t) + small;
    *s = t;
}

/// Mean of the samples, summed in order (0 for none).
pub(super) fn mean_of(samples: &[f64]) -> f64 {
    if samples.is_empty() {
        0.0
    } else {
        samples.iter().sum::<f64>() / samples.len() as f64
    }
}

/// θ: cumulative sum of (Ω − mean Ω) with a leading 0, in units of Ω·τ0 (N + 1 values).
/// Compensated (Neumaier) summation keeps θ accurate on 1e8-sample logs.
pub fn phase_from_rate(samples: &[f64]) -> Vec<f64> {
    let mean = mean_of(samples);
    let mut x = Vec::with_capacity(samples.len() + 1);
    x.push(0.0);
    let (mut s, mut c) = (0.0f64, 0.0f64);
    for &v in samples {
        neumaier_add(&mut s, &mut c, v - mean);
        x.push(s + c);
    }
    x
}

/// [`phase_from_rate`] in the samples' own buffer: the same values, without a second array
/// of N + 1 values (for 1e8 samples, 800 MB less at the peak). The one extra slot is
/// reserved in place (a large buffer grows by remapping its pages, not by copying them).
pub fn phase_from_rate_in_place(samples: Vec<f64>) -> Vec<f64> {
    let mean = mean_of(&samples);
    phase_in_place(samples, mean)
}

/// [`phase_from_rate_in_place`] with the mean already known.
pub(super) fn phase_in_place(mut samples: Vec<f64>, mean: f64) -> Vec<f64> {
    samples.reserve_exact(1);
    samples.push(0.0);
    // Slot k receives θ_k while y_k, still needed for θ_{k+1}, is carried in `next`.
    let (mut s, mut c) = (0.0f64, 0.0f64);
    let mut iter = samples.iter_mut();
    let mut next = match iter.next() {
        Some(first) => std::mem::replace(first, 0.0),
        None => return samples,
    };
    for slot in iter {
        neumaier_add(&mut s, &mut c, next - mean);
        next = std::mem::replace(slot, s + c);
    }
    samples
}

/// Σ_k (θ_{k+2m} − 2θ_{k+m} + θ_k)² for each m of a set. The k range is split across up to
/// `available_parallelism` threads (at least 1e6 k per thread); each thread makes one blocked
/// pass (each block of θ is read once for all m, and octave offsets share cache lines).
/// Blocks of 64 Ki samples (512 kB a slice) keep the three slices of an m in the 2 MB L2 and
/// give the prefetcher long runs: on 1e8 samples, octave m, two threads, about 1.5-2× faster
/// than 2 Ki blocks (bench/allan_vs_allantools.sh).
pub(super) fn overlapping_second_diff_sums(x: &[f64], ms: &[usize]) -> Vec<f64> {
    const MIN_PER_THREAD: usize = 1_000_000;
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(8)
        .min(x.len() / MIN_PER_THREAD)
        .max(1);
    if threads == 1 {
        return second_diff_sums_range(x, ms, 0, x.len());
    }
    let step = x.len().div_ceil(threads);
    let parts: Vec<Vec<f64>> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads)
            .map(|t| {
                let (k0, k1) = (t * step, ((t + 1) * step).min(x.len()));
                s.spawn(move || second_diff_sums_range(x, ms, k0, k1))
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    });
    let mut sums = vec![0.0; ms.len()];
    for p in parts {
        for (s, v) in sums.iter_mut().zip(p) {
            *s += v;
        }
    }
    sums
}

/// The sums of [`overlapping_second_diff_sums`] over k in [k_start, k_end).
pub(super) fn second_diff_sums_range(
    x: &[f64],
    ms: &[usize],
    k_start: usize,
    k_end: usize,
) -> Vec<f64> {
    const BLOCK: usize = 1 << 16;
    let len = x.len();
    let mut sums = vec![0.0f64; ms.len()];
    let mut k0 = k_start;
    while k0 < k_end {
        let k1 = (k0 + BLOCK).min(k_end);
        let mut any = false;
        for (sum, &m) in sums.iter_mut().zip(ms) {
            let kmax = len.saturating_sub(2 * m); // k < len − 2m
            if k0 >= kmax {
                continue;
            }
            any = true;
            let end = k1.min(kmax);
            let a = &x[k0..end];
            let b = &x[k0 + m..end + m];
            let c = &x[k0 + 2 * m..end + 2 * m];
            let mut acc = [0.0f64; 4];
            let (ac, bc, cc) = (a.chunks_exact(4), b.chunks_exact(4), c.chunks_exact(4));
            let (ar, br, cr) = (ac.remainder(), bc.remainder(), cc.remainder());
            for ((a4, b4), c4) in ac.zip(bc).zip(cc) {
                for l in 0..4 {
                    let d = c4[l] - 2.0 * b4[l] + a4[l];
                    acc[l] += d * d;
                }
            }
            for ((a1, b1), c1) in ar.iter().zip(br).zip(cr) {
                let d = c1 - 2.0 * b1 + a1;
                acc[0] += d * d;
            }
            *sum += (acc[0] + acc[1]) + (acc[2] + acc[3]);
        }
        if !any {
            break;
        }
        k0 = k1;
    }
    sums
}

/// Deviation from θ (as made by [`phase_from_rate`]) for one m; returns (σ, terms) in the
/// unit of the samples, or None when no term fits.
pub fn deviation_from_phase(x: &[f64], kind: DevKind, m: usize) -> Option<(f64, usize)> {
    if x.is_empty() || m == 0 {
        return None;
    }
    let n_samples = x.len() - 1;
    let n = kind.terms(n_samples, m);
    if n == 0 {
        return None;
    }
    let mf = m as f64;
    let var = match kind {
        DevKind::Oadev => overlapping_second_diff_sums(x, &[m])[0] / (2.0 * mf * mf * n as f64),
        DevKind::Adev => {
            let s: f64 = (0..n)
                .map(|j| {
                    let k = j * m;
                    let d = x[k + 2 * m] - 2.0 * x[k + m] + x[k];
                    d * d
                })
                .sum();
            s / (2.0 * mf * mf * n as f64)
        }
        DevKind::Hdev | DevKind::Ohdev => {
            let stride = if kind == DevKind::Hdev { m } else { 1 };
            let s: f64 = (0..n)
                .map(|j| {
                    let k = j * stride;
                    let d = x[k + 3 * m] - 3.0 * x[k + 2 * m] + 3.0 * x[k + m] - x[k];
                    d * d
                })
                .sum();
            s / (6.0 * mf * mf * n as f64)
        }
        DevKind::Mdev => {
            // s_j = Σ_{i=j}^{j+m−1} d_i with d_i the second difference at lag m; s_{j+1} =
            // s_j + d_{j+m} − d_j, the running sum kept with Neumaier compensation.
            let d = |i: usize| x[i + 2 * m] - 2.0 * x[i + m] + x[i];
            let (mut s, mut c) = (0.0f64, 0.0f64);
            let add = neumaier_add;
            for i in 0..m {
                add(&mut s, &mut c, d(i));
            }
            let mut total = 0.0f64;
            for j in 0..n {
                let v = s + c;
                total += v * v;
                if j + 1 < n {
                    add(&mut s, &mut c, d(j + m));
                    add(&mut s, &mut c, -d(j));
                }
            }
            total / (2.0 * mf.powi(4) * n as f64)
        }
    };
    Some((var.max(0.0).sqrt(), n))
}
