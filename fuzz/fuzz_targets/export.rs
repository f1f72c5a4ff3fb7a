//! `export` on arbitrary model files.
//!
//! Holds: no panic; a model the loader accepts (as `gyrotherm model check` does: sealed or
//! not) is generated in both languages, in memory, and every generated file holds only
//! the generator's own bytes (`gyrotherm::export::is_generated_text`: printable ASCII and
//! `\n`, no `??`), whatever strings, control characters or bidirectional overrides the
//! model's free-text fields carry.

#![no_main]

use gyrotherm::export::{generate, is_generated_text, Lang};
use gyrotherm::model::ModelFile;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok((model, _seal)) = ModelFile::from_json_sealed(text) else {
        return;
    };
    for lang in [Lang::C, Lang::Rust] {
        // A model that cannot take flight form is refused with an error, which is fine.
        let Ok(files) = generate(&model, lang) else {
            continue;
        };
        for (name, text) in files {
            if let Some((at, c)) = text
                .char_indices()
                .find(|&(_, c)| c != '\n' && !(' '..='~').contains(&c))
            {
                panic!("{name}: byte offset {at}: {c:?} is not the generator's own text");
            }
            assert!(is_generated_text(&text), "{name}: holds `??` (a trigraph)");
        }
    }
});
