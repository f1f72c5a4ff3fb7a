//! How each method is fitted, one row per method: its recipe's default knobs, the features
//! its models read, and the function that fits one target. The methods themselves (names,
//! help, labels) are the registry of [`crate::settings::method`], which sits below the fit
//! so that model files and settings can name a method; this is the fit's half, an
//! exhaustive match, so a method added there is refused by the compiler until it has a row
//! here.

use super::error::FitError;
use super::recipe::{RecipeSettings, TrainSummary};
use super::{published, residual};
use crate::features::FeatureSpec;
use crate::model::{SubModel, Target};
use crate::settings::method::Method;
use crate::targets::TargetSet;

/// A recipe's fit of one target on the training runs' target sets: `(train, recipe, target,
/// n_in, seed, progress)`.
pub(crate) type RecipeFit = fn(
    &[TargetSet],
    &RecipeSettings,
    Target,
    usize,
    u64,
    &mut dyn FnMut(usize, f64),
) -> Result<(SubModel, TrainSummary), FitError>;

/// How one target of a method is fitted.
#[derive(Clone, Copy)]
pub(crate) enum TargetFit {
    /// By a recipe's function on the target sets.
    Recipe(RecipeFit),
    /// From the logs: the lags are identified first, then the target is fitted
    /// ([`super::thermal`], through [`super::fit_model`]); with `residual_lstm`, an LSTM is
    /// trained on the fitted model's residual ([`super::thermal_lstm`]).
    Identified { residual_lstm: bool },
    /// By fitting candidate methods and keeping the one that wins on held-out validation
    /// ([`super::auto`], through [`super::fit_model`]).
    Chosen,
    /// By least squares on all runs at once ([`crate::baseline`], through
    /// [`super::fit_model`]).
    LeastSquares,
    /// Not at all: the method is read only.
    None,
}

/// How a method is fitted.
#[derive(Clone, Copy)]
pub(crate) struct Fitting {
    /// The recipe with its default knobs (None: the method trains no recipe of its own).
    pub recipe: Option<fn() -> RecipeSettings>,
    /// The features the method's models read (before any identification).
    pub features: FeatureSpec,
    /// How one target is fitted.
    pub fit: TargetFit,
}

/// How `method` is fitted.
pub(crate) fn fitting(method: Method) -> Fitting {
    use FeatureSpec as F;
    let (recipe, features, fit): (Option<fn() -> RecipeSettings>, _, _) = match method {
        Method::Thermal => (
            Some(thermal),
            F::THERMAL_STATE,
            TargetFit::Identified {
                residual_lstm: false,
            },
        ),
        Method::ThermalLstm => (
            Some(RecipeSettings::thermal_lstm),
            F::THERMAL_STATE,
            TargetFit::Identified {
                residual_lstm: true,
            },
        ),
        // Each candidate fits with its own recipe; this one is the LSTM candidate's.
        Method::Auto => (
            Some(RecipeSettings::auto),
            F::THERMAL_STATE,
            TargetFit::Chosen,
        ),
        Method::Residual => (
            Some(RecipeSettings::residual),
            F::THERMAL_STATE,
            TargetFit::Recipe(residual::fit),
        ),
        Method::Generic => (
            Some(RecipeSettings::generic),
            F::THERMAL_STATE,
            TargetFit::Recipe(residual::fit),
        ),
        Method::Direct => (
            Some(RecipeSettings::direct),
            F::THERMAL_STATE,
            TargetFit::Recipe(residual::fit),
        ),
        Method::Published => (
            Some(RecipeSettings::published),
            F::PUBLISHED,
            TargetFit::Recipe(published::fit),
        ),
        Method::Linear | Method::Poly => (None, F::PUBLISHED, TargetFit::LeastSquares),
        // Its recipe is the fit configuration's, which the file did not record.
        Method::Lstm => (None, F::THERMAL_STATE, TargetFit::None),
    };
    Fitting {
        recipe,
        features,
        fit,
    }
}

impl RecipeSettings {
    /// The recipe of a recipe method with its default knobs; the default recipe
    /// ([`Method::Thermal`]'s) for a method that trains none of its own (`linear` and `poly`
    /// fit no recipe, the read-only `lstm` names none), as a
    /// [`FitConfig`](super::FitConfig) of theirs holds.
    pub fn of_kind(kind: Method) -> Self {
        match fitting(kind).recipe {
            Some(recipe) => recipe(),
            None => Self::default(),
        }
    }

    /// The feature specification this recipe's models read (for `thermal`, the shape before
    /// its lags are identified from the logs).
    pub fn feature_spec(&self) -> FeatureSpec {
        fitting(self.kind).features
    }
}

/// Whether the method trains an LSTM on the residual of the identified thermal model.
pub(crate) fn residual_lstm(method: Method) -> bool {
    matches!(
        fitting(method).fit,
        TargetFit::Identified {
            residual_lstm: true
        }
    )
}

/// The thermal recipe: the residual recipe's knobs (its optional residual LSTM trains with
/// them), the lags identified from the logs.
fn thermal() -> RecipeSettings {
    RecipeSettings {
        kind: Method::Thermal,
        ..RecipeSettings::residual()
    }
}
