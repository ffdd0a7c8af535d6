//! MJCF default classes (MuJoCo semantics): the top-level `<default>` is class `main`; a nested
//! `<default class="c">` starts as a copy of its parent and overrides per element type; an element
//! takes the class named by its `class` attribute, else the `childclass` of the nearest enclosing
//! `<body>`/`<frame>` that has one, else `main`. All actuator shortcuts (`motor`, `position`, ...)
//! share one actuator default, as in MuJoCo; since a shortcut written in a default expands into
//! the shared actuator parameters, each class also keeps its actuator defaults in order
//! ([`Defaults::actuator_defaults`]) so that the expansion can be replayed.

use super::attrs::Attrs;
use super::xml::Element;
use crate::io::LoadError;
use std::collections::HashMap;

/// The element types whose defaults actuators share.
pub const ACTUATOR_TAGS: [&str; 12] = [
    "general",
    "motor",
    "position",
    "velocity",
    "intvelocity",
    "damper",
    "cylinder",
    "muscle",
    "adhesion",
    "dcmotor",
    "pid",
    "orientation",
];

/// The key under which an element type's defaults are stored.
fn key(tag: &str) -> &str {
    if ACTUATOR_TAGS.contains(&tag) {
        "actuator"
    } else {
        tag
    }
}

#[derive(Clone, Debug, Default)]
struct Class {
    by_tag: HashMap<String, Vec<(String, String)>>,
    /// The actuator elements of this class and its ancestors, outermost class first, each in file
    /// order, with their own attributes.
    actuators: Vec<Attrs>,
}

/// All default classes of a model.
#[derive(Debug, Default)]
pub struct Defaults {
    classes: HashMap<String, Class>,
}

pub const MAIN: &str = "main";

impl Defaults {
    /// Reads every `<default>` section of the root.
    pub fn build(root: &Element) -> Result<Self, LoadError> {
        let mut d = Defaults::default();
        d.classes.insert(MAIN.to_string(), Class::default());
        for section in root.children_named("default") {
            // The top-level default is `main` whatever it is called; several sections (from
            // includes) add up.
            let main = d.classes[MAIN].clone();
            d.read(section, MAIN, &main)?;
        }
        // The classes of attached models (super::attach): each a root over MuJoCo's built-ins.
        for section in root.children_named(super::attach::ATTACHED_DEFAULTS) {
            let name = section.attr("class").unwrap_or(MAIN);
            if d.classes.contains_key(name) {
                return Err(LoadError::DuplicateName {
                    loc: section.loc.clone(),
                    element: "default class",
                    name: name.to_string(),
                });
            }
            d.read(section, name, &Class::default())?;
        }
        Ok(d)
    }

    fn read(&mut self, node: &Element, name: &str, parent: &Class) -> Result<(), LoadError> {
        let mut class = parent.clone();
        for child in &node.children {
            if child.tag == "default" {
                continue;
            }
            if ACTUATOR_TAGS.contains(&child.tag.as_str()) {
                class.actuators.push(Attrs::new(&child.tag, &child.loc, &[], &child.attrs));
            }
            let slot = class.by_tag.entry(key(&child.tag).to_string()).or_default();
            for (k, v) in &child.attrs {
                match slot.iter_mut().find(|(sk, _)| sk == k) {
                    Some(s) => s.1 = v.clone(),
                    None => slot.push((k.clone(), v.clone())),
                }
            }
        }
        for child in node.children_named("default") {
            let Some(child_name) = child.attr("class") else {
                return Err(LoadError::Invalid {
                    loc: child.loc.clone(),
                    element: "default".into(),
                    detail: "a nested <default> needs a 'class' attribute".into(),
                });
            };
            if self.classes.contains_key(child_name) && child_name != MAIN {
                return Err(LoadError::DuplicateName {
                    loc: child.loc.clone(),
                    element: "default class",
                    name: child_name.to_string(),
                });
            }
            self.read(child, child_name, &class)?;
        }
        self.classes.insert(name.to_string(), class);
        Ok(())
    }

    /// Whether a class exists.
    pub fn has(&self, class: &str) -> bool {
        self.classes.contains_key(class)
    }

    /// The attributes of `element` over the defaults of its class: its `class` attribute, else
    /// `childclass` (the enclosing body's or frame's), else `main`.
    pub fn resolve(&self, element: &Element, childclass: &str) -> Result<Attrs, LoadError> {
        self.resolve_as(element, key(&element.tag), childclass)
    }

    /// Like [`Defaults::resolve`], with the defaults written under `<default><{default_tag}>`:
    /// the elements of `<equality>` (`connect`, `weld`, `joint`, `tendon`) take the defaults of
    /// `<default><equality>`, those of `<tendon>` (`fixed`, `spatial`) of `<default><tendon>`.
    pub fn resolve_as(
        &self,
        element: &Element,
        default_tag: &str,
        childclass: &str,
    ) -> Result<Attrs, LoadError> {
        let class = self.class_of(element, childclass)?;
        let empty = Vec::new();
        let defaults = class.by_tag.get(default_tag).unwrap_or(&empty);
        let explicit: Vec<(String, String)> =
            element.attrs.iter().filter(|(k, _)| k != "class").cloned().collect();
        Ok(Attrs::new(&element.tag, &element.loc, defaults, &explicit))
    }

    /// The defaults alone that [`Defaults::resolve_as`] puts under `element`'s own attributes.
    pub fn class_defaults(&self, element: &Element, default_tag: &str) -> Result<Attrs, LoadError> {
        self.class_defaults_under(element, default_tag, MAIN)
    }

    /// [`Defaults::class_defaults`] of an element inside a body or frame whose `childclass` is
    /// `childclass`.
    pub fn class_defaults_under(
        &self,
        element: &Element,
        default_tag: &str,
        childclass: &str,
    ) -> Result<Attrs, LoadError> {
        let class = self.class_of(element, childclass)?;
        let empty = Vec::new();
        let defaults = class.by_tag.get(default_tag).unwrap_or(&empty);
        Ok(Attrs::new(&element.tag, &element.loc, defaults, &[]))
    }

    /// The actuator defaults of `element`'s class (outermost class first, each in file order), as
    /// attribute sets of the tag they were written as (`motor`, `position`, ...).
    pub fn actuator_defaults(&self, element: &Element) -> Result<&[Attrs], LoadError> {
        let class = self.class_of(element, MAIN)?;
        Ok(&class.actuators)
    }

    fn class_of(&self, element: &Element, childclass: &str) -> Result<&Class, LoadError> {
        let class_name = element.attr("class").unwrap_or(childclass);
        self.classes.get(class_name).ok_or_else(|| LoadError::UnknownClass {
            loc: element.loc.clone(),
            element: element.tag.clone(),
            class: class_name.to_string(),
        })
    }
}
