//! Allan deviation of a log column: the settings, and the policy of which curve the noise
//! terms are read from.

use crate::allan::{self, AllanError, AllanPoint, DevKind, NoiseModel, NoiseTerms, TauSet};
use crate::csvlog::{rate_column_to_dph, GYRO_COL};
use crate::setting_rule::{Rule, SettingError};

/// Names of the deviations, default first.
pub(crate) const KIND_NAMES: [&str; 5] = ["oadev", "adev", "mdev", "hdev", "ohdev"];
/// Default deviation.
pub const DEFAULT_KIND: DevKind = DevKind::Oadev;
/// Names of the automatic τ sets, default first (a comma-separated list of seconds is also
/// a τ set).
pub(crate) const TAU_SET_NAMES: [&str; 3] = ["octave", "decade", "all"];
/// Default τ set.
pub const DEFAULT_TAUS: TauSet = TauSet::Octave;

impl DevKind {
    /// One line on the deviation (the `--help` text of its value).
    pub fn help(self) -> &'static str {
        match self {
            DevKind::Oadev => "overlapping Allan deviation",
            DevKind::Adev => "non-overlapping Allan deviation",
            DevKind::Mdev => "modified Allan deviation",
            DevKind::Hdev => "non-overlapping Hadamard deviation (as Stable32 \"Hadamard\")",
            DevKind::Ohdev => "overlapping Hadamard deviation",
        }
    }
}

impl std::fmt::Display for DevKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::fmt::Display for TauSet {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TauSet::Octave => f.write_str("octave"),
            TauSet::Decade => f.write_str("decade"),
            TauSet::All => f.write_str("all"),
            TauSet::Seconds(s) => f.write_str(
                &s.iter()
                    .map(|t| t.to_string())
                    .collect::<Vec<_>>()
                    .join(","),
            ),
        }
    }
}

/// Parse a noise exponent α (`--alpha`): an integer from -4 to 2.
pub fn parse_alpha(s: &str) -> Result<i32, SettingError> {
    let bad = || SettingError::Invalid {
        setting: "alpha",
        value: format!("{s:?}"),
        rule: Rule::NoiseAlpha,
    };
    let a: i32 = s.trim().parse().map_err(|_| bad())?;
    Rule::NoiseAlpha
        .holds(f64::from(a))
        .then_some(a)
        .ok_or_else(bad)
}

/// What `gyrotherm allan` computes.
#[derive(Debug, Clone, PartialEq)]
pub struct AllanSettings {
    /// Column to analyse: `gyro_dps`, `temp_c`, `table_dps` or a numeric extra column.
    pub column: String,
    /// Which deviation.
    pub kind: DevKind,
    /// Which τ values.
    pub taus: TauSet,
    /// Noise exponent α for the confidence intervals at every τ (None: identified at each τ
    /// by the lag-1 autocorrelation).
    pub alpha: Option<i32>,
}

impl Default for AllanSettings {
    fn default() -> Self {
        AllanSettings {
            column: GYRO_COL.to_owned(),
            kind: DEFAULT_KIND,
            taus: DEFAULT_TAUS,
            alpha: None,
        }
    }
}

/// A deviation curve of a column and, for a rate column, its noise terms.
#[derive(Debug, Clone, PartialEq)]
pub struct AllanAnalysis {
    pub points: Vec<AllanPoint>,
    /// Noise terms (None: the column's unit is not a rate, so they mean nothing).
    pub noise: Option<NoiseTerms>,
    /// The curve the noise terms were read from: `adev` or `oadev`.
    pub noise_from: Option<&'static str>,
}

impl AllanSettings {
    /// Check every value; the error names the setting and the rule.
    pub fn validate(&self) -> Result<(), SettingError> {
        if let Some(a) = self.alpha {
            if !Rule::NoiseAlpha.holds(f64::from(a)) {
                return Err(SettingError::Invalid {
                    setting: "alpha",
                    value: a.to_string(),
                    rule: Rule::NoiseAlpha,
                });
            }
        }
        Ok(())
    }

    /// The noise model of the confidence intervals.
    pub(crate) fn noise_model(&self) -> NoiseModel {
        self.alpha.map_or(NoiseModel::Identify, NoiseModel::Alpha)
    }

    /// The curve of `values` (sampled every `tau0_s`) and its noise terms. Noise terms are
    /// defined on the Allan deviation (IEEE Std 952 annex C): for `adev` and `oadev` they are
    /// read from this curve, for the other kinds from an OADEV curve at the same τ; a column
    /// whose name gives no rate unit (`*_dps`, `*_dph`, `*_rad_s`) gets none. The samples are
    /// handed over (the phase is built in their buffer) unless the OADEV curve still needs
    /// them.
    pub fn analyse(&self, values: Vec<f64>, tau0_s: f64) -> Result<AllanAnalysis, AllanError> {
        let kind = self.kind;
        let noise_model = self.noise_model();
        let to_dph = rate_column_to_dph(&self.column);
        let needs_oadev = to_dph.is_some() && !matches!(kind, DevKind::Adev | DevKind::Oadev);
        let (points, values) = if needs_oadev {
            let p = allan::deviation(&values, tau0_s, kind, &self.taus, noise_model)?;
            (p, values)
        } else {
            let p = allan::deviation_owned(values, tau0_s, kind, &self.taus, noise_model)?;
            (p, Vec::new())
        };
        let (noise, noise_from) = match to_dph {
            None => (None, None),
            Some(f) => {
                let curve: Vec<AllanPoint> = match kind {
                    DevKind::Adev | DevKind::Oadev => points.clone(),
                    _ => {
                        let taus = TauSet::Seconds(points.iter().map(|p| p.tau_s).collect());
                        allan::deviation(&values, tau0_s, DevKind::Oadev, &taus, noise_model)
                            .unwrap_or_default()
                    }
                };
                let from = match kind {
                    DevKind::Adev => "adev",
                    _ => "oadev",
                };
                (Some(allan::noise_terms(&curve, f)), Some(from))
            }
        };
        Ok(AllanAnalysis {
            points,
            noise,
            noise_from,
        })
    }
}
