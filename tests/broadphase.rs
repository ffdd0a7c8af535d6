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

/// 8 free bodies of three geoms each (a sphere, a capsule and a box, apart in the body) above a
/// plane, and a mocap body of two geoms: few enough pairs that the body-level runs are used.
fn run_scene() -> String {
    let mut bodies = String::new();
    for i in 0..8 {
        bodies += &format!(
            r#"<body pos="0 0 {}"><freejoint/><geom type="sphere" size="0.03" pos="0.05 0 0"/>
               <geom type="capsule" size="0.02 0.04" pos="-0.04 0.02 0"/>
               <geom type="box" size="0.03 0.02 0.01" pos="0 -0.05 0.03"/></body>"#,
            0.2 * i as f64
        );
    }
    format!(
        r#"<mujoco><worldbody><geom type="plane" size="2 2 0.1"/>{bodies}
           <body mocap="true" pos="0 0 0.1"><geom type="box" size="0.05 0.05 0.02"/>
             <geom type="sphere" size="0.03" pos="0.1 0 0"/></body></worldbody></mujoco>"#
    )
}

/// The runs of pairs between two bodies (or a plane and a body) that a pass skips whole: at
/// random poses, every pair of a skipped run fails its own bounding-sphere test, and the contacts
/// are those of the pass that tests every pair.
#[test]
fn the_body_level_runs_skip_only_pairs_whose_spheres_are_apart() {
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("runs.xml");
    let model = lagrange::io::load_str(&run_scene(), &path, &Default::default()).unwrap();
    let cm = CollisionModel::new(&model);
    assert!(!cm.sweep.sweep, "{} candidate pairs: the sweep runs instead", model.collision_pairs.len());
    assert!(cm.runs.iter().any(|r| r.end - r.start > 1), "no run of more than one pair");
    let mut every = cm.clone();
    for r in &mut every.runs {
        r.reach = f64::INFINITY;
    }
    let (mut d1, mut d2) = (Data::new(&model), Data::new(&model));
    let mut seed = 11u64;
    let mut rand = || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((seed >> 11) as f64) / ((1u64 << 53) as f64)
    };
    let (mut skipped, mut kept, mut touching) = (0, 0, 0);
    for _ in 0..100 {
        let mut q = model.qpos0.clone();
        for b in 0..8 {
            let a = 7 * b;
            q[a] = 0.6 * rand() - 0.3;
            q[a + 1] = 0.6 * rand() - 0.3;
            q[a + 2] = 0.4 * rand() - 0.02;
            let u = [rand() - 0.5, rand() - 0.5, rand() - 0.5, rand() - 0.5];
            let n = u.iter().map(|x| x * x).sum::<f64>().sqrt();
            for k in 0..4 {
                q[a + 3 + k] = u[k] / n;
            }
        }
        d1.mocap_pos[0] = nalgebra::Vector3::new(0.4 * rand() - 0.2, 0.4 * rand() - 0.2, 0.2 * rand());
        d2.mocap_pos[0] = d1.mocap_pos[0];
        forward_kinematics(&model, &mut d1, q.as_slice()).unwrap();
        forward_kinematics(&model, &mut d2, q.as_slice()).unwrap();
        collide(&model, &cm, &mut d1, 0.0);
        collide(&model, &every, &mut d2, 0.0);
        assert_eq!(d1.contacts, d2.contacts);
        touching += d1.contacts.len();
        for run in &cm.runs {
            if !run.apart(&d1.x_world_geom, 0.0) {
                kept += 1;
                continue;
            }
            skipped += 1;
            for b in &cm.broad[run.start as usize..run.end as usize] {
                let (x1, x2) = (&d1.x_world_geom[b.geom[0] as usize], &d1.x_world_geom[b.geom[1] as usize]);
                let d = x2.pos - x1.pos;
                let gap = if b.plane { x1.rot.column(2).dot(&d) } else { d.norm() };
                assert!(
                    gap > b.reach,
                    "a skipped run's pair {:?} within its reach: {gap} ≤ {}",
                    b.geom,
                    b.reach
                );
            }
        }
    }
    assert!(
        skipped > 1000 && kept > 200,
        "runs skipped {skipped}, kept {kept}: the poses do not test the runs"
    );
    assert!(touching > 100, "only {touching} contacts over 100 poses");
}
