//! A JSON object that names a key twice. `serde_json` keeps the last value (into a `Value`)
//! or refuses (into a struct), and other readers may keep the first, so one file can mean
//! two models: a sealed model file with a decoy array before the real one would check out
//! against its content hash while a reader that keeps the first value uses the decoy.
//! `check_unique_keys` reads the text once, keeping nothing, and refuses the first
//! repeated key with its place (`bias.baseline.coefficients`).

use std::cell::RefCell;
use std::collections::HashSet;
use std::fmt;

use serde::de::{self, DeserializeSeed, MapAccess, SeqAccess, Visitor};

/// The first key found twice in one object.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DuplicateKey {
    /// The key, as decoded (escapes resolved).
    pub key: String,
    /// Where it is: object keys joined by `.`, array indices as `[i]`; ends with the key.
    pub path: String,
    /// Line (1-based) of the second occurrence.
    pub line: usize,
    /// Column (1-based) just past the second occurrence.
    pub column: usize,
}

impl fmt::Display for DuplicateKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}: key {:?} appears twice in one object (line {}, column {}): readers disagree \
             on which value counts, so each key may appear once; remove one",
            self.path, self.key, self.line, self.column
        )
    }
}

/// Why [`check_unique_keys`] refused a text.
#[derive(Debug)]
pub(crate) enum KeyCheckError {
    /// An object names a key twice.
    Duplicate(DuplicateKey),
    /// The text is not JSON.
    NotJson(serde_json::Error),
}

/// Refuse `text` if any object in it, at any depth, names a key twice; also refuses text
/// that is not one JSON value.
pub(crate) fn check_unique_keys(text: &str) -> Result<(), KeyCheckError> {
    let found = RefCell::new(None);
    let mut de = serde_json::Deserializer::from_str(text);
    let result = Walk {
        at: At::Root,
        found: &found,
    }
    .deserialize(&mut de)
    .and_then(|()| de.end());
    match (result, found.into_inner()) {
        (Ok(()), _) => Ok(()),
        (Err(e), Some((key, path))) => Err(KeyCheckError::Duplicate(DuplicateKey {
            key,
            path,
            line: e.line(),
            column: e.column(),
        })),
        (Err(e), None) => Err(KeyCheckError::NotJson(e)),
    }
}

/// The place of a value: a chain of borrowed keys and indices up to the root, so walking
/// allocates nothing until a duplicate is found.
#[derive(Clone, Copy)]
enum At<'p> {
    Root,
    Key(&'p At<'p>, &'p str),
    Index(&'p At<'p>, usize),
}

impl At<'_> {
    fn render(&self, out: &mut String) {
        match self {
            At::Root => {}
            At::Key(up, key) => {
                up.render(out);
                if !out.is_empty() {
                    out.push('.');
                }
                // Escaped: the key comes from the file and ends up on a terminal.
                out.extend(key.escape_debug());
            }
            At::Index(up, i) => {
                up.render(out);
                out.push_str(&format!("[{i}]"));
            }
        }
    }
}

struct Walk<'p, 'f> {
    at: At<'p>,
    found: &'f RefCell<Option<(String, String)>>,
}

impl<'de> DeserializeSeed<'de> for Walk<'_, '_> {
    type Value = ();

    fn deserialize<D: de::Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        d.deserialize_any(self)
    }
}

impl<'de> Visitor<'de> for Walk<'_, '_> {
    type Value = ();

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("any JSON value")
    }

    fn visit_bool<E>(self, _: bool) -> Result<(), E> {
        Ok(())
    }

    fn visit_i64<E>(self, _: i64) -> Result<(), E> {
        Ok(())
    }

    fn visit_u64<E>(self, _: u64) -> Result<(), E> {
        Ok(())
    }

    fn visit_f64<E>(self, _: f64) -> Result<(), E> {
        Ok(())
    }

    fn visit_str<E>(self, _: &str) -> Result<(), E> {
        Ok(())
    }

    fn visit_unit<E>(self) -> Result<(), E> {
        Ok(())
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<(), A::Error> {
        let mut i = 0;
        while seq
            .next_element_seed(Walk {
                at: At::Index(&self.at, i),
                found: self.found,
            })?
            .is_some()
        {
            i += 1;
        }
        Ok(())
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<(), A::Error> {
        let mut seen = HashSet::new();
        while let Some(key) = map.next_key::<String>()? {
            if seen.contains(&key) {
                let mut path = String::new();
                At::Key(&self.at, &key).render(&mut path);
                let message = format!("duplicate key {key:?} at {path}");
                *self.found.borrow_mut() = Some((key, path));
                return Err(de::Error::custom(message));
            }
            map.next_value_seed(Walk {
                at: At::Key(&self.at, &key),
                found: self.found,
            })?;
            seen.insert(key);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dup(text: &str) -> DuplicateKey {
        match check_unique_keys(text) {
            Err(KeyCheckError::Duplicate(d)) => d,
            other => panic!("{text}: want a duplicate, got {other:?}"),
        }
    }

    #[test]
    fn unique_keys_pass_at_every_depth() {
        check_unique_keys(r#"{"a": {"b": [1, {"c": 2, "d": null}], "c": true}, "b": "x"}"#)
            .unwrap();
        check_unique_keys("[]").unwrap();
    }

    #[test]
    fn a_repeated_key_is_named_with_its_path() {
        let d = dup(r#"{"bias": {"baseline": {"coefficients": [0.5], "coefficients": [1]}}}"#);
        assert_eq!(d.key, "coefficients");
        assert_eq!(d.path, "bias.baseline.coefficients");
        assert_eq!(d.line, 1);
        let d = dup("{\"a\": [0, {\"x\": 1,\n \"x\": 2}]}");
        assert_eq!(d.path, "a[1].x");
        assert_eq!(d.line, 2);
        assert_eq!(dup(r#"{"k": 1, "k": 1}"#).path, "k");
    }

    #[test]
    fn escapes_are_decoded_before_keys_are_compared() {
        // `\u0063` is `c`: the same key written two ways.
        let d = dup(r#"{"coefficients": [0.5], "\u0063oefficients": [1]}"#);
        assert_eq!(d.key, "coefficients");
    }

    #[test]
    fn a_key_with_control_characters_is_escaped_in_the_path() {
        let d = dup("{\"a\\nb\": 1, \"a\\nb\": 2}");
        assert_eq!(d.key, "a\nb");
        assert_eq!(d.path, "a\\nb");
    }

    #[test]
    fn text_that_is_not_json_is_refused() {
        for text in ["", "{", "{} {}", "[1,]"] {
            assert!(
                matches!(check_unique_keys(text), Err(KeyCheckError::NotJson(_))),
                "{text:?}"
            );
        }
    }
}
