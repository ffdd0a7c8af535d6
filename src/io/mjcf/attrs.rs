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

    /// Overwrites the first values of `out` with the numbers of attribute `name` (at most
    /// `out.len()` of them), as MuJoCo reads a partial array: entries not given keep their value.
    /// Returns whether the attribute is there.
    pub fn fill(&self, name: &str, out: &mut [f64]) -> Result<bool, LoadError> {
        let Some(v) = self.numbers(name)? else { return Ok(false) };
        if v.is_empty() || v.len() > out.len() {
            return Err(self.count_error(name, v.len(), &format!("1 to {}", out.len())));
        }
        out[..v.len()].copy_from_slice(&v);
        Ok(true)
    }

    /// [`Attrs::fill`] from the default class's value, then from the element's own (`self` holds
    /// both; `class` the class's alone), so that a partial value overrides a class value entry by
    /// entry, as in MuJoCo.
    pub fn fill_over(&self, class: &Attrs, name: &str, out: &mut [f64]) -> Result<bool, LoadError> {
        let from_class = class.fill(name, out)?;
        if self.explicit.iter().any(|e| e == name) {
            return self.fill(name, out);
        }
        Ok(from_class)
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

    /// A range and its `…limited` switch as MuJoCo compiles them (`checklimited`, `islimited`):
    /// `true` needs `range` with lower < upper; `auto` (the default) is limited when
    /// `<compiler autolimits>` is on and lower < upper, and is an error when autolimits is off and
    /// a nonzero range is given. A reversed range left unlimited by `auto` adds a warning.
    pub fn limited_range(
        &self,
        limited: &str,
        range: &str,
        autolimits: bool,
        warnings: &mut Vec<String>,
    ) -> Result<Option<[f64; 2]>, LoadError> {
        let r = self.array::<2>(range)?;
        match self.keyword(limited, &["false", "true", "auto"])?.as_deref() {
            Some("false") => Ok(None),
            Some("true") => match r {
                Some([lo, hi]) if lo < hi => Ok(Some([lo, hi])),
                _ => Err(self.error(
                    range,
                    format!(
                        "must be given with lower < upper when {limited}=\"true\" (it is {})",
                        r.map_or("missing".to_string(), |[lo, hi]| format!("[{lo}, {hi}]"))
                    ),
                )),
            },
            _ => match r {
                Some(v) if v != [0.0, 0.0] && !autolimits => Err(self.error(
                    range,
                    format!(
                        "is given without '{limited}' while <compiler autolimits=\"false\">; give {limited}=\"true\" or \"false\", set autolimits=\"true\", or remove the range"
                    ),
                )),
                Some([lo, hi]) if lo < hi => Ok(Some([lo, hi])),
                Some([lo, hi]) => {
                    if [lo, hi] != [0.0, 0.0] {
                        warnings.push(format!(
                            "{}: <{}>: '{range}' is [{lo}, {hi}] (lower ≥ upper), so the element is not limited (MuJoCo's rule for {limited}=\"auto\")",
                            self.loc, self.tag
                        ));
                    }
                    Ok(None)
                }
                None => Ok(None),
            },
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
