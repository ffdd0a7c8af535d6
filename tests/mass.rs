//! Mass properties from geometry (`lagrange::mass`) against the lecture notes
//! (`shared/reference/classical-mechanics-notes.md` §2.1–2.3 and §3.1–3.2), exactly for primitives
//! and polyhedra, by convergence for meshes of curved bodies (inscribed polyhedra: the error must
//! shrink as h² when the resolution doubles), under rigid transformations and scales, and for
//! every way a mesh file can be broken (the error must name the defect and the fix).
//!
//! Run with `--nocapture` for every case's error.

mod common;

use common::{rel_err, rel_err_vec, repo_path, MASS_EXACT_REL, MESH_ORDER_BAND, MESH_TRANSFORM_REL};
use lagrange::mass::{
    compose, convex_hull, mesh_inertia, parallel_axis, primitive_inertia, primitive_measure,
    principal_angle_xy, principal_axes, read_mesh, read_mesh_with, rotate_tensor, Distribution, MeshError,
    MeshInertia, ObjObjects, Primitive, ReadOptions, TriangleMesh,
};
use lagrange::spatial::{Mat3, RigidInertia, Transform, Vec3};
use std::f64::consts::PI;

const ALL_MODES: [MeshInertia; 4] =
    [MeshInertia::Legacy, MeshInertia::Exact, MeshInertia::Convex, MeshInertia::Shell];

// ------------------------------------------------------------------------------------------------
// Mesh generators (counter-clockwise seen from outside)
// ------------------------------------------------------------------------------------------------

/// Adds a vertex, returns its index.
fn push(m: &mut TriangleMesh, v: Vec3) -> u32 {
    m.vertices.push(v);
    (m.vertices.len() - 1) as u32
}

/// Points of latitude ring `i` (polar angle θ = π i / n_lat) of a sphere of radius `a`.
fn ring(a: f64, theta: f64, n_lon: usize) -> Vec<Vec3> {
    (0..n_lon)
        .map(|j| {
            let phi = 2.0 * PI * j as f64 / n_lon as f64;
            Vec3::new(a * theta.sin() * phi.cos(), a * theta.sin() * phi.sin(), a * theta.cos())
        })
        .collect()
}

/// The surface band of a sphere between polar angles 0 and `theta_max` (π: the whole sphere,
/// π/2: the upper hemisphere's dome), with `n_lat` rings over [0, π] and `2 n_lat` meridians,
/// inscribed in the sphere. Returns the mesh and the indices of its last ring.
fn sphere_band(a: f64, n_lat: usize, rings: usize) -> (TriangleMesh, Vec<u32>) {
    let n_lon = 2 * n_lat;
    let mut m = TriangleMesh::default();
    let north = push(&mut m, Vec3::new(0.0, 0.0, a));
    let mut prev: Vec<u32> = Vec::new();
    for i in 1..=rings {
        let theta = PI * i as f64 / n_lat as f64;
        let ids: Vec<u32> = if i == n_lat {
            vec![push(&mut m, Vec3::new(0.0, 0.0, -a))]
        } else {
            ring(a, theta, n_lon).into_iter().map(|v| push(&mut m, v)).collect()
        };
        for j in 0..n_lon {
            let k = (j + 1) % n_lon;
            match (prev.is_empty(), ids.len() == 1) {
                (true, _) => m.triangles.push([north, ids[j], ids[k]]),
                (false, true) => m.triangles.push([prev[j], ids[0], prev[k]]),
                (false, false) => {
                    m.triangles.push([prev[j], ids[j], ids[k]]);
                    m.triangles.push([prev[j], ids[k], prev[k]]);
                }
            }
        }
        prev = ids;
    }
    (m, prev)
}

/// A closed sphere of radius `a`.
fn sphere(a: f64, n_lat: usize) -> TriangleMesh {
    sphere_band(a, n_lat, n_lat).0
}

/// The upper hemisphere's dome (open), `n_lat` even.
fn dome(a: f64, n_lat: usize) -> TriangleMesh {
    sphere_band(a, n_lat, n_lat / 2).0
}

/// The solid upper hemisphere: the dome closed by a flat disk at z = 0.
fn solid_hemisphere(a: f64, n_lat: usize) -> TriangleMesh {
    let (mut m, rim) = sphere_band(a, n_lat, n_lat / 2);
    let centre = push(&mut m, Vec3::zeros());
    for j in 0..rim.len() {
        // Seen from below (outside), the rim runs clockwise in xy: wind (centre, k, j).
        m.triangles.push([centre, rim[(j + 1) % rim.len()], rim[j]]);
    }
    m
}

/// A flat polygon as a fan from its first point `c` (normal +z for counter-clockwise input).
fn fan(c: Vec3, boundary: &[Vec3], closed: bool) -> TriangleMesh {
    let mut m = TriangleMesh::default();
    let c = push(&mut m, c);
    let ids: Vec<u32> = boundary.iter().map(|v| push(&mut m, *v)).collect();
    let n = if closed { ids.len() } else { ids.len() - 1 };
    for j in 0..n {
        m.triangles.push([c, ids[j], ids[(j + 1) % ids.len()]]);
    }
    m
}

/// A regular `n`-gon disk of radius `a` in the plane z = 0 (a lamina: shell mode).
fn disk(a: f64, n: usize) -> TriangleMesh {
    let b: Vec<Vec3> = (0..n)
        .map(|j| 2.0 * PI * j as f64 / n as f64)
        .map(|p| Vec3::new(a * p.cos(), a * p.sin(), 0.0))
        .collect();
    fan(Vec3::zeros(), &b, true)
}

/// The half-disk {x² + z² ≤ a², z ≥ 0} in the plane y = 0 with `n` segments on the arc.
fn half_disk(a: f64, n: usize) -> TriangleMesh {
    let b: Vec<Vec3> =
        (0..=n).map(|j| PI * j as f64 / n as f64).map(|p| Vec3::new(a * p.cos(), 0.0, a * p.sin())).collect();
    fan(Vec3::zeros(), &b, false)
}

/// An axis-aligned box with corners `lo`, `hi` (12 triangles).
fn box_mesh(lo: Vec3, hi: Vec3) -> TriangleMesh {
    let c = |i: usize| {
        Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    };
    // Unit-cube corners 0..8 by bits (x, y, z); faces counter-clockwise from outside.
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    TriangleMesh {
        vertices: (0..8).map(c).collect(),
        triangles: quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect(),
    }
}

/// A closed cylinder of radius `a` and length `l` along z, centred, with `n` sides.
fn cylinder(a: f64, l: f64, n: usize) -> TriangleMesh {
    let mut m = TriangleMesh::default();
    let top = push(&mut m, Vec3::new(0.0, 0.0, l / 2.0));
    let bottom = push(&mut m, Vec3::new(0.0, 0.0, -l / 2.0));
    let ring_at = |m: &mut TriangleMesh, z: f64| -> Vec<u32> {
        (0..n)
            .map(|j| 2.0 * PI * j as f64 / n as f64)
            .map(|p| push(m, Vec3::new(a * p.cos(), a * p.sin(), z)))
            .collect()
    };
    let up = ring_at(&mut m, l / 2.0);
    let down = ring_at(&mut m, -l / 2.0);
    for j in 0..n {
        let k = (j + 1) % n;
        m.triangles.push([top, up[j], up[k]]);
        m.triangles.push([bottom, down[k], down[j]]);
        m.triangles.push([down[j], down[k], up[k]]);
        m.triangles.push([down[j], up[k], up[j]]);
    }
    m
}

/// The prism of height `h` over a counter-clockwise polygon in the xy plane, its caps
/// triangulated by `caps` (counter-clockwise triangles of polygon corners).
fn prism(poly: &[[f64; 2]], caps: &[[u32; 3]], h: f64) -> TriangleMesh {
    let n = poly.len() as u32;
    let mut m = TriangleMesh::default();
    for z in [0.0, h] {
        for p in poly {
            push(&mut m, Vec3::new(p[0], p[1], z));
        }
    }
    for t in caps {
        m.triangles.push([t[0], t[2], t[1]]); // bottom, seen from below
        m.triangles.push(t.map(|i| i + n)); // top
    }
    for i in 0..n {
        let j = (i + 1) % n;
        m.triangles.push([i, j, n + j]);
        m.triangles.push([i, n + j, n + i]);
    }
    m
}

/// A capsule: a cylinder of radius `a` and half-length `hl` along z capped by hemispheres, with
/// `n_lat` (even) rings over the two caps and `2 n_lat` meridians.
fn capsule(a: f64, hl: f64, n_lat: usize) -> TriangleMesh {
    let n_lon = 2 * n_lat;
    let mut m = TriangleMesh::default();
    let north = push(&mut m, Vec3::new(0.0, 0.0, a + hl));
    let south = push(&mut m, Vec3::new(0.0, 0.0, -a - hl));
    // Rings from north to south; the equator twice (top and bottom of the cylinder).
    let mut rings: Vec<Vec<u32>> = Vec::new();
    for i in 1..n_lat {
        let theta = PI * i as f64 / n_lat as f64;
        let shifts: &[f64] = if 2 * i == n_lat {
            &[hl, -hl]
        } else if 2 * i < n_lat {
            &[hl]
        } else {
            &[-hl]
        };
        for dz in shifts {
            rings.push(
                ring(a, theta, n_lon)
                    .into_iter()
                    .map(|v| push(&mut m, v + Vec3::new(0.0, 0.0, *dz)))
                    .collect(),
            );
        }
    }
    for j in 0..n_lon {
        let k = (j + 1) % n_lon;
        m.triangles.push([north, rings[0][j], rings[0][k]]);
        let last = &rings[rings.len() - 1];
        m.triangles.push([last[j], south, last[k]]);
        for w in rings.windows(2) {
            m.triangles.push([w[0][j], w[1][j], w[1][k]]);
            m.triangles.push([w[0][j], w[1][k], w[0][k]]);
        }
    }
    m
}

fn scaled(mut m: TriangleMesh, s: Vec3) -> TriangleMesh {
    m.apply_scale(&s);
    m
}

/// Unit-density mass properties, or a panic naming the case.
fn props(m: &TriangleMesh, mode: MeshInertia, what: &str) -> (f64, RigidInertia) {
    mesh_inertia(m, mode).unwrap_or_else(|e| panic!("{what} ({mode:?}): {e}"))
}

fn mesh_file(name: &str) -> std::path::PathBuf {
    repo_path(&format!("tests/data/meshes/{name}"))
}

// ------------------------------------------------------------------------------------------------
// Convergence
// ------------------------------------------------------------------------------------------------

/// Errors of `f(n)` against `exact` at the resolutions `ns` (each the double of the previous);
/// prints them with the observed orders log₂(eₖ/eₖ₊₁) and asserts second order within
/// [`MESH_ORDER_BAND`] on the last two ratios. Returns the error at the finest resolution.
fn assert_second_order(what: &str, ns: &[usize], exact: f64, f: impl Fn(usize) -> f64) -> f64 {
    let errs: Vec<f64> = ns.iter().map(|&n| ((f(n) - exact) / exact).abs()).collect();
    let orders: Vec<f64> = errs.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    println!(
        "{what:<52} rel. err {} ; orders {}",
        ns.iter().zip(&errs).map(|(n, e)| format!("n={n}: {e:.2e}")).collect::<Vec<_>>().join(", "),
        orders.iter().map(|o| format!("{o:.3}")).collect::<Vec<_>>().join(", ")
    );
    for (k, w) in errs.windows(2).enumerate().skip(errs.len().saturating_sub(3)) {
        let ratio = w[0] / w[1];
        assert!(
            (4.0 / MESH_ORDER_BAND..=4.0 * MESH_ORDER_BAND).contains(&ratio),
            "{what}: error ratio {ratio:.3} between n = {} and {} is not second order (4 × [1/{MESH_ORDER_BAND}, {MESH_ORDER_BAND}])",
            ns[k],
            ns[k + 1]
        );
    }
    *errs.last().unwrap()
}

const NS: [usize; 5] = [8, 16, 32, 64, 128];

#[test]
fn solid_hemisphere_centre_of_mass_eq37() {
    // z_CM = 3a/8 (docs/physics.md (37)).
    let a = 0.7;
    let e = assert_second_order("solid hemisphere z_CM = 3a/8 (eq. 37)", &NS, 3.0 * a / 8.0, |n| {
        props(&solid_hemisphere(a, n), MeshInertia::Exact, "hemisphere").1.com().z
    });
    assert!(e < 1e-3);
    // Legacy mode agrees: the hemisphere is star-shaped about its face centroid and its centre of mass.
    let m = solid_hemisphere(a, 64);
    let (vl, il) = props(&m, MeshInertia::Legacy, "hemisphere");
    let (ve, ie) = props(&m, MeshInertia::Exact, "hemisphere");
    assert!(
        rel_err(vl, ve) < MASS_EXACT_REL
            && rel_err_vec(il.com().as_slice(), ie.com().as_slice()) < MASS_EXACT_REL
    );
}

#[test]
fn hemispherical_shell_centre_of_mass_eq38() {
    // z_CM = a/2 (eq. 38): the dome alone, mass on the surface.
    let a = 1.3;
    let e = assert_second_order("hemispherical shell z_CM = a/2 (eq. 38)", &NS, a / 2.0, |n| {
        props(&dome(a, n), MeshInertia::Shell, "dome").1.com().z
    });
    assert!(e < 1e-3);
    // The open dome is no solid: exact and legacy refuse it and say why.
    for mode in [MeshInertia::Exact, MeshInertia::Legacy] {
        let err = mesh_inertia(&dome(a, 16), mode).unwrap_err();
        assert!(matches!(err, MeshError::Open { .. }), "{mode:?}: {err}");
    }
}

#[test]
fn half_disk_centre_of_mass_eq40() {
    // z_CM = 4a/(3π) (eq. 40): a flat lamina (shell mode measures area).
    let a = 2.0;
    let e = assert_second_order("half-disk z_CM = 4a/(3π) (eq. 40)", &NS, 4.0 * a / (3.0 * PI), |n| {
        props(&half_disk(a, n), MeshInertia::Shell, "half-disk").1.com().z
    });
    assert!(e < 1e-3);
}

#[test]
fn sphere_moment_of_inertia_eq53() {
    // I = 2ma²/5 (eq. 53): inscribed polyhedra converge as h²; the primitive is exact.
    let a = 0.4;
    let e = assert_second_order("sphere mesh I/(m a²) = 2/5 (eq. 53)", &NS, 0.4, |n| {
        let (_, i) = props(&sphere(a, n), MeshInertia::Exact, "sphere");
        i.i_com()[(2, 2)] / (i.mass * a * a)
    });
    assert!(e < 1e-3);
    let e = assert_second_order("sphere mesh volume 4πa³/3", &NS, 4.0 * PI * a.powi(3) / 3.0, |n| {
        props(&sphere(a, n), MeshInertia::Exact, "sphere").0
    });
    assert!(e < 1e-3);
    let e = assert_second_order("spherical shell mesh I/(m a²) = 2/3", &NS, 2.0 / 3.0, |n| {
        let (_, i) = props(&sphere(a, n), MeshInertia::Shell, "sphere");
        i.i_com()[(0, 0)] / (i.mass * a * a)
    });
    assert!(e < 1e-3);
    // Primitives (MuJoCo's formulas) exactly.
    let m = 3.0;
    let sph = primitive_inertia(&Primitive::Sphere { radius: a }, Distribution::Volume, m);
    let err = rel_err_vec(sph.i_com().as_slice(), (Mat3::identity() * (2.0 * m * a * a / 5.0)).as_slice());
    println!("sphere primitive I = 2ma²/5 (eq. 53): rel err {err:.2e}");
    assert!(err <= MASS_EXACT_REL);
}

#[test]
fn rod_disk_and_perpendicular_axis_eq51_eq52_eq54() {
    let m = 2.5;
    // Rod (eq. 51): a cylinder of vanishing radius about a transverse axis, mL²/12.
    let l = 1.7;
    let rod = primitive_inertia(
        &Primitive::Cylinder { radius: 0.0, half_length: l / 2.0 },
        Distribution::Volume,
        m,
    );
    let err = rel_err(rod.i_com()[(0, 0)], m * l * l / 12.0);
    println!("rod I = mL²/12 (eq. 51), cylinder primitive r = 0: rel err {err:.2e}");
    assert!(err <= MASS_EXACT_REL);
    // A thin box mesh approaches it as (w/L)²: I = m(L² + w²)/12 exactly for the box.
    for w in [1e-2, 1e-4] {
        let (_, i) = props(
            &box_mesh(Vec3::new(-l / 2.0, -w / 2.0, -w / 2.0), Vec3::new(l / 2.0, w / 2.0, w / 2.0)),
            MeshInertia::Exact,
            "rod",
        );
        let i_y = i.i_com()[(1, 1)] / i.mass * m;
        let exact_box = m * (l * l + w * w) / 12.0;
        println!(
            "rod as a {w:e}-thick box mesh: vs box formula {:.2e}, vs eq. 51 {:.2e}",
            rel_err(i_y, exact_box),
            rel_err(i_y, m * l * l / 12.0)
        );
        assert!(rel_err(i_y, exact_box) <= MASS_EXACT_REL);
    }
    // Disk (eq. 52): I_z = ma²/2 — a cylinder primitive of any length, and n-gon laminae.
    let a = 0.3;
    let cyl =
        primitive_inertia(&Primitive::Cylinder { radius: a, half_length: 0.1 }, Distribution::Volume, m);
    let err = rel_err(cyl.i_com()[(2, 2)], m * a * a / 2.0);
    println!("disk I = ma²/2 (eq. 52), cylinder primitive: rel err {err:.2e}");
    assert!(err <= MASS_EXACT_REL);
    let e = assert_second_order("disk lamina mesh I_z/(m a²) = 1/2 (eq. 52)", &NS, 0.5, |n| {
        let (_, i) = props(&disk(a, n), MeshInertia::Shell, "disk");
        i.i_com()[(2, 2)] / (i.mass * a * a)
    });
    assert!(e < 1e-3);
    // Perpendicular-axis theorem (eq. 54): I_z = I_x + I_y for any lamina in z = 0, here an
    // irregular star polygon, to round-off; and I_x = ma²/4 for the disk.
    let star: Vec<Vec3> = (0..11)
        .map(|j| {
            let p = 2.0 * PI * j as f64 / 11.0;
            let r = if j % 2 == 0 { 1.0 } else { 0.45 + 0.03 * j as f64 };
            Vec3::new(r * p.cos() + 0.2, r * p.sin() - 0.1, 0.0)
        })
        .collect();
    let (_, i) = props(&fan(Vec3::new(0.2, -0.1, 0.0), &star, true), MeshInertia::Shell, "star");
    let (io, ic) = (i.i_origin, i.i_com());
    let err = rel_err(io[(2, 2)], io[(0, 0)] + io[(1, 1)]).max(rel_err(ic[(2, 2)], ic[(0, 0)] + ic[(1, 1)]));
    println!("perpendicular-axis theorem I_z = I_x + I_y (eq. 54), star lamina: rel err {err:.2e}");
    assert!(err <= MASS_EXACT_REL);
    let (_, i) = props(&disk(a, 4096), MeshInertia::Shell, "disk");
    let err = rel_err(i.i_com()[(0, 0)] / i.mass, a * a / 4.0);
    println!("disk I_x = ma²/4 (from eq. 54), 4096-gon: rel err {err:.2e} (discretization)");
    assert!(err < 1e-5);
}

#[test]
fn square_plate_about_centre_and_corner_section_3_1() {
    // A uniform l × l plate (docs/physics.md §3.1): about its centre (ml²/12) diag(1, 1, 2); about a corner
    // with x, y along the edges (ml²/12) [[4, −3, 0], [−3, 4, 0], [0, 0, 8]].
    let l = 0.8;
    let plate =
        fan(Vec3::zeros(), &[Vec3::new(l, 0.0, 0.0), Vec3::new(l, l, 0.0), Vec3::new(0.0, l, 0.0)], false);
    let (area, i) = props(&plate, MeshInertia::Shell, "plate");
    assert!(rel_err(area, l * l) <= MASS_EXACT_REL);
    let m = i.mass;
    let centre = Mat3::from_diagonal(&Vec3::new(1.0, 1.0, 2.0)) * (m * l * l / 12.0);
    let corner = Mat3::new(4.0, -3.0, 0.0, -3.0, 4.0, 0.0, 0.0, 0.0, 8.0) * (m * l * l / 12.0);
    let e1 = rel_err_vec(i.i_com().as_slice(), centre.as_slice());
    let e2 = rel_err_vec(i.i_origin.as_slice(), corner.as_slice());
    // The same through the parallel-axis theorem (eq. 56) from the centre.
    let shifted = parallel_axis(&centre, m, &Vec3::new(-l / 2.0, -l / 2.0, 0.0));
    let e3 = rel_err_vec(shifted.as_slice(), corner.as_slice());
    println!("square plate about its centre (§3.1): rel err {e1:.2e}; about a corner: {e2:.2e}; parallel-axis shift (eq. 56): {e3:.2e}");
    assert!(e1.max(e2).max(e3) <= MASS_EXACT_REL);
}

#[test]
fn principal_axis_angle_eq83() {
    // A rectangular a × b lamina turned by θ₀ about z: eq. 83 gives back θ₀ (up to the quarter
    // turn that swaps the two in-plane axes), and principal_axes finds the same axes.
    let (a, b) = (1.0, 0.4);
    let mut worst: f64 = 0.0;
    for k in 0..12 {
        let theta0 = -1.4 + 0.25 * k as f64;
        let rect = box_mesh(Vec3::new(-a / 2.0, -b / 2.0, 0.0), Vec3::new(a / 2.0, b / 2.0, 0.0));
        // Keep only the bottom face (z = 0): a lamina.
        let lamina =
            TriangleMesh { vertices: rect.vertices.clone(), triangles: rect.triangles[..2].to_vec() };
        let x = Transform::new(
            nalgebra::Rotation3::from_axis_angle(&Vec3::z_axis(), theta0).into_inner(),
            Vec3::zeros(),
        );
        let (_, i) = props(&lamina.transformed(&x), MeshInertia::Shell, "rectangle");
        let t = i.i_com();
        let theta = principal_angle_xy(t[(0, 0)], t[(1, 1)], t[(0, 1)]);
        // tan 2θ = 2 I_xy / (I_xx − I_yy) holds for θ (eq. 83).
        let lhs = (2.0 * theta).tan();
        let rhs = 2.0 * t[(0, 1)] / (t[(0, 0)] - t[(1, 1)]);
        // The larger in-plane moment is about the rectangle's short axis, at θ₀ ± π/2.
        let d = (theta - theta0 - PI / 2.0).rem_euclid(PI);
        let angle_err = d.min(PI - d);
        let (moments, axes) = principal_axes(&t);
        let e_mid = axes.column(1).into_owned(); // I₂: the larger in-plane moment (I₃ is about z)
        let axis_err = 1.0 - e_mid.dot(&Vec3::new(theta.cos(), theta.sin(), 0.0)).abs();
        let moment_err = rel_err(moments.y, i.mass * a * a / 12.0);
        worst = worst.max(angle_err).max(axis_err).max(moment_err).max(((lhs - rhs) / rhs).abs().min(1.0));
        assert!(
            angle_err < 1e-12 && axis_err < 1e-12 && moment_err <= MASS_EXACT_REL,
            "θ₀ = {theta0}: θ = {theta}"
        );
    }
    println!(
        "principal-axis angle tan 2θ = 2I_xy/(I_xx − I_yy) (eq. 83), 12 angles: worst error {worst:.2e}"
    );
}

// ------------------------------------------------------------------------------------------------
// Exact polyhedra and primitives
// ------------------------------------------------------------------------------------------------

#[test]
fn polyhedra_are_exact_and_match_primitive_formulas() {
    // A box mesh is its own polyhedron: every mode gives the box formulas to round-off.
    let h = Vec3::new(0.3, 0.2, 0.05);
    let bx = box_mesh(-h, h);
    let p = Primitive::Box { half_extents: h };
    let mut worst: f64 = 0.0;
    for mode in ALL_MODES {
        let d = if mode == MeshInertia::Shell { Distribution::Shell } else { Distribution::Volume };
        let (measure, i) = props(&bx, mode, "box");
        let exact = primitive_inertia(&p, d, measure);
        let e = rel_err(measure, primitive_measure(&p, d))
            .max(rel_err_vec(i.i_com().as_slice(), exact.i_com().as_slice()))
            .max(i.com().amax() / h.amax());
        worst = worst.max(e);
        assert!(e <= MASS_EXACT_REL, "{mode:?}: {e:.2e}");
    }
    println!("box mesh vs box primitive, all four modes: worst rel err {worst:.2e}");
    // Curved primitives: the meshes converge to MuJoCo's closed forms.
    let (r, hl) = (0.05, 0.2);
    let e = assert_second_order(
        "cylinder mesh vs cylinder primitive (I_xx)",
        &NS,
        {
            let c = Primitive::Cylinder { radius: r, half_length: hl };
            primitive_inertia(&c, Distribution::Volume, 1.0).i_com()[(0, 0)]
        },
        |n| {
            let (_, i) = props(&cylinder(r, 2.0 * hl, 4 * n), MeshInertia::Exact, "cylinder");
            i.i_com()[(0, 0)] / i.mass
        },
    );
    assert!(e < 1e-3);
    let c = Primitive::Cylinder { radius: r, half_length: hl };
    let e = assert_second_order(
        "cylinder shell mesh vs primitive (I_xx / m)",
        &NS,
        primitive_inertia(&c, Distribution::Shell, 1.0).i_com()[(0, 0)],
        |n| {
            let (_, i) = props(&cylinder(r, 2.0 * hl, 4 * n), MeshInertia::Shell, "cylinder");
            i.i_com()[(0, 0)] / i.mass
        },
    );
    assert!(e < 1e-3);
    let cap = Primitive::Capsule { radius: r, half_length: hl };
    for (d, mode, label) in [
        (Distribution::Volume, MeshInertia::Exact, "capsule mesh vs primitive (I_xx / m)"),
        (Distribution::Shell, MeshInertia::Shell, "capsule shell mesh vs primitive (I_xx / m)"),
    ] {
        let e = assert_second_order(label, &NS, primitive_inertia(&cap, d, 1.0).i_com()[(0, 0)], |n| {
            let (_, i) = props(&capsule(r, hl, n), mode, "capsule");
            i.i_com()[(0, 0)] / i.mass
        });
        assert!(e < 1e-3);
        let e = assert_second_order(
            &format!("{} measure", label.split(" vs").next().unwrap()),
            &NS,
            primitive_measure(&cap, d),
            |n| props(&capsule(r, hl, n), mode, "capsule").0,
        );
        assert!(e < 1e-3);
    }
    let radii = Vec3::new(0.3, 0.2, 0.1);
    let e = assert_second_order(
        "ellipsoid (scaled sphere mesh) vs primitive (I_yy)",
        &NS,
        primitive_inertia(&Primitive::Ellipsoid { radii }, Distribution::Volume, 1.0).i_com()[(1, 1)],
        |n| {
            let (_, i) = props(&scaled(sphere(1.0, n), radii), MeshInertia::Exact, "ellipsoid");
            i.i_com()[(1, 1)] / i.mass
        },
    );
    assert!(e < 1e-3);
}

#[test]
fn exact_legacy_and_convex_differ_as_documented() {
    // A U-shaped (non-convex) prism whose centroid lies in its notch: exact = its volume 7 and the
    // sum of its three boxes; convex = its hull, the 3 × 3 × 1 block; legacy > exact (|V| of the
    // tetrahedra that reach across the notch are added, not cancelled).
    let u = prism(
        &[[0.0, 0.0], [3.0, 0.0], [3.0, 3.0], [2.0, 3.0], [2.0, 1.0], [1.0, 1.0], [1.0, 3.0], [0.0, 3.0]],
        &[[0, 1, 4], [0, 4, 5], [4, 1, 2], [4, 2, 3], [0, 5, 6], [0, 6, 7]],
        1.0,
    );
    let parts = [
        box_mesh(Vec3::zeros(), Vec3::new(3.0, 1.0, 1.0)),
        box_mesh(Vec3::new(0.0, 1.0, 0.0), Vec3::new(1.0, 3.0, 1.0)),
        box_mesh(Vec3::new(2.0, 1.0, 0.0), Vec3::new(3.0, 3.0, 1.0)),
    ];
    let (ve, ie) = props(&u, MeshInertia::Exact, "U");
    let (vc, _) = props(&u, MeshInertia::Convex, "U");
    let (vl, il) = props(&u, MeshInertia::Legacy, "U");
    let inertias: Vec<RigidInertia> = parts.iter().map(|p| props(p, MeshInertia::Exact, "box").1).collect();
    let id = Transform::identity();
    let sum = compose(inertias.iter().map(|i| (&id, i)));
    let e = rel_err(ve, 7.0).max(rel_err_vec(ie.i_origin.as_slice(), sum.i_origin.as_slice()));
    println!("U-shape: exact {ve} (= 7, rel err {e:.1e} with its boxes composed), convex {vc} (= 9), legacy {vl:.6} (com y {:.4} vs {:.4})", il.com().y, ie.com().y);
    assert!(e <= MASS_EXACT_REL);
    assert!(rel_err(vc, 9.0) <= MASS_EXACT_REL);
    assert!(vl > ve * 1.01, "legacy overcounts a body that is not star-shaped about its centroid");
    let l = u;
    // The hull is closed and outward: its exact volume is its convex volume.
    let hull = convex_hull(&l.vertices).unwrap();
    assert!(rel_err(hull.signed_volume(), 9.0) <= MASS_EXACT_REL);
    assert!(hull.topology().is_closed_oriented());
}

// ------------------------------------------------------------------------------------------------
// Transformations, scale, composition
// ------------------------------------------------------------------------------------------------

#[test]
fn moved_mesh_gives_transformed_properties() {
    // A real, asymmetric mesh (Barkour's upper leg, 2.7k triangles) in every mode, moved by random
    // rigid transformations: the properties of the moved mesh are the moved properties (docs/physics.md
    // (56) for the shift, §3.2 for the rotation, through RigidInertia::transformed).
    let mesh = read_mesh(&mesh_file("mujoco/google_barkour_vb/upper_leg.stl"), &Vec3::repeat(1.0)).unwrap();
    let size = mesh.diameter();
    let mut rng = common::rng(4242);
    let mut worst = [0.0f64; 3];
    for k in 0..8 {
        let x = Transform::new(common::random_rotation(&mut rng), common::random_vec3(&mut rng, 2.0));
        let moved = mesh.transformed(&x);
        for mode in ALL_MODES {
            let (v0, i0) = props(&mesh, mode, "leg");
            let (v1, i1) = props(&moved, mode, "moved leg");
            let expected = i0.transformed(&x);
            let e_mass = rel_err(v1, v0);
            let e_com = (i1.com() - expected.com()).amax() / size;
            let e_i = rel_err_vec(i1.i_com().as_slice(), expected.i_com().as_slice());
            worst = [worst[0].max(e_mass), worst[1].max(e_com), worst[2].max(e_i)];
            assert!(
                e_mass.max(e_com).max(e_i) <= MESH_TRANSFORM_REL,
                "transform {k}, {mode:?}: mass {e_mass:.2e}, com {e_com:.2e}, inertia {e_i:.2e}"
            );
        }
    }
    println!(
        "moved mesh (8 random poses x 4 modes): rel err mass {:.2e}, com {:.2e} (of the size), inertia about the com {:.2e}",
        worst[0], worst[1], worst[2]
    );
    // Composition (sum rule under eq. 50): a body of two geoms = the two placed inertias.
    let x1 = Transform::new(common::random_rotation(&mut rng), Vec3::new(0.1, 0.0, 0.0));
    let x2 = Transform::new(common::random_rotation(&mut rng), Vec3::new(-0.2, 0.3, 0.0));
    let (_, i0) = props(&mesh, MeshInertia::Exact, "leg");
    let body = compose([(&x1, &i0), (&x2, &i0)]);
    let mut both = mesh.transformed(&x1);
    let off = both.vertices.len() as u32;
    let m2 = mesh.transformed(&x2);
    both.vertices.extend(&m2.vertices);
    both.triangles.extend(m2.triangles.iter().map(|t| t.map(|i| i + off)));
    let (_, ib) = props(&both, MeshInertia::Exact, "two legs");
    let e = rel_err_vec(ib.i_origin.as_slice(), body.i_origin.as_slice()).max(rel_err(ib.mass, body.mass));
    println!("two geoms composed into one body vs one mesh holding both: rel err {e:.2e}");
    assert!(e <= MESH_TRANSFORM_REL);
}

#[test]
fn scale_and_mirror() {
    // Non-uniform scale of the unit cube file: a 2 × 3 × 4 box.
    let s = Vec3::new(2.0, 3.0, 4.0);
    let m = read_mesh(&mesh_file("cube_binary.stl"), &s).unwrap();
    let (v, i) = props(&m, MeshInertia::Exact, "scaled cube");
    let expected = primitive_inertia(&Primitive::Box { half_extents: s / 2.0 }, Distribution::Volume, 24.0);
    assert!(rel_err(v, 24.0) <= MASS_EXACT_REL);
    assert!(rel_err_vec(i.i_com().as_slice(), expected.i_com().as_slice()) <= MASS_EXACT_REL);
    assert!(rel_err_vec(i.com().as_slice(), (s / 2.0).as_slice()) <= MASS_EXACT_REL);
    // A mirroring scale keeps the volume positive (windings reversed, as MuJoCo does) and
    // mirrors the centre of mass and the products of inertia.
    let leg = mesh_file("mujoco/google_barkour_vb/upper_leg.stl");
    let plain = read_mesh(&leg, &Vec3::repeat(1.0)).unwrap();
    let mirrored = read_mesh(&leg, &Vec3::new(1.0, -1.0, 1.0)).unwrap();
    let flip = Mat3::from_diagonal(&Vec3::new(1.0, -1.0, 1.0));
    for mode in ALL_MODES {
        let (v0, i0) = props(&plain, mode, "leg");
        let (v1, i1) = props(&mirrored, mode, "mirrored leg");
        assert!(v1 > 0.0 && rel_err(v0, v1) <= MASS_EXACT_REL, "{mode:?}");
        assert!(rel_err_vec((flip * i0.com()).as_slice(), i1.com().as_slice()) <= MASS_EXACT_REL, "{mode:?}");
        assert!(
            rel_err_vec((flip * i0.i_com() * flip).as_slice(), i1.i_com().as_slice()) <= MASS_EXACT_REL,
            "{mode:?}"
        );
    }
    println!("scale (2, 3, 4) and mirror (1, −1, 1): exact to {MASS_EXACT_REL:.0e}");
}

#[test]
fn tensor_algebra() {
    let mut rng = common::rng(7);
    for _ in 0..50 {
        // Random physical tensor, random rotation.
        let r = common::random_rotation(&mut rng);
        let d = Vec3::new(rng_f(&mut rng, 0.1, 1.0), rng_f(&mut rng, 0.1, 1.0), 0.0);
        let d = Vec3::new(d.x, d.y, rng_f(&mut rng, (d.x - d.y).abs() + 0.01, d.x + d.y));
        let t = rotate_tensor(&r, &Mat3::from_diagonal(&d));
        let (moments, axes) = principal_axes(&t);
        // Ascending, right-handed, reconstructs the tensor, sign convention.
        assert!(moments.x <= moments.y && moments.y <= moments.z);
        assert!((axes.determinant() - 1.0).abs() < 1e-12);
        let back = axes * Mat3::from_diagonal(&moments) * axes.transpose();
        assert!(rel_err_vec(back.as_slice(), t.as_slice()) < 1e-13);
        for c in 0..2 {
            let col = axes.column(c);
            let k = (0..3).max_by(|&a, &b| col[a].abs().total_cmp(&col[b].abs())).unwrap();
            assert!(col[k] > 0.0);
        }
        // Deterministic: the same input gives bit-identical output.
        assert_eq!(principal_axes(&t), (moments, axes));
        // Parallel-axis (eq. 56) agrees with RigidInertia's shift.
        let c = common::random_vec3(&mut rng, 1.0);
        let m = 2.0;
        let body = RigidInertia::from_com(m, c, t);
        assert!(rel_err_vec(parallel_axis(&t, m, &c).as_slice(), body.i_origin.as_slice()) < 1e-14);
    }
}

fn rng_f(rng: &mut impl rand::Rng, lo: f64, hi: f64) -> f64 {
    rng.random_range(lo..=hi)
}

// ------------------------------------------------------------------------------------------------
// File formats
// ------------------------------------------------------------------------------------------------

#[test]
fn every_format_reads_the_unit_cube() {
    let one = Vec3::repeat(1.0);
    let reference = props(&box_mesh(Vec3::zeros(), one), MeshInertia::Exact, "cube").1;
    for name in ["cube.obj", "cube_ascii.stl", "cube_binary.stl", "cube.msh", "two_objects.obj"] {
        let m = read_mesh(&mesh_file(name), &one).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(m.triangles.len(), 12, "{name}");
        assert!(m.topology().is_closed_oriented(), "{name}");
        for mode in ALL_MODES {
            let (v, i) = props(&m, mode, name);
            // two_objects.obj: MuJoCo keeps the faces of the first object but every vertex, and
            // its convex mode takes the hull of all vertices: both cubes and the gap, volume 3.
            if name == "two_objects.obj" && mode == MeshInertia::Convex {
                assert!(rel_err(v, 3.0) <= MASS_EXACT_REL, "{v}");
                continue;
            }
            let expected = if mode == MeshInertia::Shell { 6.0 } else { 1.0 };
            assert!(rel_err(v, expected) <= MASS_EXACT_REL, "{name} {mode:?}: {v}");
            if mode != MeshInertia::Shell {
                assert!(
                    rel_err_vec(i.i_origin.as_slice(), reference.i_origin.as_slice()) <= MASS_EXACT_REL,
                    "{name}"
                );
            }
        }
    }
    // MuJoCo keeps the first object of an OBJ file; ObjObjects::All reads both cubes.
    let all =
        read_mesh_with(&mesh_file("two_objects.obj"), &one, &ReadOptions { obj_objects: ObjObjects::All })
            .unwrap();
    let (v, i) = props(&all, MeshInertia::Exact, "two cubes");
    assert!(rel_err(v, 2.0) <= MASS_EXACT_REL && rel_err(i.com().x, 1.5) <= MASS_EXACT_REL);
    // The T-junction box is combinatorially open but encloses its volume exactly: accepted.
    let tj = read_mesh(&mesh_file("tjunction_box.stl"), &one).unwrap();
    let topo = tj.topology();
    assert!(topo.boundary_edges == 6 && topo.hole_area == 0.0, "{topo:?}");
    for mode in [MeshInertia::Exact, MeshInertia::Legacy] {
        let (v, i) = props(&tj, mode, "T-junction box");
        assert!(rel_err(v, 2.0) <= MASS_EXACT_REL && rel_err(i.com().x, 1.0) <= MASS_EXACT_REL, "{mode:?}");
    }
}

/// Asserts that `result` is an error whose message contains every one of `needles`, and prints it.
fn assert_error<T: std::fmt::Debug>(what: &str, result: Result<T, MeshError>, needles: &[&str]) -> MeshError {
    let e = result.expect_err(what);
    let msg = e.to_string();
    println!("{what}: {msg}");
    for n in needles {
        assert!(msg.contains(n), "{what}: message lacks {n:?}: {msg}");
    }
    e
}

#[test]
fn broken_meshes_name_the_defect_and_the_fix() {
    let one = Vec3::repeat(1.0);
    let read = |name: &str| read_mesh(&mesh_file(name), &one);
    let solid = |name: &str, mode| mesh_inertia(&read(name).unwrap(), mode);
    const INERTIAL: &str = "explicit <inertial>";

    // Open: refused for solids in exact and legacy mode, fine as a shell or a hull.
    for mode in [MeshInertia::Exact, MeshInertia::Legacy] {
        let e = assert_error(
            "open cube",
            solid("open_cube.stl", mode),
            &["not closed", "4 boundary edge", "1 hole", "inertia=\"shell\"", "inertia=\"convex\"", INERTIAL],
        );
        assert!(matches!(e, MeshError::Open { edges: 4, holes: 1, .. }));
    }
    assert!(
        solid("open_cube.stl", MeshInertia::Shell).is_ok()
            && solid("open_cube.stl", MeshInertia::Convex).is_ok()
    );

    // One triangle wound the wrong way: exact refuses, legacy's |V| absorbs it (MuJoCo's purpose
    // for that mode), giving the cube.
    assert_error(
        "misoriented cube",
        solid("misoriented_cube.obj", MeshInertia::Exact),
        &["not consistently oriented", "same direction", "inertia=\"legacy\"", INERTIAL],
    );
    let (v, _) = solid("misoriented_cube.obj", MeshInertia::Legacy).unwrap();
    assert!(rel_err(v, 1.0) <= MASS_EXACT_REL);

    // Inside out: never flipped silently, in any solid mode.
    for mode in [MeshInertia::Exact, MeshInertia::Legacy] {
        let e = assert_error(
            "inside-out cube",
            solid("inside_out_cube.stl", mode),
            &["negative", "inside-out", "reverse the winding", INERTIAL],
        );
        assert!(matches!(e, MeshError::NegativeVolume { volume } if (volume + 1.0).abs() < 1e-12));
    }

    // Zero volume (a closed but flat surface): suggest the shell.
    for mode in [MeshInertia::Exact, MeshInertia::Legacy] {
        assert_error(
            "flat square",
            solid("flat_square.obj", mode),
            &["too small", "flat", "inertia=\"shell\"", INERTIAL],
        );
    }
    assert_error(
        "flat square hull",
        solid("flat_square.obj", MeshInertia::Convex),
        &["convex hull", "one plane"],
    );
    let (area, _) = solid("flat_square.obj", MeshInertia::Shell).unwrap();
    assert!(rel_err(area, 2.0) <= MASS_EXACT_REL);

    // Degenerate: zero area; too few vertices.
    for mode in ALL_MODES {
        assert_error("collinear", solid("collinear.obj", mode), &["surface area", "degenerate", INERTIAL]);
        assert_error(
            "three vertices",
            solid("three_vertices.obj", mode),
            &["3 vertices", "at least 4", INERTIAL],
        );
    }

    // Unreadable files: the format, the line when there is one, what is wrong.
    assert_error("bad index", read("bad_index.obj"), &["OBJ", "line 20", "vertex 9", "8 vertices"]);
    assert_error("truncated", read("truncated.stl"), &["STL", "truncated", "664 bytes", "12 triangles"]);
    assert_error("garbage", read("garbage.stl"), &["STL", "'solid'"]);
    assert_error("collada", read("cube.dae"), &["'.dae'", "not supported", "STL", "OBJ", INERTIAL]);
    assert_error("missing", read("no_such_mesh.stl"), &["cannot be read"]);
    assert_error(
        "bad scale",
        read_mesh(&mesh_file("cube.obj"), &Vec3::new(1.0, f64::NAN, 1.0)),
        &["scale", "not finite"],
    );

    // In-memory defects: non-finite vertices, indices out of range.
    let mut m = box_mesh(Vec3::zeros(), one);
    m.vertices[3].y = f64::INFINITY;
    assert_error("infinite vertex", mesh_inertia(&m, MeshInertia::Exact), &["vertex 3", "non-finite"]);
    let mut m = box_mesh(Vec3::zeros(), one);
    m.triangles[5][1] = 99;
    assert_error(
        "index out of range",
        mesh_inertia(&m, MeshInertia::Exact),
        &["triangle 5", "vertex 99", "8 vertices"],
    );
}

#[test]
fn mesh_without_triangles_uses_its_hull() {
    // MuJoCo measures a vertex-only mesh through its convex hull, in every mode.
    let cloud =
        TriangleMesh { vertices: box_mesh(Vec3::zeros(), Vec3::repeat(1.0)).vertices, triangles: vec![] };
    for mode in ALL_MODES {
        let (v, i) = props(&cloud, mode, "vertex cloud");
        let expected = if mode == MeshInertia::Shell { 6.0 } else { 1.0 };
        assert!(
            rel_err(v, expected) <= MASS_EXACT_REL && rel_err(i.com().z, 0.5) <= MASS_EXACT_REL,
            "{mode:?}"
        );
    }
}

#[test]
fn exact_mode_agrees_with_parry() {
    // An independent implementation of the same integrals: parry3d-f64's
    // MassProperties::from_trimesh (signed tetrahedra about the vertex mean) on closed meshes.
    // Compared: mass, centre of mass, the trace of the tensor and, where they are distinct, the
    // principal moments. Not compared: parry 0.31.1's principal frame, which its eigen-solver
    // leaves unconverged for small tensors (an absolute tolerance: Barkour's upper leg at unit
    // density, I ~ 3e-7, comes back with its x and z axes swapped, correct once scaled by 1e3;
    // MuJoCo agrees with ours to 5e-8), and repeated moments, which it splits by ~5e-9. Nor does parry refuse an
    // inside-out mesh: it flips the sign silently, which is why lagrange integrates itself.
    use parry3d_f64::mass_properties::MassProperties;
    use parry3d_f64::math::Vector;
    let mut cases: Vec<(String, TriangleMesh)> = vec![
        ("sphere n=32".into(), sphere(0.3, 32)),
        ("solid hemisphere n=32".into(), solid_hemisphere(0.3, 32)),
        ("capsule n=16".into(), capsule(0.05, 0.2, 16)),
    ];
    for f in [
        "mujoco/google_barkour_vb/upper_leg.stl",
        "mujoco/dm_control/BONETibia_L.stl",
        "mujoco/franka_emika_panda/link0_11.obj",
    ] {
        cases.push((f.into(), read_mesh(&mesh_file(f), &Vec3::repeat(1.0)).unwrap()));
    }
    let mut worst: f64 = 0.0;
    for (name, m) in &cases {
        let (v, i) = props(m, MeshInertia::Exact, name);
        let pts: Vec<Vector> = m.vertices.iter().map(|p| Vector::new(p.x, p.y, p.z)).collect();
        let mp = MassProperties::from_trimesh(1.0, &pts, &m.triangles);
        let c = mp.local_com;
        let pm = mp.principal_inertia();
        let mut theirs = [pm.x, pm.y, pm.z];
        theirs.sort_by(f64::total_cmp);
        let (ours, _) = principal_axes(&i.i_com());
        let e_m = rel_err(v, mp.mass());
        let e_c = (i.com() - Vec3::new(c.x, c.y, c.z)).amax() / m.diameter();
        let e_t = rel_err(ours.sum(), theirs.iter().sum());
        let distinct = (ours.y - ours.x).min(ours.z - ours.y) > 1e-6 * ours.z;
        let e_p = if distinct { rel_err_vec(ours.as_slice(), &theirs) } else { 0.0 };
        println!(
            "exact mode vs parry, {name}: mass {e_m:.1e}, com {e_c:.1e}, trace {e_t:.1e}, moments {}",
            if distinct { format!("{e_p:.1e}") } else { "(repeated, not compared)".into() }
        );
        worst = worst.max(e_m).max(e_c).max(e_t).max(e_p);
    }
    assert!(worst <= MASS_EXACT_REL, "worst {worst:.2e}");
}
