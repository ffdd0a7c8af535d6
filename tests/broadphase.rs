//! The sweep and prune (and its dense pair table) against the all-pairs loop: on a scene with
//! enough candidate pairs for the sweep to run, at random poses, the collision pass gives the
//! same contacts in the same order whether the sweep narrows the pairs or every pair is tested.

use lagrange::collision::{collide, CollisionModel};
use lagrange::kinematics::forward_kinematics;
use lagrange::Data;

/// 60 free bodies — spheres, capsules, boxes and cylinders — above a plane.
fn scene() -> String {
    let mut bodies = String::new();
    let shapes = [
        r#"type="sphere" size="0.05""#,
        r#"type="capsule" size="0.03 0.05""#,
        r#"type="box" size="0.04 0.03 0.05""#,
        r#"type="cylinder" size="0.04 0.03""#,
    ];
    for i in 0..60 {
        bodies +=
            &format!(r#"<body pos="0 0 {}"><freejoint/><geom {}/></body>"#, 0.1 * i as f64, shapes[i % 4]);
    }
    format!(r#"<mujoco><worldbody><geom type="plane" size="2 2 0.1"/>{bodies}</worldbody></mujoco>"#)
}

#[test]
fn the_sweep_finds_the_contacts_of_the_all_pairs_loop() {
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("broadphase.xml");
    let model = lagrange::io::load_str(&scene(), &path, &Default::default()).unwrap();
    let swept = CollisionModel::new(&model);
    assert!(
        swept.sweep.sweep,
        "the scene has {} candidate pairs: too few for the sweep",
        model.collision_pairs.len()
    );
    let mut all = swept.clone();
    all.sweep.sweep = false;
    let (mut d1, mut d2) = (Data::new(&model), Data::new(&model));
    let mut seed = 7u64;
    let mut rand = || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((seed >> 11) as f64) / ((1u64 << 53) as f64)
    };
    let mut touching = 0;
    for _ in 0..50 {
        // Bodies scattered in a 0.5 m cube over the plane, randomly turned: many overlaps.
        let mut q = model.qpos0.clone();
        for b in 0..60 {
            let a = 7 * b;
            q[a] = 0.5 * rand() - 0.25;
            q[a + 1] = 0.5 * rand() - 0.25;
            q[a + 2] = 0.5 * rand() - 0.02;
            let u = [rand() - 0.5, rand() - 0.5, rand() - 0.5, rand() - 0.5];
            let n = u.iter().map(|x| x * x).sum::<f64>().sqrt();
            for k in 0..4 {
                q[a + 3 + k] = u[k] / n;
            }
        }
        forward_kinematics(&model, &mut d1, q.as_slice()).unwrap();
        forward_kinematics(&model, &mut d2, q.as_slice()).unwrap();
        collide(&model, &swept, &mut d1, 0.0);
        collide(&model, &all, &mut d2, 0.0);
        assert_eq!(d1.contacts, d2.contacts);
        touching += d1.contacts.len();
    }
    assert!(touching > 500, "only {touching} contacts over 50 poses: the scene does not test the sweep");
}
