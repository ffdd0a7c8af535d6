//! Tendon springs and dampers (MuJoCo's `mj_springdamper`, engine_passive.c, its tendon part;
//! MuJoCo documentation, "XML Reference → tendon": `stiffness`, `springlength`, `damping`):
//! the scalar force along tendon t is
//!
//! f = −k · x − b · L̇,  x = L − upper if L > upper, L − lower if L < lower, else 0,
//!
//! with `[lower, upper]` the spring's rest lengths (a dead band when they differ), and it enters
//! `qfrc_passive` as `ten_J`ᵀ f. `<flag spring|damper="disable">` switch the two terms off.

use crate::model::{Data, Model};

/// Adds every tendon's spring and damper force `ten_J`ᵀ f to `qfrc_passive` (needs `ten_length`,
/// `ten_velocity`, `ten_j` of this evaluation).
pub(crate) fn add_tendon_passive(model: &Model, data: &mut Data) {
    let flags = &model.options.flags;
    for (t, tendon) in model.tendons.iter().enumerate() {
        let k = if flags.spring { tendon.stiffness } else { 0.0 };
        let b = if flags.damper { tendon.damping } else { 0.0 };
        if k == 0.0 && b == 0.0 {
            continue;
        }
        let length = data.ten_length[t];
        let [lower, upper] = tendon.spring_length;
        let x = if length > upper {
            length - upper
        } else if length < lower {
            length - lower
        } else {
            0.0
        };
        let force = -k * x - b * data.ten_velocity[t];
        if force == 0.0 {
            continue;
        }
        for c in 0..model.nv {
            data.qfrc_passive[c] += data.ten_j[(t, c)] * force;
        }
    }
}

/// The number of tendons of `model` with a spring or damper that acts (for the plan).
pub(crate) fn count_tendon_passive(model: &Model) -> usize {
    let flags = &model.options.flags;
    model
        .tendons
        .iter()
        .filter(|t| (flags.spring && t.stiffness != 0.0) || (flags.damper && t.damping != 0.0))
        .count()
}
