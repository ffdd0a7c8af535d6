//! The curved built-in meshes with faces beyond the icosphere, generated as MuJoCo 4.0 does
//! (`mjCMesh::MakeHemisphere`, `MakeSupersphere`, `MakeSupertorus`, user_mesh.cc): vertices
//! computed in `f64` and stored as `f32` (MuJoCo's `uservert`), faces in MuJoCo's order.
//! Parameter checks are in src/io/mjcf/mesh_builtin.rs.

use crate::mass::TriangleMesh;
use crate::spatial::Vec3;
use std::f64::consts::PI;

/// A mesh from MuJoCo-style flat `f32` vertices and `u32` faces.
fn mesh(vert: &[f32], face: &[u32]) -> TriangleMesh {
    TriangleMesh {
        vertices: vert.chunks_exact(3).map(|c| Vec3::new(c[0].into(), c[1].into(), c[2].into())).collect(),
        triangles: face.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
    }
}

/// MuJoCo's `aux_c`: `sign(cos ω) |cos ω|^m`.
fn aux_c(omega: f64, m: f64) -> f64 {
    omega.cos().abs().powf(m).copysign(omega.cos())
}

/// MuJoCo's `aux_s`: `sign(sin ω) |sin ω|^m`.
fn aux_s(omega: f64, m: f64) -> f64 {
    omega.sin().abs().powf(m).copysign(omega.sin())
}

/// `MakeHemisphere(res, make_faces = true, make_cap = true)`: rows of points from the north pole
/// to the equator on the four octant arcs, pushed onto the unit sphere, and a bottom cap fanned
/// around a centre vertex at the origin.
pub(crate) fn hemisphere(res: usize) -> TriangleMesh {
    const POLE: [f64; 3] = [0.0, 0.0, 1.0];
    const EQUATOR: [[f64; 3]; 4] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]];
    let nvert = 1 + 2 * (res + 1) * (res + 2) + 1;
    let mut vert: Vec<f32> = Vec::with_capacity(3 * nvert);
    vert.extend_from_slice(&[0.0, 0.0, 1.0]);
    for row in 0..=res {
        for side in 0..4 {
            let factor = (row + 1) as f64 / (res + 1) as f64;
            let mut start = [0.0; 3];
            let mut delta = [0.0; 3];
            for i in 0..3 {
                start[i] = POLE[i] + factor * (EQUATOR[side][i] - POLE[i]);
                let end = POLE[i] + factor * (EQUATOR[(side + 1) % 4][i] - POLE[i]);
                delta[i] = (end - start[i]) / (row + 1) as f64;
            }
            for i in 0..=row {
                let p: [f64; 3] = std::array::from_fn(|j| start[j] + i as f64 * delta[j]);
                let norm = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
                vert.extend(p.iter().map(|x| (x / norm) as f32));
            }
        }
    }
    vert.extend_from_slice(&[0.0, 0.0, 0.0]);
    let mut face: Vec<u32> = vec![0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 1];
    for row in 0..res {
        let start_curr = 2 * row * (row + 1) + 1;
        let count_curr = 4 * (row + 1);
        let start_next = start_curr + count_curr;
        let count_next = 4 * (row + 2);
        for side in 0..4 {
            for i in 0..row + 2 {
                let v_curr = i + (row + 1) * side;
                let v_next = i + (row + 2) * side;
                let a = start_curr + v_curr % count_curr;
                let b = start_next + v_next % count_next;
                let c = start_next + (v_next + 1) % count_next;
                face.extend([a, b, c].map(|x| x as u32));
                if i < row + 1 {
                    let d = start_curr + (v_curr + 1) % count_curr;
                    face.extend([a, c, d].map(|x| x as u32));
                }
            }
        }
    }
    let start = 2 * res * (res + 1) + 1;
    let count = 4 * (res + 1);
    for i in 0..count {
        face.extend([start + i, nvert - 1, start + (i + 1) % count].map(|x| x as u32));
    }
    mesh(&vert, &face)
}

/// `MakeSupersphere(res, e, n)`: poles at z = ∓1 and `res − 1` rings of `res` points at
/// `(c(v,n) c(u,e), c(v,n) s(u,e), s(v,n))`.
pub(crate) fn supersphere(res: usize, e: f64, n: f64) -> TriangleMesh {
    let nvert = (res - 1) * res + 2;
    let mut vert: Vec<f32> = Vec::with_capacity(3 * nvert);
    vert.extend_from_slice(&[0.0, 0.0, -1.0]);
    for i in 1..res {
        let v = -PI / 2.0 + i as f64 * PI / res as f64;
        for j in 0..res {
            let u = -PI + j as f64 * 2.0 * PI / res as f64;
            vert.push((aux_c(v, n) * aux_c(u, e)) as f32);
            vert.push((aux_c(v, n) * aux_s(u, e)) as f32);
            vert.push(aux_s(v, n) as f32);
        }
    }
    vert.extend_from_slice(&[0.0, 0.0, 1.0]);
    let mut face: Vec<usize> = Vec::with_capacity(6 * res * (res - 1));
    for j in 0..res {
        face.extend([0, 1 + (j + 1) % res, 1 + j]);
    }
    for i in 0..res - 2 {
        for j in 0..res {
            let v1 = 1 + i * res + j;
            let v2 = 1 + i * res + (j + 1) % res;
            let v4 = 1 + (i + 1) * res + j;
            let v3 = 1 + (i + 1) * res + (j + 1) % res;
            face.extend([v1, v2, v4, v2, v3, v4]);
        }
    }
    let last = 1 + (res - 2) * res;
    for j in 0..res {
        face.extend([last + j, last + (j + 1) % res, nvert - 1]);
    }
    let face: Vec<u32> = face.into_iter().map(|x| x as u32).collect();
    mesh(&vert, &face)
}

/// `MakeSupertorus(res, radius, s, t)`: a `res × res` grid of
/// `((1 + r c(v,s)) c(u,t), (1 + r c(v,s)) s(u,t), r s(v,s))`, two triangles per cell.
pub(crate) fn supertorus(res: usize, radius: f64, s: f64, t: f64) -> TriangleMesh {
    let mut vert: Vec<f32> = Vec::with_capacity(3 * res * res);
    for i in 0..res {
        for j in 0..res {
            let u = 2.0 * PI * i as f64 / res as f64;
            let v = 2.0 * PI * j as f64 / res as f64;
            vert.push(((1.0 + radius * aux_c(v, s)) * aux_c(u, t)) as f32);
            vert.push(((1.0 + radius * aux_c(v, s)) * aux_s(u, t)) as f32);
            vert.push((radius * aux_s(v, s)) as f32);
        }
    }
    let mut face: Vec<u32> = Vec::with_capacity(6 * res * res);
    for i in 0..res {
        for j in 0..res {
            let (i1, j1) = ((i + 1) % res, (j + 1) % res);
            let (v1, v2, v3, v4) = (i * res + j, i1 * res + j, i1 * res + j1, i * res + j1);
            face.extend([v1, v2, v4, v2, v3, v4].map(|x| x as u32));
        }
    }
    mesh(&vert, &face)
}
