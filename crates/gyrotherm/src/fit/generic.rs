//! The generic recipe: the residual recipe ([`super::residual`]) on a generic base, linear in
//! every thermal-state input plus `T²` ([`BaseTerms::LinearT2`]); nothing chosen from the
//! bias equation. The scale factor keeps the tailored [`super::terms::scale_terms`]: generic
//! linear + `T²` scale terms left 23–92 ppm held out, against a 10 ppm target
//! (`docs/experiments/lstm-recipes.md`).

use super::recipe::RecipeSettings;
use super::terms::BaseTerms;
use crate::settings::method::Method;

impl RecipeSettings {
    /// The residual recipe on the generic base [`BaseTerms::LinearT2`].
    pub fn generic() -> Self {
        RecipeSettings {
            kind: Method::Generic,
            base: BaseTerms::LinearT2,
            scale_base: BaseTerms::Tailored,
            ..Self::residual()
        }
    }
}
