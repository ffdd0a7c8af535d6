//! Types of the generated MJCF schema table ([`super::schema`]) and look-ups into it.

use super::schema::ELEMENTS;

/// The value type of an attribute.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Real,
    Int,
    Bool,
    /// One keyword of a fixed set.
    Keyword,
    /// Several keywords.
    Keywords,
    /// Free text: names, file names, references.
    Text,
}

/// One attribute of an element: its value count bounds (`max` 0 = unbounded) and keywords.
#[derive(Debug)]
pub struct Attr {
    pub name: &'static str,
    pub kind: Kind,
    pub min: u8,
    pub max: u8,
    pub keywords: &'static [&'static str],
}

/// One element declaration: its XML tag, the element whose grammar it shares (`alias`), its
/// attributes and the declarations of its children.
#[derive(Debug)]
pub struct ElementSchema {
    pub name: &'static str,
    pub tag: &'static str,
    pub alias: Option<&'static str>,
    pub attrs: &'static [Attr],
    pub children: &'static [&'static str],
}

impl ElementSchema {
    /// The declaration by name.
    pub fn get(name: &str) -> Option<&'static ElementSchema> {
        ELEMENTS.iter().find(|e| e.name == name)
    }
    /// The attribute by name.
    pub fn attr(&self, name: &str) -> Option<&'static Attr> {
        self.attrs.iter().find(|a| a.name == name)
    }
    /// The child declaration with XML tag `tag`, if the grammar allows it here.
    pub fn child(&self, tag: &str) -> Option<&'static ElementSchema> {
        let grammar = self.alias.and_then(ElementSchema::get).unwrap_or(self);
        grammar.children.iter().filter_map(|c| ElementSchema::get(c)).find(|c| c.tag == tag)
    }
}
