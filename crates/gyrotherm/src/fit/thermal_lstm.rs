//! The `thermal-lstm` recipe: `thermal`'s model ([`super::thermal`]: lags identified from
//! the logs, a ridge fit on them) plus an LSTM of real capacity on its residual. The LSTM reads
//! the identified thermal states (T, dT, T − each identified lag) and `thermal`'s prediction,
//! and trains with minibatch truncated BPTT: windows drawn at random over the training blocks,
//! their first steps left out of the loss, Adam with cosine decay, the gradient norm clipped,
//! stopped early on held-out blocks. It is kept only where it beats `thermal` there (the gate
//! of the residual recipe, [`super::residual`]); otherwise the model is `thermal` alone and is
//! labelled so. The scale factor keeps `thermal`'s model.
//!
//! Why capacity: an 8-unit LSTM on the thermal model's residual did not move the worst
//! held-out case (docs/experiments/lstm-on-thermal-base.md); larger networks trained on
//! windows drawn at random did (docs/experiments/lstm-capacity.md).

use super::recipe::RecipeSettings;
use crate::model::SubModel;
use crate::nn::LrSchedule;
use crate::settings::fit::{THERMAL_LSTM_HIDDEN, THERMAL_LSTM_WINDOWS};
use crate::settings::method::Method;

impl RecipeSettings {
    /// The `thermal-lstm` recipe with its default knobs.
    pub(crate) fn thermal_lstm() -> Self {
        RecipeSettings {
            kind: Method::ThermalLstm,
            // Adam steps, one batch of windows each: 300 fitted the design family's sweep on
            // two cores (docs/experiments/lstm-capacity.md).
            epochs: 300,
            lr: 5e-3,
            hidden: THERMAL_LSTM_HIDDEN,
            window: 768,
            burn_in: 256,
            batch: THERMAL_LSTM_WINDOWS,
            // Long enough for several window starts per block after the burn-in.
            block_steps: 2048,
            validation_every: 4,
            // Adam steps without a better validation loss (checked every step).
            patience: Some(150),
            base_input: true,
            sampled_windows: true,
            lr_schedule: LrSchedule::Cosine,
            ..RecipeSettings::residual()
        }
    }

    /// The `auto` recipe: its LSTM candidate's knobs (`Self::thermal_lstm`), under its own
    /// name.
    pub fn auto() -> Self {
        RecipeSettings {
            kind: Method::Auto,
            ..Self::thermal_lstm()
        }
    }
}

/// What a `thermal-lstm` fit is: `thermal-lstm` while either sub-model holds its LSTM, else
/// `thermal` (the gate left the LSTM out: the model is the thermal model alone). Any other
/// method is returned unchanged.
pub(crate) fn label(method: Method, bias: Option<&SubModel>, scale: Option<&SubModel>) -> Method {
    let holds_lstm = [bias, scale]
        .into_iter()
        .flatten()
        .any(|s| s.lstm().is_some());
    match method {
        Method::ThermalLstm if !holds_lstm => Method::Thermal,
        m => m,
    }
}
