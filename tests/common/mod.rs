//! Shared by the integration tests: the tolerances (the ONLY place they live), the relative-error
//! definition, a random kinematic-tree generator covering every joint type, random states, and
//! loading the shipped robots.
//!
//! Each test binary uses a different subset of these helpers, hence the `dead_code` allowance.
#![allow(dead_code)]

pub mod contact_scenes;

use lagrange::integrate::{IntegratorKind, State};
use lagrange::io::compile;
use lagrange::io::{load, LoadOptions};
use lagrange::model::spec::{InertialSpec, JointSpec, JointType, LinkSpec, ModelSpec};
use lagrange::model::{JointKind, SourceLoc};
use lagrange::sim::{SimOptions, Simulation};
use lagrange::spatial::{quat_to_matrix, Mat3, Transform, Vec3};
use lagrange::{Data, Model};
use nalgebra::DMatrix;
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};
use std::f64::consts::PI;
use std::path::PathBuf;
use std::sync::Arc;

// ------------------------------------------------------------------------------------------------
// Tolerances
// ------------------------------------------------------------------------------------------------

/// Relative tolerance of algorithm-against-algorithm checks (ABA vs. M⁻¹(τ − c), RNEA∘ABA = id,
/// Jacobian·v vs. propagated velocities, energy and momentum balances). Every quantity is computed
/// in f64 by two routes that differ only by the order of round-off, so the norm-wise relative
/// difference is a small multiple of ε = 2.2e-16 times the condition of the problem. 1e-12 leaves
/// ~4500 ε for the accumulation over trees of up to ~30 bodies and for cond(M) of the random
/// trees and robots (the ABA/solve comparison is the most sensitive one; see the printout).
pub const ALGO_REL: f64 = 1e-12;

/// Relative tolerance against reference data (Pinocchio golden files). The references are
/// themselves f64 round-off accurate; the DESIGN target is 1e-9 relative on M, bias, ABA, poses.
pub const REF_REL: f64 = 1e-9;

/// Base step of the finite differences on the configuration manifold (see [`FD_REL`]).
pub const FD_STEP: f64 = 1e-3;

/// Relative tolerance of Jacobians against finite differences of forward kinematics.
///
/// The derivative is the Richardson extrapolation `(4 D(h/2) − D(h)) / 3` of central differences
/// `D(h) = (f(q ⊕ h eₖ) − f(q ⊕ −h eₖ)) / 2h`, with `h` = [`FD_STEP`] = 1e-3. `D` is even in `h`
/// (true also for the rotation part, `log(R₊R₋ᵀ)/2h`), so the extrapolation cancels the h² term:
/// - truncation: `h⁴/480 · |f⁽⁵⁾|` ≈ 2e-15 for the O(1)–O(10) derivatives of rotations about unit
///   axes at lever arms of at most a few metres;
/// - round-off: each forward-kinematics evaluation carries ≈ κ ε |f| with κ ≲ 30 (the depth of the
///   chain), and the extrapolation weights sum to 3/h, giving ≈ 3 κ ε |f| / h ≈ 2e-11 · |f| with
///   |f| ≲ 5 m.
///
/// The two add up to ≲ 1e-10 of the Jacobian's scale; the tolerance keeps a factor 10 above that.
pub const FD_REL: f64 = 1e-9;

/// Band for measured convergence orders of time integrators (used by `tests/physics.rs`): when dt
/// halves, an order-p method's error must shrink by a ratio within `[2ᵖ / BAND, 2ᵖ · BAND]`. The
/// asymptotic ratio is exactly 2ᵖ; at the step sizes used the next term of the error expansion is
/// a few per cent of the leading one (measured RK4 ratios 14.4–15.7 for 16, Euler 2.00 and 4.00), and
/// 1.25 keeps neighbouring orders well apart (2ᵖ·1.25 < 2ᵖ⁺¹/1.25).
pub const INTEGRATOR_ORDER_BAND: f64 = 1.25;

/// `lagrange workprec` on the double pendulum (`tests/workprec.rs`): the least-squares slope of
/// log(error) against log(dt) must lie within this distance of the method's order (measured:
/// RK4 4.04, Euler 1.01 over dt = 8, 4, 2, 1 ms).
pub const WORKPREC_SLOPE_TOL: f64 = 0.25;

/// Global error of the adaptive Dormand–Prince 5(4) stepper over 0.5 s of the quaternion cases
/// of `tests/integrator_order.rs`, in units of the requested rtol (local error control does not
/// bound the global error; it accumulates over the steps and through the dynamics' sensitivity).
pub const ADAPTIVE_TOL_FACTOR: f64 = 100.0;

/// Relative error of the small-amplitude period of the physical pendulum (docs/physics.md (59)) measured
/// from an RK4 run of 4000 steps per period (`tests/physics.rs`). Model errors: the amplitude
/// correction θ₀²/16 = 6.25e-12 at θ₀ = 1e-5 (eq. 59 is its limit θ₀ → 0); RK4's phase error
/// ≈ (ω dt)⁴/120 ≈ 5e-14 for ω dt = 2π/4000. Measured 6.3e-12 (the amplitude term); 1e-10 leaves a
/// factor ~15 over the sum.
pub const PERIOD_SMALL_AMPLITUDE_REL: f64 = 1e-10;

/// Drift of a conserved quantity along an RK4 trajectory (`tests/physics.rs`: the cyclic momentum
/// of the pendulum on a movable support over 5 s at dt = 1e-3), relative to its scale. RK4's
/// global error is ≈ T·ω⁵dt⁴/120 ≈ 4e-11 for ω ≈ 4 rad/s (measured 2.6e-12); 1e-9 bounds it with a
/// margin of 25 over the estimate, while a first-order error (≈ ω² dt ≈ 1e-2) would fail by far.
pub const RK4_CONSERVATION_REL: f64 = 1e-9;

/// Soft (MuJoCo-compatible) constraints against MuJoCo's `mj_forward` (`tests/soft.rs`,
/// 1e-6): both sides minimize the same strictly convex cost, MuJoCo's Newton stopping at its
/// tolerance (set to 1e-15 in the golden data's copy of the model). Measured on the go1, humanoid,
/// box and weld scenes: qacc ≤ 1e-9 and forces ≤ 1e-8 of their scale (the elliptic cones with
/// impratio 100 of go1 are the worst conditioned); 1e-6 keeps a margin of 100.
pub const SOFT_REL: f64 = 1e-6;

/// The inside wrap of a spatial tendon (side site inside the geom) against MuJoCo 4.0: its contact
/// point comes from a Newton solve that stops at MuJoCo's tolerance (1e-6 on the angle equation),
/// and MuJoCo 4.0's iterates differ from lagrange's in the last steps: the point and the tendon's
/// Jacobian agree to ~2e-7 relative (its length, stationary in the point, to 1e-14).
#[allow(dead_code)]
pub const INSIDE_WRAP_REL: f64 = 1e-6;

/// CG against MuJoCo's Newton optimum (`tests/soft.rs`): CG stops when its cost stagnates at
/// round-off, which on go1's elliptic cones with impratio 100 is still ~1e-6 of the force scale
/// from the optimum — MuJoCo 4.0's own CG (same tight options, the golden states) stops 6.1e-7
/// from its Newton's solution, lagrange's 4.5e-7 to 1.3e-6 depending on the last bits of the
/// kinematics; 5e-6 is eight times MuJoCo's own gap. More iterations change nothing (measured up
/// to 10000: CG stops on stagnation, not on the iteration limit).
pub const SOFT_CG_REL: f64 = 5e-6;

/// Relative tolerance of mesh mass properties against MuJoCo (`tests/mujoco_meshes.rs`,
/// 1e-6). Both sides integrate the same polyhedron in f64 by the same decomposition
/// (`mjCMesh::ComputeVolume`/`ComputeInertia`), so binary STL meshes agree to the round-off of sums
/// over up to 2e5 triangles (~1e-12); MuJoCo reads OBJ coordinates as f32 where we keep f64, a
/// relative perturbation of ≤ 6e-8 per coordinate that moves masses and tensors by up to a few
/// 1e-7. 1e-6 bounds that with a margin; a wrong formula or mode errs by ≥ 1e-3.
pub const MESH_MUJOCO_REL: f64 = 1e-6;

/// Absolute tolerance (m) of a built-in mesh's hull-vertex distances from its centre of mass
/// against MuJoCo's compiled `mesh_vert` (`tests/mesh_builtin_mujoco.rs`). Both sides generate the
/// same f32 vertices; MuJoCo then stores the recentred, rotated vertices as f32 again, a rounding
/// of ≤ 6e-8 relative on coordinates of ≤ 0.1 m, so ~1e-8 m; 1e-7 m bounds it with margin, where
/// a wrong generator errs by ≥ 1e-4 m.
pub const BUILTIN_HULL_ABS: f64 = 1e-7;

/// Relative tolerance of mass properties that are exact in f64 (`tests/mass.rs`): a polyhedron
/// (box, L-shape, plate, T-junction box) against its closed form, a primitive formula against the
/// notes (eq. 51–53), identities such as the perpendicular-axis theorem (eq. 54). The only error is
/// the round-off of sums over at most a few thousand triangles, a few hundred ε.
pub const MASS_EXACT_REL: f64 = 1e-12;

/// Band for the measured convergence order of meshes inscribed in curved bodies
/// (`tests/mass.rs`): when the resolution doubles the error of a second-order approximation must
/// shrink by a ratio in `[4 / BAND, 4 · BAND]`. Measured ratios at n = 32 → 64 → 128 are within
/// 1 % of 4; 1.1 keeps first (2) and third (8) order far outside.
pub const MESH_ORDER_BAND: f64 = 1.1;

/// Relative tolerance of a mesh moved by a rigid transformation against the moved mass
/// properties (`tests/mass.rs`, translations up to 2 m of a 0.2 m part). Moving the vertices
/// rounds each coordinate to ε·2 m, i.e. 1e-15 of 2 m but 1e-14 of the part's size; the centre of
/// mass and the tensor about it inherit that, amplified by the cancellation in I_com = I_O − m[c]×²
/// for offsets 10× the part. Measured ≤ 1e-12; 1e-10 leaves a factor 100.
pub const MESH_TRANSFORM_REL: f64 = 1e-10;

/// Floor of the denominator of the relative error: only there to turn 0/0 (two exactly-zero
/// quantities, e.g. the Jacobian of a frame welded to the world) into 0. It is far below any
/// physical magnitude, so it never hides a real discrepancy.
pub const REL_FLOOR: f64 = 1e-300;

/// The absolute floor under a sensor's scale (tests/sensors.rs): sensors read quantities of order
/// one (m, rad, N, m/s); values below 1e-12 are the round-off of such quantities (a joint
/// velocity of 1e-17 where the reference has 0), not a difference.
pub const SENSOR_ABS_FLOOR: f64 = 1e-12;

// ------------------------------------------------------------------------------------------------
// Relative errors
// ------------------------------------------------------------------------------------------------

/// Norm-wise relative error `‖a − b‖_∞ / max(‖a‖_∞, ‖b‖_∞, REL_FLOOR)` and the index where
/// `|a − b|` is largest.
pub fn rel_err_vec_at(a: &[f64], b: &[f64]) -> (f64, usize) {
    assert_eq!(a.len(), b.len(), "rel_err_vec: lengths differ");
    let mut diff = 0.0;
    let mut at = 0;
    let mut scale = REL_FLOOR;
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        let d = (x - y).abs();
        // NaN compares false: make it win so that it is reported.
        if d > diff || (d.is_nan() && !diff.is_nan()) {
            diff = d;
            at = i;
        }
        scale = scale.max(x.abs()).max(y.abs());
    }
    (diff / scale, at)
}

/// Norm-wise relative error of two vectors (see [`rel_err_vec_at`]).
pub fn rel_err_vec(a: &[f64], b: &[f64]) -> f64 {
    rel_err_vec_at(a, b).0
}

/// Norm-wise relative error of two scalars: `|a − b| / max(|a|, |b|, REL_FLOOR)`.
pub fn rel_err(a: f64, b: f64) -> f64 {
    rel_err_vec(&[a], &[b])
}

/// Norm-wise relative error of two matrices with the max-abs-entry norm, and the (row, column) of
/// the largest entry difference.
/// An n×n matrix from the rows of reference data (JSON), checking its shape.
pub fn matrix(rows: &[Vec<f64>], n: usize) -> DMatrix<f64> {
    assert_eq!(rows.len(), n, "matrix rows");
    assert!(rows.iter().all(|r| r.len() == n), "matrix columns");
    DMatrix::from_fn(n, n, |i, j| rows[i][j])
}

pub fn rel_err_mat_at(a: &DMatrix<f64>, b: &DMatrix<f64>) -> (f64, (usize, usize)) {
    assert_eq!(a.shape(), b.shape(), "rel_err_mat: shapes differ");
    // Column-major storage: index i ↔ (i % nrows, i / nrows).
    let (e, i) = rel_err_vec_at(a.as_slice(), b.as_slice());
    (e, (i % a.nrows().max(1), i / a.nrows().max(1)))
}

/// Norm-wise relative error of two matrices (see [`rel_err_mat_at`]).
pub fn rel_err_mat(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    rel_err_mat_at(a, b).0
}

/// Asserts `rel_err_vec(a, b) ≤ tol`, printing the error and where it is largest; returns it.
pub fn assert_close_vec(name: &str, a: &[f64], b: &[f64], tol: f64) -> f64 {
    let (e, i) = rel_err_vec_at(a, b);
    let (ai, bi) = (a.get(i).copied().unwrap_or(f64::NAN), b.get(i).copied().unwrap_or(f64::NAN));
    println!("{name}: rel err {e:.3e} (largest at [{i}]: {ai:.17e} vs {bi:.17e}), tol {tol:.0e}");
    assert!(e <= tol, "{name}: rel err {e:.3e} > {tol:.0e} at [{i}]: {ai:.17e} vs {bi:.17e}");
    e
}

/// Asserts `rel_err_mat(a, b) ≤ tol`, printing the error and where it is largest; returns it.
pub fn assert_close_mat(name: &str, a: &DMatrix<f64>, b: &DMatrix<f64>, tol: f64) -> f64 {
    let (e, (r, c)) = rel_err_mat_at(a, b);
    println!("{name}: rel err {e:.3e} (largest at ({r}, {c})), tol {tol:.0e}");
    assert!(e <= tol, "{name}: rel err {e:.3e} > {tol:.0e} at ({r}, {c}): {} vs {}", a[(r, c)], b[(r, c)]);
    e
}

/// The largest error of one check over many comparisons, with where it happened; prints a one-line
/// summary and asserts at the end, so that the numbers are printed even when the check fails.
#[derive(Debug)]
pub struct MaxErr {
    pub label: String,
    pub tol: f64,
    pub max: f64,
    pub at: String,
    pub count: usize,
    pub failures: Vec<String>,
}

impl MaxErr {
    pub fn new(label: &str, tol: f64) -> Self {
        Self { label: label.to_string(), tol, max: 0.0, at: String::new(), count: 0, failures: Vec::new() }
    }
    /// Records one error; `at` describes where (model, state, item) and is evaluated lazily.
    pub fn add(&mut self, err: f64, at: impl FnOnce() -> String) {
        self.count += 1;
        let bad = err > self.tol || err.is_nan();
        if err > self.max || (err.is_nan() && !self.max.is_nan()) || self.count == 1 {
            self.max = err;
            let s = at();
            if bad && self.failures.len() < 10 {
                self.failures.push(format!("{err:.3e} at {s}"));
            }
            self.at = s;
        } else if bad && self.failures.len() < 10 {
            self.failures.push(format!("{err:.3e} at {}", at()));
        }
    }
    /// Prints the one-line summary.
    pub fn report(&self) {
        println!(
            "{:<58} max rel err {:>10.3e}  (tol {:.0e}, {} comparisons; worst: {})",
            self.label, self.max, self.tol, self.count, self.at
        );
    }
    /// Whether every recorded error was within tolerance (a NaN never is).
    pub fn ok(&self) -> bool {
        self.max <= self.tol && !self.max.is_nan()
    }
}

/// Prints every summary, then fails if any check exceeded its tolerance.
pub fn report_and_assert(checks: &[&MaxErr]) {
    for c in checks {
        c.report();
    }
    let bad: Vec<String> = checks
        .iter()
        .filter(|c| !c.ok() || c.count == 0)
        .map(|c| {
            if c.count == 0 {
                format!("{}: nothing was compared", c.label)
            } else {
                format!("{}: {:.3e} > {:.0e}; first failures: {:?}", c.label, c.max, c.tol, c.failures)
            }
        })
        .collect();
    assert!(bad.is_empty(), "failed checks:\n{}", bad.join("\n"));
}

// ------------------------------------------------------------------------------------------------
// Random models
// ------------------------------------------------------------------------------------------------

/// Every joint type a spec can hold (the coverage test checks that each appears).
pub const ALL_JOINT_TYPES: [JointType; 7] = [
    JointType::Fixed,
    JointType::Revolute,
    JointType::Continuous,
    JointType::Prismatic,
    JointType::Floating,
    JointType::Planar,
    JointType::Ball,
];

/// A uniformly random rotation (Shoemake's subgroup algorithm) as a unit quaternion [w, x, y, z].
pub fn random_quat(rng: &mut impl Rng) -> [f64; 4] {
    let (u1, u2, u3): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    let (t2, t3) = (2.0 * PI * u2, 2.0 * PI * u3);
    [b * t3.cos(), a * t2.sin(), a * t2.cos(), b * t3.sin()]
}

/// A uniformly random rotation matrix.
pub fn random_rotation(rng: &mut impl Rng) -> Mat3 {
    let q = random_quat(rng);
    quat_to_matrix(q[0], q[1], q[2], q[3])
}

/// A vector with components uniform in [−r, r].
pub fn random_vec3(rng: &mut impl Rng, r: f64) -> Vec3 {
    Vec3::new(rng.random_range(-r..=r), rng.random_range(-r..=r), rng.random_range(-r..=r))
}

/// A random unit vector (uniform on the sphere).
pub fn random_unit(rng: &mut impl Rng) -> Vec3 {
    loop {
        let v = random_vec3(rng, 1.0);
        let n = v.norm();
        if n > 0.1 && n <= 1.0 {
            return v / n;
        }
    }
}

/// A random physical inertial: mass in [0.5, 3] kg; principal moments `m (s₂ + s₃)`,
/// `m (s₁ + s₃)`, `m (s₁ + s₂)` with sᵢ = ∫xᵢ² dm / m ∈ [0.002, 0.05] m² (which is exactly the set of
/// moments satisfying the triangle inequality); random principal axes; centre of mass within
/// 0.2 m of the link origin.
pub fn random_inertial(rng: &mut impl Rng) -> InertialSpec {
    let mass = rng.random_range(0.5..=3.0);
    let s: [f64; 3] = std::array::from_fn(|_| rng.random_range(0.002..=0.05));
    let principal = Mat3::from_diagonal(&Vec3::new(s[1] + s[2], s[0] + s[2], s[0] + s[1])) * mass;
    let rot = random_rotation(rng);
    let com = random_vec3(rng, 0.2);
    // Half the time give the tensor in rotated axes with an unrotated inertial frame: the compile
    // step must treat both the same way.
    let (x_link_inertial, inertia) = if rng.random_bool(0.5) {
        (Transform::new(rot, com), principal)
    } else {
        (Transform::from_translation(com), rot * principal * rot.transpose())
    };
    InertialSpec { mass, x_link_inertial, inertia, loc: SourceLoc::default() }
}

/// Random joint type. The root may be any type (a fixed root welds its subtree to the world);
/// below it free joints are rarer (a free joint anywhere in the tree is legal, just unusual).
fn random_joint_type(rng: &mut impl Rng, root: bool) -> JointType {
    // (type, weight)
    let table: &[(JointType, u32)] = if root {
        &[
            (JointType::Floating, 30),
            (JointType::Fixed, 14),
            (JointType::Revolute, 14),
            (JointType::Continuous, 8),
            (JointType::Prismatic, 10),
            (JointType::Planar, 10),
            (JointType::Ball, 14),
        ]
    } else {
        &[
            (JointType::Revolute, 26),
            (JointType::Continuous, 12),
            (JointType::Prismatic, 14),
            (JointType::Ball, 14),
            (JointType::Planar, 8),
            (JointType::Fixed, 18),
            (JointType::Floating, 8),
        ]
    };
    let total: u32 = table.iter().map(|t| t.1).sum();
    let mut pick = rng.random_range(0..total);
    for &(t, w) in table {
        if pick < w {
            return t;
        }
        pick -= w;
    }
    unreachable!()
}

/// A random tree of `n_links` links (so at most `n_links` bodies; fixed joints get fused) as a
/// spec: each link's parent is a uniformly random earlier link; joint placements are a random
/// rotation and a translation in [−0.5, 0.5]³ m; axes are random (and deliberately not unit: the
/// compile step normalizes them); every joint type appears with fixed probabilities; a third of
/// the movable joints get an armature in [0.01, 0.2]; movable links always carry a random physical
/// inertial, fixed ones most of the time (a massless fixed link is fused into its parent body
/// without changing it). Gravity has magnitude 9.81 in a random direction. Deterministic in
/// `seed`; at least one degree of freedom.
pub fn random_tree_spec(seed: u64, n_links: usize) -> ModelSpec {
    assert!(n_links >= 1);
    let mut rng = SmallRng::seed_from_u64(seed);
    let mut links: Vec<LinkSpec> = Vec::with_capacity(n_links);
    for i in 0..n_links {
        let parent = if i == 0 { None } else { Some(rng.random_range(0..i)) };
        let mut jtype = random_joint_type(&mut rng, i == 0);
        if i + 1 == n_links && links.iter().all(|l| l.joint.jtype == JointType::Fixed) {
            jtype = JointType::Revolute; // at least one degree of freedom
        }
        let mut joint = JointSpec::new(&format!("joint{i}"), jtype, SourceLoc::default());
        joint.x_parent_joint = Transform::new(random_rotation(&mut rng), random_vec3(&mut rng, 0.5));
        joint.axis = random_unit(&mut rng) * rng.random_range(0.5..=2.0);
        if jtype != JointType::Fixed && rng.random_bool(1.0 / 3.0) {
            joint.armature = rng.random_range(0.01..=0.2);
        }
        if jtype == JointType::Revolute || jtype == JointType::Prismatic {
            joint.limits = Some([-PI, PI]);
        }
        let inertial = if jtype != JointType::Fixed || rng.random_bool(0.7) {
            Some(random_inertial(&mut rng))
        } else {
            None
        };
        links.push(LinkSpec {
            name: format!("link{i}"),
            loc: SourceLoc::default(),
            parent,
            joint,
            inertial,
            inertia_from_geoms: false,
            geoms: Vec::new(),
            kind: lagrange::model::FrameKind::Link,
            frames: Vec::new(),
            mocap: false,
        });
    }
    let gravity = random_unit(&mut rng) * 9.81;
    ModelSpec {
        name: format!("random_tree_{seed}_{n_links}"),
        source: None,
        gravity,
        links,
        ..Default::default()
    }
}

/// [`random_tree_spec`] compiled into a model.
pub fn random_tree(seed: u64, n_links: usize) -> Model {
    compile(&random_tree_spec(seed, n_links)).expect("random tree must compile")
}

/// Sizes (in links) of the random trees of the cross-checks: 26 trees from 1 to 40 links (fixed
/// links are fused, so the largest have about 30 bodies).
pub const TREE_SIZES: [usize; 26] =
    [1, 1, 2, 2, 3, 3, 4, 5, 6, 7, 8, 9, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30, 30, 36, 40];

/// The random trees of the cross-checks, with their specs: tree k has `TREE_SIZES[k]` links and
/// seed `1000 + k`.
pub fn random_trees() -> Vec<(String, ModelSpec, Model)> {
    TREE_SIZES
        .iter()
        .enumerate()
        .map(|(k, &n)| {
            let seed = 1000 + k as u64;
            let spec = random_tree_spec(seed, n);
            let model = compile(&spec).expect("random tree must compile");
            (format!("tree(seed {seed}, {n} links, nv {})", model.nv), spec, model)
        })
        .collect()
}

// ------------------------------------------------------------------------------------------------
// Random states
// ------------------------------------------------------------------------------------------------

/// A random configuration: one-dof joints uniform in [−π, π]; free-joint positions and planar
/// translations uniform in [−1, 1]; quaternions uniformly random unit quaternions (either sign).
pub fn random_q(model: &Model, rng: &mut impl Rng) -> Vec<f64> {
    let mut q = vec![0.0; model.nq];
    for j in &model.joints {
        let qj = &mut q[j.qpos_adr..j.qpos_adr + j.kind.nq()];
        match &j.kind {
            JointKind::Revolute { .. } | JointKind::Prismatic { .. } => qj[0] = rng.random_range(-PI..=PI),
            JointKind::Free => {
                for x in &mut qj[0..3] {
                    *x = rng.random_range(-1.0..=1.0);
                }
                qj[3..7].copy_from_slice(&random_quat(rng));
            }
            JointKind::Ball => qj.copy_from_slice(&random_quat(rng)),
            JointKind::Planar { .. } => {
                qj[0] = rng.random_range(-1.0..=1.0);
                qj[1] = rng.random_range(-1.0..=1.0);
                qj[2] = rng.random_range(-PI..=PI);
            }
        }
    }
    q
}

/// A random velocity, uniform in [−2, 2] per coordinate.
pub fn random_v(model: &Model, rng: &mut impl Rng) -> Vec<f64> {
    (0..model.nv).map(|_| rng.random_range(-2.0..=2.0)).collect()
}

/// A random generalized force, uniform in [−5, 5] per coordinate.
pub fn random_tau(model: &Model, rng: &mut impl Rng) -> Vec<f64> {
    (0..model.nv).map(|_| rng.random_range(-5.0..=5.0)).collect()
}

/// A seeded small RNG.
pub fn rng(seed: u64) -> SmallRng {
    SmallRng::seed_from_u64(seed)
}

// ------------------------------------------------------------------------------------------------
// Shipped robots
// ------------------------------------------------------------------------------------------------

/// The shipped robots: (name, floating base).
pub const ROBOTS: [(&str, bool); 3] = [("ur5", false), ("panda", false), ("solo12", true)];

/// Absolute path of a file given relative to the repository root.
pub fn repo_path(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// Loads MJCF text (a scene of a reference-data file) through a temporary file of its own:
/// one file per call, as tests running in parallel may load the same scene; `label` names the
/// test binary in the file name.
pub fn load_mjcf_text(label: &str, scene: &str, mjcf: &str) -> Model {
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lagrange-{label}-{}-{call}-{scene}.xml", std::process::id()));
    std::fs::write(&path, mjcf).unwrap();
    let model = load(&path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{scene}: {e}"));
    let _ = std::fs::remove_file(&path);
    model
}

/// Loads `models/<name>/<name>.urdf`, with a free root joint if `floating`.
pub fn load_robot(name: &str, floating: bool) -> Model {
    let path = repo_path(&format!("models/{name}/{name}.urdf"));
    let options = LoadOptions { floating, ..Default::default() };
    match load(&path, &options) {
        Ok(m) => m,
        Err(e) => panic!("loading {}: {e}", path.display()),
    }
}

/// All four robots, loaded.
pub fn robots() -> Vec<(String, Model)> {
    ROBOTS.iter().map(|&(name, floating)| (name.to_string(), load_robot(name, floating))).collect()
}

/// Exact-mode constraint checks: rod tension against docs/physics.md §1.6, KKT residuals, J q̈ + J̇v = 0 and
/// the mimic full/reduced equality are algebraic identities, checked at this relative tolerance.
pub const CONSTRAINT_REL: f64 = 1e-10;
/// A loop closed by projection stays closed to this (max |φ| in m over a long run).
pub const PROJECTED_DRIFT: f64 = 1e-9;
/// Central differences of J along v (step 1e-6) reproduce J̇v to this relative error.
pub const JDOTV_FD_REL: f64 = 1e-6;
/// Joints with limits stay within them to this (rad or m) in exact mode.
pub const LIMIT_EXCURSION: f64 = 1e-6;
/// Energy gain allowed in simulations with impacts, limits, friction and contacts, relative to the
/// magnitude of the initial energy: the integrator's own drift on the smooth phases (RK4 at 1 ms
/// on a ball joint gains ≈ 7e-10 of the energy in 0.2 s of free flight). A constraint force or an
/// impulse that added energy would show at the scale of the motion's kinetic energy, orders above.
pub const ENERGY_GAIN_REL: f64 = 1e-9;
/// Contact accelerations and forces in exact mode against the closed forms of docs/physics.md §2.5
/// (1e-8): the solve is exact for sticking contacts (the Coulomb problem's fixed point) and
/// iterated to 1e-13 of the right-hand side's scale otherwise.
pub const CONTACT_REL: f64 = 1e-8;
/// Penetration (m) of a body at rest on a floor, and of a foot below it, in exact mode.
pub const PENETRATION_AT_REST: f64 = 1e-6;
/// Contact distances, normals and points against closed forms (m): the primitives are closed
/// forms themselves (round-off), GJK/EPA converges to ~1e-10 on smooth support maps.
pub const COLLISION_ABS: f64 = 1e-9;

/// Simulation options of the contact, limit and friction tests: RK4 at step `dt`, exact mode.
pub fn exact_rk4(dt: f64) -> lagrange::sim::SimOptions {
    lagrange::sim::SimOptions {
        integrator: Some(lagrange::integrate::IntegratorKind::Rk4),
        timestep: Some(dt),
        constraints: Some(lagrange::constraint::ConstraintMode::Exact),
        ..Default::default()
    }
}

/// The largest difference of `data`'s `qpos` and `qvel` from a reference sample
/// (`{"qpos": [...], "qvel": [...]}` of a golden file), each relative to the sample's largest entry
/// (at least 1).
pub fn state_rel_err(sample: &serde_json::Value, data: &Data) -> f64 {
    let mut worst = 0.0f64;
    for (key, ours) in [("qpos", &data.qpos), ("qvel", &data.qvel)] {
        let theirs: Vec<f64> = sample[key].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
        let scale = theirs.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        let err = ours.iter().zip(&theirs).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max) / scale;
        worst = worst.max(err);
    }
    worst
}

/// Steps `data` from its state to each golden sample's `"step"` count in turn (samples in
/// increasing order) and returns the worst of `err(sample, data, step)` over them (the caller
/// asserts inside `err` where a sample must pass).
pub fn follow_samples(
    model: &lagrange::Model,
    data: &mut Data,
    samples: &serde_json::Value,
    mut err: impl FnMut(&serde_json::Value, &Data, u64) -> f64,
) -> f64 {
    let (mut worst, mut k) = (0.0f64, 0u64);
    for sample in samples.as_array().unwrap() {
        while k < sample["step"].as_u64().unwrap() {
            lagrange::integrate::step(model, data).unwrap();
            k += 1;
        }
        worst = worst.max(err(sample, data, k));
    }
    worst
}

/// The model at `path` with the golden data's tight solver options (Newton, tolerance 1e-15,
/// 1000 iterations; line search 100 iterations to 1e-12), as validation/crossval_soft.py's
/// tight copies.
#[allow(dead_code)]
pub fn tight_model(path: &str) -> Model {
    let mut model = load(std::path::Path::new(path), &LoadOptions::default()).unwrap();
    let o = &mut model.options;
    o.solver = lagrange::model::options::Solver::Newton;
    o.tolerance = 1e-15;
    o.iterations = 1000;
    o.ls_iterations = 100;
    o.ls_tolerance = 1e-12;
    model
}

/// `model` solving its constraints in `mode` ([`Model::set_constraint_mode`]).
pub fn with_mode(mut model: Model, mode: lagrange::constraint::ConstraintMode) -> Model {
    model.set_constraint_mode(mode);
    model
}

/// Forward dynamics at (q, v): the state is written into `data`, then
/// [`forward`](lagrange::forward::forward) (the tests evaluate at many states).
pub fn forward_at(model: &Model, data: &mut Data, q: &[f64], v: &[f64]) {
    data.qpos.copy_from_slice(q);
    data.qvel.copy_from_slice(v);
    lagrange::forward::forward(model, data);
}

/// Runs `n` steps of `dt` from (q0, v0) with zero torques; returns the final state.
pub fn run(model: &Model, kind: IntegratorKind, q0: &[f64], v0: &[f64], dt: f64, n: usize) -> State {
    let mut sim = Simulation::new(
        Arc::new(model.clone()),
        &SimOptions { integrator: Some(kind), timestep: Some(dt), ..Default::default() },
    );
    sim.set_state(q0, v0).unwrap();
    for _ in 0..n {
        sim.step().unwrap();
    }
    State::of(&sim.data)
}

/// Ray casting against MuJoCo's `mj_ray` and `mju_rayGeom` on sites (`tests/geom_queries.rs`)
/// for primitive shapes and for meshes whose vertices MuJoCo stores exactly: both sides solve the
/// same closed forms in f64, so the hit points agree to the round-off of the poses and of the
/// quadratics' roots. The error is that of the hit point relative to the larger of the distance
/// travelled and 1 m (a hit 1 mm from a ray's origin 1 m from the world origin inherits the
/// origin's round-off); normals are unit vectors, whose error is the hit point's over the
/// surface's curvature radius. Measured: hit points 1.2e-14, normals 2.0e-13 (on a capsule of
/// 5 cm radius); sites 3.3e-15 and 4.8e-14; 1e-12.
pub const GEOMQ_REL: f64 = 1e-12;

/// Rays against meshes that MuJoCo moves to their inertial frame and stores as f32
/// (`tests/geom_queries.rs`): its vertices differ from the file's (which lagrange keeps, in f64)
/// by the f32 rounding of coordinates, 2⁻²⁴ ≈ 6e-8 relative, which moves hit points by that much
/// of the mesh's size and tilts the normals of its triangles by that much of the ratio of the
/// mesh's size to the triangle's. Measured 2.3e-8 (distances) and 4.7e-8 (normals); 1e-6.
pub const GEOMQ_MESH_REL: f64 = 1e-6;

/// `mj_geomDistance` against MuJoCo (`tests/geom_queries.rs`), in metres, for the distance of
/// every pair and the from–to segment of the pairs MuJoCo and lagrange compute in closed form or
/// on polytopes (planes, spheres, capsules, boxes, meshes): both are exact to round-off there
/// (measured 1e-15); the distances of the GJK/EPA pairs with curved surfaces agree to 1.3e-11
/// (MuJoCo's GJK run to ccd_tolerance 1e-14 in the scene; lagrange's to round-off). 1e-9.
pub const GEOMQ_DIST_ABS: f64 = 1e-9;

/// The from–to segment of `mj_geomDistance` for the GJK/EPA pairs with a curved surface
/// (ellipsoids, cylinders, spheres and capsules against meshes), in metres: the distance is
/// stationary in the witness points, so GJK and EPA fix them only to √ε of the shapes' size.
/// MuJoCo's own, on an ellipsoid–sphere pair against the exact nearest point, are 4e-9 off
/// (ccd_tolerance 1e-14; 4e-7 at its default 1e-6); lagrange polishes its witnesses by Newton steps
/// where both surfaces are smooth. Measured differences: up to 4e-8 apart, 1.7e-7 overlapping
/// (EPA); 1e-6.
pub const GEOMQ_FROMTO_CURVED_ABS: f64 = 1e-6;

// ------------------------------------------------------------------------------------------------
// Translation invariance (tests/far_origin.rs)
// ------------------------------------------------------------------------------------------------

/// Relative tolerance on M, qacc and contact forces of a scene translated by `distance` metres
/// against the same scene at the origin, for a scene whose shortest length that matters (a lever
/// arm, a penetration depth) is `length` metres.
///
/// A coordinate of size d is stored to half an ulp, ≤ ε·d (ε = 2.2e-16): every body position,
/// geom position and contact point of the translated scene carries that absolute error (the
/// state itself does: a free body's qpos is its world position). Differences of such positions
/// (lever arms, penetrations) are then known to ε·d / length relative, and every output computed
/// from them to a small multiple of that. A computation free of other losses (about a local
/// point, not the world origin) stays within 100 times that bound; one that works about the
/// world origin loses (d / length)² ε instead (1e6 m, 0.1 m: 2e-2), far above it.
pub fn far_origin_tol(distance: f64, length: f64) -> f64 {
    ALGO_REL + 100.0 * f64::EPSILON * distance / length
}

/// `model` with everything fixed to the world moved by `offset`: the geoms and frames on the world
/// body and the placement of every tree root without a free joint (a free root moves with its
/// qpos: [`translate_q`]). Models with mocap bodies are not handled.
pub fn translate_scene(model: &Model, offset: &Vec3) -> Model {
    let mut moved = model.clone();
    for g in moved.geoms.iter_mut().filter(|g| g.body == 0) {
        g.x_body_geom.pos += offset;
    }
    for f in moved.frames.iter_mut().filter(|f| f.body == 0) {
        f.x_body_frame.pos += offset;
    }
    for b in 1..moved.nbody() {
        if moved.bodies[b].parent == 0 && !matches!(moved.joint_of(b).kind, JointKind::Free) {
            moved.bodies[b].x_parent_joint.pos += offset;
        }
    }
    moved
}

/// `q` with every free tree root moved by `offset` (the state of [`translate_scene`]'s model).
pub fn translate_q(model: &Model, q: &[f64], offset: &Vec3) -> Vec<f64> {
    let mut q = q.to_vec();
    for b in 1..model.nbody() {
        let j = model.joint_of(b);
        if model.bodies[b].parent == 0 && matches!(j.kind, JointKind::Free) {
            for i in 0..3 {
                q[j.qpos_adr + i] += offset[i];
            }
        }
    }
    q
}

/// Relative tolerance on the accelerations of a mass matrix singular at the state
/// (`tests/warnings.rs`) against MuJoCo's: both raise the same factor pivot to 1e-15 and solve,
/// so a direction with a force on it gets ~f / 1e-15; the pivot replaced is round-off of order
/// ε |M| (≈ 1e-17 here) in either engine before the raise, and the other pivots and the solve
/// agree to round-off: 1e-9 allows for a few ulps of difference in the O(1) entries of L.
pub const SINGULAR_REL: f64 = 1e-9;

/// Analytic derivatives of the dynamics (`tests/derivatives.rs`) against Richardson-extrapolated
/// central differences of the library's own kernels (h = 1e-4): truncation ≈ h⁴ |f⁽⁵⁾|, round-off
/// ≈ 3 ε |f| / h ≈ 7e-12 |f|, amplified by M⁻¹ for the ABA derivatives (measured worst 1.3e-8,
/// solo12's ∂q̈/∂v); 1e-6 is the bound.
pub const DERIV_FD_REL: f64 = 1e-6;

/// Transition Jacobians (`tests/transition.rs`) against MuJoCo's `mjd_transitionFD` (both centred
/// differences with ε = 1e-6 of one step, tight solver): the steps agree to the soft solve's
/// cross-validation level and the differences divide their disagreement by 2ε, so the issue's
/// 1e-6 relative holds only where both engines' steps agree smoothly (the same contact set).
pub const TRANSITION_REL: f64 = 1e-6;

/// Relative tolerance between the stage-skipping transition Jacobians and the plain ones
/// (tests/transition.rs), both from the input's warm start: the same arithmetic but for the
/// stages' order of evaluation (measured: bitwise equal on every scene and integrator).
pub const SKIP_REL: f64 = 1e-12;

/// Relative tolerance between the transition Jacobians with the nominal warm start (the
/// default) and the plain ones (tests/transition.rs): the nudged solves (tight solver, tolerance
/// 1e-15 on the scaled improvement) start from other points and stop at others within the
/// solver's tolerance, divided by 2ε. Measured: 2.9e-6 on the gripper holding a box (friction),
/// 1.3e-9 on the humanoid, ≤ 2e-11 on the go1.
pub const NOMINAL_WARMSTART_REL: f64 = 1e-5;

/// Relative tolerance of the hybrid transition Jacobians (analytic velocity and control columns
/// through the soft solve's optimality conditions) against lagrange's own centred differences
/// (tests/transition.rs), on scenes whose contact set and row zones stay the same under the
/// nudges: the 1e-6; the differences' own error is O(ε²) truncation plus round-off / ε.
pub const HYBRID_REL: f64 = 1e-6;

/// Relative tolerance of the poses and joint values in the viewer's pages (`cli/tests/viewer.rs`):
/// they are stored as f32, whose rounding is 2⁻²⁴ ≈ 6e-8 of a value; 1e-7 allows one rounding.
pub const VIEW_F32_REL: f64 = 1e-7;

/// How far (CSS pixels) the drawn pixels of a model may reach outside the box its geoms' bounding
/// boxes project to in the viewer's browser tests (`cli/tests/viewer_browser.rs`): antialiasing
/// spreads an edge by a pixel; 3 allows for it and for the arrows' and grid's rasterization.
pub const VIEW_BOX_MARGIN_PX: f64 = 3.0;

/// The compiler's lengthrange simulation against MuJoCo's (tests/lengthrange_mujoco.rs), relative
/// to the range's width: the same 1000-step soft simulations, agreeing to round-off (7.5e-11 at
/// worst on MyoSuite's 86 muscle models, validation/mujoco_lengthrange_golden.py) — far below
/// the simulation's own `tolrange` (0.05 of the width).
pub const LENGTHRANGE_REL: f64 = 1e-9;
