//! Reads an `eval` states file `{"states": [{...}, ...]}` one state at a time: serde_json's
//! deserializer over a buffered reader, driven by a visitor that hands each state to a function as
//! soon as it is parsed and drops it, so memory does not grow with the number of states. The
//! file's shape is checked as a whole-file parse would: `states` required, once; any other field is
//! an error naming it; nothing after the object.

use super::CliError;
use serde::de::{self, DeserializeSeed, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;
use std::cell::RefCell;
use std::fmt;
use std::io::Read;

/// What the function given to [`for_each_state`] is handed: the index of the state and the state.
type Sink<'a, S> = dyn FnMut(usize, S) -> Result<(), CliError> + 'a;

/// Calls `f(i, state)` on each state of the file `reader` reads, in order; returns the number of
/// states. A parse error is `CliError::Input` on `file` with its line and `expected`; an error of
/// `f` stops the reading and is returned as it is.
pub fn for_each_state<S, R>(
    reader: R,
    file: &str,
    expected: &str,
    f: &mut Sink<'_, S>,
) -> Result<usize, CliError>
where
    S: for<'de> Deserialize<'de>,
    R: Read,
{
    // An error of `f` travels through serde as a marker; the error itself waits here.
    let failure = RefCell::new(None);
    let mut de = serde_json::Deserializer::from_reader(reader);
    let parsed = de::Deserializer::deserialize_map(&mut de, FileVisitor { f, failure: &failure })
        .and_then(|n| de.end().map(|()| n));
    match (parsed, failure.into_inner()) {
        (Ok(n), _) => Ok(n),
        (Err(_), Some(e)) => Err(e),
        (Err(e), None) => Err(CliError::Input {
            file: file.to_string(),
            detail: format!("line {}: {e}; expected {expected}", e.line()),
        }),
    }
}

struct FileVisitor<'a, 'f, S> {
    f: &'a mut Sink<'f, S>,
    failure: &'a RefCell<Option<CliError>>,
}

impl<'de, S: for<'d> Deserialize<'d>> Visitor<'de> for FileVisitor<'_, '_, S> {
    type Value = usize;

    fn expecting(&self, out: &mut fmt::Formatter) -> fmt::Result {
        out.write_str("an object {\"states\": [...]}")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<usize, A::Error> {
        let mut count = None;
        while let Some(key) = map.next_key::<String>()? {
            if key != "states" {
                return Err(de::Error::unknown_field(&key, &["states"]));
            }
            if count.is_some() {
                return Err(de::Error::duplicate_field("states"));
            }
            count = Some(map.next_value_seed(StatesSeed { f: &mut *self.f, failure: self.failure })?);
        }
        count.ok_or_else(|| de::Error::missing_field("states"))
    }
}

struct StatesSeed<'a, 'f, S> {
    f: &'a mut Sink<'f, S>,
    failure: &'a RefCell<Option<CliError>>,
}

impl<'de, S: for<'d> Deserialize<'d>> DeserializeSeed<'de> for StatesSeed<'_, '_, S> {
    type Value = usize;

    fn deserialize<D: de::Deserializer<'de>>(self, deserializer: D) -> Result<usize, D::Error> {
        deserializer.deserialize_seq(self)
    }
}

impl<'de, S: for<'d> Deserialize<'d>> Visitor<'de> for StatesSeed<'_, '_, S> {
    type Value = usize;

    fn expecting(&self, out: &mut fmt::Formatter) -> fmt::Result {
        out.write_str("a list of states")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<usize, A::Error> {
        let mut i = 0;
        while let Some(state) = seq.next_element::<S>()? {
            if let Err(e) = (self.f)(i, state) {
                *self.failure.borrow_mut() = Some(e);
                return Err(de::Error::custom("stopped"));
            }
            i += 1;
        }
        Ok(i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Result<Vec<(usize, Vec<f64>)>, String> {
        #[derive(Deserialize)]
        struct S {
            q: Vec<f64>,
        }
        let mut seen = Vec::new();
        let n = for_each_state::<S, _>(text.as_bytes(), "f.json", "{...}", &mut |i, s: S| {
            seen.push((i, s.q));
            Ok(())
        })
        .map_err(|e| e.to_string())?;
        assert_eq!(n, seen.len());
        Ok(seen)
    }

    #[test]
    fn hands_over_each_state_in_order_and_checks_the_shape() {
        assert_eq!(
            read(r#"{"states": [{"q": [1]}, {"q": [2, 3]}]}"#).unwrap(),
            [(0, vec![1.0]), (1, vec![2.0, 3.0])]
        );
        assert_eq!(read(r#"{"states": []}"#).unwrap(), []);
        assert!(read(r#"{}"#).unwrap_err().contains("missing field `states`"));
        assert!(read(r#"{"states": [], "x": 1}"#).unwrap_err().contains("unknown field `x`"));
        assert!(read(r#"{"states": [], "states": []}"#).unwrap_err().contains("duplicate field `states`"));
        assert!(read("{\"states\": []} x").unwrap_err().contains("trailing characters"));
        assert!(read("{\"states\": [\n{\"q\": [0,]}]}").unwrap_err().contains("line 2"));
    }

    #[test]
    fn an_error_of_the_function_stops_the_reading_and_is_returned() {
        let mut calls = 0;
        let r = for_each_state::<serde_json::Value, _>(
            r#"{"states": [1, 2, 3]}"#.as_bytes(),
            "f.json",
            "",
            &mut |i, _| {
                calls += 1;
                if i == 1 {
                    Err(CliError::Usage("stop at 1".into()))
                } else {
                    Ok(())
                }
            },
        );
        assert_eq!(r.unwrap_err().to_string(), "stop at 1");
        assert_eq!(calls, 2);
    }
}
