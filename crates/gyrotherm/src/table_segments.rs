//! Rate-table segments: runs of samples with one commanded table rate. The one segmentation
//! that the scale-factor figures ([`crate::metrics::scale_factor()`]) and the scale-factor
//! training targets (`crate::targets::scale_targets`) share, so the two always agree on
//! where a segment starts and ends.
//!
//! Tolerance: a reading belongs to the current segment when it lies within `tol_dps` of the
//! segment's **first** reading (comparing with the first, not the previous, reading keeps a
//! slow drift from chaining into one segment). `RATE_TOLERANCE_DPS` (1e-9 °/s) absorbs the
//! decimal round-off of a logged command column (`19.999999999999996`); a measured table
//! rate with encoder noise is not a command column and must be turned into one first. A
//! segment whose rate is within the tolerance of zero is a stop segment (`Segment::is_stop`).

/// Default tolerance, °/s: two readings this close are the same commanded rate.
pub(crate) const RATE_TOLERANCE_DPS: f64 = 1e-9;

/// A run of samples with one commanded table rate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// First sample index.
    pub start: usize,
    /// One past the last sample index.
    pub end: usize,
    /// Commanded rate: the segment's first reading, °/s.
    pub rate_dps: f64,
}

impl Segment {
    /// True when the rate is zero within `tol_dps` (a stop segment).
    pub(crate) fn is_stop(&self, tol_dps: f64) -> bool {
        self.rate_dps.abs() <= tol_dps
    }
}

/// Runs of one commanded rate in `table_dps`, readings within `tol_dps` of each run's first
/// reading counting as the same command (see the module doc).
pub fn segments(table_dps: &[f64], tol_dps: f64) -> Vec<Segment> {
    let mut out: Vec<Segment> = Vec::new();
    for (i, &r) in table_dps.iter().enumerate() {
        match out.last_mut() {
            Some(s) if (r - s.rate_dps).abs() <= tol_dps => s.end = i + 1,
            _ => out.push(Segment {
                start: i,
                end: i + 1,
                rate_dps: r,
            }),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_off_stays_in_one_segment_and_a_new_command_starts_one() {
        let table = [
            0.0,
            1e-12,
            -1e-12,
            20.0,
            19.999999999999996,
            20.0,
            0.0,
            -20.0,
        ];
        let s = segments(&table, RATE_TOLERANCE_DPS);
        let runs: Vec<(usize, usize)> = s.iter().map(|s| (s.start, s.end)).collect();
        assert_eq!(runs, [(0, 3), (3, 6), (6, 7), (7, 8)]);
        assert!(s[0].is_stop(RATE_TOLERANCE_DPS) && !s[1].is_stop(RATE_TOLERANCE_DPS));
        // Exact readings: every change of value is a new segment.
        assert_eq!(segments(&[1.0, 1.0, 2.0], 0.0).len(), 2);
    }
}
