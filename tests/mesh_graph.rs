//! MuJoCo's mesh hull graphs and face polygons (qhull's vertex and facet order, MuJoCo's
//! polygon merging and order), against tests/data/mujoco/qhull.json
//! (validation/mujoco_qhull_golden.py): every integer equal.

use lagrange::collision::mesh_graph::{distinct_vertices, MeshGraph};
use lagrange::spatial::Vec3;
use serde_json::Value;
use std::path::Path;

fn ints(v: &Value) -> Vec<i64> {
    v.as_array().unwrap().iter().map(|x| x.as_i64().unwrap()).collect()
}

/// MuJoCo's graph layout rebuilt from `g`: numvert, numface, vert_edgeadr, vert_globalid,
/// edge_localid, face_globalid.
fn graph_layout(g: &MeshGraph) -> Vec<i64> {
    let nv = g.vertices.len();
    let mut out = vec![nv as i64, g.faces.len() as i64];
    let mut adr = 0;
    for v in 0..nv {
        out.push(adr);
        adr += g.neighbours(v).len() as i64 + 1;
    }
    out.extend(g.globalid.iter().map(|&x| x as i64));
    for v in 0..nv {
        out.extend(g.neighbours(v).iter().map(|&x| x as i64));
        out.push(-1);
    }
    for f in &g.faces {
        out.extend(f.iter().map(|&x| g.globalid[x as usize] as i64));
    }
    out
}

#[test]
fn hull_graphs_and_polygons_are_mujocos() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let doc: Value =
        serde_json::from_str(&std::fs::read_to_string(root.join("tests/data/mujoco/qhull.json")).unwrap())
            .unwrap();
    let meshes = doc["meshes"].as_array().unwrap();
    assert!(meshes.len() >= 20);
    let (mut graphs, mut polys) = (0, 0);
    let mut failures = Vec::new();
    for m in meshes {
        let name = m["name"].as_str().unwrap();
        let vertices: Vec<Vec3> = if let Some(file) = m["file"].as_str() {
            lagrange::mass::read_mesh(&root.join(file), &Vec3::repeat(1.0)).unwrap().vertices
        } else {
            let flat: Vec<f64> =
                m["vertex"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
            flat.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect()
        };
        // MuJoCo removes repeated vertices of STL files only (its OBJ decoder and inline
        // vertices keep them).
        let stl = m["file"].as_str().is_some_and(|f| f.to_ascii_lowercase().ends_with(".stl"));
        let distinct = if stl { distinct_vertices(&vertices).0 } else { vertices };
        assert_eq!(distinct.len() as i64, m["nvert"].as_i64().unwrap(), "{name}: vertex count");
        let g = MeshGraph::new(&distinct, &distinct, &distinct, -1).unwrap();
        if graph_layout(&g) == ints(&m["graph"]) {
            graphs += 1;
        } else {
            failures.push(format!("{name}: graph"));
        }
        let want: Vec<Vec<i64>> = m["polygons"].as_array().unwrap().iter().map(ints).collect();
        let got: Vec<Vec<i64>> = (0..g.npoly())
            .map(|p| g.polygon(p).iter().map(|&v| g.globalid[v as usize] as i64).collect())
            .collect();
        let mut want_map: Vec<Vec<i64>> = m["polymap"].as_array().unwrap().iter().map(ints).collect();
        let mut got_map = vec![Vec::new(); distinct.len()];
        for v in 0..g.vertices.len() {
            got_map[g.globalid[v] as usize] = g.vertex_polygons(v).iter().map(|&p| p as i64).collect();
        }
        want_map.iter_mut().for_each(|l| l.sort_unstable());
        if got == want && got_map == want_map {
            polys += 1;
        } else {
            failures.push(format!("{name}: polygons ({} here, {} in MuJoCo)", got.len(), want.len()));
        }
    }
    println!("{graphs}/{} graphs and {polys}/{} polygon sets equal to MuJoCo's", meshes.len(), meshes.len());
    assert!(failures.is_empty(), "{failures:?}");
}
