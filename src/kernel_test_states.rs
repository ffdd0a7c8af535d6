//! Test fixtures shared by the kernels' unit tests (the runtime-dispatched builds of FK, CRBA and
//! ABA checked against their baseline builds): the panda with its fixed base and solo12 on a free
//! flyer, each at a configuration away from the neutral one.

use crate::io::{load, LoadOptions};
use crate::Model;

/// (file, model, q) for the panda and the floating solo12, q = neutral + 0.1 + 0.37 sin(i).
pub(crate) fn robots() -> Vec<(&'static str, Model, Vec<f64>)> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    [("models/panda/panda.urdf", false), ("models/solo12/solo12.urdf", true)]
        .into_iter()
        .map(|(file, floating)| {
            let model = load(&root.join(file), &LoadOptions { floating, ..Default::default() }).unwrap();
            let mut q = model.neutral();
            for (i, x) in q.iter_mut().enumerate() {
                *x += 0.1 + 0.37 * (i as f64).sin();
            }
            (file, model, q)
        })
        .collect()
}

/// Whether this CPU runs the fused (AVX2 + FMA3) kernels; if not, says that the test comparing
/// them is skipped and why.
#[cfg(target_arch = "x86_64")]
pub(crate) fn fma_available() -> bool {
    let has = std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma");
    if !has {
        eprintln!("skipped: this CPU has no AVX2+FMA, the FMA kernel is never used here");
    }
    has
}
