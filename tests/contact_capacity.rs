//! No silent caps on contacts (docs/constraints.md): the soft mode's Newton solver keeps every
//! contact of a scene with more than the initial buffers hold (they grow once; the next pass
//! allocates nothing); with a solver that forms rows × rows matrices (PGS), a pass that finds more
//! contacts than `Model::contact_budget` keeps the budget's worth, counts the rest in
//! `Data::contacts_dropped` (which `simulate` reports) and raises the `contact_full` warning with
//! the count and the time, and the next pass allocates nothing.

use lagrange::forward::forward;
use lagrange::integrate::step;
use lagrange::model::INITIAL_CONTACTS;
use lagrange::Data;

mod alloc_counter;
mod common;
use alloc_counter::allocations;

/// A plane and `n` free boxes in a grid, each pressed 1 mm into the plane: four corner contacts
/// per box (MuJoCo's box–plane points).
/// `condim`: the rows per contact (1 keeps PGS's dense rows × rows matrix small).
fn boxes_on_plane(n: usize, solver: &str, condim: u32) -> String {
    let side = (n as f64).sqrt().ceil() as usize;
    let mut bodies = String::new();
    for k in 0..n {
        let (x, y) = ((k % side) as f64 * 0.2, (k / side) as f64 * 0.2);
        bodies += &format!(
            "<body pos='{x} {y} 0.039'><freejoint/><geom type='box' size='0.04 0.04 0.04' mass='0.5'/></body>\n"
        );
    }
    format!(
        "<mujoco><option timestep='0.002' solver='{solver}'/><default><geom condim='{condim}'/></default><worldbody><geom type='plane' size='0 0 1'/>\n{bodies}</worldbody></mujoco>"
    )
}

#[test]
fn newton_keeps_every_contact_beyond_the_initial_buffers() {
    let n = 140;
    let model = common::load_mjcf_text("contact_capacity", "boxes_newton", &boxes_on_plane(n, "Newton", 3));
    assert!(model.contact_budget() >= 4 * n, "budget {}", model.contact_budget());
    assert!(INITIAL_CONTACTS < 4 * n, "the scene must exceed the initial buffers");
    let mut data = Data::new(&model);
    forward(&model, &mut data);
    assert_eq!(data.contacts.len(), 4 * n, "every contact is kept");
    assert_eq!(data.contacts_dropped, 0);
    assert!(!data.warnings.any(), "{:?}", data.warnings.messages(&model));
    assert!(data.qacc.iter().all(|a| a.is_finite()));
    let again = allocations(|| forward(&model, &mut data));
    assert_eq!(again, 0, "a pass at the same size allocated {again} times");
}

#[test]
fn a_pass_with_more_contacts_than_the_budget_counts_what_it_drops() {
    let n = 140;
    let model = common::load_mjcf_text("contact_capacity", "boxes_pgs", &boxes_on_plane(n, "PGS", 1));
    assert!(
        model.max_contacts() >= 4 * n,
        "the pairs' bound {} is below the scene's contacts",
        model.max_contacts()
    );
    let budget = model.contact_budget();
    assert!(budget >= INITIAL_CONTACTS && budget < 4 * n, "the scene must exceed the budget {budget}");
    let mut data = Data::new(&model);
    data.time = 0.25;
    forward(&model, &mut data);
    assert_eq!(data.contacts.len(), budget, "the budget's worth is kept");
    assert_eq!(data.contacts_dropped, (4 * n - budget) as u64, "the rest is counted");
    let w = &data.warnings;
    assert_eq!((w.contact_full.number, w.contact_full.last_info, w.contact_full_time), (1, 4 * n, 0.25));
    let message = w.messages(&model).join("\n");
    assert!(message.contains(&format!("{} found", 4 * n)) && message.contains("t = 0.25 s"), "{message}");
    for c in &data.contacts {
        assert!((c.dist + 1e-3).abs() < 1e-12, "depth 1 mm");
    }
    assert!(data.qacc.iter().all(|a| a.is_finite()));
    // The next pass and a step allocate nothing.
    let again = allocations(|| forward(&model, &mut data));
    assert_eq!(again, 0, "a pass at the same size allocated {again} times");
    step(&model, &mut data).unwrap();
    assert_eq!(data.contacts.len(), budget);
    assert_eq!(data.warnings.contact_full.number, 3);
}

/// The budget as an option (`Options::max_contacts`, CLI `--max-contacts`): the exact mode keeps
/// every contact of a scene beyond its default budget of 500 when asked, and a budget set below
/// the scene's contacts drops the rest with the warning naming the count, as the default does.
#[test]
fn the_contact_budget_is_an_option() {
    let n = 140;
    let text = boxes_on_plane(n, "Newton", 3);
    let mut model = common::load_mjcf_text("contact_capacity", "boxes_exact", &text);
    model.set_constraint_mode(lagrange::constraint::ConstraintMode::Exact);
    let default_budget = model.contact_budget();
    assert!(default_budget < 4 * n, "the scene must exceed the exact mode's default budget {default_budget}");
    model.options.max_contacts = Some(4 * n);
    assert_eq!(model.contact_budget(), 4 * n);
    let mut data = Data::new(&model);
    forward(&model, &mut data);
    assert_eq!(data.contacts.len(), 4 * n, "every contact is kept");
    assert_eq!(data.contacts_dropped, 0);
    assert!(data.qacc.iter().all(|a| a.is_finite()));
    let again = allocations(|| forward(&model, &mut data));
    assert_eq!(again, 0, "a pass at the same size allocated {again} times");
    // Below the scene's contacts: the option's worth kept, the rest counted and warned about.
    model.options.max_contacts = Some(100);
    let mut data = Data::new(&model);
    forward(&model, &mut data);
    assert_eq!((data.contacts.len(), data.contacts_dropped), (100, (4 * n - 100) as u64));
    let message = data.warnings.messages(&model).join("\n");
    assert!(message.contains("than the 100 kept") && message.contains("--max-contacts"), "{message}");
    // Through the loader (what the CLI's --max-contacts sets).
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("contact_capacity_option.xml");
    std::fs::write(&path, &text).unwrap();
    let options = lagrange::io::LoadOptions { max_contacts: Some(7), ..Default::default() };
    let loaded = lagrange::io::load(&path, &options).unwrap();
    let _ = std::fs::remove_file(&path);
    assert_eq!((loaded.options.max_contacts, loaded.contact_budget()), (Some(7), 7));
}
