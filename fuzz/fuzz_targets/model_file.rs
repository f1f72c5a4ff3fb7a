//! The model-file loader on arbitrary text.
//!
//! Holds: no panic; a model it accepts can be written back, read again, and made into a
//! flight compensator that runs a short constant-temperature sequence without panicking.

#![no_main]

use gyrotherm::compensate::compensator;
use gyrotherm::model::ModelFile;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(model) = ModelFile::from_json(text) else {
        return;
    };
    let again = model.to_json().expect("an accepted model writes back");
    ModelFile::from_json(&again).expect("a written model reads back");
    let Ok(mut comp) = compensator(&model) else {
        return;
    };
    for i in 0..20 {
        let t = i as f64 * 0.5;
        let _ = comp.step(t, 0.01, 25.0 + 0.1 * t);
    }
});
