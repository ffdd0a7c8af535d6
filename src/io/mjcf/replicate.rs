//! `<replicate count offset euler sep childclass>` expanded into plain `<frame>`s before the body
//! reader runs, following MuJoCo 4.0's XML reader (xml_native_reader.cc, "replicate
//! sub-element"): copy `i` (0 ≤ i < count) of the replicate's children sits in a frame at
//! `pos_i` with orientation `euler · i` (the compiler's angle unit and Euler sequence), where
//! `pos_0 = 0` and `pos_{i+1} = pos_i + R(euler · i) · offset`; every name inside copy `i` gets the
//! suffix `sep` + `i` zero-padded to the number of digits of `count` (`count="12"`: `00` … `11`).
//! Nested replicates are expanded innermost first, so their suffixes come first (`c0-1`: inner copy
//! 0 of outer copy 1). Copies keep the source lines of the elements they were copied from.

use super::attrs::Attrs;
use super::orientation::{euler_matrix, AngleConvention};
use super::xml::Element;
use crate::io::LoadError;
use crate::spatial::Vec3;

/// The elements of the body tree that a replicate may sit in.
const BODY_TREE: [&str; 4] = ["worldbody", "body", "frame", "replicate"];

/// Resource limit: copies one model may create (a hostile `count` cannot exhaust memory).
pub const MAX_COPIES: usize = 100_000;

/// Resource limit: the longest `sep` (characters). Every named element of every copy carries it,
/// so a hostile separator of hundreds of kilobytes made gigabytes of names (a fuzzer's input
/// took 35 s to load); real separators are a character or a few.
pub const MAX_SEP: usize = 256;

/// Expands every `<replicate>` below the `<worldbody>`s of `root`.
pub(crate) fn expand(root: &mut Element, angles: &AngleConvention) -> Result<(), LoadError> {
    let mut budget = MAX_COPIES;
    for wb in root.children.iter_mut().filter(|c| c.tag == "worldbody") {
        expand_children(wb, angles, &mut budget)?;
    }
    Ok(())
}

/// Whether `e` holds a `<replicate>` anywhere below it.
pub(crate) fn contains(e: &Element) -> bool {
    e.children.iter().any(|c| c.tag == "replicate" || contains(c))
}

fn expand_children(e: &mut Element, angles: &AngleConvention, budget: &mut usize) -> Result<(), LoadError> {
    if !contains(e) {
        return Ok(());
    }
    let old = std::mem::take(&mut e.children);
    for mut child in old {
        if BODY_TREE.contains(&child.tag.as_str()) {
            expand_children(&mut child, angles, budget)?;
        }
        if child.tag == "replicate" {
            e.children.extend(copies(&child, angles, budget)?);
        } else {
            e.children.push(child);
        }
    }
    Ok(())
}

/// The frames a (fully expanded inside) `<replicate>` stands for.
fn copies(r: &Element, angles: &AngleConvention, budget: &mut usize) -> Result<Vec<Element>, LoadError> {
    let a = Attrs::plain(r);
    let count = match a.int("count")? {
        // MuJoCo accepts zero copies (the children vanish).
        Some(n) if n >= 0 => n as usize,
        Some(n) => return Err(a.error("count", format!("is {n}; give a number of copies ≥ 0"))),
        None => {
            return Err(LoadError::Invalid {
                loc: r.loc.clone(),
                element: "replicate".into(),
                detail: "missing attribute 'count' (how many copies, as in MuJoCo)".into(),
            })
        }
    };
    if count > *budget {
        return Err(a.error(
            "count",
            format!(
                "makes more than {MAX_COPIES} copies in this model (a resource limit against hostile files)"
            ),
        ));
    }
    *budget -= count;
    let offset = a.vec3("offset")?.unwrap_or_default();
    let euler = a.array::<3>("euler")?.unwrap_or_default();
    let sep = a.text("sep").unwrap_or("");
    if sep.chars().count() > MAX_SEP {
        return Err(a.error(
            "sep",
            format!(
                "is {} characters long, beyond {MAX_SEP} (a resource limit: every name of every copy carries it); give a short separator",
                sep.chars().count()
            ),
        ));
    }
    let digits = count.to_string().len();
    let mut pos = Vec3::zeros();
    let mut out = Vec::with_capacity(count);
    for i in 0..count {
        let e_i = euler.map(|x| x * i as f64);
        let mut attrs = vec![
            ("pos".to_string(), format!("{:?} {:?} {:?}", pos.x, pos.y, pos.z)),
            ("euler".to_string(), format!("{:?} {:?} {:?}", e_i[0], e_i[1], e_i[2])),
        ];
        if let Some(c) = r.attr("childclass") {
            attrs.push(("childclass".to_string(), c.to_string()));
        }
        let suffix = format!("{sep}{i:0digits$}");
        let mut children = r.children.clone();
        for c in &mut children {
            add_suffix(c, &suffix);
        }
        out.push(Element { tag: "frame".into(), attrs, children, loc: r.loc.clone() });
        pos += euler_matrix(&e_i, angles) * offset;
    }
    Ok(out)
}

/// The attribute in which an `<attach>` inside a replicate collects the copies' suffixes (not an
/// MJCF attribute: it cannot come from a file); the attach gives them to every name it copies.
pub(crate) const ATTACH_SUFFIX: &str = "suffix:replicate";

/// Appends `suffix` to every `name` in the subtree (unnamed elements stay unnamed, as in MuJoCo),
/// and to the names an `<attach>` in it will copy (MuJoCo names them so: `_torso-00-00`).
fn add_suffix(e: &mut Element, suffix: &str) {
    if e.tag == "attach" {
        match e.attrs.iter_mut().find(|(k, _)| k == ATTACH_SUFFIX) {
            Some((_, v)) => v.push_str(suffix),
            None => e.attrs.push((ATTACH_SUFFIX.to_string(), suffix.to_string())),
        }
    }
    for (k, v) in &mut e.attrs {
        if k == "name" && !v.is_empty() {
            v.push_str(suffix);
        }
    }
    for c in &mut e.children {
        add_suffix(c, suffix);
    }
}
