//! Criterion benchmarks of the kernels on the shipped robots: FK, RNEA, CRBA, CRBA + LᵀDL
//! factorization, ABA. Compare the medians with Pinocchio's native figures
//! (`shared/validation-notes.md`) — a same-run side-by-side harness is in the validation work.

use criterion::{criterion_group, criterion_main, Criterion};
use lagrange::dynamics::{aba, crba, factorize_mass_matrix, rnea};
use lagrange::io::{load, LoadOptions};
use lagrange::kinematics::forward_kinematics;
use lagrange::{Data, Model};
use std::hint::black_box;
use std::path::Path;

/// A fixed, non-trivial state: joint angles spread over the range, a tilted unit quaternion.
fn state(model: &Model) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut q = model.neutral();
    let quat = [0.9, 0.1, -0.3, 0.2];
    let norm = quat.iter().map(|x: &f64| x * x).sum::<f64>().sqrt();
    for j in &model.joints {
        let a = j.qpos_adr;
        match j.kind.nq() {
            1 => q[a] = 0.3 + 0.1 * a as f64,
            7 => {
                q[a..a + 3].copy_from_slice(&[0.1, -0.2, 0.5]);
                for k in 0..4 {
                    q[a + 3 + k] = quat[k] / norm;
                }
            }
            _ => {}
        }
    }
    let v = (0..model.nv).map(|k| 0.5 - 0.03 * k as f64).collect();
    let tau = (0..model.nv).map(|k| 0.1 * k as f64 - 1.0).collect();
    (q, v, tau)
}

fn robots(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for (name, file, floating) in [
        ("ur5", "models/ur5/ur5.urdf", false),
        ("panda", "models/panda/panda.urdf", false),
        ("solo12", "models/solo12/solo12.urdf", true),
    ] {
        let model = load(&root.join(file), &LoadOptions { floating, ..Default::default() })
            .expect("shipped model loads");
        let mut data = Data::new(&model);
        let (q, v, tau) = state(&model);
        let mut group = c.benchmark_group(name);
        group.bench_function("fk", |b| {
            b.iter(|| forward_kinematics(&model, &mut data, black_box(&q)).unwrap())
        });
        group.bench_function("rnea", |b| {
            b.iter(|| {
                rnea(&model, &mut data, black_box(&q), black_box(&v), black_box(&tau)).unwrap();
            })
        });
        group.bench_function("crba", |b| {
            b.iter(|| {
                crba(&model, &mut data, black_box(&q)).unwrap();
            })
        });
        group.bench_function("crba+ltdl", |b| {
            b.iter(|| {
                crba(&model, &mut data, black_box(&q)).unwrap();
                factorize_mass_matrix(&model, &mut data);
            })
        });
        group.bench_function("aba", |b| {
            b.iter(|| {
                aba(&model, &mut data, black_box(&q), black_box(&v), black_box(&tau)).unwrap();
            })
        });
        group.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(50).warm_up_time(std::time::Duration::from_millis(500)).measurement_time(std::time::Duration::from_secs(2));
    targets = robots
}
criterion_main!(benches);
