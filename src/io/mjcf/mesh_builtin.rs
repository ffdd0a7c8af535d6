//! Built-in meshes (`<mesh builtin="…" params="…">`) that lagrange generates as MuJoCo 4.0 does
//! (`mjs_makeMesh`, user_api.cc; `mjCMesh::MakeSphere`, `MakeCone`, user_mesh.cc), in the same
//! `f32` arithmetic so that the vertices are MuJoCo's bit for bit:
//! - `sphere` (params: subdivisions 0–4): an icosahedron on the unit sphere, each subdivision
//!   splitting every triangle in four at its edges' midpoints pushed onto the sphere;
//! - `cone` (params: edges, top radius): a unit circle of `edges` points at z = −1 and a circle of
//!   the top radius at z = +1 (a single apex when it is 0); no faces, so its convex hull;
//! - `hemisphere` (params: resolution 0–10), `supersphere` (resolution ≥ 3, e, n) and
//!   `supertorus` (resolution ≥ 3, radius in (0, 1], s, t): their generators in
//!   src/io/mjcf/mesh_builtin_super.rs (`MakeHemisphere`, `MakeSupersphere`, `MakeSupertorus`).
//!
//! The sampled built-ins (`wedge`, `plate`, `grid`, `box`, `cylinder`, `ellipsoid`, `square`,
//! `disc`) are generated in src/io/mjcf/mesh_builtin_solid.rs; those MuJoCo stores as points only
//! become their convex hull here (MuJoCo's refusal when the points span no volume), those it
//! stores as surfaces without volume turn a `legacy` inertia into `shell`.

use super::attrs::Attrs;
use super::mesh_builtin_solid::Shell;
use super::xml::Element;
use crate::io::LoadError;
use crate::mass::{self, MeshInertia, TriangleMesh};
use crate::spatial::Vec3;
use std::collections::HashMap;
use std::f64::consts::PI;
use std::sync::Arc;

/// The name and triangles (mesh frame, before scale) of a built-in mesh element `e`, and its
/// inertia mode: the element's `inertia`, or `shell` where MuJoCo makes it so (the surfaces
/// without volume).
pub(crate) fn builtin_mesh(
    e: &Element,
    a: &Attrs,
    shape: &str,
    inertia: MeshInertia,
) -> Result<(String, Arc<TriangleMesh>, MeshInertia), LoadError> {
    let invalid = |detail: String| LoadError::Invalid { loc: e.loc.clone(), element: "mesh".into(), detail };
    let Some(name) = a.text("name") else {
        return Err(invalid(format!("the built-in mesh '{shape}' needs a 'name' for geoms to refer to it")));
    };
    let params = a.numbers("params")?.unwrap_or_default();
    let count = |n: usize, what: &str| -> Result<(), LoadError> {
        if params.len() == n {
            Ok(())
        } else {
            Err(a.error(
                "params",
                format!("has {} numbers: the {shape} mesh type requires {n} ({what})", params.len()),
            ))
        }
    };
    // MuJoCo switches the inertia to `shell` for the built-ins without volume.
    let mut inertia = inertia;
    let mesh = match shape {
        "sphere" => {
            count(1, "subdivisions")?;
            let subdiv = params[0] as i64;
            if !(0..=4).contains(&subdiv) {
                return Err(a.error("params", format!("gives {subdiv} subdivisions: sphere subdivision must be in 0..=4")));
            }
            sphere(subdiv as usize)
        }
        "cone" => {
            count(2, "edges, top radius")?;
            let nedge = params[0] as i64;
            if nedge < 3 {
                return Err(a.error("params", format!("gives {nedge} edges: \"Cone nvert must be at least 3\" (MuJoCo 4.0)")));
            }
            if nedge > 100_000 {
                return Err(a.error("params", format!("gives {nedge} edges: lagrange generates cones of at most 100000")));
            }
            if !(0.0..=1.0).contains(&params[1]) {
                return Err(a.error("params", format!("gives top radius {}: \"Cone radius must be in [0, 1]\" (MuJoCo 4.0)", params[1])));
            }
            let vertices = cone(nedge as usize, params[1]);
            mass::convex_hull(&vertices)
                .map_err(|err| invalid(format!("the built-in cone '{name}' has no volume: {err}")))?
        }
        "hemisphere" => {
            count(1, "resolution")?;
            let res = params[0] as i64;
            if !(0..=10).contains(&res) {
                return Err(a.error("params", format!("gives resolution {res}: hemisphere resolution must be in 0..=10")));
            }
            super::mesh_builtin_super::hemisphere(res as usize)
        }
        "supersphere" => {
            count(3, "resolution, e, n")?;
            let res = params[0] as i64;
            if res < 3 {
                return Err(a.error("params", format!("gives resolution {res}: supersphere resolution must be greater than 2")));
            }
            if params[1] < 0.0 || params[2] < 0.0 {
                return Err(a.error("params", "gives a negative exponent: supersphere 'e' and 'n' cannot be negative"));
            }
            if (res as f64 + 1.0).powi(2) > super::mesh_builtin_solid::MAX_POINTS {
                return Err(a.error("params", format!("gives resolution {res}: lagrange generates built-in meshes of at most 10^6 points")));
            }
            super::mesh_builtin_super::supersphere(res as usize, params[1], params[2])
        }
        "supertorus" => {
            count(4, "resolution, radius, s, t")?;
            let res = params[0] as i64;
            if res < 3 {
                return Err(a.error("params", format!("gives resolution {res}: supertorus resolution must be at least 3")));
            }
            if !(params[1] > 0.0 && params[1] <= 1.0) {
                return Err(a.error("params", format!("gives radius {}: supertorus radius must be in (0, 1]", params[1])));
            }
            if !(params[2] > 0.0 && params[3] > 0.0) {
                return Err(a.error("params", "gives an exponent <= 0: supertorus 's' and 't' must be greater than 0"));
            }
            if (res as f64 + 1.0).powi(2) > super::mesh_builtin_solid::MAX_POINTS {
                return Err(a.error("params", format!("gives resolution {res}: lagrange generates built-in meshes of at most 10^6 points")));
            }
            super::mesh_builtin_super::supertorus(res as usize, params[1], params[2], params[3])
        }
        "wedge" | "plate" | "grid" | "box" | "cylinder" | "ellipsoid" | "square" | "disc" => {
            let g = super::mesh_builtin_solid::generate(shape, &params).map_err(|r| {
                let by = if r.mujoco { "as MuJoCo 4.0 refuses it" } else { "by a limit of lagrange's" };
                a.error("params", format!("of the built-in {shape} mesh '{name}' is refused {by}: \"{}\"; {}", r.reason, r.fix))
            })?;
            match g.shell {
                Shell::Always => inertia = MeshInertia::Shell,
                Shell::FromLegacy if inertia == MeshInertia::Legacy => inertia = MeshInertia::Shell,
                _ => {}
            }
            let vertices: Vec<Vec3> =
                g.vert.chunks_exact(3).map(|c| Vec3::new(c[0].into(), c[1].into(), c[2].into())).collect();
            if g.face.is_empty() {
                // Points only: MuJoCo's faces are their convex hull.
                if vertices.len() < 4 {
                    return Err(invalid(format!("the built-in {shape} mesh '{name}' has {} vertices: MuJoCo refuses it (\"at least 4 vertices required\"); raise its resolution or counts", vertices.len())));
                }
                mass::convex_hull(&vertices).map_err(|err| invalid(format!("the built-in {shape} mesh '{name}' spans no volume ({err}): MuJoCo refuses it (\"has coplanar vertices, cannot compute convex hull\"); give other params or a primitive geom")))?
            } else {
                TriangleMesh { vertices, triangles: g.face.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect() }
            }
        }
        other => {
            return Err(a.error(
                "builtin",
                format!("is '{other}': MuJoCo's built-in meshes are sphere, hemisphere, cone, supersphere, supertorus, wedge, plate, grid, box, cylinder, ellipsoid, square, disc"),
            ))
        }
    };
    Ok((name.to_string(), Arc::new(mesh), inertia))
}

/// MuJoCo's `MakeSphere` (make_faces): an icosahedron subdivided `subdiv` times, in `f32`.
fn sphere(subdiv: usize) -> TriangleMesh {
    let phi: f32 = ((1.0 + 5f64.sqrt()) / 2.0) as f32;
    #[rustfmt::skip]
    let mut vert: Vec<f32> = vec![
        -1.0, phi, 0.0, 1.0, phi, 0.0, -1.0, -phi, 0.0, 1.0, -phi, 0.0,
        0.0, -1.0, phi, 0.0, 1.0, phi, 0.0, -1.0, -phi, 0.0, 1.0, -phi,
        phi, 0.0, -1.0, phi, 0.0, 1.0, -phi, 0.0, -1.0, -phi, 0.0, 1.0,
    ];
    // MuJoCo divides each f32 by a double norm (the quotient in f64, stored as f32).
    let norm = (1.0 + f64::from(phi) * f64::from(phi)).sqrt();
    for v in &mut vert {
        *v = (f64::from(*v) / norm) as f32;
    }
    #[rustfmt::skip]
    let mut face: Vec<u32> = vec![
        0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4, 11, 10, 2, 10, 7, 6, 7, 1, 8,
        3, 9, 4, 3, 4, 2, 3, 2, 6, 3, 6, 8, 3, 8, 9, 4, 9, 5, 2, 4, 11, 6, 2, 10, 8, 6, 7, 9, 8, 1,
    ];
    for _ in 0..subdiv {
        let mut cache: HashMap<(u32, u32), u32> = HashMap::new();
        let mut midpoint = |a: u32, b: u32, vert: &mut Vec<f32>| -> u32 {
            let key = (a.min(b), a.max(b));
            if let Some(&i) = cache.get(&key) {
                return i;
            }
            let (a, b) = (a as usize * 3, b as usize * 3);
            let mut m = [
                (vert[a] + vert[b]) / 2.0,
                (vert[a + 1] + vert[b + 1]) / 2.0,
                (vert[a + 2] + vert[b + 2]) / 2.0,
            ];
            let n = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
            for x in &mut m {
                *x /= n;
            }
            let i = (vert.len() / 3) as u32;
            vert.extend_from_slice(&m);
            cache.insert(key, i);
            i
        };
        let mut next = Vec::with_capacity(face.len() * 4);
        for t in face.chunks_exact(3) {
            let (v1, v2, v3) = (t[0], t[1], t[2]);
            let m12 = midpoint(v1, v2, &mut vert);
            let m23 = midpoint(v2, v3, &mut vert);
            let m31 = midpoint(v3, v1, &mut vert);
            next.extend_from_slice(&[v1, m12, m31, v2, m23, m12, v3, m31, m23, m12, m23, m31]);
        }
        face = next;
    }
    TriangleMesh {
        vertices: vert.chunks_exact(3).map(|c| Vec3::new(c[0].into(), c[1].into(), c[2].into())).collect(),
        triangles: face.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
    }
}

/// MuJoCo's `MakeCone`: its vertices (f64 angles, stored as `f32`).
fn cone(nedge: usize, radius: f64) -> Vec<Vec3> {
    let f = |x: f64| f64::from(x as f32);
    let n = nedge as f64;
    let mut out: Vec<Vec3> = (0..nedge)
        .map(|i| Vec3::new(f((2.0 * i as f64 * PI / n).cos()), f((2.0 * i as f64 * PI / n).sin()), -1.0))
        .collect();
    if radius > 0.0 {
        out.extend((nedge..2 * nedge).map(|i| {
            Vec3::new(
                f(radius * (2.0 * i as f64 * PI / n).cos()),
                f(radius * (2.0 * i as f64 * PI / n).sin()),
                1.0,
            )
        }));
    } else {
        out.push(Vec3::new(0.0, 0.0, 1.0));
    }
    out
}
