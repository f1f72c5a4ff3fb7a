//! Reading and checking the choice `auto` records on an inertial unit's axis.

use gyrotherm::model::unit::ImuAxis;
use gyrotherm::model::{MethodChoice, Validation};
use gyrotherm::settings::Method;

/// The axis's recorded choice, its line printed.
pub fn recorded(a: &ImuAxis) -> &MethodChoice {
    let choice = a
        .model
        .method_choice
        .as_ref()
        .expect("auto records its choice");
    eprintln!("{}", choice.describe());
    choice
}

/// The choice's two scores (°/s), checked: made by `validation`, `thermal`'s then
/// `thermal-lstm`'s.
pub fn scores(choice: &MethodChoice, validation: Validation) -> (f64, f64) {
    assert_eq!(choice.validation, validation);
    let methods: Vec<Method> = choice.candidates.iter().map(|c| c.method).collect();
    assert_eq!(methods, [Method::Thermal, Method::ThermalLstm]);
    (
        choice.candidates[0].bias_rms_dps,
        choice.candidates[1].bias_rms_dps,
    )
}
