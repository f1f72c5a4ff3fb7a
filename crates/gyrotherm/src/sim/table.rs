//! Rate-table schedule: repeating +Ω / stop / -Ω / stop segments (He et al. 2024, dynamic
//! test: table at +20 °/s, stop, then -20 °/s), starting at t = 0 with +Ω.
//!
//! Rate steps are instantaneous (the paper logs the output only after the rate settles; a
//! table's ~1 s acceleration is not modelled), and a rate sample is the rate at the start
//! of its sample period, so a step never falls inside a period when segment lengths are
//! whole multiples of the sample period.

/// Table rate at time `t_s`, °/s, for rate `rate_dps` and segment length `segment_s`.
pub fn table_rate_dps(rate_dps: f64, segment_s: f64, t_s: f64) -> f64 {
    // Small tolerance so that t = k·segment computed as i/fs lands in segment k.
    let k = libm::floor(t_s / segment_s + 1e-9) as i64;
    match k.rem_euclid(4) {
        0 => rate_dps,
        2 => -rate_dps,
        _ => 0.0,
    }
}
