//! qhull's convex hull of a 3-D point set, in the form MuJoCo's compiler builds its mesh graph
//! (`mjCMesh::MakeGraph`, src/user/user_mesh.cc of MuJoCo 4.0): qhull run with the options
//! `qhull Qt` (and `Q9 TA<maxhullvert − 4>` when a vertex limit is set), triangulated, with its
//! vertices in qhull's vertex-list order, each vertex's neighbours in the order its facets and
//! their vertices come in qhull's sets, and the triangles in qhull's facet-list order with
//! MuJoCo's orientation fix. The order is what matters: MuJoCo's mesh graph (hill-climbing start
//! and ties), its face polygons and where each polygon starts all follow it.
//!
//! qhull is compiled from the sources of the commit MuJoCo 4.0 pins
//! (d1c2fc0caa5f644f3a0f220290d4a868c68ed4f6, qhull 2020.2 / 8.1-alpha) under `qhull/`, with its
//! licence `qhull/COPYING.txt`; the shim `csrc/hull_graph.c` runs it and writes plain arrays.
//! qhull's own errors (it longjmps to the shim's `setjmp`) come back as [`QhullError`]; nothing
//! unwinds across the C boundary.

#![warn(missing_docs)]

use std::os::raw::{c_int, c_long};

extern "C" {
    fn lagrange_qhull_graph(
        points: *const f64,
        npoints: c_int,
        maxhullvert: c_int,
        graph: *mut c_int,
        capacity: c_long,
        qhull_code: *mut c_int,
    ) -> c_int;
}

/// MuJoCo's mesh graph of a point set's convex hull (see the crate documentation).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct HullGraph {
    /// Per hull vertex (qhull's order), the index of its input point (MuJoCo's `vert_globalid`).
    pub vert_globalid: Vec<u32>,
    /// Per hull vertex, where its neighbour list starts in `edge_localid` (`vert_edgeadr`).
    pub vert_edgeadr: Vec<u32>,
    /// Each hull vertex's neighbours as hull vertex indices, each list ended by −1
    /// (`edge_localid`, MuJoCo's layout).
    pub edge_localid: Vec<i32>,
    /// The triangles as input point indices, three per face, in qhull's facet order
    /// (`face_globalid`).
    pub face_globalid: Vec<u32>,
}

/// Why qhull gave no hull.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum QhullError {
    /// Fewer than 4 points, more than `i32::MAX`, or a coordinate that is not finite.
    BadInput(String),
    /// qhull stopped with an error (its exit code: 1 input error, 2 singular/precision,
    /// 3 precision error, 4 memory, 5 internal; qhull printed its message on stderr).
    Qhull(i32),
    /// qhull's output is not the triangulated hull MuJoCo reads (a facet that is not a triangle,
    /// a vertex that is not an input point, a vertex not in the hull's vertex list).
    Output(&'static str),
}

impl std::fmt::Display for QhullError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            QhullError::BadInput(s) => write!(f, "qhull input: {s}"),
            QhullError::Qhull(code) => write!(f, "qhull error (exit code {code})"),
            QhullError::Output(s) => write!(f, "qhull output: {s}"),
        }
    }
}

impl std::error::Error for QhullError {}

/// The hull graph of `points` (x, y, z per point) as MuJoCo builds it; `maxhullvert` is the
/// mesh's vertex limit (MJCF `maxhullvert`; −1 for none).
///
/// # Errors
/// [`QhullError`] when the input is not a point set qhull can hull or qhull fails.
pub fn hull_graph(points: &[[f64; 3]], maxhullvert: i32) -> Result<HullGraph, QhullError> {
    let n = points.len();
    if n < 4 {
        return Err(QhullError::BadInput(format!("{n} points, fewer than 4")));
    }
    if n > (i32::MAX as usize) / 16 {
        return Err(QhullError::BadInput(format!("{n} points, too many")));
    }
    if points.iter().any(|p| !p.iter().all(|x| x.is_finite())) {
        return Err(QhullError::BadInput("a coordinate is not finite".to_string()));
    }
    let flat: Vec<f64> = points.iter().flatten().copied().collect();
    // At most n hull vertices and 2n − 4 triangles (a triangulated sphere).
    let capacity = 2 + 3 * n + 6 * 2 * n;
    let mut graph = vec![0 as c_int; capacity];
    let mut code: c_int = 0;
    // SAFETY: `flat` holds 3n doubles, `graph` `capacity` ints; the shim writes within them, keeps
    // no pointer after returning, and catches qhull's longjmps itself.
    let status = unsafe {
        lagrange_qhull_graph(
            flat.as_ptr(),
            n as c_int,
            maxhullvert,
            graph.as_mut_ptr(),
            capacity as c_long,
            &mut code,
        )
    };
    match status {
        0 => {}
        1 => return Err(QhullError::Qhull(code)),
        2 => return Err(QhullError::Output("a hull vertex is not an input point")),
        3 => return Err(QhullError::Output("a facet is not a triangle")),
        4 => return Err(QhullError::Output("the graph's size is not numvert + 3 numface")),
        _ => return Err(QhullError::BadInput("rejected by the shim".to_string())),
    }
    let (nv, nf) = (graph[0] as usize, graph[1] as usize);
    let vert_edgeadr: Vec<u32> = graph[2..2 + nv].iter().map(|&a| a as u32).collect();
    let vert_globalid: Vec<u32> = graph[2 + nv..2 + 2 * nv].iter().map(|&a| a as u32).collect();
    // Point ids → hull vertex indices (MuJoCo's `hullid`).
    let mut hullid = vec![-1i32; n];
    for (local, &g) in vert_globalid.iter().enumerate() {
        hullid[g as usize] = local as i32;
    }
    let mut edge_localid = Vec::with_capacity(nv + 3 * nf);
    for &e in &graph[2 + 2 * nv..2 + 3 * nv + 3 * nf] {
        if e < 0 {
            edge_localid.push(-1);
        } else {
            let local = hullid[e as usize];
            if local < 0 {
                return Err(QhullError::Output("a neighbour is not a hull vertex"));
            }
            edge_localid.push(local);
        }
    }
    let face_globalid: Vec<u32> =
        graph[2 + 3 * nv + 3 * nf..2 + 3 * nv + 6 * nf].iter().map(|&a| a as u32).collect();
    if face_globalid.iter().any(|&g| hullid[g as usize] < 0) {
        return Err(QhullError::Output("a face corner is not a hull vertex"));
    }
    Ok(HullGraph { vert_globalid, vert_edgeadr, edge_localid, face_globalid })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_has_eight_vertices_and_twelve_triangles() {
        let mut points = Vec::new();
        for i in 0..8 {
            points.push([(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64]);
        }
        points.push([0.5, 0.5, 0.5]);
        let g = hull_graph(&points, -1).unwrap();
        assert_eq!(g.vert_globalid.len(), 8);
        assert_eq!(g.face_globalid.len(), 36);
        assert!(!g.vert_globalid.contains(&8));
    }

    #[test]
    fn flat_input_is_an_error() {
        let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
        assert!(matches!(hull_graph(&points, -1), Err(QhullError::Qhull(_))));
    }
}
