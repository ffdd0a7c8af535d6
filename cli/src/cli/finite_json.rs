//! Every number the command line prints is finite. serde_json turns a non-finite `f64` into
//! `null` when a value is built, so a `null` in a result whose schema has none marks a NaN or an
//! infinity; [`first_null`] finds it and names it by its path (`forward.qacc[1]`), for the typed
//! error that takes the result's place.

use serde_json::Value;

/// The path of the first `null` in `value` (depth first, object keys in order), if any.
pub fn first_null(value: &Value) -> Option<String> {
    match value {
        Value::Null => Some(String::new()),
        Value::Array(items) => {
            items.iter().enumerate().find_map(|(i, x)| first_null(x).map(|p| format!("[{i}]{p}")))
        }
        Value::Object(map) => map.iter().find_map(|(k, x)| first_null(x).map(|p| format!(".{k}{p}"))),
        _ => None,
    }
}

/// The readable form of a path from [`first_null`]: without its leading dot, `the result` when
/// empty.
pub fn describe(path: &str) -> String {
    match path.strip_prefix('.') {
        Some(p) => p.to_string(),
        None if path.is_empty() => "the result".to_string(),
        None => path.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn finds_the_first_non_finite_number_by_its_path() {
        assert_eq!(first_null(&json!({"a": [1.0, 2.0], "b": {"c": 3}})), None);
        let v = json!({"M": [[1.0, f64::NAN]], "forward": {"qacc": [0.0, f64::INFINITY]}});
        assert_eq!(first_null(&v).as_deref(), Some(".M[0][1]"));
        assert_eq!(describe(&first_null(&v).unwrap()), "M[0][1]");
        let v = json!({"forward": {"qacc": [0.0, f64::INFINITY]}, "kinetic": 1.0});
        assert_eq!(describe(&first_null(&v).unwrap()), "forward.qacc[1]");
        assert_eq!(describe(&first_null(&json!(f64::NAN)).unwrap()), "the result");
    }
}
