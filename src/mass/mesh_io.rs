//! Reading triangle meshes: STL (binary and ASCII), Wavefront OBJ and MuJoCo's binary MSH, with
//! MuJoCo's conventions where they matter for mass properties:
//! - coordinates are `f32` values (binary STL and MSH store them so; decimal STL and OBJ
//!   coordinates are rounded to the nearest `f32`, as MuJoCo stores mesh vertices), so that mass
//!   properties agree with MuJoCo to round-off;
//! - STL vertices at identical positions are merged (as MuJoCo's STL decoder does), so that
//!   shared edges are recognised;
//! - OBJ faces with more than three corners are split into a fan `(v0, vk, vk+1)`, which is what
//!   tinyobjloader's ear clipping (used by MuJoCo) gives for convex faces; by default only the
//!   first object of the file is used — the faces before the first `o`/`g` line that follows a
//!   face — because MuJoCo's OBJ decoder keeps only `GetShapes()[0]`; [`ObjObjects::All`] reads
//!   every object. All vertices are kept either way (they enter the convex hull, as in MuJoCo);
//! - the scale multiplies the coordinates, and a scale with negative determinant (a mirror)
//!   reverses every triangle so that outward normals stay outward (`mjCMesh::Process`).
//!
//! COLLADA (`.dae`) and other formats give [`MeshError::UnsupportedFormat`].

use super::error::MeshError;
use super::fast_hash::{point_key, FastMap};
use super::mesh::TriangleMesh;
use crate::spatial::Vec3;
use std::path::Path;

/// Which objects of a multi-object OBJ file become the mesh.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ObjObjects {
    /// The first object only (MuJoCo's rule: its decoder keeps tinyobjloader's first shape).
    #[default]
    First,
    /// Every face of the file.
    All,
}

/// Options of [`read_mesh_with`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ReadOptions {
    /// Which objects of a multi-object OBJ file become the mesh.
    pub obj_objects: ObjObjects,
}

/// Reads an STL (binary or ASCII), OBJ or MSH file with MuJoCo's conventions (see the module
/// documentation) and applies `scale` (per-axis factors, MJCF `<mesh scale>` / URDF
/// `<mesh scale>`).
pub fn read_mesh(path: &Path, scale: &Vec3) -> Result<TriangleMesh, MeshError> {
    read_mesh_with(path, scale, &ReadOptions::default())
}

/// [`read_mesh`] with explicit options.
pub fn read_mesh_with(path: &Path, scale: &Vec3, options: &ReadOptions) -> Result<TriangleMesh, MeshError> {
    if !(scale.x.is_finite() && scale.y.is_finite() && scale.z.is_finite()) {
        return Err(MeshError::BadScale { x: scale.x, y: scale.y, z: scale.z });
    }
    let extension = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    let reader: fn(&[u8], &Path, &ReadOptions) -> Result<TriangleMesh, MeshError> = match extension.as_str() {
        "stl" => |b, p, _| parse_stl(b, p),
        "obj" => |b, p, o| parse_obj(b, p, o.obj_objects),
        "msh" => |b, p, _| parse_msh(b, p),
        _ => {
            let extension =
                if extension.is_empty() { "no extension".to_string() } else { format!(".{extension}") };
            return Err(MeshError::UnsupportedFormat { path: path.to_path_buf(), extension });
        }
    };
    let io = |source| MeshError::Io { path: path.to_path_buf(), source };
    let size = std::fs::metadata(path).map_err(io)?.len();
    if size > MAX_MESH_BYTES {
        return Err(parse_error(
            path,
            "mesh",
            None,
            format!("the file has {size} bytes, more than the limit of {MAX_MESH_BYTES} (a resource limit against hostile files); simplify the mesh"),
        ));
    }
    let bytes = std::fs::read(path).map_err(io)?;
    let mut mesh = reader(&bytes, path, options)?;
    if mesh.vertices.len() > MAX_MESH_VERTICES || mesh.triangles.len() > MAX_MESH_TRIANGLES {
        return Err(parse_error(
            path,
            "mesh",
            None,
            format!(
                "{} vertices and {} triangles, more than the limits of {MAX_MESH_VERTICES} and {MAX_MESH_TRIANGLES} (a resource limit); simplify the mesh",
                mesh.vertices.len(),
                mesh.triangles.len()
            ),
        ));
    }
    mesh.apply_scale(scale);
    Ok(mesh)
}

/// Resource limits on a mesh file: its size, and the vertices and triangles it may hold (a
/// hostile file must not exhaust memory; MuJoCo Menagerie's largest meshes have ~1e5 faces).
pub const MAX_MESH_BYTES: u64 = 512 * 1024 * 1024;
pub const MAX_MESH_VERTICES: usize = 10_000_000;
pub const MAX_MESH_TRIANGLES: usize = 20_000_000;

/// A decimal coordinate as the nearest `f32`, widened: MuJoCo stores mesh vertices as `float`
/// (and tinyobjloader parses them so), and STL is single precision by definition. Keeping the
/// same values makes mass properties agree with MuJoCo to round-off instead of to ~1e-7 (more
/// for thin parts, where a volume is a small difference of large terms).
fn parse_f32(s: &str) -> Option<f64> {
    s.parse::<f64>().ok().map(|x| x as f32 as f64)
}

fn parse_error(
    path: &Path,
    format: &'static str,
    line: Option<usize>,
    detail: impl Into<String>,
) -> MeshError {
    MeshError::Parse { path: path.to_path_buf(), format, line, detail: detail.into() }
}

/// Merges bitwise-identical vertices (with −0 read as +0) while building an indexed mesh.
#[derive(Default)]
struct VertexMerger {
    index: FastMap<[u64; 3], u32>,
    vertices: Vec<Vec3>,
}

impl VertexMerger {
    fn with_capacity(n: usize) -> Self {
        Self {
            index: FastMap::with_capacity_and_hasher(n, Default::default()),
            vertices: Vec::with_capacity(n),
        }
    }
    fn id(&mut self, v: Vec3) -> u32 {
        let key = point_key(v.x, v.y, v.z);
        let next = self.vertices.len() as u32;
        *self.index.entry(key).or_insert_with(|| {
            self.vertices.push(v);
            next
        })
    }
}

/// STL: binary when the size is exactly `84 + 50 n` for the triangle count `n` in the header,
/// else ASCII when the text starts with `solid`.
pub(crate) fn parse_stl(bytes: &[u8], path: &Path) -> Result<TriangleMesh, MeshError> {
    if bytes.len() >= 84 {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        if n.checked_mul(50).and_then(|s| s.checked_add(84)) == Some(bytes.len()) {
            return parse_stl_binary(bytes, n, path);
        }
    }
    let text_start = bytes.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(bytes.len());
    if bytes[text_start..].starts_with(b"solid") {
        return parse_stl_ascii(bytes, path);
    }
    let detail = if bytes.len() >= 84 {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        format!(
            "it does not start with 'solid' (ASCII STL), and its size {} bytes does not match the \
             binary layout for the {n} triangles its header announces (84 + 50 × {n} = {} bytes): \
             the file is truncated or not an STL file",
            bytes.len(),
            84 + 50 * n
        )
    } else {
        format!(
            "it has {} bytes, fewer than a binary STL header (84), and does not start with 'solid'",
            bytes.len()
        )
    };
    Err(parse_error(path, "STL", None, detail))
}

fn parse_stl_binary(bytes: &[u8], n: usize, path: &Path) -> Result<TriangleMesh, MeshError> {
    if n == 0 {
        return Err(parse_error(path, "binary STL", None, "it holds no triangles"));
    }
    // A closed mesh has about half as many vertices as triangles.
    let mut merger = VertexMerger::with_capacity(n / 2 + 3);
    let mut triangles = Vec::with_capacity(n);
    let f32_at = |o: usize| f32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]) as f64;
    for t in 0..n {
        let base = 84 + 50 * t;
        let mut tri = [0u32; 3];
        for (k, id) in tri.iter_mut().enumerate() {
            let o = base + 12 * (k + 1);
            *id = merger.id(Vec3::new(f32_at(o), f32_at(o + 4), f32_at(o + 8)));
        }
        triangles.push(tri);
    }
    Ok(TriangleMesh { vertices: merger.vertices, triangles })
}

fn parse_stl_ascii(bytes: &[u8], path: &Path) -> Result<TriangleMesh, MeshError> {
    const F: &str = "ASCII STL";
    let text = String::from_utf8_lossy(bytes);
    let mut merger = VertexMerger::default();
    let mut triangles = Vec::new();
    let mut lp: Vec<u32> = Vec::with_capacity(3); // corners of the current loop
    let mut in_loop = false;
    for (i, line) in text.lines().enumerate() {
        let lineno = i + 1;
        let mut tok = line.split_ascii_whitespace();
        let Some(key) = tok.next() else { continue };
        match key {
            "solid" | "endsolid" | "facet" | "endfacet" => {}
            "outer" => {
                if in_loop {
                    return Err(parse_error(path, F, Some(lineno), "'outer loop' inside an open loop"));
                }
                in_loop = true;
                lp.clear();
            }
            "vertex" => {
                if !in_loop {
                    return Err(parse_error(
                        path,
                        F,
                        Some(lineno),
                        "'vertex' outside 'outer loop' ... 'endloop'",
                    ));
                }
                let mut c = [0.0; 3];
                for x in &mut c {
                    *x = tok.next().and_then(parse_f32).ok_or_else(|| {
                        parse_error(
                            path,
                            F,
                            Some(lineno),
                            format!("expected 'vertex x y z', found '{}'", line.trim()),
                        )
                    })?;
                }
                lp.push(merger.id(Vec3::new(c[0], c[1], c[2])));
            }
            "endloop" => {
                if !in_loop || lp.len() < 3 {
                    return Err(parse_error(
                        path,
                        F,
                        Some(lineno),
                        format!("a facet loop has {} vertices (at least 3 are needed)", lp.len()),
                    ));
                }
                for k in 1..lp.len() - 1 {
                    triangles.push([lp[0], lp[k], lp[k + 1]]);
                }
                in_loop = false;
            }
            other => {
                return Err(parse_error(path, F, Some(lineno), format!("unexpected keyword '{other}'")));
            }
        }
    }
    if in_loop {
        return Err(parse_error(path, F, None, "the file ends inside a facet loop (truncated?)"));
    }
    if triangles.is_empty() {
        return Err(parse_error(path, F, None, "it holds no facets"));
    }
    Ok(TriangleMesh { vertices: merger.vertices, triangles })
}

/// Wavefront OBJ: `v` lines give vertices (extra components such as colours are ignored), `f`
/// lines give polygons by 1-based or negative (relative) vertex indices in `v`, `v/vt`, `v//vn`
/// or `v/vt/vn` form; everything else (normals, texture coordinates, materials, lines) is
/// irrelevant for mass and skipped.
pub(crate) fn parse_obj(bytes: &[u8], path: &Path, objects: ObjObjects) -> Result<TriangleMesh, MeshError> {
    const F: &str = "OBJ";
    let text = String::from_utf8_lossy(bytes);
    let mut vertices: Vec<Vec3> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    // (line, index as written) of every corner, checked once all vertices are known.
    let mut pending: Vec<(usize, i64)> = Vec::new();
    let mut corners: Vec<i64> = Vec::with_capacity(8);
    let mut closed = false; // MuJoCo rule: the first object is complete
    for (i, raw) in text.lines().enumerate() {
        let lineno = i + 1;
        let line = raw.split('#').next().unwrap_or("");
        let mut tok = line.split_ascii_whitespace();
        let Some(key) = tok.next() else { continue };
        match key {
            "v" => {
                let mut c = [0.0; 3];
                for x in &mut c {
                    *x = tok.next().and_then(parse_f32).ok_or_else(|| {
                        parse_error(
                            path,
                            F,
                            Some(lineno),
                            format!("expected 'v x y z', found '{}'", raw.trim()),
                        )
                    })?;
                }
                vertices.push(Vec3::new(c[0], c[1], c[2]));
            }
            "f" => {
                corners.clear();
                for t in tok {
                    let first = t.split('/').next().unwrap_or("");
                    let idx: i64 = first.parse().map_err(|_| {
                        parse_error(path, F, Some(lineno), format!("bad vertex reference '{t}' in a face"))
                    })?;
                    let resolved = match idx {
                        0 => {
                            return Err(parse_error(
                                path,
                                F,
                                Some(lineno),
                                "vertex index 0 (OBJ indices start at 1)",
                            ))
                        }
                        i if i > 0 => i - 1,
                        i => vertices.len() as i64 + i,
                    };
                    corners.push(resolved);
                }
                // tinyobjloader skips faces with fewer than 3 corners.
                if corners.len() < 3 || closed {
                    continue;
                }
                for &c in &corners {
                    pending.push((lineno, c));
                }
                for k in 1..corners.len() - 1 {
                    // Indices are range-checked below; negative ones become u32::MAX here.
                    let id = |c: i64| u32::try_from(c).unwrap_or(u32::MAX);
                    triangles.push([id(corners[0]), id(corners[k]), id(corners[k + 1])]);
                }
            }
            "o" | "g" if objects == ObjObjects::First && !triangles.is_empty() => closed = true,
            _ => {}
        }
    }
    let n = vertices.len() as i64;
    if let Some(&(line, idx)) = pending.iter().find(|&&(_, c)| c < 0 || c >= n) {
        return Err(parse_error(
            path,
            F,
            Some(line),
            format!("a face refers to vertex {} but the file defines {n} vertices", idx + 1),
        ));
    }
    if triangles.is_empty() && vertices.is_empty() {
        return Err(parse_error(path, F, None, "it defines no vertices"));
    }
    Ok(TriangleMesh { vertices, triangles })
}

/// MuJoCo's binary MSH: four little-endian `i32` counts (vertices, normals, texture coordinates,
/// faces), then `f32` vertex, normal and texture data and `i32` face indices (`mjCMesh::LoadMSH`).
pub(crate) fn parse_msh(bytes: &[u8], path: &Path) -> Result<TriangleMesh, MeshError> {
    const F: &str = "MSH";
    let i32_at = |o: usize| i32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]);
    if bytes.len() < 16 {
        return Err(parse_error(path, F, None, "the 16-byte header is missing"));
    }
    let (nv, nn, nt, nf) = (i32_at(0), i32_at(4), i32_at(8), i32_at(12));
    if nv < 0 || nn < 0 || nt < 0 || nf < 0 || (nn > 0 && nn != nv) || (nt > 0 && nt != nv) {
        return Err(parse_error(
            path,
            F,
            None,
            format!("invalid counts in the header: {nv} vertices, {nn} normals, {nt} texture coordinates, {nf} faces"),
        ));
    }
    let (nv, nn, nt, nf) = (nv as usize, nn as usize, nt as usize, nf as usize);
    let expected = 16 + 4 * (3 * nv + 3 * nn + 2 * nt + 3 * nf);
    if bytes.len() != expected {
        return Err(parse_error(
            path,
            F,
            None,
            format!("the file has {} bytes but its header announces {expected}", bytes.len()),
        ));
    }
    let f32_at = |o: usize| f32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]) as f64;
    let vertices =
        (0..nv).map(|k| Vec3::new(f32_at(16 + 12 * k), f32_at(20 + 12 * k), f32_at(24 + 12 * k))).collect();
    let face0 = 16 + 4 * (3 * nv + 3 * nn + 2 * nt);
    let mut triangles = Vec::with_capacity(nf);
    for k in 0..nf {
        let mut tri = [0u32; 3];
        for (j, t) in tri.iter_mut().enumerate() {
            let idx = i32_at(face0 + 12 * k + 4 * j);
            *t = match u32::try_from(idx) {
                Ok(i) if (i as usize) < nv => i,
                _ => {
                    return Err(parse_error(
                        path,
                        F,
                        None,
                        format!(
                            "face {k} refers to vertex {idx}, but the file has {nv} vertices (valid indices 0..{}); fix the face list",
                            nv.saturating_sub(1)
                        ),
                    ))
                }
            };
        }
        triangles.push(tri);
    }
    Ok(TriangleMesh { vertices, triangles })
}
