//! The fitting methods, one registry: per method, its name as typed (what a model file's
//! `"method"` says, what `gyrotherm train --method` and Python's `fit(method=…)` take), its
//! kind of fit, the label of its comparison column and its `--help` line.
//!
//! A new method is its fitting module, one entry of the registry below and one row of the
//! fit's table of how each method is fitted (`fit/methods.rs`, an exhaustive match: the
//! compiler refuses a method without its row). The two halves cannot be one table: model
//! files and settings name a method, and they sit below the fit, so the registry imports
//! only [`crate::setting_rule`] and the fit imports it.

use serde::{Deserialize, Serialize};

use crate::setting_rule::SettingError;

/// The kind of fit a method is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Family {
    /// A recipe: thermal-state (or, for `published`, the paper's) features and an optional
    /// LSTM, trained with a [`RecipeSettings`](crate::fit::RecipeSettings) of its own.
    Recipe,
    /// Classic least squares on T and dT ([`crate::baseline`]).
    LeastSquares,
    /// Read only: files of earlier versions name it; no fit writes it, and no fit takes it.
    ReadOnly,
}

/// One method's entry in the registry.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MethodInfo {
    pub method: Method,
    /// Its name as typed, and as model files record it.
    pub name: &'static str,
    pub family: Family,
    /// The label of its comparison column (None: the fitted model's own label).
    pub column_label: Option<&'static str>,
    /// One line on what the method fits (the `--help` text of its value).
    pub help: &'static str,
}

/// Defines [`Method`] and [`REGISTRY`] from one entry per method, so that a variant and its
/// name, kind, label and help cannot drift apart.
macro_rules! registry {
    ($(
        $(#[$doc:meta])*
        $variant:ident = $name:literal, $family:ident, $label:expr, $help:expr;
    )*) => {
        /// How a model is fitted. The five recipes of the former `lstm` method are methods of
        /// their own, each named for what it fits (two of them hold no LSTM at all).
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
        pub enum Method {
            $( $(#[$doc])* #[serde(rename = $name)] $variant, )*
        }

        /// Every method's entry, in the order of [`Method`]'s variants: the fitting methods
        /// default first, in the order `--help` lists them, then the read-only ones.
        pub(crate) const REGISTRY: &[MethodInfo] = &[$(
            MethodInfo {
                method: Method::$variant,
                name: $name,
                family: Family::$family,
                column_label: $label,
                help: $help,
            },
        )*];
    };
}

registry! {
    /// Fits `Thermal` and `ThermalLstm`, scores both on held-out validation (each training
    /// run left out in turn, or held-out blocks of a single run) and keeps the better one
    /// ([`crate::fit::auto`]). The default: on the design family its median held-out figure
    /// was no worse than `Thermal`'s and its worst case lower, trained on one chamber profile
    /// or with the planned one (`docs/experiments/lstm-capacity.md`).
    Auto = "auto", Recipe, None,
        "the default: fits `thermal` and `thermal-lstm`, scores each on held-out \
         validation (each run left out in turn; held-out blocks of a single run) and keeps \
         the better; prints and records the scores (about a minute an axis)";
    /// Thermal time constants identified from the logs and a ridge fit on the thermal-state
    /// inputs; no LSTM ([`crate::fit::thermal`]). Chosen over the classic fits on a family of
    /// simulated units (`docs/experiments/generalisation.md`); `Auto`'s first candidate.
    Thermal = "thermal", Recipe, None,
        "thermal time constants identified from the logs and a ridge fit on them, no \
         LSTM (fast: under a second); degrades on short or coarse logs and says how";
    /// `Thermal`'s model plus an LSTM of real capacity on its residual, reading the thermal
    /// states and `Thermal`'s prediction; kept only where it beats `Thermal` on held-out
    /// blocks, else the model is `Thermal` alone (`crate::fit::thermal_lstm`).
    ThermalLstm = "thermal-lstm", Recipe, None,
        "`thermal` plus a 32-unit LSTM on its residual (reading the thermal states and \
         thermal's prediction, minibatch training), kept only where it beats `thermal` on \
         held-out blocks (else the model is `thermal`)";
    /// Least squares on thermal-state inputs plus an LSTM on its residual, kept only where it
    /// beats the least-squares base on validation blocks ([`crate::fit::residual`]).
    Residual = "residual", Recipe, None,
        "least squares on thermal-state inputs (T, dT, T − first-order lags) plus an \
         LSTM on its residual, kept only where it beats the least-squares base on \
         validation blocks";
    /// As `Residual`, on a generic linear + T² base ([`crate::fit::generic`]).
    Generic = "generic", Recipe, None, "as `residual`, on a generic linear + T² base";
    /// An LSTM alone on the thermal-state inputs ([`crate::fit::direct`]).
    Direct = "direct", Recipe, None, "an LSTM alone on the thermal-state inputs";
    /// He et al. 2024 as published: LSTM networks on T and dT, 1000 Adam steps at lr 0.01
    /// ([`crate::fit::published`]). Its comparison column is named after its authors.
    Published = "published", Recipe, Some("LSTM, He et al."),
        "He et al. 2024 as published: LSTM networks on T and dT (whole run, 1000 Adam \
         steps at lr 0.01)";
    /// Linear least squares `c0 + c1·T + c2·dT` (the paper's comparison).
    Linear = "linear", LeastSquares, None, "bias = c0 + c1·T + c2·dT (the paper's comparison)";
    /// Polynomial least squares in T and dT.
    Poly = "poly", LeastSquares, None, "polynomial in T and dT (industry standard)";
    /// Read from files written before the methods were one list: the `lstm` method with a
    /// recipe the file did not record. Such files load and compensate as before (the
    /// sub-models say what they are); no fit writes it or takes it.
    Lstm = "lstm", ReadOnly, None,
        "the former LSTM method, read from older model files only";
}

/// How many entries of the registry are of a kind (`None`: every fitting method, that is
/// every kind but [`Family::ReadOnly`]).
const fn count(family: Option<Family>) -> usize {
    let mut n = 0;
    let mut i = 0;
    while i < REGISTRY.len() {
        if in_family(&REGISTRY[i], family) {
            n += 1;
        }
        i += 1;
    }
    n
}

const fn in_family(e: &MethodInfo, family: Option<Family>) -> bool {
    match family {
        None => !matches!(e.family, Family::ReadOnly),
        Some(Family::Recipe) => matches!(e.family, Family::Recipe),
        Some(Family::LeastSquares) => matches!(e.family, Family::LeastSquares),
        Some(Family::ReadOnly) => matches!(e.family, Family::ReadOnly),
    }
}

const N_METHODS: usize = count(None);
const N_RECIPES: usize = count(Some(Family::Recipe));

/// The names of the registry's entries of a kind, in registry order.
const fn names<const N: usize>(family: Option<Family>) -> [&'static str; N] {
    let mut out = [""; N];
    let (mut i, mut n) = (0, 0);
    while i < REGISTRY.len() {
        if in_family(&REGISTRY[i], family) {
            out[n] = REGISTRY[i].name;
            n += 1;
        }
        i += 1;
    }
    out
}

/// Every method a fit can use, default first, in the order `--help` lists them.
pub const METHODS: [Method; N_METHODS] = {
    let mut out = [REGISTRY[0].method; N_METHODS];
    let (mut i, mut n) = (0, 0);
    while i < REGISTRY.len() {
        if in_family(&REGISTRY[i], None) {
            out[n] = REGISTRY[i].method;
            n += 1;
        }
        i += 1;
    }
    out
};

/// The names of [`METHODS`].
pub const METHOD_NAMES: [&str; N_METHODS] = names(None);

/// The names of the recipe methods.
pub(crate) const RECIPE_NAMES: [&str; N_RECIPES] = names(Some(Family::Recipe));

/// The default method of `train` and `fit()`: the data choose between `thermal` and
/// `thermal-lstm` (`docs/experiments/lstm-capacity.md`).
pub const DEFAULT_METHOD: Method = Method::Auto;

impl Method {
    /// The method's entry in `REGISTRY`.
    pub const fn info(&self) -> &'static MethodInfo {
        // The variants are declared in registry order, one per entry.
        &REGISTRY[*self as usize]
    }

    /// The name in model files, on the command line and in Python.
    pub const fn as_str(&self) -> &'static str {
        self.info().name
    }

    /// One line on what the method fits (the `--help` text of its value).
    pub const fn help(&self) -> &'static str {
        self.info().help
    }

    /// The kind of fit.
    pub const fn family(&self) -> Family {
        self.info().family
    }

    /// The label of the method's comparison column (None: the fitted model's own label).
    pub const fn column_label(&self) -> Option<&'static str> {
        self.info().column_label
    }

    /// Whether the method is a recipe of its own (thermal-state features, optional LSTM):
    /// `thermal`, `thermal-lstm`, `auto`, `residual`, `generic`, `direct`, `published`.
    pub const fn is_own_recipe(&self) -> bool {
        matches!(self.family(), Family::Recipe)
    }

    /// Whether the model is fitted by a recipe (thermal-state features, optional LSTM), as
    /// opposed to the classic least-squares fits `linear` and `poly` (the read-only `lstm`
    /// counts as a recipe: its recipe is the fit's).
    pub const fn is_recipe(&self) -> bool {
        !matches!(self.family(), Family::LeastSquares)
    }

    /// A recipe method by name (`RECIPE_NAMES`).
    pub fn parse_recipe(s: &str) -> Result<Method, SettingError> {
        REGISTRY
            .iter()
            .find(|e| e.name == s && matches!(e.family, Family::Recipe))
            .map(|e| e.method)
            .ok_or_else(|| SettingError::unknown("recipe", s, &RECIPE_NAMES))
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl std::str::FromStr for Method {
    type Err = SettingError;
    /// A name of [`METHOD_NAMES`], or `lstm`, which older model files record.
    fn from_str(s: &str) -> Result<Self, SettingError> {
        REGISTRY
            .iter()
            .find(|e| e.name == s)
            .map(|e| e.method)
            .ok_or_else(|| SettingError::unknown("method", s, &METHOD_NAMES))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The help of `thermal-lstm` names the LSTM size its fit uses: the registry holds
    /// string literals, so this keeps the text and the setting one number.
    #[test]
    fn thermal_lstm_help_names_its_default_size() {
        let hidden = crate::settings::fit::THERMAL_LSTM_HIDDEN;
        let help = Method::ThermalLstm.info().help;
        assert!(help.contains(&format!(" {hidden}-unit ")), "{help}");
    }

    /// Each variant indexes its own entry, and a model file writes the entry's name.
    #[test]
    fn every_entry_is_its_variant_and_serialises_by_its_name() {
        for (i, e) in REGISTRY.iter().enumerate() {
            assert_eq!(e.method as usize, i, "{}", e.name);
            assert_eq!(e.method.info(), e);
            assert_eq!(
                serde_json::to_string(&e.method).unwrap(),
                format!("\"{}\"", e.name)
            );
            assert_eq!(e.name.parse::<Method>(), Ok(e.method));
        }
        assert_eq!(METHODS[0], DEFAULT_METHOD);
        assert_eq!(
            RECIPE_NAMES,
            [
                "auto",
                "thermal",
                "thermal-lstm",
                "residual",
                "generic",
                "direct",
                "published"
            ]
        );
        assert_eq!(Method::parse_recipe("direct"), Ok(Method::Direct));
        assert!(Method::parse_recipe("linear").is_err());
    }
}
