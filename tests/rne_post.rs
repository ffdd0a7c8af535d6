//! MuJoCo's `mj_rnePostConstraint` (`lagrange::dynamics::rne_post_constraint`): per MuJoCo body
//! the acceleration with the gravity offset (`cacc`), the external wrench (`cfrc_ext`) and the
//! interaction wrench with the parent (`cfrc_int`), and `mj_objectAcceleration`, against MuJoCo
//! 4.0 at random states of scenes covering what enters them (golden data of
//! `validation/mujoco_rnepost_golden.py`, checked against the live MuJoCo in `.ci/run`); and
//! against mechanics: a body in free flight carries no interaction wrench and an accelerometer
//! on it reads the rigid-body closed form, a hanging chain's joints carry its weight, a free
//! root's external wrenches balance its subtree's inertial wrench in both constraint modes.

mod common;

use common::{REF_REL, SOFT_REL};
use lagrange::constraint::ConstraintMode;
use lagrange::dynamics::{
    body_acceleration, external_wrench, interaction_wrench, object_acceleration, rne_post_constraint,
};
use lagrange::prelude::*;
use lagrange::spatial::{Mat3, Vec3};
use serde_json::Value;

/// The model with the golden data's tight solver options (Newton, tolerance 1e-15), in `mode`.
fn tight(path: &str, mode: ConstraintMode) -> Model {
    common::with_mode(common::tight_model(path), mode)
}

fn golden(name: &str) -> Value {
    let text = std::fs::read_to_string(format!("tests/data/mujoco_rnepost/{name}.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

fn rows(v: &Value) -> Vec<Vec<f64>> {
    v.as_array().unwrap().iter().map(floats).collect()
}

fn vec3(x: &[f64]) -> Vec3 {
    Vec3::new(x[0], x[1], x[2])
}

/// [a; b] as one 6-vector.
fn six(a: &Vec3, b: &Vec3) -> Vec<f64> {
    a.iter().chain(b.iter()).copied().collect()
}

/// Largest |a − b| over paired 6-vectors, and the largest |b|.
#[derive(Default)]
struct Worst {
    diff: f64,
    scale: f64,
}

impl Worst {
    fn add(&mut self, ours: &[f64], reference: &[f64]) {
        for (x, y) in ours.iter().zip(reference) {
            self.diff = self.diff.max((x - y).abs());
            self.scale = self.scale.max(y.abs());
        }
    }
    /// max |a − b| / max |b| (0 when both are zero).
    fn rel(&self) -> f64 {
        self.rel_to(self.scale)
    }
    /// max |a − b| / scale (0 when both are zero).
    fn rel_to(&self, scale: f64) -> f64 {
        if self.diff == 0.0 {
            0.0
        } else {
            self.diff / scale.max(1e-300)
        }
    }
}

/// The golden scene `name` in soft mode at each state, with the scene's `xfrc_applied`: forward,
/// then `rne_post_constraint`; returns the worst relative errors of (qacc, cacc, cfrc_int,
/// cfrc_ext, object accelerations, site wrenches), each against the largest entry of its
/// quantity in the state (qacc: of qacc and qacc_smooth, as tests/soft.rs measures it; the
/// wrenches: of all the state's wrenches).
fn against_golden(name: &str) -> [f64; 6] {
    let g = golden(name);
    let model = tight(g["model"].as_str().unwrap(), ConstraintMode::Soft);
    let links = &model.links;
    let names: Vec<&str> = g["bodies"].as_array().unwrap().iter().map(|n| n.as_str().unwrap()).collect();
    assert_eq!(links.len(), names.len(), "{name}: MuJoCo bodies");
    for (b, n) in names.iter().enumerate().skip(1) {
        assert_eq!(model.frames[links.frame[b]].name, *n, "{name}: body {b}");
    }
    let parent: Vec<usize> = floats(&g["body_parentid"]).iter().map(|&x| x as usize).collect();
    assert_eq!(links.parent, parent, "{name}: body_parentid");
    let rootid: Vec<usize> = floats(&g["body_rootid"]).iter().map(|&x| x as usize).collect();
    let site_body: Vec<usize> = floats(&g["site_bodyid"]).iter().map(|&x| x as usize).collect();
    let mut data = Data::new(&model);
    for (body, w) in g["xfrc_applied"].as_object().unwrap() {
        let b = names.iter().position(|n| n == body).unwrap();
        data.xfrc_applied[b].copy_from_slice(&floats(w));
    }
    let mut worst = [0.0_f64; 6];
    for (i, s) in g["states"].as_array().unwrap().iter().enumerate() {
        common::forward_at(&model, &mut data, &floats(&s["qpos"]), &floats(&s["qvel"]));
        assert_eq!(data.nefc as u64, s["nefc"].as_u64().unwrap(), "{name} state {i}: rows");
        rne_post_constraint(&model, &mut data).unwrap();
        let qacc = floats(&s["qacc"]);
        let smooth = floats(&s["qacc_smooth"]).iter().chain(&qacc).fold(0.0_f64, |m, x| m.max(x.abs()));
        let e_acc = data.qacc.iter().zip(&qacc).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs())) / smooth;
        let com = rows(&s["subtree_com"]);
        let (cacc, cfrc_int, cfrc_ext) = (rows(&s["cacc"]), rows(&s["cfrc_int"]), rows(&s["cfrc_ext"]));
        let [mut w_cacc, mut w_int, mut w_ext, mut w_obj, mut w_site]: [Worst; 5] = Default::default();
        for b in 0..links.len() {
            // MuJoCo's convention: world axes about subtree_com[body_rootid].
            let p = vec3(&com[rootid[b]]);
            let (ang, lin) = body_acceleration(&model, &data, b, &p).unwrap();
            w_cacc.add(&six(&ang, &lin), &cacc[b]);
            let (force, torque) = interaction_wrench(&model, &data, b, &p).unwrap();
            w_int.add(&six(&torque, &force), &cfrc_int[b]);
            let (force, torque) = external_wrench(&model, &data, b, &p).unwrap();
            w_ext.add(&six(&torque, &force), &cfrc_ext[b]);
        }
        // mj_objectAcceleration at every body frame (mjOBJ_XBODY) and site.
        for (b, (x, acc)) in rows(&s["xpos"]).iter().zip(rows(&s["xbody_acc"])).enumerate() {
            let (ang, lin) = object_acceleration(&model, &data, b, &vec3(x)).unwrap();
            w_obj.add(&six(&ang, &lin), &acc);
        }
        for (k, x) in rows(&s["site_xpos"]).iter().enumerate() {
            let b = site_body[k];
            let (ang, lin) = object_acceleration(&model, &data, b, &vec3(x)).unwrap();
            w_obj.add(&six(&ang, &lin), &rows(&s["site_acc"])[k]);
            let (force, torque) = interaction_wrench(&model, &data, b, &vec3(x)).unwrap();
            w_site.add(&six(&torque, &force), &rows(&s["site_int"])[k]);
        }
        // Wrenches against the largest of the state's wrenches: a free body's cfrc_int is zero
        // up to round-off, which has no relative error of its own.
        let wrench = w_int.scale.max(w_ext.scale).max(w_site.scale);
        let errors = [
            e_acc,
            w_cacc.rel(),
            w_int.rel_to(wrench),
            w_ext.rel_to(wrench),
            w_obj.rel(),
            w_site.rel_to(wrench),
        ];
        for (w, e) in worst.iter_mut().zip(errors) {
            *w = w.max(e);
        }
    }
    worst
}

/// Every scene of the golden data against MuJoCo: 1e-9 relative where no constraint force
/// enters (the arm and the gravity-free scene), the solver's tolerance where contact or
/// equality forces do.
#[test]
fn matches_mujoco_rne_post_constraint() {
    let scenes = [
        ("arm", REF_REL),
        ("space", REF_REL),
        ("stack", SOFT_REL),
        ("go1", SOFT_REL),
        ("mocap", SOFT_REL),
        ("weld_bodies_torquescale", SOFT_REL),
        ("connect_free_sites", SOFT_REL),
        ("weld_sites", SOFT_REL),
        ("fourbar_connect", SOFT_REL),
    ];
    for (name, tol) in scenes {
        let e = against_golden(name);
        println!(
            "{name}: qacc {:.1e}, cacc {:.1e}, cfrc_int {:.1e}, cfrc_ext {:.1e}, object acc {:.1e}, site cfrc_int {:.1e} (tolerance {tol:e})",
            e[0], e[1], e[2], e[3], e[4], e[5]
        );
        assert!(e.iter().all(|&x| x <= tol), "{name}: {e:?}");
    }
}

/// A body in free flight under gravity, spinning about no principal axis: its joint transmits
/// nothing (cfrc_int = 0: I a + v ×* I v = 0 with a = the acceleration minus gravity), its
/// centre of mass falls with gravity (an accelerometer there reads 0), and an accelerometer off
/// the centre of mass reads the rigid-body closed form α × r + ω × (ω × r) with Euler's
/// α = −I⁻¹ (ω × I ω) (world axes).
#[test]
fn a_body_in_free_flight() {
    let model = Model::from_str(
        r#"<mujoco><worldbody><body name="b" pos="0.3 -0.2 1.5" euler="20 30 40"><freejoint/>
           <geom type="box" size="0.1 0.2 0.3" mass="3" pos="0.05 -0.02 0.01"/>
           <site name="s" pos="0.12 0.1 -0.2"/></body></worldbody></mujoco>"#,
    )
    .unwrap();
    let mut data = Data::new(&model);
    data.qvel.copy_from_slice(&[0.4, -0.3, 1.0, 2.0, -3.0, 1.5]);
    forward(&model, &mut data);
    rne_post_constraint(&model, &mut data).unwrap();
    let b = 1;
    let frame = &model.frames[model.links.frame[b]];
    let x = lagrange::frames::pose(&model, &mut data, "b").unwrap();
    let com = x.act_point(&frame.inertia.com());
    let (force, torque) = interaction_wrench(&model, &data, b, &com).unwrap();
    let weight = frame.inertia.mass * 9.81;
    assert!(force.norm() <= 1e-12 * weight && torque.norm() <= 1e-12 * weight, "{force:?} {torque:?}");
    let (_, lin) = object_acceleration(&model, &data, b, &com).unwrap();
    assert!(lin.norm() <= 1e-12 * 9.81, "free fall: {lin:?}");
    // Closed form at the site.
    let omega = x.rot * Vec3::new(2.0, -3.0, 1.5);
    let i_world: Mat3 = x.rot * frame.inertia.i_com() * x.rot.transpose();
    let alpha = -(i_world.try_inverse().unwrap() * omega.cross(&(i_world * omega)));
    let site = model.site_id("s").unwrap();
    let r = x.act_point(&model.frames[site].x_body_frame.pos) - com;
    let want = alpha.cross(&r) + omega.cross(&omega.cross(&r));
    let (ang, lin) = object_acceleration(&model, &data, b, &(com + r)).unwrap();
    println!("free flight: accelerometer {lin:?}, closed form {want:?}");
    assert!((ang - alpha).norm() <= 1e-12 * alpha.norm(), "{ang:?} {alpha:?}");
    assert!((lin - want).norm() <= 1e-12 * want.norm(), "{lin:?} {want:?}");
}

/// A chain hanging at rest (three hinges, a body welded to the middle link, a two-hinge body):
/// each joint carries the weight of what hangs below it, with no torque about the hinge line
/// through the centres of mass; the world's entry carries the whole chain; accelerometers read
/// −g in world axes (+9.81 up), as MuJoCo's do at rest.
#[test]
fn a_hanging_chain_carries_its_weight() {
    let model = Model::from_str(
        r#"<mujoco><worldbody><body name="l1" pos="0 0 2"><joint type="hinge" axis="0 1 0"/>
           <geom type="capsule" fromto="0 0 0 0 0 -0.4" size="0.02" mass="1"/>
           <body name="l2" pos="0 0 -0.4"><joint type="hinge" axis="1 0 0"/>
             <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.02" mass="0.7"/>
             <body name="weight" pos="0 0 -0.15"><geom type="sphere" size="0.05" mass="2"/>
               <site name="s"/></body>
             <body name="l3" pos="0 0 -0.3"><joint type="hinge" axis="0 1 0"/><joint type="hinge" axis="1 0 0"/>
               <geom type="capsule" fromto="0 0 0 0 0 -0.2" size="0.02" mass="0.4"/></body>
           </body></body></worldbody></mujoco>"#,
    )
    .unwrap();
    let mut data = Data::new(&model);
    forward(&model, &mut data);
    assert!(data.qacc.amax() < 1e-12, "at rest: {:?}", data.qacc.as_slice());
    rne_post_constraint(&model, &mut data).unwrap();
    let id = |n: &str| model.links.frame.iter().position(|&f| model.frames[f].name == n).unwrap();
    let g = 9.81;
    for (body, mass, anchor_z) in
        [("l1", 4.1, 2.0), ("l2", 3.1, 1.6), ("weight", 2.0, 1.45), ("l3", 0.4, 1.3)]
    {
        let anchor = Vec3::new(0.0, 0.0, anchor_z);
        let (force, torque) = interaction_wrench(&model, &data, id(body), &anchor).unwrap();
        let want = Vec3::new(0.0, 0.0, mass * g);
        println!("{body}: joint force {force:?} (weight below {:.4} N), torque {torque:?}", mass * g);
        assert!((force - want).norm() <= 1e-12 * want.norm(), "{body}: {force:?}");
        assert!(torque.norm() <= 1e-12 * want.norm(), "{body}: {torque:?}");
    }
    let (world, _) = interaction_wrench(&model, &data, 0, &Vec3::zeros()).unwrap();
    assert!((world.z - 4.1 * g).abs() <= 1e-12 * 4.1 * g, "{world:?}");
    let x = lagrange::frames::pose(&model, &mut data, "s").unwrap();
    let (_, lin) = object_acceleration(&model, &data, id("weight"), &x.pos).unwrap();
    assert!((lin - Vec3::new(0.0, 0.0, g)).norm() <= 1e-12 * g, "{lin:?}");
}

/// A free joint transmits nothing: for every body on a free joint, cfrc_int = 0, i.e. the
/// subtree's inertial wrench equals the sum of its external wrenches (applied, contact and
/// equality forces). In the soft mode the balance holds to the solver's tolerance; in the exact
/// mode (no MuJoCo reference: its weld rows are s (ω_A − ω_B), their torque s λ) to round-off of
/// the direct solve. Measured against the subtree's weight and the largest external force.
#[test]
fn free_roots_balance_their_external_wrenches() {
    for (name, modes) in [
        ("stack", &[ConstraintMode::Soft, ConstraintMode::Exact][..]),
        ("go1", &[ConstraintMode::Soft][..]),
        ("connect_free_sites", &[ConstraintMode::Soft, ConstraintMode::Exact][..]),
        ("weld_sites", &[ConstraintMode::Soft, ConstraintMode::Exact][..]),
        ("mocap", &[ConstraintMode::Soft][..]),
    ] {
        let g = golden(name);
        for &mode in modes {
            let model = tight(g["model"].as_str().unwrap(), mode);
            let free: Vec<usize> = (1..model.links.len())
                .filter(|&b| {
                    let cb = model.frames[model.links.frame[b]].body;
                    cb != 0
                        && model.frames[model.links.frame[b]].x_body_frame.pos.norm() == 0.0
                        && model.joint_of(cb).kind == lagrange::model::JointKind::Free
                })
                .collect();
            assert!(!free.is_empty(), "{name}: a free body");
            let mut data = Data::new(&model);
            let names: Vec<&str> =
                g["bodies"].as_array().unwrap().iter().map(|n| n.as_str().unwrap()).collect();
            for (body, w) in g["xfrc_applied"].as_object().unwrap() {
                data.xfrc_applied[names.iter().position(|n| n == body).unwrap()].copy_from_slice(&floats(w));
            }
            let mut worst = 0.0_f64;
            for s in g["states"].as_array().unwrap() {
                common::forward_at(&model, &mut data, &floats(&s["qpos"]), &floats(&s["qvel"]));
                rne_post_constraint(&model, &mut data).unwrap();
                let mut scale = 0.0_f64;
                for b in 1..model.links.len() {
                    let (f, _) = external_wrench(&model, &data, b, &Vec3::zeros()).unwrap();
                    scale = scale.max(f.norm()).max(model.frames[model.links.frame[b]].inertia.mass * 9.81);
                }
                for &b in &free {
                    let p = data.x_world_body[model.frames[model.links.frame[b]].body].pos;
                    let (f, t) = interaction_wrench(&model, &data, b, &p).unwrap();
                    worst = worst.max(f.norm().max(t.norm()) / scale);
                }
            }
            let tol = if mode == ConstraintMode::Soft { SOFT_REL } else { common::ALGO_REL };
            println!("{name} {mode:?}: free bodies' cfrc_int / force scale {worst:.1e} (tolerance {tol:e})");
            assert!(worst <= tol, "{name} {mode:?}: {worst:e}");
        }
    }
}

/// The accessors refuse a body that does not exist.
#[test]
fn accessors_refuse_unknown_bodies() {
    let model = Model::from_str(
        r#"<mujoco><worldbody><body><freejoint/><geom size="0.1"/></body></worldbody></mujoco>"#,
    )
    .unwrap();
    let mut data = Data::new(&model);
    forward(&model, &mut data);
    rne_post_constraint(&model, &mut data).unwrap();
    let p = Vec3::zeros();
    assert!(matches!(
        object_acceleration(&model, &data, 2, &p),
        Err(InputError::Index { what: "body", index: 2, count: 2, .. })
    ));
    assert!(interaction_wrench(&model, &data, 7, &p).is_err());
    assert!(external_wrench(&model, &data, 2, &p).is_err());
    assert!(body_acceleration(&model, &data, 2, &p).is_err());
    let other =
        Model::from_str(r#"<mujoco><worldbody><body><joint/><geom size="0.1"/></body></worldbody></mujoco>"#)
            .unwrap();
    assert!(rne_post_constraint(&other, &mut data).is_err(), "data of another model");
}
