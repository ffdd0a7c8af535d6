//! The built-in meshes of MuJoCo 4.0 made of sampled points rather than a closed parametric
//! surface: `wedge` and `plate` (`mjCMesh::MakeWedge`, `MakeRect`, user_mesh.cc), `grid`,
//! `square` and `disc` (the 2D/3D grids of `mjCFlexcomp::MakeGrid`/`MakeSquare`,
//! user_flexcomp.cc), and `box`, `cylinder` and `ellipsoid` (`mjCFlexcomp::MakeBox` with
//! `BoxProject`), with the parameter checks and messages of the live MuJoCo 4.0.0 (`mjs_makeMesh`).
//! Points are computed in `f64` and stored as `f32`, as MuJoCo's `uservert`.
//!
//! What MuJoCo keeps of each, and so what lagrange builds on (mass, collision hull):
//! - a volumetric (`dim` 3) `grid`, `box`, `cylinder` or `ellipsoid`, and the `wedge`: points
//!   only (MuJoCo stores no faces: the tetrahedra are not a surface), so the mesh is their convex
//!   hull;
//! - a `dim` 2 `box`, `cylinder` or `ellipsoid`: an open-top surface (the `+z` side omitted) whose
//!   `legacy` inertia becomes `shell`;
//! - `plate`, `square`, `disc` and a `dim` 2 `grid`: flat triangulated surfaces (inertia `shell`:
//!   always for `plate`, over `legacy` for the others), which MuJoCo refuses as a colliding geom
//!   ("has coplanar vertices, cannot compute convex hull") and accepts as a visual one.
//!
//! The checks are MuJoCo's, in MuJoCo's order; the messages quote MuJoCo's reason.

use std::f64::consts::PI;

/// The most points a built-in may generate here (about (count + 1) per direction, multiplied).
pub(crate) const MAX_POINTS: f64 = 1e6;

/// MuJoCo's `mjEPS` (user_util.h), the threshold of `mjuu_normvec`.
const EPS: f64 = 1e-14;

/// A generated built-in mesh: MuJoCo's `uservert` (flat `f32` triples), its `userface` (empty
/// when MuJoCo stores only points) and how MuJoCo changes its inertia mode.
pub(crate) struct Generated {
    /// Vertices, three `f32` per vertex.
    pub vert: Vec<f32>,
    /// Triangles, three vertex indices per face; empty for a point cloud (hull).
    pub face: Vec<u32>,
    /// How MuJoCo sets `inertia` for this surface.
    pub shell: Shell,
}

/// How MuJoCo 4.0 changes a built-in's inertia mode.
#[derive(Clone, Copy, PartialEq, Debug)]
pub(crate) enum Shell {
    /// The mesh's `inertia` stands.
    Keep,
    /// A `legacy` inertia (the default, or given) becomes `shell`: the surfaces without volume
    /// (documented under `<mesh params>`).
    FromLegacy,
    /// `shell` whatever the file says (`MakeRect` sets it for `plate`).
    Always,
}

/// A refused parameter set: MuJoCo's reason and how to fix it.
pub(crate) struct Refusal {
    /// MuJoCo 4.0's message (or lagrange's, when `mujoco` is false).
    pub reason: &'static str,
    /// What to change.
    pub fix: &'static str,
    /// Whether MuJoCo 4.0 refuses the mesh too (false: a limit of lagrange's).
    pub mujoco: bool,
}

fn refuse<T>(reason: &'static str, fix: &'static str) -> Result<T, Refusal> {
    Err(Refusal { reason, fix, mujoco: true })
}

/// Generates built-in `shape` (one of `wedge`, `plate`, `grid`, `box`, `cylinder`, `ellipsoid`,
/// `square`, `disc`) from `params`, with MuJoCo's checks.
pub(crate) fn generate(shape: &str, params: &[f64]) -> Result<Generated, Refusal> {
    // MuJoCo truncates integer parameters (`static_cast<int>`).
    let int = |x: f64| x as i64;
    // lagrange's bound on the points a built-in generates (MuJoCo has none; a file asking for
    // billions would exhaust memory).
    let at_most = |counts: &[i64]| {
        let points: f64 = counts.iter().map(|&c| c as f64 + 1.0).product();
        if points > MAX_POINTS {
            Err(Refusal {
                reason: "lagrange generates built-in meshes of at most 10^6 points",
                fix: "give smaller resolutions or counts",
                mujoco: false,
            })
        } else {
            Ok(())
        }
    };
    match shape {
        "wedge" => {
            if params.len() != 5 {
                return refuse(
                    "Wedge builtin mesh types require 5 parameters",
                    "give res_phi res_theta fov_phi fov_theta gamma",
                );
            }
            let (fov, gamma) = ([params[2], params[3]], params[4]);
            if fov[0] <= 0.0 || fov[0] > 180.0 {
                return refuse("fov[0] must be a float between (0, 180] degrees", "give fov_phi in (0, 180]");
            }
            if fov[1] <= 0.0 || fov[1] > 90.0 {
                return refuse(
                    "`fov[1]` must be a float between (0, 90] degrees",
                    "give fov_theta in (0, 90]",
                );
            }
            let res = [int(params[0]), int(params[1])];
            if res[0] <= 0 || res[1] <= 0 {
                return refuse(
                    "Horizontal and vertical resolutions must be positive",
                    "give resolutions of at least 1",
                );
            }
            if !(0.0..=1.0).contains(&gamma) {
                return refuse("`gamma` must be a nonnegative float between [0, 1]", "give gamma in [0, 1]");
            }
            at_most(&res)?;
            Ok(wedge([res[0] as usize, res[1] as usize], fov, gamma))
        }
        "plate" => {
            if params.len() != 2 {
                return refuse("Plate builtin mesh type requires 2 parameters", "give res_x res_y");
            }
            let res = [int(params[0]), int(params[1])];
            if res[0] <= 0 || res[1] <= 0 {
                return refuse(
                    "Horizontal and vertical resolutions must be positive",
                    "give resolutions of at least 1",
                );
            }
            at_most(&res)?;
            Ok(plate([res[0] as usize, res[1] as usize]))
        }
        "grid" => {
            if params.len() != 6 && params.len() != 7 {
                return refuse(
                    "Grid mesh type requires 6 or 7 parameters (count[3], spacing[3], [dim])",
                    "give count[3] spacing[3] and optionally dim",
                );
            }
            let dim = params.get(6).map_or(3, |&d| int(d));
            if dim != 2 && dim != 3 {
                return refuse("Grid dim must be 2 or 3", "give dim 2 or 3");
            }
            let count = [int(params[0]), int(params[1]), int(params[2])];
            if count.iter().any(|&c| c <= 0) {
                return refuse("Grid count must be positive", "give counts of at least 1");
            }
            if dim == 2 && count[2] != 1 {
                return refuse(
                    "Grid count must be 1 along dimensions beyond dim",
                    "give count[2] = 1 for dim 2",
                );
            }
            at_most(&count)?;
            let count = count.map(|c| c as usize);
            let spacing = [params[3], params[4], params[5]];
            grid(count, spacing, dim == 3, false).map_or_else(
                || {
                    refuse(
                        "Failed to create grid mesh",
                        "give counts of at least 2 along the grid's dimensions",
                    )
                },
                Ok,
            )
        }
        "square" | "disc" => {
            if params.len() != 6 {
                return refuse(
                    "Square/disc mesh type requires 6 parameters (count[3], spacing[3])",
                    "give count[3] spacing[3]",
                );
            }
            let count = [int(params[0]), int(params[1]), int(params[2])];
            if count[0] <= 0 || count[1] <= 0 {
                return refuse("Count must be positive", "give count[0] and count[1] of at least 1");
            }
            if count[2] != 1 {
                return refuse("Square/disc count[2] must be 1", "give count[2] = 1");
            }
            at_most(&count)?;
            let count = count.map(|c| c as usize);
            let spacing = [params[3], params[4], params[5]];
            grid(count, spacing, false, shape == "disc").map_or_else(
                || refuse("Failed to create square/disc mesh", "give count[0] and count[1] of at least 2"),
                Ok,
            )
        }
        "box" | "cylinder" | "ellipsoid" => {
            if params.len() != 6 && params.len() != 7 {
                return refuse(
                    "Box/cylinder/ellipsoid mesh type requires 6 or 7 parameters (count[3], spacing[3], [dim])",
                    "give count[3] spacing[3] and optionally dim",
                );
            }
            let dim = params.get(6).map_or(3, |&d| int(d));
            if dim != 2 && dim != 3 {
                return refuse("Mesh dim must be 2 or 3 for box/cylinder/ellipsoid", "give dim 2 or 3");
            }
            let count = [int(params[0]), int(params[1]), int(params[2])];
            if count.iter().any(|&c| c < 2) {
                return refuse(
                    "Box/cylinder/ellipsoid count must be at least 2",
                    "give counts of at least 2",
                );
            }
            let kind = match shape {
                "box" => Projection::Box,
                "cylinder" => Projection::Cylinder,
                _ => Projection::Ellipsoid,
            };
            at_most(&count)?;
            Ok(solid(kind, count.map(|c| c as usize), [params[3], params[4], params[5]], dim == 3))
        }
        _ => refuse("Unsupported mesh type", "give one of MuJoCo's built-in mesh types"),
    }
}

/// MuJoCo's `mjuu_normvec` on the first `n` components: unchanged when the squared norm is
/// below `mjEPS` or the norm within `mjEPS` of 1.
fn normalize(v: &mut [f64]) {
    let sq: f64 = v.iter().map(|x| x * x).sum();
    if sq < EPS {
        return;
    }
    let norm = sq.sqrt();
    if (norm - 1.0).abs() > EPS {
        for x in v {
            *x /= norm;
        }
    }
}

/// MuJoCo's `LinSpace`: `n` values from `lower` by repeated addition of the increment.
fn linspace(lower: f64, upper: f64, n: usize) -> Vec<f64> {
    let increment = if n > 1 { (upper - lower) / (n - 1) as f64 } else { 0.0 };
    let mut x = lower;
    (0..n)
        .map(|_| {
            let v = x;
            x += increment;
            v
        })
        .collect()
}

/// MuJoCo's `Fovea`: `g x⁵ + (1 − g) x`, the identity when `gamma` is 0.
fn fovea(x: f64, gamma: f64) -> f64 {
    if gamma == 0.0 {
        return x;
    }
    let g = gamma.clamp(0.0, 1.0);
    g * x.powf(5.0) + (1.0 - g) * x
}

/// `MakeWedge(resolution, fov, gamma)`: bin centres of a foveated azimuth × elevation grid on the
/// unit sphere, `(cos e sin a, sin e, −cos e cos a)`; points only.
fn wedge(res: [usize; 2], fov: [f64; 2], gamma: f64) -> Generated {
    let edges = |n: usize, fov: f64| -> Vec<f64> {
        let scale = fov * PI / 180.0;
        linspace(-1.0, 1.0, n + 1).into_iter().map(|x| scale * fovea(x, gamma)).collect()
    };
    let (x_edges, y_edges) = (edges(res[0], fov[0]), edges(res[1], fov[1]));
    let mut vert = Vec::with_capacity(3 * res[0] * res[1]);
    for i in 0..res[0] {
        for j in 0..res[1] {
            let a = 0.5 * (x_edges[i + 1] + x_edges[i]);
            let e = 0.5 * (y_edges[j + 1] + y_edges[j]);
            vert.extend([e.cos() * a.sin(), e.sin(), -e.cos() * a.cos()].map(|x| x as f32));
        }
    }
    Generated { vert, face: Vec::new(), shell: Shell::Keep }
}

/// `MakeRect(resolution)`: cell centres of a `[−1, 1]²` grid at z = −1, two triangles between
/// each four neighbouring centres; inertia `shell`.
fn plate(res: [usize; 2]) -> Generated {
    let (dx, dy) = (2.0 / res[0] as f64, 2.0 / res[1] as f64);
    let mut vert = Vec::with_capacity(3 * res[0] * res[1]);
    let mut face = Vec::with_capacity(6 * (res[0] - 1) * (res[1] - 1));
    for i in 0..res[0] {
        for j in 0..res[1] {
            vert.extend([-1.0 + (i as f64 + 0.5) * dx, -1.0 + (j as f64 + 0.5) * dy, -1.0].map(|x| x as f32));
            if i > 0 && j > 0 {
                let at = |i: usize, j: usize| (i * res[1] + j) as u32;
                face.extend([
                    at(i - 1, j - 1),
                    at(i, j - 1),
                    at(i - 1, j),
                    at(i, j),
                    at(i - 1, j),
                    at(i, j - 1),
                ]);
            }
        }
    }
    Generated { vert, face, shell: Shell::Always }
}

/// `MakeGrid` in 3D (`volume`: the points of a `count` grid centred on the origin; the
/// tetrahedra are not kept) or 2D (the z = 0 grid, two triangles per cell; `disc` then flips
/// the diagonal in two quadrants and projects the square onto the disc, `MakeSquare`). None when
/// the grid has no cell (MuJoCo's "No elements were created").
fn grid(count: [usize; 3], spacing: [f64; 3], volume: bool, disc: bool) -> Option<Generated> {
    let coord = |k: usize, i: usize| spacing[k] * (i as f64 - 0.5 * (count[k] as f64 - 1.0));
    let mut vert = Vec::new();
    if volume {
        if count.iter().any(|&c| c < 2) {
            return None;
        }
        for ix in 0..count[0] {
            for iy in 0..count[1] {
                for iz in 0..count[2] {
                    vert.extend([coord(0, ix), coord(1, iy), coord(2, iz)].map(|x| x as f32));
                }
            }
        }
        return Some(Generated { vert, face: Vec::new(), shell: Shell::Keep });
    }
    if count[0] < 2 || count[1] < 2 {
        return None;
    }
    let size = [0.5 * spacing[0] * (count[0] as f64 - 1.0), 0.5 * spacing[1] * (count[1] as f64 - 1.0)];
    let mut face = Vec::new();
    for ix in 0..count[0] {
        for iy in 0..count[1] {
            let mut pos = [coord(0, ix), coord(1, iy)];
            let mut quad2tri = [[0, 1, 2], [0, 2, 3]];
            if disc && ((pos[0] < -EPS && pos[1] > -EPS) || (pos[0] > -EPS && pos[1] < -EPS)) {
                quad2tri[0][2] = 3;
                quad2tri[1][0] = 1;
            }
            if ix + 1 < count[0] && iy + 1 < count[1] {
                let at = |i: usize, j: usize| (count[2] * count[1] * i + count[2] * j) as u32;
                let quad = [at(ix, iy), at(ix + 1, iy), at(ix + 1, iy + 1), at(ix, iy + 1)];
                for tri in quad2tri {
                    face.extend(tri.map(|v| quad[v]));
                }
            }
            if disc {
                let l0 = pos[0].abs().max(pos[1].abs());
                normalize(&mut pos);
                pos[0] *= size[0] * l0;
                pos[1] *= size[1] * l0;
            }
            vert.extend([pos[0] as f32, pos[1] as f32, 0.0]);
        }
    }
    Some(Generated { vert, face, shell: Shell::FromLegacy })
}

/// Which surface `BoxProject` maps the box's grid onto.
#[derive(Clone, Copy, PartialEq)]
enum Projection {
    Box,
    Cylinder,
    Ellipsoid,
}

/// MuJoCo's `BoxProject`: grid point `(ix, iy, iz)` of the box surface, on the box of half-sizes
/// `spacing (count − 1) / 2`, or pushed radially onto the cylinder or ellipsoid of those sizes.
fn project(kind: Projection, count: [usize; 3], spacing: [f64; 3], i: [usize; 3]) -> [f64; 3] {
    let mut pos: [f64; 3] = std::array::from_fn(|k| 2.0 * i[k] as f64 / (count[k] - 1) as f64 - 1.0);
    let size: [f64; 3] = std::array::from_fn(|k| 0.5 * spacing[k] * (count[k] - 1) as f64);
    match kind {
        Projection::Box => {}
        Projection::Cylinder => {
            let l0 = pos[0].abs().max(pos[1].abs());
            normalize(&mut pos[..2]);
            return [pos[0] * (size[0] * l0), pos[1] * (size[1] * l0), pos[2] * size[2]];
        }
        Projection::Ellipsoid => normalize(&mut pos),
    }
    for k in 0..3 {
        pos[k] *= size[k];
    }
    pos
}

/// `MakeBox(dim, open)`: the surface points of a `count` grid (bottom and top, then the `y`
/// sides, then the `x` sides), projected by `kind`. Volumetric (`volume`): a centre point
/// first, no faces (MuJoCo's tetrahedra fan from it). Surface: the top side omitted, two
/// triangles per cell in MuJoCo's order and winding, inertia `shell`.
fn solid(kind: Projection, count: [usize; 3], spacing: [f64; 3], volume: bool) -> Generated {
    let open = !volume;
    let mut vert: Vec<f32> = Vec::new();
    if volume {
        vert.extend([0.0, 0.0, 0.0]);
    }
    let lin = |ix: usize, iy: usize, iz: usize| (ix * count[1] + iy) * count[2] + iz;
    let mut idx = vec![0u32; count[0] * count[1] * count[2]];
    let mut n = 0u32;
    let mut add = |vert: &mut Vec<f32>, idx: &mut Vec<u32>, ix: usize, iy: usize, iz: usize| {
        let p = project(kind, count, spacing, [ix, iy, iz]);
        vert.extend(p.map(|x| x as f32));
        idx[lin(ix, iy, iz)] = n;
        n += 1;
    };
    let sides = |c: usize| [0, c - 1];
    for iz in sides(count[2]) {
        for ix in 0..count[0] {
            for iy in 0..count[1] {
                if open && iz != 0 {
                    continue;
                }
                add(&mut vert, &mut idx, ix, iy, iz);
            }
        }
    }
    for iy in sides(count[1]) {
        for ix in 0..count[0] {
            for iz in 0..count[2] {
                if iz > 0 && (open || iz < count[2] - 1) {
                    add(&mut vert, &mut idx, ix, iy, iz);
                }
            }
        }
    }
    for ix in sides(count[0]) {
        for iy in 0..count[1] {
            for iz in 0..count[2] {
                if iz > 0 && (open || iz < count[2] - 1) && iy > 0 && iy < count[1] - 1 {
                    add(&mut vert, &mut idx, ix, iy, iz);
                }
            }
        }
    }
    if volume {
        return Generated { vert, face: Vec::new(), shell: Shell::Keep };
    }
    let at = |ix: usize, iy: usize, iz: usize| idx[lin(ix, iy, iz)];
    let mut face = Vec::new();
    // Bottom (the top is open).
    for ix in 0..count[0] - 1 {
        for iy in 0..count[1] - 1 {
            face.extend([at(ix, iy, 0), at(ix + 1, iy + 1, 0), at(ix + 1, iy, 0)]);
            face.extend([at(ix, iy, 0), at(ix, iy + 1, 0), at(ix + 1, iy + 1, 0)]);
        }
    }
    for iy in sides(count[1]) {
        for ix in 0..count[0] - 1 {
            for iz in 0..count[2] - 1 {
                let (ix0, ix1) = if iy == 0 { (ix, ix + 1) } else { (ix + 1, ix) };
                face.extend([at(ix0, iy, iz), at(ix1, iy, iz), at(ix1, iy, iz + 1)]);
                face.extend([at(ix0, iy, iz), at(ix1, iy, iz + 1), at(ix0, iy, iz + 1)]);
            }
        }
    }
    for ix in sides(count[0]) {
        for iy in 0..count[1] - 1 {
            for iz in 0..count[2] - 1 {
                let (iy0, iy1) = if ix != 0 { (iy, iy + 1) } else { (iy + 1, iy) };
                face.extend([at(ix, iy0, iz), at(ix, iy1, iz), at(ix, iy1, iz + 1)]);
                face.extend([at(ix, iy0, iz), at(ix, iy1, iz + 1), at(ix, iy0, iz + 1)]);
            }
        }
    }
    Generated { vert, face, shell: Shell::FromLegacy }
}
