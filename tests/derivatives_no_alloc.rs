//! The derivative kernels allocate nothing once their `DerivativesWork` / `TransitionWork` exist
//! (a counting global allocator, as tests/no_alloc.rs; a binary of its own, since the allocator
//! is per binary).

use lagrange::derivatives::{
    aba_derivatives, rnea_derivatives, smooth_derivatives, transition_jacobians, DerivativesWork,
    TransitionOptions, TransitionWork,
};
use lagrange::io::{load, LoadOptions};
use lagrange::Data;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::Path;

struct Counting;

thread_local! {
    static ACTIVE: Cell<bool> = const { Cell::new(false) };
    static COUNT: Cell<u64> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if ACTIVE.with(|a| a.get()) {
            COUNT.with(|c| c.set(c.get() + 1));
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if ACTIVE.with(|a| a.get()) {
            COUNT.with(|c| c.set(c.get() + 1));
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

fn allocations(f: impl FnOnce()) -> u64 {
    COUNT.with(|c| c.set(0));
    ACTIVE.with(|a| a.set(true));
    f();
    ACTIVE.with(|a| a.set(false));
    COUNT.with(|c| c.get())
}

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
    }
}
