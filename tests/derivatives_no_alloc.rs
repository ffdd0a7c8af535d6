//! The derivative kernels allocate nothing once their `DerivativesWork` / `TransitionWork` exist
//! (the counting global allocator of tests/alloc_counter; a binary of its own, since the allocator
//! is per binary).

use lagrange::derivatives::{
    aba_derivatives, rnea_derivatives, smooth_derivatives, transition_jacobians, DerivativesWork,
    TransitionMethod, TransitionOptions, TransitionWork,
};
use lagrange::io::{load, LoadOptions};
use lagrange::Data;
use std::path::Path;

mod alloc_counter;
use alloc_counter::allocations;

#[test]
fn derivative_kernels_do_not_allocate() {
    assert!(allocations(|| drop(std::hint::black_box(vec![1u8; 16]))) >= 1);
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for (file, floating) in
        [("models/solo12/solo12.urdf", true), ("models/mjcf/unitree_go1/scene.xml", false)]
    {
        let model = load(&root.join(file), &LoadOptions { floating, ..Default::default() }).unwrap();
        let mut data = Data::new(&model);
        let mut work = DerivativesWork::new(&model);
        let mut tw = TransitionWork::new(&model);
        let q = model.neutral();
        let v: Vec<f64> = (0..model.nv).map(|k| 0.1 * k as f64).collect();
        data.qpos.copy_from_slice(&q);
        // Warm-up: the stepper is built at the first step.
        transition_jacobians(&model, &mut data, &mut tw, &TransitionOptions::default()).unwrap();
        let n = allocations(|| {
            rnea_derivatives(&model, &mut data, &mut work, &q, &v, &v).unwrap();
            aba_derivatives(&model, &mut data, &mut work, &q, &v, &v).unwrap();
            smooth_derivatives(&model, &mut data, &mut work).unwrap();
        });
        assert_eq!(n, 0, "{file}: the analytic derivatives allocated {n} times");
        let n = allocations(|| {
            transition_jacobians(&model, &mut data, &mut tw, &TransitionOptions::default()).unwrap();
        });
        assert_eq!(n, 0, "{file}: transition_jacobians allocated {n} times");
        let hybrid = TransitionOptions { method: TransitionMethod::Hybrid, ..Default::default() };
        transition_jacobians(&model, &mut data, &mut tw, &hybrid).unwrap();
        let n = allocations(|| {
            transition_jacobians(&model, &mut data, &mut tw, &hybrid).unwrap();
        });
        assert_eq!(n, 0, "{file}: the hybrid transition_jacobians allocated {n} times");
    }
}
