//! The hill-climbing support function of mesh hulls (`collision::hull_support`, MuJoCo's
//! `mjc_hillclimbSupport`) against the exhaustive scan: for every corpus mesh under
//! tests/data/meshes/mujoco and the test meshes, on 2000 seeded random directions plus the 26
//! grid directions, the vertex found is as far along the direction as the scan's (the same
//! vertex unless two are exactly as far).

use lagrange::collision::hull_support::HullSupport;
use lagrange::collision::mesh_graph::{distinct_vertices, MeshGraph};
use lagrange::mass::read_mesh;
use lagrange::spatial::Vec3;
use parry3d_f64::math::Vector;
use std::path::PathBuf;
use std::sync::Arc;

/// The first point farthest along `dir` (the exhaustive scan).
fn scan(points: &[Vector], dir: Vector) -> usize {
    let mut best = 0;
    for (i, p) in points.iter().enumerate() {
        if p.dot(dir) > points[best].dot(dir) {
            best = i;
        }
    }
    best
}

fn meshes() -> Vec<PathBuf> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/meshes/mujoco");
    let mut out = Vec::new();
    for dir in std::fs::read_dir(&root).unwrap() {
        let dir = dir.unwrap().path();
        if !dir.is_dir() {
            continue;
        }
        for f in std::fs::read_dir(&dir).unwrap() {
            let f = f.unwrap().path();
            let ext = f.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
            if ext == "stl" || ext == "obj" {
                out.push(f);
            }
        }
    }
    out.sort();
    out
}

#[test]
fn hill_climbing_support_equals_the_exhaustive_scan_on_every_corpus_hull() {
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    let mut uniform = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let (mut hulls, mut queries, mut same_vertex) = (0, 0, 0);
    for path in meshes() {
        let mesh = read_mesh(&path, &Vec3::new(1.0, 1.0, 1.0)).unwrap();
        let (points, _) = distinct_vertices(&mesh.vertices);
        let support = HullSupport::new(Arc::new(MeshGraph::new(&points, &points, &points, -1).unwrap()));
        let pts = support.points();
        let mut dirs: Vec<Vector> = (0..27)
            .filter(|&k| k != 13)
            .map(|k| Vector::new((k / 9) as f64 - 1.0, ((k / 3) % 3) as f64 - 1.0, (k % 3) as f64 - 1.0))
            .collect();
        dirs.extend((0..2000).map(|_| Vector::new(uniform(), uniform(), uniform())));
        for d in dirs {
            let (a, b) = (support.support_index(d), scan(pts, d));
            assert_eq!(pts[a].dot(d), pts[b].dot(d), "{}: direction {d:?}", path.display());
            same_vertex += usize::from(a == b);
            queries += 1;
        }
        hulls += 1;
    }
    println!(
        "{hulls} hulls, {queries} directions: as far as the scan on all, the same vertex on {same_vertex}"
    );
    assert!(hulls >= 10, "corpus meshes not found");
}
