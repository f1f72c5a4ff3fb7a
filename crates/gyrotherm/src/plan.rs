//! `gyrotherm plan`: what the training logs so far cover of a flight's (T, dT) envelope, and
//! a chamber profile that covers the rest.
//!
//! **Coverage.** The training logs are fitted with `thermal` (what the default `auto` fits
//! first); the fit's coverage map
//! ([`crate::coverage`]) is the region they cover. Against it: the flight log's samples,
//! stepped as `compensate` steps them ([`crate::coverage_track`]), and a 41 × 41 lattice
//! over the envelope's rectangle (temperature × ±rate).
//!
//! **Profile.** A deliberately simple design (constants in [`crate::settings::plan`]):
//! from room temperature, ramp to the envelope's hot end and soak; then at each of
//! `crate::settings::plan::RATE_LEVELS` rates `R·k/levels` (slowest first, R
//! the flight's largest |dT| with a margin, at most the chamber's), ramp cold, soak, ramp
//! hot, soak, repeated until every temperature cell of the coverage grid holds
//! `crate::settings::plan::MIN_CELL_S` seconds of each ramp direction; back to
//! room. The envelope is the flight's temperature extremes widened by
//! `crate::settings::plan::TEMP_MARGIN_C`, clipped to the chamber's range.
//! Down- and up-ramps give −r and +r, the soaks 0: the rate rows of the grid between levels
//! are at most one cell from a covered one.
//!
//! **Soaks.** With training logs, the first soak at each extreme is long enough to separate
//! the slowest thermal lag their fit identified: `LONG_SOAK_PER_LAG` times that lag
//! ([`crate::settings::plan`]), so that its state settles at a constant temperature, where it
//! can be told from the faster ones. The other soaks, and every soak without training logs,
//! last `SOAK_S`. [`Plan::soak`] says which length was chosen and why.
//!
//! **Units.** An inertial unit's logs ([`set_coverage`]) are planned for pair by pair: every
//! gyro axis on every temperature sensor, each as a single gyro's logs; the soaks follow the
//! slowest lag of any pair ([`slowest_lag`]), and a unit's flight envelope is the union over
//! its sensors ([`resolve_set_envelope`]).

use std::borrow::Cow;
use std::fmt;

use crate::coverage_track::track;
use crate::csvlog::{LogSet, LogSetForm, ReadOptions, TestLog};
use crate::fit::{fit_model, FitConfig, FitError, NamedLog};
use crate::settings::coverage::TEMP_CELLS;
use crate::settings::plan::{
    PlanSettings, LONG_SOAK_PER_LAG, MIN_CELL_S, RATE_LEVELS, RATE_MARGIN, ROOM_C, SOAK_S,
    TEMP_MARGIN_C,
};
use crate::settings::{Method, SettingError};
use crate::sim::{Profile, Segment};

/// The flight's envelope: temperature extremes (°C) and largest |dT| (°C/min).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Envelope {
    pub temp_min_c: f64,
    pub temp_max_c: f64,
    pub max_rate_c_per_min: f64,
}

/// Why no plan was made.
#[derive(Debug)]
#[non_exhaustive]
pub enum PlanError {
    /// A setting breaks its rule.
    Setting(SettingError),
    /// No flight log and an incomplete envelope.
    NoEnvelope,
    /// The flight log has no finite temperature.
    EmptyFlight,
    /// Fitting the training logs failed.
    Fit(FitError),
    /// Stepping a log through the fitted model failed.
    Compensate(crate::compensate::CompensateError),
    /// The fit's coverage map is refused by the flight crate.
    Coverage(gyrotherm_core::coverage::CoverageError),
    /// The flight log's temperature never changes (or it has one sample): no rate to plan
    /// ramps for.
    FlatFlight { samples: usize },
    /// The proposed profile breaks a limit of `simulate --profile-file` (the message of
    /// [`Profile::parse`] on the text `plan --out` writes).
    Profile(crate::sim::SimError),
}

impl fmt::Display for PlanError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PlanError::Setting(e) => e.fmt(f),
            PlanError::NoEnvelope => f.write_str(
                "no envelope: give a flight log (--flight) or all of --temp-min-c, --temp-max-c \
                 and --max-rate-c-per-min",
            ),
            PlanError::EmptyFlight => f.write_str("the flight log has no finite temperature"),
            PlanError::Fit(_) => f.write_str("fitting the training logs"),
            PlanError::Compensate(_) => f.write_str("stepping the flight through the fit"),
            PlanError::Coverage(e) => write!(f, "the fit's coverage map: {e}"),
            PlanError::FlatFlight { samples } => write!(
                f,
                "the flight log's temperature does not change ({samples} sample{}), so it \
                 gives no largest |dT| to plan ramps for: give --max-rate-c-per-min",
                if *samples == 1 { "" } else { "s" }
            ),
            PlanError::Profile(e) => write!(
                f,
                "the proposed profile is not one `simulate --profile-file` accepts: {e}; a \
                 ramp longer than its longest segment ({} s) needs a faster \
                 --max-rate-c-per-min or --chamber-max-rate-c-per-min",
                crate::sim::profile::MAX_SEGMENT_S
            ),
        }
    }
}

impl std::error::Error for PlanError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            // Transparent: the setting's message is this error's own.
            PlanError::Setting(e) => e.source(),
            PlanError::Fit(e) => Some(e),
            PlanError::Compensate(e) => Some(e),
            _ => None,
        }
    }
}

/// The envelope of a flight log: its sensor temperature's extremes and the largest |rate|
/// of the report's temperature rate (100 s smoothing, so the sensor's 0.0625 °C steps do not
/// read as rates; `crate::features::temperature_rate_c_per_min`).
pub fn envelope_of(log: &TestLog) -> Result<Envelope, PlanError> {
    let finite = || log.temp_c.iter().copied().filter(|t| t.is_finite());
    let lo = finite().fold(f64::INFINITY, f64::min);
    let hi = finite().fold(f64::NEG_INFINITY, f64::max);
    if !(lo.is_finite() && hi.is_finite()) {
        return Err(PlanError::EmptyFlight);
    }
    let rate = crate::features::temperature_rate_c_per_min(&log.time_s, &log.temp_c)
        .into_iter()
        .filter(|r| r.is_finite())
        .fold(0.0f64, |m, r| m.max(r.abs()));
    // The fold starts at 0 and keeps finite rates only: 0 is a flat flight.
    if rate == 0.0 {
        return Err(PlanError::FlatFlight {
            samples: log.time_s.len(),
        });
    }
    Ok(Envelope {
        temp_min_c: lo,
        temp_max_c: hi,
        max_rate_c_per_min: rate,
    })
}

/// The envelope of a flight whose temperature does not change, with the rate given.
fn flat_envelope(log: &TestLog, max_rate_c_per_min: f64) -> Envelope {
    let t = log
        .temp_c
        .iter()
        .copied()
        .find(|t| t.is_finite())
        .unwrap_or(ROOM_C);
    Envelope {
        temp_min_c: t,
        temp_max_c: t,
        max_rate_c_per_min,
    }
}

/// The envelope to plan for: the settings' values where given, else the flight's.
pub fn resolve_envelope(flight: Option<&TestLog>, s: &PlanSettings) -> Result<Envelope, PlanError> {
    s.validate().map_err(PlanError::Setting)?;
    // A flight's flat temperature matters only when its rate is what is planned for.
    let from_flight = match flight.map(envelope_of).transpose() {
        Err(PlanError::FlatFlight { .. }) if s.max_rate_c_per_min.is_some() => {
            flight.map(|log| flat_envelope(log, s.max_rate_c_per_min.unwrap_or(0.0)))
        }
        r => r?,
    };
    let pick = |given: Option<f64>, f: fn(&Envelope) -> f64| {
        given
            .or(from_flight.as_ref().map(f))
            .ok_or(PlanError::NoEnvelope)
    };
    Ok(Envelope {
        temp_min_c: pick(s.temp_min_c, |e| e.temp_min_c)?,
        temp_max_c: pick(s.temp_max_c, |e| e.temp_max_c)?,
        max_rate_c_per_min: pick(s.max_rate_c_per_min, |e| e.max_rate_c_per_min)?,
    })
}

/// What the training logs cover.
#[derive(Debug, Clone, PartialEq)]
pub struct CoverageSummary {
    /// Covered cells and all cells of the grid.
    pub covered_cells: usize,
    pub cells: usize,
    /// The covered cells' span: temperature (°C) and rate (°C/min).
    pub temp_span_c: (f64, f64),
    pub rate_span_c_per_min: (f64, f64),
    /// The flight's samples inside, at the edge and outside (None without a flight log).
    pub flight_shares: Option<[f64; 3]>,
    /// Share of the envelope's rectangle (41 × 41 lattice) outside.
    pub envelope_outside: f64,
    /// The slowest thermal lag the fit identified, s (None: the fit holds no lag), and
    /// whether it sits at the lag search's upper bound (the true lag may then be longer).
    pub slowest_lag_s: Option<f64>,
    pub lag_at_bound: bool,
}

/// The coverage of `train` against the flight and the envelope; None when the fit carries no
/// coverage map (the reason is `FitOutcome::coverage_note`'s, returned as the error text).
pub fn training_coverage(
    train: &[NamedLog],
    flight: Option<&TestLog>,
    env: &Envelope,
) -> Result<Result<CoverageSummary, String>, PlanError> {
    // `thermal`, whatever the default: the plan needs the (T, dT) cells the training covers
    // and the slowest lag, which `thermal` identifies and an LSTM on its residual leaves as
    // they are (and `thermal` fits in under a second).
    let fit = fit_model(train, &FitConfig::new(Method::Thermal), &|_, _, _| {})
        .map_err(PlanError::Fit)?;
    let Some(def) = fit.model.coverage.as_ref() else {
        return Ok(Err(fit
            .coverage_note
            .unwrap_or_else(|| "the fit has no coverage map".to_owned())));
    };
    let cells = crate::coverage_track::covered_cells(def);
    let span = |f: fn(&crate::coverage_track::CoveredCell) -> (f64, f64)| {
        cells
            .iter()
            .map(f)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), (l, h)| {
                (a.min(l), b.max(h))
            })
    };
    let (r0, r1) = span(|c| c.rate_c_per_s);
    let flight_shares = match flight {
        Some(log) => track(&fit.model, log)
            .map_err(PlanError::Compensate)?
            .and_then(|t| t.shares()),
        None => None,
    };
    let slowest_lag_s = fit
        .model
        .features
        .lag_tau_s
        .iter()
        .copied()
        .filter(|t| t.is_finite())
        .reduce(f64::max);
    let bound_s = FitConfig::new(Method::Thermal).thermal.tau_range_s.1;
    let lag_at_bound = slowest_lag_s.is_some_and(|t| t >= 0.99 * bound_s);
    let map = def.to_core().map_err(PlanError::Coverage)?;
    const N: usize = 41;
    let mut outside = 0usize;
    for i in 0..N {
        let t = env.temp_min_c + (env.temp_max_c - env.temp_min_c) * i as f64 / (N - 1) as f64;
        for j in 0..N {
            let r = env.max_rate_c_per_min * (2.0 * j as f64 / (N - 1) as f64 - 1.0) / 60.0;
            if map.verdict(t, r).coverage == gyrotherm_core::coverage::Coverage::Outside {
                outside += 1;
            }
        }
    }
    Ok(Ok(CoverageSummary {
        covered_cells: cells.len(),
        cells: def.n_temp * def.n_rate,
        temp_span_c: span(|c| c.temp_c),
        rate_span_c_per_min: (60.0 * r0, 60.0 * r1),
        flight_shares,
        envelope_outside: outside as f64 / (N * N) as f64,
        slowest_lag_s,
        lag_at_bound,
    }))
}

/// What the training logs cover on one gyro column read with one temperature column.
#[derive(Debug, Clone, PartialEq)]
pub struct PairCoverage {
    pub gyro: String,
    pub temp: String,
    /// What they cover, or why there is no coverage map (the fit's note).
    pub coverage: Result<CoverageSummary, String>,
}

/// What a job's training logs cover ([`training_coverage`] per pair): a single gyro's one
/// gyro and temperature column (named by `opts`), or every gyro axis of an inertial unit on
/// every temperature sensor, since an axis's bias follows each sensor with lags of its own.
/// A unit's `flight` is its own log, each pair seen on the same columns; the envelope `env`
/// is the one of [`resolve_set_envelope`].
pub fn set_coverage(
    train: &LogSet,
    flight: Option<&LogSet>,
    env: &Envelope,
    opts: &ReadOptions,
) -> Result<Vec<PairCoverage>, PlanError> {
    let mut out = Vec::new();
    for (gyro, temp) in column_pairs(train, opts) {
        let logs = views_on(train, &gyro, &temp);
        let named: Vec<NamedLog> = logs
            .iter()
            .map(|(n, l)| NamedLog { name: n, log: l })
            .collect();
        // The flight's view on the same columns (its first log), made for this pair only.
        let flight = flight.and_then(|f| views_on(f, &gyro, &temp).into_iter().next());
        out.push(PairCoverage {
            coverage: training_coverage(&named, flight.as_ref().map(|(_, l)| &**l), env)?,
            gyro,
            temp,
        });
    }
    Ok(out)
}

/// The slowest lag any pair's fit identified, with the pair: what sizes the soaks.
pub fn slowest_lag(pairs: &[PairCoverage]) -> Option<(&PairCoverage, f64)> {
    pairs
        .iter()
        .filter_map(|p| {
            let c = p.coverage.as_ref().ok()?;
            Some((p, c.slowest_lag_s?))
        })
        .reduce(|a, b| if b.1 > a.1 { b } else { a })
}

/// Every (gyro, temperature) pair of a set: a single gyro's one (its columns named by
/// `opts`), a unit's every gyro column with every temperature column of its first log.
fn column_pairs(set: &LogSet, opts: &ReadOptions) -> Vec<(String, String)> {
    match set.form() {
        LogSetForm::Single(_) => vec![(opts.gyro_col.clone(), opts.temp_col.clone())],
        LogSetForm::Unit(logs) => logs.first().map_or_else(Vec::new, |(_, l)| {
            l.gyro
                .iter()
                .flat_map(|g| l.temp.iter().map(|t| (g.name.clone(), t.name.clone())))
                .collect()
        }),
    }
}

/// The set's logs seen on one pair of columns as single-axis logs (the gyro column, the
/// temperature column, the table rate where the table turns that gyro): a single gyro's as
/// they are, a unit's each log that holds both columns.
fn views_on<'a>(set: &'a LogSet, gyro: &str, temp: &str) -> Vec<(&'a str, Cow<'a, TestLog>)> {
    match set.form() {
        LogSetForm::Single(logs) => logs
            .iter()
            .map(|(n, l)| (n.as_str(), Cow::Borrowed(l)))
            .collect(),
        LogSetForm::Unit(logs) => logs
            .iter()
            .filter_map(|(n, l)| {
                let k = l.gyro.iter().position(|g| g.name == gyro)?;
                let j = l.temp.iter().position(|t| t.name == temp)?;
                Some((n.as_str(), Cow::Owned(l.axis_data(k, j))))
            })
            .collect(),
    }
}

/// [`resolve_envelope`] for a flight read as a set: a single gyro's log as it is; an inertial
/// unit's the union over its temperature columns (the coldest and hottest reading of any
/// sensor, the fastest rate of any).
pub fn resolve_set_envelope(
    flight: Option<&LogSet>,
    s: &PlanSettings,
) -> Result<Envelope, PlanError> {
    let logs = match flight.map(LogSet::form) {
        None => return resolve_envelope(None, s),
        Some(LogSetForm::Single(logs)) => return resolve_envelope(logs.first().map(|(_, l)| l), s),
        Some(LogSetForm::Unit(logs)) => logs,
    };
    let Some((_, log)) = logs.first() else {
        return resolve_envelope(None, s);
    };
    if log.gyro.is_empty() {
        return resolve_envelope(None, s);
    }
    let views: Vec<TestLog> = (0..log.temp.len()).map(|j| log.axis_data(0, j)).collect();
    // A sensor whose reading never changes gives no envelope of its own; the others do.
    let mut env: Option<Envelope> = None;
    let mut first_error = None;
    for v in &views {
        let e = match resolve_envelope(Some(v), s) {
            Ok(e) => e,
            Err(e @ (PlanError::FlatFlight { .. } | PlanError::EmptyFlight)) => {
                first_error.get_or_insert(e);
                continue;
            }
            Err(e) => return Err(e),
        };
        env = Some(match env {
            None => e,
            Some(a) => Envelope {
                temp_min_c: a.temp_min_c.min(e.temp_min_c),
                temp_max_c: a.temp_max_c.max(e.temp_max_c),
                max_rate_c_per_min: a.max_rate_c_per_min.max(e.max_rate_c_per_min),
            },
        });
    }
    match (env, first_error) {
        (Some(e), _) => Ok(e),
        (None, Some(e)) => Err(e),
        (None, None) => resolve_envelope(None, s),
    }
}

/// What a segment of the proposed profile does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    Hold,
    Ramp,
    Soak,
}

/// One row of the proposed profile, for the table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlannedSegment {
    pub step: Step,
    pub from_c: f64,
    pub to_c: f64,
    /// Set-point rate, °C/min (0 for holds and soaks).
    pub rate_c_per_min: f64,
    pub duration_s: f64,
}

/// The proposed profile.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The temperatures and the rate the profile spans (the envelope widened, clipped).
    pub temp_lo_c: f64,
    pub temp_hi_c: f64,
    pub max_rate_c_per_min: f64,
    /// Rates of the ramps, °C/min, slowest first, and each one's repetitions.
    pub rates_c_per_min: Vec<(f64, usize)>,
    pub segments: Vec<PlannedSegment>,
    /// What the chamber's limits cut from the envelope.
    pub notes: Vec<String>,
    /// The soaks' lengths and why.
    pub soak: SoakLength,
}

/// How long the proposed profile soaks (see the module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct SoakLength {
    /// The first soak at each extreme, s.
    pub long_s: f64,
    /// Every other soak, s.
    pub other_s: f64,
    /// Why `long_s`, in words.
    pub why: String,
}

impl SoakLength {
    fn for_lag(slowest_lag_s: Option<f64>) -> SoakLength {
        match slowest_lag_s {
            Some(tau) if LONG_SOAK_PER_LAG * tau > SOAK_S => SoakLength {
                long_s: LONG_SOAK_PER_LAG * tau,
                other_s: SOAK_S,
                why: format!(
                    "{LONG_SOAK_PER_LAG} × the slowest lag the training logs' fit identified \
                     ({tau:.0} s), so that its state settles at each extreme"
                ),
            },
            Some(tau) => SoakLength {
                long_s: SOAK_S,
                other_s: SOAK_S,
                why: format!(
                    "the slowest lag the training logs' fit identified ({tau:.0} s) settles \
                     within the fixed soak"
                ),
            },
            None => SoakLength {
                long_s: SOAK_S,
                other_s: SOAK_S,
                why: "no lag identified (give training logs to size the first soak at each \
                      extreme to their slowest lag)"
                    .to_owned(),
            },
        }
    }
}

impl Plan {
    /// Total duration, s.
    pub fn duration_s(&self) -> f64 {
        self.segments.iter().map(|s| s.duration_s).sum()
    }

    /// The profile as `simulate --profile-file` reads it ([`Profile::parse`]).
    pub fn profile_text(&self) -> String {
        let mut out = String::from(
            "# gyrotherm plan: chamber set point, one segment per row (see gyrotherm::plan)\n\
             duration_s,target_c\n",
        );
        for s in &self.segments {
            out.push_str(&format!("{},{}\n", round3(s.duration_s), round3(s.to_c)));
        }
        out
    }

    /// The profile as the simulator's.
    pub fn profile(&self) -> Profile {
        Profile {
            name: "plan".into(),
            start_c: self.segments.first().map_or(ROOM_C, |s| s.to_c),
            segments: self
                .segments
                .iter()
                .map(|s| Segment {
                    duration_s: round3(s.duration_s),
                    target_c: round3(s.to_c),
                })
                .collect(),
        }
    }
}

fn round3(v: f64) -> f64 {
    (v * 1000.0).round() / 1000.0
}

/// The chamber profile for `env` under the chamber limits of `s` (see the module doc).
pub fn propose(env: &Envelope, s: &PlanSettings) -> Result<Plan, PlanError> {
    s.validate().map_err(PlanError::Setting)?;
    let mut notes = Vec::new();
    let want_lo = env.temp_min_c - TEMP_MARGIN_C;
    let want_hi = env.temp_max_c + TEMP_MARGIN_C;
    let want_rate = env.max_rate_c_per_min * RATE_MARGIN;
    let lo = want_lo.max(s.chamber_min_c);
    let hi = want_hi.min(s.chamber_max_c);
    let rate = want_rate.min(s.chamber_max_rate_c_per_min);
    if lo > want_lo {
        notes.push(format!(
            "the chamber's coldest set point {} °C is above the envelope's {want_lo:.1} °C: \
             the coldest part stays outside coverage",
            s.chamber_min_c
        ));
    }
    if hi < want_hi {
        notes.push(format!(
            "the chamber's hottest set point {} °C is below the envelope's {want_hi:.1} °C: \
             the hottest part stays outside coverage",
            s.chamber_max_c
        ));
    }
    if rate < want_rate {
        notes.push(format!(
            "the chamber's fastest ramp {} °C/min is below the envelope's {want_rate:.2} \
             °C/min: the fastest rates stay outside coverage",
            s.chamber_max_rate_c_per_min
        ));
    }
    let (lo, hi) = if lo < hi { (lo, hi) } else { (hi - 1.0, hi) };
    let span = hi - lo;
    let soak = SoakLength::for_lag(s.slowest_lag_s);
    // The first soak at each extreme is the long one.
    let mut long_left = [true, true];
    let mut segments = vec![PlannedSegment {
        step: Step::Hold,
        from_c: ROOM_C,
        to_c: ROOM_C,
        rate_c_per_min: 0.0,
        duration_s: SOAK_S,
    }];
    let mut at = ROOM_C;
    let mut go = |to: f64, r: f64, segments: &mut Vec<PlannedSegment>| {
        let extreme = [lo, hi].iter().position(|&e| e == to);
        let long = extreme.is_some_and(|k| std::mem::take(&mut long_left[k]));
        if (to - at).abs() > 0.0 {
            segments.push(PlannedSegment {
                step: Step::Ramp,
                from_c: at,
                to_c: to,
                rate_c_per_min: r,
                duration_s: (to - at).abs() / r * 60.0,
            });
        }
        segments.push(PlannedSegment {
            step: Step::Soak,
            from_c: to,
            to_c: to,
            rate_c_per_min: 0.0,
            duration_s: if long { soak.long_s } else { soak.other_s },
        });
        at = to;
    };
    let slowest = rate / RATE_LEVELS as f64;
    go(hi, slowest, &mut segments);
    let mut rates = Vec::new();
    for k in 1..=RATE_LEVELS {
        let r = rate * k as f64 / RATE_LEVELS as f64;
        // Seconds a ramp at r spends in one temperature cell of the grid.
        let cell_s = span / TEMP_CELLS as f64 / r * 60.0;
        let reps = ((MIN_CELL_S / cell_s).ceil() as usize).max(1);
        rates.push((r, reps));
        for _ in 0..reps {
            go(lo, r, &mut segments);
            go(hi, r, &mut segments);
        }
    }
    go(ROOM_C.clamp(lo, hi), slowest, &mut segments);
    let plan = Plan {
        temp_lo_c: lo,
        temp_hi_c: hi,
        max_rate_c_per_min: rate,
        rates_c_per_min: rates,
        segments,
        notes,
        soak,
    };
    // What `plan --out` writes must be a profile `simulate --profile-file` reads: checked by
    // its own parser, so the two sets of limits cannot drift apart.
    Profile::parse(&plan.profile_text(), "plan").map_err(PlanError::Profile)?;
    Ok(plan)
}
