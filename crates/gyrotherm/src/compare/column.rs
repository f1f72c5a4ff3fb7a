//! The comparison's columns: a [`Candidate`] (a method and, for a recipe method, its recipe)
//! and the column names `--methods` takes.

use super::CompareConfig;
use crate::fit::{FitConfig, RecipeSettings};
use crate::settings::export::{ExportTarget, EXPORT_TARGETS};
use crate::settings::fit::FitSettings;
use crate::settings::method::{Method, METHODS, METHOD_NAMES};
use crate::settings::rule::{check, Rule, SettingError};

/// One column of the comparison: a method and, for a recipe method, the recipe it trains.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    pub method: Method,
    /// The recipe (recipe methods only; None: the comparison's [`FitConfig::recipe`] when
    /// it is this method's, else the method's own).
    pub recipe: Option<RecipeSettings>,
}

impl Candidate {
    /// A column fitting `method` with the comparison's settings.
    pub fn of(method: Method) -> Self {
        Candidate {
            method,
            recipe: None,
        }
    }

    /// The `linear` fit.
    pub fn linear() -> Self {
        Self::of(Method::Linear)
    }

    /// The `poly` fit.
    pub fn poly() -> Self {
        Self::of(Method::Poly)
    }

    /// The `published` method (He et al. 2024 as published), `epochs` Adam steps (None: the
    /// published 1000).
    pub fn published(epochs: Option<usize>) -> Self {
        let mut recipe = RecipeSettings::published();
        if let Some(e) = epochs {
            recipe.epochs = e;
        }
        Candidate {
            method: Method::Published,
            recipe: Some(recipe),
        }
    }

    /// The fit settings of this column: `base` with its method and recipe.
    pub fn fit_config(&self, base: &FitConfig) -> FitConfig {
        let recipe = match &self.recipe {
            Some(r) => r.clone(),
            None if self.method.is_own_recipe() && self.method != base.recipe.kind => {
                RecipeSettings::of_kind(self.method)
            }
            None => base.recipe.clone(),
        };
        FitConfig {
            method: self.method,
            recipe,
            ..base.clone()
        }
    }

    /// The column's own label, if its method has one ([`Method::column_label`]: the
    /// published recipe's names its authors); otherwise the column is labelled by its model.
    pub(crate) fn column_label(&self, base: &FitConfig) -> Option<&'static str> {
        self.fit_config(base).model_method().column_label()
    }

    /// The column's key in `gyrotherm compare --json` and `--methods`: the method's name.
    pub fn key(&self, base: &FitConfig) -> &'static str {
        self.fit_config(base).model_method().as_str()
    }

    /// Whether fitting this column trains an LSTM (and reports its epochs).
    pub(crate) fn trains_lstm(&self, base: &FitConfig) -> bool {
        let c = self.fit_config(base);
        c.method.is_recipe()
            && c.recipe.epochs > 0
            && (c.recipe.kind != Method::Thermal || c.thermal.residual_lstm)
    }
}

/// A column asked for by name (`compare --methods`, Python's `methods=`): a method, fitted on
/// the training logs, or an autopilot's polynomial ([`ExportTarget::is_autopilot`]) fitted to
/// the steady-state bias of the comparison's own method's model, as `export --target` writes
/// it and the firmware computes it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColumnName {
    Method(Method),
    Autopilot(ExportTarget),
}

impl ColumnName {
    /// Every name a column may be asked for by, with its help line: the methods a fit can
    /// use, then the autopilot targets.
    pub fn all() -> Vec<(&'static str, &'static str)> {
        METHODS
            .iter()
            .map(|m| (m.as_str(), m.help()))
            .chain(
                EXPORT_TARGETS
                    .iter()
                    .filter(|t| t.is_autopilot())
                    .map(|t| (t.as_str(), autopilot_column_help(*t))),
            )
            .collect()
    }
}

fn autopilot_column_help(t: ExportTarget) -> &'static str {
    match t {
        ExportTarget::Px4 => {
            "PX4's TC_G cubic in temperature, fitted to the steady-state bias of --method's \
             model (what `export --target px4` writes), as the firmware computes it"
        }
        _ => {
            "ArduPilot's INS_TCAL cubic in temperature, fitted to the steady-state bias of \
             --method's model (what `export --target ardupilot` writes), as the firmware \
             computes it"
        }
    }
}

impl std::str::FromStr for ColumnName {
    type Err = SettingError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if let Some(m) = METHODS.iter().find(|m| m.as_str() == s) {
            return Ok(ColumnName::Method(*m));
        }
        match EXPORT_TARGETS
            .iter()
            .find(|t| t.is_autopilot() && t.as_str() == s)
        {
            Some(t) => Ok(ColumnName::Autopilot(*t)),
            None => Err(SettingError::Unknown {
                setting: "methods",
                value: s.to_owned(),
                expected: column_names(),
            }),
        }
    }
}

/// The names [`ColumnName`] parses, for error messages.
fn column_names() -> &'static [&'static str] {
    static NAMES: std::sync::OnceLock<Vec<&'static str>> = std::sync::OnceLock::new();
    NAMES.get_or_init(|| ColumnName::all().into_iter().map(|(n, _)| n).collect())
}

/// The comparison's side of the user's settings: the settings sit below the comparison and
/// know nothing of it, so the comparison builds its configuration from them here.
impl FitSettings {
    /// The comparison of `methods` (None: `linear`, `poly`, this settings' method and
    /// `published`, once) with these settings, bias stability over `tau_s`.
    pub fn compare_config(
        &self,
        columns: Option<&[ColumnName]>,
        tau_s: f64,
    ) -> Result<CompareConfig, SettingError> {
        check("tau_s", tau_s, Rule::PositiveSeconds)?;
        let fit = self.fit_config()?;
        let main = fit.model_method();
        let methods: Option<Vec<Method>> = columns.map(|c| {
            c.iter()
                .filter_map(|c| match c {
                    ColumnName::Method(m) => Some(*m),
                    ColumnName::Autopilot(_) => None,
                })
                .collect()
        });
        let autopilot: Vec<ExportTarget> = columns
            .into_iter()
            .flatten()
            .filter_map(|c| match c {
                ColumnName::Autopilot(t) => Some(*t),
                ColumnName::Method(_) => None,
            })
            .collect();
        let wanted: Vec<Method> = match methods.as_deref() {
            Some(m) => {
                // `lstm`, which older model files record, is no method a fit can use.
                if let Some(old) = m.iter().find(|m| !METHODS.contains(m)) {
                    return Err(SettingError::unknown(
                        "methods",
                        old.as_str(),
                        &METHOD_NAMES,
                    ));
                }
                m.to_vec()
            }
            None => {
                let mut all = vec![Method::Linear, Method::Poly, main];
                if main != Method::Published {
                    all.push(Method::Published);
                }
                all
            }
        };
        let candidates = wanted
            .into_iter()
            .map(|m| Candidate {
                method: m,
                recipe: m.is_own_recipe().then(|| self.recipe_for(m)),
            })
            .collect();
        Ok(CompareConfig {
            candidates,
            autopilot,
            fit,
            tau_s,
            settle_s: self.settle_s,
        })
    }
}
