//! The fitting methods, one flat list: what a model file's `"method"` says, what
//! `gyrotherm train --method` and Python's `fit(method=…)` take.

use serde::{Deserialize, Serialize};

use super::SettingError;
use crate::fit::RecipeKind;

/// How a model is fitted. The five recipes of the former `lstm` method are methods of their
/// own, each named for what it fits (two of them hold no LSTM at all).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// Thermal time constants identified from the logs and a ridge fit on the thermal-state
    /// inputs; no LSTM ([`crate::fit::thermal`]). The default: chosen on a family of simulated
    /// units (`docs/experiments/generalisation.md`).
    Thermal,
    /// Least squares on thermal-state inputs plus an LSTM on its residual, kept only where it
    /// beats the least-squares base on validation blocks ([`crate::fit::residual`]).
    Residual,
    /// As `Residual`, on a generic linear + T² base ([`crate::fit::generic`]).
    Generic,
    /// An LSTM alone on the thermal-state inputs ([`crate::fit::direct`]).
    Direct,
    /// He et al. 2024 as published: LSTM networks on T and dT, 1000 Adam steps at lr 0.01
    /// ([`crate::fit::published`]).
    Published,
    /// Linear least squares `c0 + c1·T + c2·dT` (the paper's comparison).
    Linear,
    /// Polynomial least squares in T and dT.
    Poly,
    /// Read from files written before the methods were one list: the `lstm` method with a
    /// recipe the file did not record. Such files load and compensate as before (the
    /// sub-models say what they are); no fit writes it. On the command line and in Python,
    /// `lstm` is a deprecated spelling resolved by [`super::FitSettings::resolve`].
    Lstm,
}

/// Every method a fit can use, default first, in the order `--help` lists them.
pub const METHODS: [Method; 7] = [
    Method::Thermal,
    Method::Residual,
    Method::Generic,
    Method::Direct,
    Method::Published,
    Method::Linear,
    Method::Poly,
];

/// The names of [`METHODS`].
pub const METHOD_NAMES: [&str; 7] = [
    "thermal",
    "residual",
    "generic",
    "direct",
    "published",
    "linear",
    "poly",
];

/// The default method of `train` and `fit()`.
pub const DEFAULT_METHOD: Method = Method::Thermal;

impl Method {
    /// The name in model files, on the command line and in Python.
    pub fn as_str(&self) -> &'static str {
        match self {
            Method::Thermal => "thermal",
            Method::Residual => "residual",
            Method::Generic => "generic",
            Method::Direct => "direct",
            Method::Published => "published",
            Method::Linear => "linear",
            Method::Poly => "poly",
            Method::Lstm => "lstm",
        }
    }

    /// One line on what the method fits (the `--help` text of its value).
    pub fn help(&self) -> &'static str {
        match self {
            Method::Thermal => {
                "thermal time constants identified from the logs and a ridge fit on them, no \
                 LSTM (the default: chosen on a family of simulated units); degrades on short \
                 or coarse logs and says how"
            }
            Method::Residual => {
                "least squares on thermal-state inputs (T, dT, T − first-order lags) plus an \
                 LSTM on its residual, kept only where it beats the least-squares base on \
                 validation blocks"
            }
            Method::Generic => "as `residual`, on a generic linear + T² base",
            Method::Direct => "an LSTM alone on the thermal-state inputs",
            Method::Published => {
                "He et al. 2024 as published: LSTM networks on T and dT (whole run, 1000 Adam \
                 steps at lr 0.01)"
            }
            Method::Linear => "bias = c0 + c1·T + c2·dT (the paper's comparison)",
            Method::Poly => "polynomial in T and dT (industry standard)",
            Method::Lstm => "deprecated: the former LSTM method; use `thermal` or a recipe's name",
        }
    }

    /// The fitting recipe behind a recipe method (None for `linear`, `poly` and the legacy
    /// `lstm`, whose recipe a file does not record).
    pub fn recipe_kind(&self) -> Option<RecipeKind> {
        match self {
            Method::Thermal => Some(RecipeKind::Thermal),
            Method::Residual => Some(RecipeKind::Residual),
            Method::Generic => Some(RecipeKind::Generic),
            Method::Direct => Some(RecipeKind::Direct),
            Method::Published => Some(RecipeKind::Published),
            Method::Linear | Method::Poly | Method::Lstm => None,
        }
    }

    /// Whether the model is fitted by a recipe (thermal-state features, optional LSTM), as
    /// opposed to the classic least-squares fits `linear` and `poly`.
    pub fn is_recipe(&self) -> bool {
        !matches!(self, Method::Linear | Method::Poly)
    }
}

impl RecipeKind {
    /// The method of this recipe.
    pub fn method(&self) -> Method {
        match self {
            RecipeKind::Thermal => Method::Thermal,
            RecipeKind::Residual => Method::Residual,
            RecipeKind::Generic => Method::Generic,
            RecipeKind::Direct => Method::Direct,
            RecipeKind::Published => Method::Published,
        }
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl std::str::FromStr for Method {
    type Err = SettingError;
    /// A name of [`METHOD_NAMES`], or the deprecated `lstm`.
    fn from_str(s: &str) -> Result<Self, SettingError> {
        METHODS
            .iter()
            .chain(&[Method::Lstm])
            .find(|m| m.as_str() == s)
            .copied()
            .ok_or_else(|| SettingError::unknown("method", s, &METHOD_NAMES))
    }
}
