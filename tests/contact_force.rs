//! Reading contacts: `contact_force` (MuJoCo's `mj_contactForce`) for frictionless, elliptic and
//! pyramidal contacts, the `contacts` iterator, the count of contacts with rows on both cone
//! types (`efc_is_normal`), and the typed error of a contact index out of
//! range. The comparison with MuJoCo itself is `validation/crossval_contact_force.py`.

mod common;

use lagrange::prelude::*;

/// A 1 kg box resting on a plane (4 corner contacts), settled for 1 s, with `cone` and `condim`.
fn resting_box(cone: &str, condim: u32) -> (Model, Data) {
    let model = Model::from_str(&format!(
        r#"<mujoco><option cone="{cone}" timestep="0.002"/><worldbody>
           <geom name="floor" type="plane" size="2 2 .1" condim="{condim}"/>
           <body name="box" pos="0 0 0.1"><freejoint/>
             <geom name="box" type="box" size="0.1 0.1 0.1" mass="1" condim="{condim}"/></body>
           </worldbody></mujoco>"#
    ))
    .unwrap();
    let mut data = Data::new(&model);
    for _ in 0..500 {
        step(&model, &mut data).unwrap();
    }
    forward(&model, &mut data);
    (model, data)
}

/// On both cones and every condim, the contacts' normal forces carry the box's weight, each
/// force is in its contact frame (normal first), and the tangential forces cancel at rest.
#[test]
fn contact_forces_carry_the_weight_on_every_cone() {
    for (cone, condim) in
        [("pyramidal", 1), ("pyramidal", 3), ("pyramidal", 4), ("elliptic", 3), ("elliptic", 6)]
    {
        let (model, data) = resting_box(cone, condim);
        let list: Vec<ContactInfo> = contacts(&model, &data).collect();
        let active = list.iter().filter(|c| c.active).count();
        let normal: f64 = list.iter().map(|c| c.force[0]).sum();
        let world: Vec<f64> = (0..3).map(|k| list.iter().map(|c| c.force_world()[k]).sum()).collect();
        println!(
            "{cone} condim {condim}: {active} contacts with rows, Σ normal {normal:.9} N, Σ world {world:?}"
        );
        assert_eq!(active, 4, "{cone} condim {condim}: the box's 4 corners");
        assert!((normal - 9.81).abs() < 1e-6, "{cone} condim {condim}: Σ normal force {normal}");
        // The floor (geom 1) pushes the box (geom 2) up: +z in the world.
        assert!((world[2] - 9.81).abs() < 1e-6 && world[0].abs() < 1e-6 && world[1].abs() < 1e-6);
        for c in &list {
            assert_eq!(c.geom_names, ["floor", "box"]);
            assert_eq!(c.body_names[1], "box");
            assert_eq!(c.force, contact_force(&model, &data, c.index).unwrap());
            // Entries beyond the contact's dimension are zero.
            assert!(c.force[condim as usize..].iter().all(|&f| f == 0.0), "{:?}", c.force);
        }
        // Counting block starts counts the contacts on both cones.
        let starts = (0..data.nefc).filter(|&i| data.efc_is_normal(i)).count();
        assert_eq!(starts, 4, "{cone} condim {condim}: efc_is_normal counts each contact once");
    }
}

/// A pyramidal contact's force decodes its edges: f_n = Σ edges, f_i = μ_i (f⁺_i − f⁻_i); the
/// friction forces are what accelerates the pushed box.
#[test]
fn pyramidal_forces_decode_the_edges() {
    let (model, mut data) = resting_box("pyramidal", 3);
    // Push the box sideways so that friction acts.
    data.qfrc_applied[0] = 2.0;
    forward(&model, &mut data);
    let c = 0;
    let first = (0..data.nefc).find(|&r| data.efc_type[r].is_contact() && data.efc_id[r] == c).unwrap();
    let edges = &data.efc_force.as_slice()[first..first + 4];
    let mu = data.contacts[c].friction;
    let f = contact_force(&model, &data, c).unwrap();
    assert_eq!(f[0], edges.iter().sum::<f64>());
    assert_eq!(f[1], mu[0] * (edges[0] - edges[1]));
    assert_eq!(f[2], mu[1] * (edges[2] - edges[3]));
    // Newton along x (1 kg, no rotation of the origin's acceleration at rest): m ẍ = push + Σ f_x.
    let friction: f64 = contacts(&model, &data).map(|c| c.force_world()[0]).sum();
    println!("Σ friction along x {friction:.9} N against the push of 2 N, ẍ = {:.9}", data.qacc[0]);
    assert!(friction < 0.0 && (data.qacc[0] - (2.0 + friction)).abs() < 1e-9);
}

#[test]
fn a_contact_index_out_of_range_is_a_typed_error() {
    let (model, data) = resting_box("elliptic", 3);
    let err = contact_force(&model, &data, 99).unwrap_err();
    assert_eq!(err, InputError::Index { function: "contact_force", what: "contact", index: 99, count: 4 });
    assert!(err.to_string().contains("contact 99 does not exist (4 contacts"), "{err}");
}
