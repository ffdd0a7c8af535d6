//! Attribute values of one MJCF element after its default class was applied, with typed readers
//! whose errors name file, line, element and attribute.

use super::schema_types::{ElementSchema, Kind};
use crate::io::LoadError;
use crate::model::SourceLoc;
use crate::spatial::Vec3;

/// The attributes of one element: its own, over those of its default class.
#[derive(Clone, Debug)]
pub struct Attrs {
    pub tag: String,
    pub loc: SourceLoc,
    /// Name → value; explicit attributes replace class defaults.
    pub values: Vec<(String, String)>,
    /// The names written on the element itself (not inherited from a class).
    pub explicit: Vec<String>,
}

impl Attrs {
    /// `explicit` over `defaults`.
    pub fn new(
        tag: &str,
        loc: &SourceLoc,
        defaults: &[(String, String)],
        explicit: &[(String, String)],
    ) -> Self {
        let mut values: Vec<(String, String)> = defaults.to_vec();
        for (k, v) in explicit {
            match values.iter_mut().find(|(dk, _)| dk == k) {
                Some(slot) => slot.1 = v.clone(),
                None => values.push((k.clone(), v.clone())),
            }
        }
        let explicit = explicit.iter().map(|(k, _)| k.clone()).collect();
        Self { tag: tag.to_string(), loc: loc.clone(), values, explicit }
    }

    /// The attributes of an element that takes no default class (body, frame, inertial, ...).
    pub fn plain(e: &super::xml::Element) -> Self {
        Self::new(&e.tag, &e.loc, &[], &e.attrs)
    }

    pub fn has(&self, name: &str) -> bool {
        self.values.iter().any(|(k, _)| k == name)
    }

    pub fn text(&self, name: &str) -> Option<&str> {
        self.values.iter().find(|(k, _)| k == name).map(|(_, v)| v.as_str())
    }

    /// An error about attribute `name` of this element.
    pub fn error(&self, name: &str, detail: impl Into<String>) -> LoadError {
        LoadError::BadAttribute {
            loc: self.loc.clone(),
            element: self.tag.clone(),
            attribute: name.to_string(),
            detail: detail.into(),
        }
    }

    /// All numbers of a numeric attribute.
    pub fn numbers(&self, name: &str) -> Result<Option<Vec<f64>>, LoadError> {
        let Some(text) = self.text(name) else { return Ok(None) };
        let mut out = Vec::new();
        for word in text.split_whitespace() {
            match word.parse::<f64>() {
                Ok(x) if x.is_finite() => out.push(x),
                Ok(_) => {
                    return Err(
                        self.error(name, format!("has the non-finite value '{word}'; give finite numbers"))
                    )
                }
                Err(_) => return Err(self.error(name, format!("has '{word}', which is not a number"))),
            }
        }
        Ok(Some(out))
    }

    /// Exactly `N` numbers.
    pub fn array<const N: usize>(&self, name: &str) -> Result<Option<[f64; N]>, LoadError> {
        let Some(v) = self.numbers(name)? else { return Ok(None) };
        if v.len() != N {
            return Err(self.count_error(name, v.len(), &N.to_string()));
        }
        let mut out = [0.0; N];
        out.copy_from_slice(&v);
        Ok(Some(out))
    }

    /// Between `lo` and `hi` numbers (MuJoCo fills the rest from the default).
    pub fn some_numbers(&self, name: &str, lo: usize, hi: usize) -> Result<Option<Vec<f64>>, LoadError> {
        let Some(v) = self.numbers(name)? else { return Ok(None) };
        if v.len() < lo || v.len() > hi {
            return Err(self.count_error(name, v.len(), &format!("{lo} to {hi}")));
        }
        Ok(Some(v))
    }

    fn count_error(&self, name: &str, got: usize, want: &str) -> LoadError {
        self.error(name, format!("has {got} value{}, it takes {want}", if got == 1 { "" } else { "s" }))
    }

    pub fn real(&self, name: &str) -> Result<Option<f64>, LoadError> {
        Ok(self.array::<1>(name)?.map(|a| a[0]))
    }

    pub fn vec3(&self, name: &str) -> Result<Option<Vec3>, LoadError> {
        Ok(self.array::<3>(name)?.map(Vec3::from))
    }

    pub fn int(&self, name: &str) -> Result<Option<i64>, LoadError> {
        let Some(text) = self.text(name) else { return Ok(None) };
        text.trim()
            .parse::<i64>()
            .map(Some)
            .map_err(|_| self.error(name, format!("has '{text}', which is not an integer")))
    }

    pub fn bool(&self, name: &str) -> Result<Option<bool>, LoadError> {
        match self.text(name).map(str::trim) {
            None => Ok(None),
            Some("true") => Ok(Some(true)),
            Some("false") => Ok(Some(false)),
            Some(other) => Err(self.error(name, format!("is '{other}'; use true or false"))),
        }
    }

    /// One keyword of `allowed`.
    pub fn keyword(&self, name: &str, allowed: &[&str]) -> Result<Option<String>, LoadError> {
        let Some(text) = self.text(name).map(str::trim) else { return Ok(None) };
        if allowed.contains(&text) {
            Ok(Some(text.to_string()))
        } else {
            Err(self.error(name, format!("is '{text}'; use one of {}", allowed.join(", "))))
        }
    }

    /// Checks the value counts and keywords of every attribute this element's schema knows
    /// (MuJoCo's own checks), and returns the names the schema does not know.
    pub fn check(&self, schema: &ElementSchema) -> Result<Vec<String>, LoadError> {
        let mut unknown = Vec::new();
        for (name, _) in &self.values {
            let Some(a) = schema.attr(name) else {
                unknown.push(name.clone());
                continue;
            };
            match a.kind {
                Kind::Real | Kind::Int => {
                    let n = self.numbers(name)?.map_or(0, |v| v.len());
                    let (lo, hi) = (a.min as usize, a.max as usize);
                    if hi == 0 {
                        continue;
                    }
                    if n < lo.max(1) || n > hi {
                        let want = if lo == hi { lo.to_string() } else { format!("{} to {hi}", lo.max(1)) };
                        return Err(self.count_error(name, n, &want));
                    }
                }
                Kind::Keyword => {
                    self.keyword(name, a.keywords)?;
                }
                Kind::Bool => {
                    self.bool(name)?;
                }
                Kind::Keywords | Kind::Text => {}
            }
        }
        Ok(unknown)
    }
}
