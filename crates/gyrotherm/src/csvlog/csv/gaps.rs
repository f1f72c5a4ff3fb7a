//! Gap filling: a step longer than [`GAP_FACTOR`](super::GAP_FACTOR) nominal periods is a
//! gap; with a fill limit it is filled by linear interpolation (gyro, temperature; the table
//! rate holds the earlier sample's value), else it is an error.

/// Most samples one gap may be filled with; beyond it the gap is reported as too long, so
/// that a tiny period and a large limit cannot exhaust memory.
pub const MAX_FILL_SAMPLES_PER_GAP: usize = 10_000_000;

/// One validated row: finite numbers, gyro converted to °/s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Time, s (strictly increasing along the log).
    pub time_s: f64,
    /// Gyro output, °/s (converted from the file's unit).
    pub gyro_dps: f64,
    /// Temperature, °C.
    pub temp_c: f64,
    /// Rate-table input rate, °/s (None: the log has no table column).
    pub table_dps: Option<f64>,
}

/// Gap filling in progress: `n` samples between `from` and `to`, `k` already handed out.
#[derive(Debug, Clone, Copy)]
pub(super) struct Fill {
    pub(super) from: Sample,
    pub(super) to: Sample,
    pub(super) to_line: u64,
    pub(super) n: usize,
    pub(super) k: usize,
}

impl Fill {
    /// The next interpolated sample, None once all `n` are out.
    #[inline]
    pub(super) fn next_filled(&mut self) -> Option<Sample> {
        if self.k >= self.n {
            return None;
        }
        self.k += 1;
        let a = self.k as f64 / (self.n + 1) as f64;
        Some(Sample {
            time_s: lerp(self.from.time_s, self.to.time_s, a),
            gyro_dps: lerp(self.from.gyro_dps, self.to.gyro_dps, a),
            temp_c: lerp(self.from.temp_c, self.to.temp_c, a),
            table_dps: self.from.table_dps,
        })
    }
}

/// What to do with a gap of `dt` seconds at nominal period `period`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum GapVerdict {
    /// Fill it with this many samples.
    Fill(usize),
    /// Longer than the fill limit (s).
    TooLong(f64),
    /// Within the fill limit, but it would take this many samples, more than
    /// [`MAX_FILL_SAMPLES_PER_GAP`].
    TooManySamples(f64),
    /// No filling asked for.
    NotAllowed,
}

/// A gap of `dt` s gets `round(dt / period) − 1` samples when filling is on, `dt` is within
/// the limit and the count within [`MAX_FILL_SAMPLES_PER_GAP`].
pub(super) fn gap_verdict(dt: f64, period: f64, fill_max_s: Option<f64>) -> GapVerdict {
    let n_f = (dt / period).round() - 1.0;
    match fill_max_s {
        // dt > 1.5 period, so n_f >= 1.
        Some(max) if dt > max => GapVerdict::TooLong(max),
        Some(_) if n_f > MAX_FILL_SAMPLES_PER_GAP as f64 => GapVerdict::TooManySamples(n_f),
        Some(_) => GapVerdict::Fill((n_f as usize).max(1)),
        None => GapVerdict::NotAllowed,
    }
}

#[inline]
fn lerp(a: f64, b: f64, t: f64) -> f64 {
    let v = a + (b - a) * t;
    // `b - a` overflows for values of opposite sign near f64's limit; only then the
    // weighted sum, which cannot, is used (elsewhere the values stay as they were).
    if v.is_finite() {
        v
    } else {
        a * (1.0 - t) + b * t
    }
}
