//! The MJCF document as one owned element tree, `<include>` files spliced in (MuJoCo semantics:
//! the children of the included file's `<mujoco>` replace the `<include>` element; paths are
//! relative to the including file; nesting allowed, cycles are errors; the included file's root
//! may be `<mujoco>` or MuJoCo-era `<mujocoinclude>`). Every element remembers its file and line
//! for messages.

use crate::io::lines::LineIndex;
use crate::io::LoadError;
use crate::model::SourceLoc;
use roxmltree::{Document, Node, ParsingOptions};
use std::path::{Path, PathBuf};

/// Resource limits: how deep includes may nest and how many files one model may include.
pub const MAX_INCLUDE_DEPTH: usize = 32;
pub const MAX_INCLUDE_FILES: usize = 1000;
/// Resource limit: how deep elements may nest (a chain of nearly 400 nested bodies loads). The
/// loader walks the tree recursively with about 3 kB of stack per level, so this keeps a load on a
/// 2 MB thread stack (Rust's default for spawned threads) well clear of overflow.
pub const MAX_ELEMENT_DEPTH: usize = 400;

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
    let root = parse_file(text, path, &mut stack, 0)?;
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

fn parse_file(text: &str, path: &Path, stack: &mut Includes, depth: usize) -> Result<Element, LoadError> {
    let file = path.display().to_string();
    let options = ParsingOptions { allow_dtd: true, ..ParsingOptions::default() };
    let doc = Document::parse_with_options(text, options).map_err(|e| LoadError::Xml {
        file: file.clone(),
        line: e.pos().row,
        col: e.pos().col,
        detail: e.to_string(),
    })?;
    let lines = LineIndex::new(text);
    convert(doc.root_element(), &lines, path, &file, stack, depth)
}

/// Converts a roxmltree element, splicing includes.
fn convert(
    node: Node,
    lines: &LineIndex,
    path: &Path,
    file: &str,
    stack: &mut Includes,
    depth: usize,
) -> Result<Element, LoadError> {
    let loc = SourceLoc { file: file.to_string(), line: lines.line(node.range().start) };
    if depth > MAX_ELEMENT_DEPTH {
        return Err(LoadError::Invalid {
            loc,
            element: node.tag_name().name().to_string(),
            detail: format!(
                "elements nest more than {MAX_ELEMENT_DEPTH} levels deep (a resource limit: the loader's walks are recursive); flatten the body tree or split the chain"
            ),
        });
    }
    let mut out = Element {
        tag: node.tag_name().name().to_string(),
        attrs: node.attributes().map(|a| (a.name().to_string(), a.value().to_string())).collect(),
        children: Vec::new(),
        loc,
    };
    for child in node.children().filter(|n| n.is_element()) {
        if child.tag_name().name() == "include" {
            // The included root takes the <include>'s place: its children nest one level deeper.
            out.children.extend(include(child, lines, path, file, stack, depth)?);
        } else {
            out.children.push(convert(child, lines, path, file, stack, depth + 1)?);
        }
    }
    Ok(out)
}

/// The children of the `<mujoco>` root of an included file.
fn include(
    node: Node,
    lines: &LineIndex,
    path: &Path,
    file: &str,
    stack: &mut Includes,
    depth: usize,
) -> Result<Vec<Element>, LoadError> {
    let loc = SourceLoc { file: file.to_string(), line: lines.line(node.range().start) };
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
    if stack.open.len() > MAX_INCLUDE_DEPTH || stack.seen.len() >= MAX_INCLUDE_FILES {
        return Err(LoadError::Invalid {
            loc,
            element: "include".into(),
            detail: format!(
                "more than {MAX_INCLUDE_DEPTH} nested includes or {MAX_INCLUDE_FILES} included files (a resource limit against hostile files); flatten the includes"
            ),
        });
    }
    stack.seen.push(key.clone());
    stack.open.push(key);
    let root = parse_file(&text, &target, stack, depth)?;
    stack.open.pop();
    // Any root is accepted, as MuJoCo does: `<mujoco>`, or `<mujocoinclude>` in MuJoCo-era files.
    Ok(root.children)
}
