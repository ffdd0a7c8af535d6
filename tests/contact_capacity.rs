//! No contact is dropped (issue 26, "no silent caps"): a pass that finds more contacts than
//! `Data` reserved room for (`INITIAL_CONTACTS`) keeps them all, grows the buffers once, and the
//! next pass at that size allocates nothing.

use lagrange::forward::forward;
use lagrange::integrate::step;
use lagrange::model::INITIAL_CONTACTS;
use lagrange::Data;

mod alloc_counter;
mod common;
use alloc_counter::allocations;

/// A plane and `n` free boxes in a grid, each pressed 1 mm into the plane: four corner contacts
/// per box (MuJoCo's box–plane points).
fn boxes_on_plane(n: usize) -> String {
    let side = (n as f64).sqrt().ceil() as usize;
    let mut bodies = String::new();
    for k in 0..n {
        let (x, y) = ((k % side) as f64 * 0.2, (k / side) as f64 * 0.2);
        bodies += &format!(
            "<body pos='{x} {y} 0.039'><freejoint/><geom type='box' size='0.04 0.04 0.04' mass='0.5'/></body>\n"
        );
    }
    format!(
        "<mujoco><option timestep='0.002'/><worldbody><geom type='plane' size='0 0 1'/>\n{bodies}</worldbody></mujoco>"
    )
}

#[test]
fn a_pass_with_more_contacts_than_reserved_keeps_them_all() {
    let n = 140;
    let model = common::load_mjcf_text("contact_capacity", "boxes", &boxes_on_plane(n));
    assert!(
        model.max_contacts() >= 4 * n,
        "the pairs' bound {} is below the scene's contacts",
        model.max_contacts()
    );
    let mut data = Data::new(&model);
    assert!(data.contacts.capacity() <= INITIAL_CONTACTS);
    forward(&model, &mut data);
    assert_eq!(data.contacts.len(), 4 * n, "every box keeps its four corners");
    assert!(4 * n > INITIAL_CONTACTS, "the scene must exceed the reserved room");
    for (b, body_contacts) in data.contacts.chunks(4).enumerate() {
        let geom = body_contacts[0].geom;
        assert!(body_contacts.iter().all(|c| c.geom == geom), "box {b}: its 4 contacts are consecutive");
        assert!(body_contacts.iter().all(|c| (c.dist + 1e-3).abs() < 1e-12), "box {b}: depth 1 mm");
    }
    // The rows and the solver took every contact: the boxes are held (no box accelerates down).
    assert!(data.qacc.iter().step_by(6).all(|a| a.is_finite()));
    for b in 0..n {
        assert!(data.qacc[6 * b + 2] > -1.0, "box {b} falls through: qacc_z {}", data.qacc[6 * b + 2]);
    }
    // Grown once: the next pass and a step at this size allocate nothing.
    let again = allocations(|| forward(&model, &mut data));
    assert_eq!(again, 0, "a pass at the grown size allocated {again} times");
    step(&model, &mut data).unwrap();
    assert_eq!(data.contacts.len(), 4 * n);
}
