//! Mutations of model and mesh files: byte-level ones for every format (bit flips, splices,
//! interesting integers and floats at aligned offsets — what finds header and index bugs in binary
//! STL and MSH) and structure-aware ones for XML (URDF, MJCF): elements deleted, duplicated or
//! moved, attributes deleted or duplicated, numbers replaced by NaN, infinities, huge or tiny
//! values, deep nesting, long strings, and `<include>`s of other files (MJCF).

use rand::rngs::SmallRng;
use rand::Rng;

/// Numbers that break naive arithmetic: non-finite, overflowing when squared or summed, negative,
/// denormal, zero.
const INTERESTING_NUMBERS: &[&str] = &[
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e308",
    "-1e308",
    "1e200",
    "-1e200",
    "1e13",
    "1e-300",
    "0",
    "-0",
    "-1",
    "1",
    "2",
    "3",
    "-2",
    "0.5",
    "4294967295",
    "-2147483648",
    "1e",
    "--1",
    "0x10",
    "",
];

/// Words that change the meaning of an attribute value (joint and geom types, flags, modes).
const INTERESTING_WORDS: &[&str] = &[
    "hinge",
    "slide",
    "ball",
    "free",
    "revolute",
    "continuous",
    "prismatic",
    "fixed",
    "floating",
    "planar",
    "sphere",
    "capsule",
    "cylinder",
    "box",
    "ellipsoid",
    "plane",
    "mesh",
    "hfield",
    "true",
    "false",
    "auto",
    "enable",
    "disable",
    "legacy",
    "exact",
    "convex",
    "shell",
    "world",
    "package://x/y.stl",
    "../../x.xml",
    "main",
    "a",
    "",
    " ",
    "degree",
    "radian",
    "xyz",
    "XYZ",
    "zxz",
];

/// Byte patterns for binary formats: counts and indices at their limits, floats that are not
/// finite or overflow.
fn interesting_word(rng: &mut SmallRng) -> [u8; 4] {
    let candidates: [[u8; 4]; 10] = [
        0u32.to_le_bytes(),
        1u32.to_le_bytes(),
        u32::MAX.to_le_bytes(),
        (i32::MAX as u32).to_le_bytes(),
        (i32::MIN as u32).to_le_bytes(),
        0x007f_ffff_u32.to_le_bytes(),
        f32::NAN.to_le_bytes(),
        f32::INFINITY.to_le_bytes(),
        f32::MAX.to_le_bytes(),
        1e30f32.to_le_bytes(),
    ];
    candidates[rng.random_range(0..candidates.len())]
}

/// One to four stacked mutations of `input`; `other` is another seed for splicing, `xml` selects
/// the structure-aware XML mutations, `includes` names files an MJCF `<include>` may point at.
pub fn mutate(rng: &mut SmallRng, input: &[u8], other: &[u8], xml: bool, includes: &[String]) -> Vec<u8> {
    let mut out = input.to_vec();
    for _ in 0..rng.random_range(1..=4) {
        out = if xml && rng.random_bool(0.8) {
            match std::str::from_utf8(&out) {
                Ok(text) => xml_mutation(rng, text, other, includes).into_bytes(),
                Err(_) => byte_mutation(rng, &out, other),
            }
        } else {
            byte_mutation(rng, &out, other)
        };
    }
    out
}

fn byte_mutation(rng: &mut SmallRng, input: &[u8], other: &[u8]) -> Vec<u8> {
    let mut out = input.to_vec();
    let n = out.len();
    match rng.random_range(0..7) {
        0 if n > 0 => {
            let i = rng.random_range(0..n);
            out[i] ^= 1 << rng.random_range(0..8);
        }
        1 if n > 0 => {
            let i = rng.random_range(0..n);
            out[i] = rng.random();
        }
        2 if n >= 4 => {
            // An interesting 32-bit word at a 4-aligned offset (counts, indices, coordinates).
            let i = rng.random_range(0..n / 4) * 4;
            out[i..i + 4].copy_from_slice(&interesting_word(rng));
        }
        3 if n > 0 => {
            let a = rng.random_range(0..n);
            let b = (a + rng.random_range(1..=64)).min(n);
            out.drain(a..b);
        }
        4 if n > 0 => {
            let a = rng.random_range(0..n);
            let b = (a + rng.random_range(1..=256)).min(n);
            let chunk = out[a..b].to_vec();
            let at = rng.random_range(0..=n);
            out.splice(at..at, chunk);
        }
        5 if !other.is_empty() => {
            // Splice: a prefix of this input and a suffix of the other.
            let a = rng.random_range(0..=n);
            let b = rng.random_range(0..other.len());
            out.truncate(a);
            out.extend_from_slice(&other[b..]);
        }
        _ => {
            let at = rng.random_range(0..=n);
            let len = rng.random_range(1..=16);
            let bytes: Vec<u8> = (0..len).map(|_| rng.random()).collect();
            out.splice(at..at, bytes);
        }
    }
    out
}

/// Byte ranges `[start, end)` of the XML elements of `text` (start tag to the end of the matching
/// end tag, or of the self-closing tag), found by a tolerant scan that needs no well-formed input.
fn elements(text: &str) -> Vec<(usize, usize)> {
    let b = text.as_bytes();
    let mut stack: Vec<(usize, &str)> = Vec::new();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i] != b'<' {
            i += 1;
            continue;
        }
        let Some(close) = text[i..].find('>').map(|k| i + k) else { break };
        let tag = &text[i + 1..close];
        if tag.starts_with('!') || tag.starts_with('?') {
            // Comments, declarations: skip (comments end at the first '>', good enough here).
        } else if let Some(name) = tag.strip_prefix('/') {
            let name = name.trim();
            if let Some(pos) = stack.iter().rposition(|(_, n)| *n == name) {
                let (start, _) = stack[pos];
                stack.truncate(pos);
                out.push((start, close + 1));
            }
        } else if tag.ends_with('/') {
            out.push((i, close + 1));
        } else {
            let name = tag.split(|c: char| c.is_whitespace()).next().unwrap_or("");
            stack.push((i, name));
        }
        i = close + 1;
    }
    out
}

/// Byte ranges of `name="value"` attributes (the whole attribute, and the value inside quotes).
fn attributes(text: &str) -> Vec<((usize, usize), (usize, usize))> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i + 1 < b.len() {
        if b[i] == b'=' && b[i + 1] == b'"' {
            let mut s = i;
            while s > 0 && (b[s - 1].is_ascii_alphanumeric() || b[s - 1] == b'_' || b[s - 1] == b':') {
                s -= 1;
            }
            if let Some(k) = text[i + 2..].find('"') {
                let vend = i + 2 + k;
                out.push(((s, vend + 1), (i + 2, vend)));
                i = vend + 1;
                continue;
            }
        }
        i += 1;
    }
    out
}

/// Byte ranges of numbers inside attribute values.
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let starts = b[i].is_ascii_digit() || (b[i] == b'-' && i + 1 < b.len() && b[i + 1].is_ascii_digit());
        if starts && (i == 0 || !b[i - 1].is_ascii_alphanumeric()) {
            let s = i;
            i += 1;
            while i < b.len() && (b[i].is_ascii_digit() || b"eE.+-".contains(&b[i])) {
                i += 1;
            }
            out.push((s, i));
        } else {
            i += 1;
        }
    }
    out
}

fn pick<T: Copy>(rng: &mut SmallRng, items: &[T]) -> Option<T> {
    (!items.is_empty()).then(|| items[rng.random_range(0..items.len())])
}

fn replace(text: &str, (a, b): (usize, usize), with: &str) -> String {
    let mut s = String::with_capacity(text.len() + with.len());
    s.push_str(&text[..a]);
    s.push_str(with);
    s.push_str(&text[b..]);
    s
}

/// A chain of `depth` nested bodies (MJCF) or links (URDF), for the depth limits.
fn deep_nesting(rng: &mut SmallRng, urdf: bool) -> String {
    // Around the loaders' limits (400 nested elements, 3000 dofs, 10000 links) and beyond.
    // (Chains beyond the link limit are refused before the slow second URDF parse, but a chain
    // nested inside another element is not a chain of links and costs a full parse: rarely.)
    let depths: &[usize] =
        if urdf { &[10, 100, 450, 3001, 12000] } else { &[10, 100, 399, 450, 3001, 12000] };
    let depth = depths[rng.random_range(0..depths.len())];
    let mut s = String::new();
    if urdf {
        s.push_str("<link name=\"d0\"/>");
        for k in 1..depth {
            s.push_str(&format!(
                "<link name=\"d{k}\"><inertial><mass value=\"1\"/><inertia ixx=\"1\" iyy=\"1\" izz=\"1\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link><joint name=\"dj{k}\" type=\"continuous\"><parent link=\"d{}\"/><child link=\"d{k}\"/></joint>",
                k - 1
            ));
        }
    } else {
        for _ in 0..depth {
            s.push_str("<body><joint/><geom size=\".1\"/>");
        }
        for _ in 0..depth {
            s.push_str("</body>");
        }
    }
    s
}

fn xml_mutation(rng: &mut SmallRng, text: &str, other: &[u8], includes: &[String]) -> String {
    let urdf = text.contains("<robot");
    match rng.random_range(0..12) {
        0 | 1 => match pick(rng, &numbers(text)) {
            Some(r) => {
                let with = INTERESTING_NUMBERS[rng.random_range(0..INTERESTING_NUMBERS.len())];
                replace(text, r, with)
            }
            None => text.to_string(),
        },
        2 => match pick(rng, &elements(text)) {
            Some(r) => replace(text, r, ""),
            None => text.to_string(),
        },
        3 => match pick(rng, &elements(text)) {
            Some((a, b)) => {
                let copy = text[a..b].to_string();
                replace(text, (b, b), &copy)
            }
            None => text.to_string(),
        },
        4 => {
            // Move (copy) an element to the position of another, possibly into itself.
            let all = elements(text);
            match (pick(rng, &all), pick(rng, &all)) {
                (Some((a, b)), Some((c, _))) => {
                    let copy = text[a..b].to_string();
                    replace(text, (c, c), &copy)
                }
                _ => text.to_string(),
            }
        }
        5 => match pick(rng, &attributes(text)) {
            Some((whole, _)) => replace(text, whole, ""),
            None => text.to_string(),
        },
        6 => match pick(rng, &attributes(text)) {
            Some(((a, b), _)) => {
                let copy = format!(" {}", &text[a..b]);
                replace(text, (b, b), &copy)
            }
            None => text.to_string(),
        },
        7 => match pick(rng, &attributes(text)) {
            Some((_, value)) => {
                let with = INTERESTING_WORDS[rng.random_range(0..INTERESTING_WORDS.len())];
                replace(text, value, with)
            }
            None => text.to_string(),
        },
        8 => match pick(rng, &attributes(text)) {
            Some((_, value)) => {
                let unit = if rng.random_bool(0.5) { "1 " } else { "x" };
                let long =
                    unit.repeat(*[100usize, 10_000, 200_000].get(rng.random_range(0..3)).unwrap_or(&100));
                replace(text, value, &long)
            }
            None => text.to_string(),
        },
        // (URDF: rarely; a big chain costs a full parse by the URDF crate, ~100 ms.)
        9 if !urdf || rng.random_bool(0.2) => {
            // Deep nesting inside a random element (or at the end of the root).
            let at = match pick(rng, &elements(text)) {
                Some((_, b)) => b,
                None => text.len(),
            };
            replace(text, (at, at), &deep_nesting(rng, urdf))
        }
        10 if !urdf => {
            // An <include> of another file of the seed set, or of the input itself (a cycle).
            let at = match pick(rng, &elements(text)) {
                Some((_, b)) => b,
                None => text.len(),
            };
            let k = rng.random_range(0..includes.len().max(1));
            let file = includes.get(k).map(String::as_str).unwrap_or("__fuzz.xml");
            let file = if rng.random_bool(0.2) { "__fuzz.xml" } else { file };
            replace(text, (at, at), &format!("<include file=\"{file}\"/>"))
        }
        _ => {
            // Splice an element of the other seed into this one.
            let other = String::from_utf8_lossy(other);
            let theirs = elements(&other);
            match (pick(rng, &theirs), pick(rng, &elements(text))) {
                (Some((a, b)), Some((c, _))) => replace(text, (c, c), &other[a..b]),
                _ => text.to_string(),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scans_elements_attributes_and_numbers() {
        let t = r#"<a x="1 2"><b y="-3e2"/></a>"#;
        assert_eq!(elements(t), vec![(11, 24), (0, t.len())]);
        assert_eq!(attributes(t).len(), 2);
        let nums: Vec<&str> = numbers(t).iter().map(|&(a, b)| &t[a..b]).collect();
        assert_eq!(nums, vec!["1", "2", "-3e2"]);
    }
}
