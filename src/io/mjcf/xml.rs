//! The MJCF document as one owned element tree, `<include>` files spliced in (MuJoCo semantics:
//! the children of the included file's `<mujoco>` replace the `<include>` element; paths are
//! relative to the including file; nesting allowed, cycles are errors). Every element remembers
//! its file and line for messages.

use crate::io::LoadError;
use crate::model::SourceLoc;
use roxmltree::{Document, Node, ParsingOptions};
use std::path::{Path, PathBuf};

/// An XML element with its attributes (file order), children and source location.
#[derive(Clone, Debug)]
pub struct Element {
    pub tag: String,
    pub attrs: Vec<(String, String)>,
    pub children: Vec<Element>,
    pub loc: SourceLoc,
}

impl Element {
    /// The value of attribute `name`.
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs.iter().find(|(k, _)| k == name).map(|(_, v)| v.as_str())
    }
    /// Child elements with tag `tag`.
    pub fn children_named<'a>(&'a self, tag: &'a str) -> impl Iterator<Item = &'a Element> + 'a {
        self.children.iter().filter(move |c| c.tag == tag)
    }
}

/// Reads `path` and every file it includes into one tree rooted at `<mujoco>`.
pub fn read_document(path: &Path) -> Result<Element, LoadError> {
    let text = std::fs::read_to_string(path)
        .map_err(|source| LoadError::Io { file: path.display().to_string(), source })?;
    read_text(&text, path)
}

/// Like [`read_document`] for text already in memory (`path` names it and anchors includes).
pub fn read_text(text: &str, path: &Path) -> Result<Element, LoadError> {
    let mut stack = Includes { open: vec![canonical(path)], seen: Vec::new() };
    let root = parse_file(text, path, &mut stack)?;
    if root.tag != "mujoco" {
        return Err(LoadError::Invalid {
            loc: root.loc.clone(),
            element: root.tag.clone(),
            detail: "the root element of an MJCF file must be <mujoco>".into(),
        });
    }
    Ok(root)
}

/// The files being read (the include chain, for cycles) and every file included so far (MuJoCo
/// includes a file at most once).
struct Includes {
    open: Vec<PathBuf>,
    seen: Vec<PathBuf>,
}

fn canonical(path: &Path) -> PathBuf {
    path.canonicalize().unwrap_or_else(|_| path.to_path_buf())
}

fn parse_file(text: &str, path: &Path, stack: &mut Includes) -> Result<Element, LoadError> {
    let file = path.display().to_string();
    let options = ParsingOptions { allow_dtd: true, ..ParsingOptions::default() };
    let doc = Document::parse_with_options(text, options).map_err(|e| LoadError::Xml {
        file: file.clone(),
        line: e.pos().row,
        col: e.pos().col,
        detail: e.to_string(),
    })?;
    convert(doc.root_element(), &doc, path, &file, stack)
}

/// Converts a roxmltree element, splicing includes.
fn convert(
    node: Node,
    doc: &Document,
    path: &Path,
    file: &str,
    stack: &mut Includes,
) -> Result<Element, LoadError> {
    let loc = SourceLoc { file: file.to_string(), line: doc.text_pos_at(node.range().start).row };
    let mut out = Element {
        tag: node.tag_name().name().to_string(),
        attrs: node.attributes().map(|a| (a.name().to_string(), a.value().to_string())).collect(),
        children: Vec::new(),
        loc,
    };
    for child in node.children().filter(|n| n.is_element()) {
        if child.tag_name().name() == "include" {
            out.children.extend(include(child, doc, path, file, stack)?);
        } else {
            out.children.push(convert(child, doc, path, file, stack)?);
        }
    }
    Ok(out)
}

/// The children of the `<mujoco>` root of an included file.
fn include(
    node: Node,
    doc: &Document,
    path: &Path,
    file: &str,
    stack: &mut Includes,
) -> Result<Vec<Element>, LoadError> {
    let loc = SourceLoc { file: file.to_string(), line: doc.text_pos_at(node.range().start).row };
    let Some(name) = node.attribute("file") else {
        return Err(LoadError::Invalid {
            loc,
            element: "include".into(),
            detail: "missing attribute 'file'; write <include file=\"other.xml\"/>".into(),
        });
    };
    // MuJoCo tries the top-level model's folder first, then the including file's folder.
    let top = stack.open.first().and_then(|p| p.parent()).map(Path::to_path_buf).unwrap_or_default();
    let beside = path.parent().unwrap_or(Path::new("")).join(name);
    let target = if top.join(name).is_file() { top.join(name) } else { beside };
    let key = canonical(&target);
    if let Some(first) = stack.open.iter().position(|p| *p == key) {
        let chain: Vec<String> =
            stack.open[first..].iter().chain([&key]).map(|p| p.display().to_string()).collect();
        return Err(LoadError::IncludeCycle { loc, chain });
    }
    let text = std::fs::read_to_string(&target).map_err(|e| LoadError::IncludeNotFound {
        loc: loc.clone(),
        path: target.display().to_string(),
        reason: e.to_string(),
    })?;
    if stack.seen.contains(&key) {
        return Err(LoadError::Invalid {
            loc,
            element: "include".into(),
            detail: format!(
                "'{}' is included a second time; MuJoCo includes a file at most once: remove the repeated <include>",
                target.display()
            ),
        });
    }
    stack.seen.push(key.clone());
    stack.open.push(key);
    let root = parse_file(&text, &target, stack)?;
    stack.open.pop();
    if root.tag != "mujoco" {
        return Err(LoadError::Invalid {
            loc: root.loc,
            element: root.tag,
            detail: format!("an included file must have <mujoco> as its root (included from {loc})"),
        });
    }
    Ok(root.children)
}
