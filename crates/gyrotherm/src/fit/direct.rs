//! The direct recipe: the LSTM models the whole bias from the thermal-state inputs, on a
//! constant base holding the per-run offsets ([`BaseTerms::Constant`]; windowed truncated
//! BPTT, early stopping, as [`super::residual`]). Kept for comparison: held out it left 2–4 ×
//! the noise floor where a least-squares base left 1–1.4 (`docs/experiments/lstm-recipes.md`).

use super::recipe::RecipeSettings;
use super::terms::BaseTerms;
use crate::settings::method::Method;

impl RecipeSettings {
    /// The direct LSTM: the residual recipe on a constant base ([`BaseTerms::Constant`]).
    pub fn direct() -> Self {
        RecipeSettings {
            kind: Method::Direct,
            base: BaseTerms::Constant,
            scale_base: BaseTerms::Tailored,
            ..Self::residual()
        }
    }
}
