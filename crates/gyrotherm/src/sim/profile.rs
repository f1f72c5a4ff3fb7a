//! Thermal-chamber set-point profiles: built-ins and the user segment file.
//!
//! A profile is a start temperature and a list of segments `(duration_s, target_c)`: during a
//! segment the set point ramps linearly from the previous target to `target_c` over
//! `duration_s`; a segment whose target equals the previous one is a soak.
//!
//! # User profile file
//! Plain text, one segment per line, two fields `duration_s,target_c` separated by a comma
//! (or whitespace). Lines starting with `#` and blank lines are skipped; an optional header
//! line `duration_s,target_c` is allowed. The set point **starts at the first row's target**
//! and holds it for the first row's duration; each later row ramps from the previous target
//! to its own. Example (room, cool at 3 °C/min to -40 °C, soak):
//! ```text
//! duration_s,target_c
//! 3000,22     # hold at room temperature
//! 1240,-40    # 62 °C at 3 °C/min
//! 9000,-40    # soak
//! ```
//! Limits (a row outside them is an error naming the line): duration in (0, 10^7] s, target in
//! [-80, 180] °C (thermal-chamber range), ramp rate at most `MAX_RAMP_C_PER_MIN`.

use super::SimError;

/// Fastest set-point ramp a profile may ask for, °C/min (fast thermal-shock chambers reach
/// about 15-25 °C/min; anything beyond is most likely a typo in the file).
pub(crate) const MAX_RAMP_C_PER_MIN: f64 = 30.0;
/// Coldest / hottest allowed set point, °C (typical thermal-chamber range).
pub(crate) const TARGET_RANGE_C: (f64, f64) = (-80.0, 180.0);
/// Longest allowed segment, s.
pub(crate) const MAX_SEGMENT_S: f64 = 1e7;

/// One profile segment: ramp the set point linearly to `target_c` over `duration_s`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// Segment length, s (> 0).
    pub duration_s: f64,
    /// Set point at the end of the segment, °C.
    pub target_c: f64,
}

/// A chamber set-point profile.
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    /// Name (a built-in's name, or the file it came from).
    pub name: String,
    /// Set point at t = 0, °C.
    pub start_c: f64,
    /// Segments, in order.
    pub segments: Vec<Segment>,
}

/// Names of the built-in profiles, with a one-line description each.
pub const BUILTIN_PROFILES: [(&str, &str); 6] = [
    (
        "seed-shock",
        "the published shock test (He et al. 2024): 22 °C, 3 °C/min to -40 °C, soak 9000 s, \
         3 °C/min to +60 °C, soak 9000 s, back to 22 °C; 30,000 s",
    ),
    (
        "slow-ramp",
        "the usual test limit: 22 °C, 1 °C/min to -20 °C, soak 7000 s, 1 °C/min to +50 °C, \
         soak 7000 s, back to 22 °C; 28,000 s",
    ),
    (
        "fast-cycle",
        "harsher shock: 22 °C, two cycles at 5 °C/min between -30 °C and +70 °C with 3000 s \
         soaks, back to 22 °C; 20,300 s",
    ),
    (
        "room-steady",
        "constant 22 °C set point for 10,000 s (noise and static checks)",
    ),
    (
        "shock-5",
        "seed-shock at 5 °C/min: 22 °C, 5 °C/min to -40 °C, soak 9000 s, 5 °C/min to +60 °C, \
         soak 9000 s, back to 22 °C; 28,400 s",
    ),
    (
        "airborne",
        "a flight: soak at +50 °C on the ground for 3600 s, climb to -45 °C in 600 s \
         (9.5 °C/min), cruise 4 h, descend to +20 °C in 1800 s, 3000 s on the ground; 23,400 s",
    ),
];

impl Profile {
    /// A built-in profile by name (see [`BUILTIN_PROFILES`]).
    pub fn builtin(name: &str) -> Result<Profile, SimError> {
        // (duration_s, target_c) rows; the first row is a hold at the start temperature.
        let rows: &[(f64, f64)] = match name {
            // He et al. 2024, sec. "tests": room, cool 3 °C/min to -40, soak, heat 3 °C/min to
            // +60, soak; we add the return to room so that runs can be chained.
            "seed-shock" => &[
                (3000.0, 22.0),
                (1240.0, -40.0), // 62 °C / (3 °C/min)
                (9000.0, -40.0),
                (2000.0, 60.0), // 100 °C / (3 °C/min)
                (9000.0, 60.0),
                (760.0, 22.0), // 38 °C / (3 °C/min)
                (5000.0, 22.0),
            ],
            "slow-ramp" => &[
                (2000.0, 22.0),
                (2520.0, -20.0), // 42 °C / (1 °C/min)
                (7000.0, -20.0),
                (4200.0, 50.0), // 70 °C / (1 °C/min)
                (7000.0, 50.0),
                (1680.0, 22.0), // 28 °C / (1 °C/min)
                (3600.0, 22.0),
            ],
            "fast-cycle" => &[
                (1500.0, 22.0),
                (624.0, -30.0), // 52 °C / (5 °C/min)
                (3000.0, -30.0),
                (1200.0, 70.0), // 100 °C / (5 °C/min)
                (3000.0, 70.0),
                (1200.0, -30.0),
                (3000.0, -30.0),
                (1200.0, 70.0),
                (3000.0, 70.0),
                (576.0, 22.0), // 48 °C / (5 °C/min)
                (2000.0, 22.0),
            ],
            "room-steady" => &[(10000.0, 22.0)],
            // The seed-shock test at the faster rate of a shock chamber.
            "shock-5" => &[
                (3000.0, 22.0),
                (744.0, -40.0), // 62 °C / (5 °C/min)
                (9000.0, -40.0),
                (1200.0, 60.0), // 100 °C / (5 °C/min)
                (9000.0, 60.0),
                (456.0, 22.0), // 38 °C / (5 °C/min)
                (5000.0, 22.0),
            ],
            // The seed paper's motivating case (He et al. 2024, introduction: +50 °C on the
            // ground to about -50 °C at altitude): a gyro soaked on a hot apron, a climb,
            // hours of cruise, the descent.
            "airborne" => &[
                (3600.0, 50.0),
                (600.0, -45.0), // 95 °C in 10 min
                (14400.0, -45.0),
                (1800.0, 20.0), // 65 °C in 30 min
                (3000.0, 20.0),
            ],
            _ => {
                let names: Vec<&str> = BUILTIN_PROFILES.iter().map(|p| p.0).collect();
                return Err(SimError::Config(format!(
                    "unknown profile {name:?}; built-in profiles are {} (or give a segment file)",
                    names.join(", ")
                )));
            }
        };
        Ok(Profile {
            name: name.to_owned(),
            start_c: rows[0].1,
            segments: rows
                .iter()
                .map(|&(duration_s, target_c)| Segment {
                    duration_s,
                    target_c,
                })
                .collect(),
        })
    }

    /// Parse a user profile file's text (format in the module doc). `source` names the file in
    /// error messages.
    pub fn parse(text: &str, source: &str) -> Result<Profile, SimError> {
        let err = |line: usize, message: String| SimError::Profile {
            source: source.to_owned(),
            line,
            message,
        };
        let mut segments: Vec<Segment> = Vec::new();
        let mut seen_data = false;
        for (idx, raw) in text.lines().enumerate() {
            let line_no = idx + 1;
            let body = raw.split('#').next().unwrap_or("").trim();
            if body.is_empty() {
                continue;
            }
            let fields: Vec<&str> = body
                .split(|c: char| c == ',' || c.is_whitespace())
                .filter(|f| !f.is_empty())
                .collect();
            if !seen_data
                && segments.is_empty()
                && fields.len() == 2
                && fields[0] == "duration_s"
                && fields[1] == "target_c"
            {
                seen_data = true;
                continue;
            }
            seen_data = true;
            if fields.len() != 2 {
                return Err(err(
                    line_no,
                    format!(
                        "expected 2 fields `duration_s,target_c`, found {} in {body:?}",
                        fields.len()
                    ),
                ));
            }
            let num = |f: &str, what: &str| -> Result<f64, SimError> {
                let v: f64 = f.parse().map_err(|_| {
                    err(
                        line_no,
                        format!("{what} {f:?} is not a number (write e.g. `1200,-40`)"),
                    )
                })?;
                if !v.is_finite() {
                    return Err(err(line_no, format!("{what} {f:?} is not finite")));
                }
                Ok(v)
            };
            let duration_s = num(fields[0], "duration_s")?;
            let target_c = num(fields[1], "target_c")?;
            if !(duration_s > 0.0 && duration_s <= MAX_SEGMENT_S) {
                return Err(err(
                    line_no,
                    format!(
                        "duration_s {} must be > 0 and at most {MAX_SEGMENT_S} s",
                        crate::csvlog::short_f64(duration_s)
                    ),
                ));
            }
            if !(TARGET_RANGE_C.0..=TARGET_RANGE_C.1).contains(&target_c) {
                return Err(err(
                    line_no,
                    format!(
                        "target_c {target_c} is outside the chamber range {} to {} °C",
                        TARGET_RANGE_C.0, TARGET_RANGE_C.1
                    ),
                ));
            }
            if let Some(prev) = segments.last() {
                let rate = (target_c - prev.target_c).abs() / duration_s * 60.0;
                if rate > MAX_RAMP_C_PER_MIN {
                    return Err(err(
                        line_no,
                        format!(
                            "ramp from {} to {target_c} °C in {duration_s} s is {rate:.3} °C/min, \
                             faster than {MAX_RAMP_C_PER_MIN} °C/min; lengthen the segment",
                            prev.target_c
                        ),
                    ));
                }
            }
            segments.push(Segment {
                duration_s,
                target_c,
            });
        }
        let first = segments.first().ok_or_else(|| {
            err(
                0,
                "no segments: the file needs at least one `duration_s,target_c` row".into(),
            )
        })?;
        Ok(Profile {
            name: source.to_owned(),
            start_c: first.target_c,
            segments,
        })
    }

    /// Total length, s.
    pub fn duration_s(&self) -> f64 {
        self.segments.iter().map(|s| s.duration_s).sum()
    }

    /// Set point at time `t_s`, °C (held at the last target after the end).
    pub fn setpoint_c(&self, t_s: f64) -> f64 {
        let mut from = self.start_c;
        let mut t0 = 0.0;
        for s in &self.segments {
            if t_s < t0 + s.duration_s {
                let f = ((t_s - t0) / s.duration_s).clamp(0.0, 1.0);
                return from + (s.target_c - from) * f;
            }
            t0 += s.duration_s;
            from = s.target_c;
        }
        from
    }

    /// Checks a profile built in code (same limits as the file parser).
    pub fn validate(&self) -> Result<(), SimError> {
        let bad = |m: String| Err(SimError::Config(format!("profile {:?}: {m}", self.name)));
        if self.segments.is_empty() {
            return bad("no segments".into());
        }
        if !self.start_c.is_finite() {
            return bad("start_c is not finite".into());
        }
        for (i, s) in self.segments.iter().enumerate() {
            if !(s.duration_s > 0.0 && s.duration_s <= MAX_SEGMENT_S && s.target_c.is_finite()) {
                return bad(format!(
                    "segment {i}: duration_s {} must be in (0, {MAX_SEGMENT_S}] and target_c {} finite",
                    s.duration_s, s.target_c
                ));
            }
        }
        Ok(())
    }
}

/// Steps through a profile at increasing times without rescanning from the start.
#[derive(Debug, Clone)]
pub(crate) struct SetpointCursor<'a> {
    profile: &'a Profile,
    seg: usize,
    seg_t0_s: f64,
    from_c: f64,
}

impl<'a> SetpointCursor<'a> {
    pub(crate) fn new(profile: &'a Profile) -> Self {
        SetpointCursor {
            profile,
            seg: 0,
            seg_t0_s: 0.0,
            from_c: profile.start_c,
        }
    }

    /// Set point at `t_s`, °C; `t_s` must not decrease between calls.
    pub(crate) fn at(&mut self, t_s: f64) -> f64 {
        let segs = &self.profile.segments;
        while self.seg < segs.len() && t_s >= self.seg_t0_s + segs[self.seg].duration_s {
            self.seg_t0_s += segs[self.seg].duration_s;
            self.from_c = segs[self.seg].target_c;
            self.seg += 1;
        }
        match segs.get(self.seg) {
            None => self.from_c,
            Some(s) => {
                let f = ((t_s - self.seg_t0_s) / s.duration_s).clamp(0.0, 1.0);
                self.from_c + (s.target_c - self.from_c) * f
            }
        }
    }
}
