//! Decimation for drawing: a run of 100 000 samples drawn into 900 pixel columns needs at most
//! two points per column, the column's minimum and maximum, to look exactly the same: every
//! spike stays visible.

/// Reduce `(x, y)` to at most `2 * columns + 2` points that draw the same as the full series
/// at `columns` pixel columns: the first and last points, and for each column (equal slices
/// of `x[0]..=x[last]`) its minimum and maximum `y`, in the order they occur.
///
/// When `x` is not in non-decreasing order (output against temperature, which cycles), the
/// columns are instead equal runs of consecutive samples, so the drawn path still follows
/// the data and keeps each run's extremes. Points whose `x` or `y` is not finite are dropped
/// (a gap, not a value). Series short enough already (`<= 2 * columns + 2` finite points)
/// are returned whole. Extra elements of the longer slice are ignored.
pub fn decimate_min_max(x: &[f64], y: &[f64], columns: usize) -> Vec<(f64, f64)> {
    let points: Vec<(f64, f64)> = x
        .iter()
        .zip(y)
        .map(|(&a, &b)| (a, b))
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .collect();
    let columns = columns.max(1);
    if points.len() <= 2 * columns + 2 {
        return points;
    }
    if points.windows(2).any(|w| w[1].0 < w[0].0) {
        return by_runs(&points, columns);
    }
    let (x0, x1) = (points[0].0, points[points.len() - 1].0);
    let span = x1 - x0;
    if span <= 0.0 {
        // All at one x: the extremes are all there is to draw.
        return min_max_in_order(&points, 0, points.len());
    }
    let column_of = |x: f64| -> usize {
        let c = ((x - x0) / span * columns as f64).floor();
        if c < 0.0 {
            0
        } else {
            (c as usize).min(columns - 1)
        }
    };
    let last = points.len() - 1;
    let mut out = Vec::with_capacity(2 * columns + 2);
    out.push(points[0]);
    let mut start = 1;
    while start < last {
        let col = column_of(points[start].0);
        let mut end = start + 1;
        while end < last && column_of(points[end].0) == col {
            end += 1;
        }
        out.extend(min_max_in_order(&points, start, end));
        start = end;
    }
    out.push(points[last]);
    out
}

/// Decimation over runs of consecutive samples (for non-monotonic `x`).
fn by_runs(points: &[(f64, f64)], columns: usize) -> Vec<(f64, f64)> {
    let last = points.len() - 1;
    let inner = last - 1; // points[1..last]
    let mut out = Vec::with_capacity(2 * columns + 2);
    out.push(points[0]);
    for c in 0..columns {
        let start = 1 + c * inner / columns;
        let end = 1 + (c + 1) * inner / columns;
        if start < end {
            out.extend(min_max_in_order(points, start, end));
        }
    }
    out.push(points[last]);
    out
}

/// The minimum and maximum of `points[start..end]` by y, in index order (one point if they
/// coincide).
fn min_max_in_order(points: &[(f64, f64)], start: usize, end: usize) -> Vec<(f64, f64)> {
    let mut i_min = start;
    let mut i_max = start;
    for i in start..end {
        if points[i].1 < points[i_min].1 {
            i_min = i;
        }
        if points[i].1 > points[i_max].1 {
            i_max = i;
        }
    }
    match i_min.cmp(&i_max) {
        std::cmp::Ordering::Less => vec![points[i_min], points[i_max]],
        std::cmp::Ordering::Greater => vec![points[i_max], points[i_min]],
        std::cmp::Ordering::Equal => vec![points[i_min]],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extremes_survive_and_size_is_bounded() {
        // A slow sine with two single-sample spikes: both spikes must survive.
        let n = 100_000;
        let x: Vec<f64> = (0..n).map(|i| i as f64 * 0.1).collect();
        let mut y: Vec<f64> = x.iter().map(|t| (t / 500.0).sin()).collect();
        y[12_345] = 50.0;
        y[87_654] = -40.0;
        let columns = 800;
        let d = decimate_min_max(&x, &y, columns);
        assert!(d.len() <= 2 * columns + 2, "got {} points", d.len());
        assert_eq!(d[0], (x[0], y[0]), "first point kept");
        assert_eq!(*d.last().unwrap(), (x[n - 1], y[n - 1]), "last point kept");
        assert!(d.contains(&(x[12_345], 50.0)), "max spike lost");
        assert!(d.contains(&(x[87_654], -40.0)), "min spike lost");
        // Global extremes equal those of the full series (independent computation: fold).
        let want_max = y.iter().cloned().fold(f64::MIN, f64::max);
        let want_min = y.iter().cloned().fold(f64::MAX, f64::min);
        let got_max = d.iter().map(|p| p.1).fold(f64::MIN, f64::max);
        let got_min = d.iter().map(|p| p.1).fold(f64::MAX, f64::min);
        assert_eq!((got_min, got_max), (want_min, want_max));
        // Time order kept.
        assert!(d.windows(2).all(|w| w[0].0 <= w[1].0), "not in time order");
    }

    #[test]
    fn every_column_extreme_survives() {
        // Per column: the decimated points of a column hold that column's min and max.
        let n = 10_000;
        let x: Vec<f64> = (0..n).map(|i| i as f64).collect();
        let y: Vec<f64> = (0..n).map(|i| ((i * 7919) % 1000) as f64 - 500.0).collect();
        let columns = 50;
        let d = decimate_min_max(&x, &y, columns);
        let width = (x[n - 1] - x[0]) / columns as f64;
        for c in 0..columns {
            let lo = x[0] + c as f64 * width;
            let hi = lo + width;
            let in_col = |t: f64| t >= lo && (t < hi || c == columns - 1);
            let full: Vec<f64> = (1..n - 1).filter(|&i| in_col(x[i])).map(|i| y[i]).collect();
            let dec: Vec<f64> = d.iter().filter(|p| in_col(p.0)).map(|p| p.1).collect();
            let fmax = full.iter().cloned().fold(f64::MIN, f64::max);
            let fmin = full.iter().cloned().fold(f64::MAX, f64::min);
            assert!(dec.contains(&fmax), "column {c}: max {fmax} lost");
            assert!(dec.contains(&fmin), "column {c}: min {fmin} lost");
        }
    }

    #[test]
    fn non_monotonic_x_keeps_path_and_extremes() {
        // Output against a cycling temperature: x goes up and down.
        let n = 20_000;
        let x: Vec<f64> = (0..n).map(|i| (i as f64 / 1000.0).sin() * 40.0).collect();
        let mut y: Vec<f64> = (0..n).map(|i| ((i * 31) % 17) as f64).collect();
        y[5_000] = 99.0;
        y[15_000] = -99.0;
        let d = decimate_min_max(&x, &y, 300);
        assert!(d.len() <= 602, "got {}", d.len());
        assert!(d.contains(&(x[5_000], 99.0)) && d.contains(&(x[15_000], -99.0)));
        // Every kept point is a point of the series, in sample order (x range covered).
        let xmin = d.iter().map(|p| p.0).fold(f64::MAX, f64::min);
        let xmax = d.iter().map(|p| p.0).fold(f64::MIN, f64::max);
        assert!(xmin < -39.0 && xmax > 39.0, "x range lost: {xmin}..{xmax}");
    }

    #[test]
    fn short_series_and_non_finite() {
        let x = [0.0, 1.0, 2.0, f64::NAN, 4.0];
        let y = [1.0, f64::INFINITY, 3.0, 4.0, 5.0];
        assert_eq!(
            decimate_min_max(&x, &y, 100),
            vec![(0.0, 1.0), (2.0, 3.0), (4.0, 5.0)]
        );
        assert!(decimate_min_max(&[], &[], 10).is_empty());
    }
}
