//! A contact's frame rows over the dofs that move it (MuJoCo's `mj_contactJacobian` over
//! `mj_jacDifPair`'s chain, compactly): for each dof that moves one of the contact's two bodies
//! and not the other, the velocity its unit rate gives geom 2's body relative to geom 1's at the
//! contact point, in the contact frame (normal, tangents, then torsion and rolling; the rows of
//! `contact.rs`'s module doc, the values `add_contact_jacobian` writes, to the bit).
//!
//! A dof's column at point p is formed about its body's origin x: angular R s_ω, linear
//! R s_v + R s_ω × (p − x) (`kinematics::for_each_ancestor_dof_at`: no digits lost far from the
//! world origin). Its p-independent part (R s_ω, R s_v) is the same for every contact the dof
//! moves — a box resting on four corners, a foot on its sole's contacts — so [`DofAxes`] forms it
//! once per position stage, for the dofs a contact reaches, and the contacts read it.

use crate::constraint::contact::frame_values;
use crate::model::{Contact, Model};
use crate::spatial::{Motion, Transform, Vec3};

/// Each dof's motion-subspace column in world axes at its body's origin, (R s_ω, R s_v), formed on
/// first use after [`DofAxes::forget`].
#[derive(Clone, Debug)]
pub(crate) struct DofAxes {
    axes: Vec<(Vec3, Vec3)>,
    /// The pass each dof's axes were formed in (`pass` when current).
    formed: Vec<u32>,
    pass: u32,
}

impl DofAxes {
    /// Room for `nv` dofs, none formed.
    pub fn new(nv: usize) -> Self {
        Self { axes: vec![(Vec3::zeros(), Vec3::zeros()); nv], formed: vec![0; nv], pass: 1 }
    }

    /// Forgets every formed column (the poses change between position stages).
    pub fn forget(&mut self) {
        self.pass = self.pass.wrapping_add(1);
        if self.pass == 0 {
            self.formed.fill(0);
            self.pass = 1;
        }
    }

    /// Dof `k`'s (R s_ω, R s_v), `x` its body's world pose and `s` its body-frame column.
    #[inline]
    fn get(&mut self, k: usize, x: &Transform, s: &Motion) -> (Vec3, Vec3) {
        if self.formed[k] != self.pass {
            self.formed[k] = self.pass;
            self.axes[k] = (x.rot * s.ang, x.rot * s.lin);
        }
        self.axes[k]
    }
}

/// The nonzero columns of `contact`'s frame rows (`dim` of them), compactly: the dofs that move
/// one body and not the other — both paths to the root below their lowest common ancestor (a
/// common ancestor's columns cancel to exact zeros) — ascending into `cols`, and each one's `dim`
/// row values into `vals`. Columns whose values are all zero are dropped. Needs body poses and
/// motion subspaces (`x_world_body`, `s_body`) and `axes` forgotten since they changed; `cols`
/// and `vals` are cleared first and need capacity nv to stay without allocation.
#[allow(clippy::too_many_arguments)]
pub(crate) fn contact_jacobian_columns(
    model: &Model,
    x_world_body: &[Transform],
    s_body: &[Motion],
    axes: &mut DofAxes,
    contact: &Contact,
    dim: usize,
    cols: &mut Vec<usize>,
    vals: &mut Vec<[f64; 6]>,
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above), all `columns_avx2` requires.
        unsafe { columns_avx2(model, x_world_body, s_body, axes, contact, dim, cols, vals) };
        return;
    }
    columns_by_dim(model, x_world_body, s_body, axes, contact, dim, cols, vals);
}

/// [`columns_kernel`] compiled for AVX2: the same products and sums (Rust fuses no
/// multiply–add unasked), so the same bits, in fewer instructions (three-operand VEX forms,
/// no register copies).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[allow(clippy::too_many_arguments)]
unsafe fn columns_avx2(
    model: &Model,
    x_world_body: &[Transform],
    s_body: &[Motion],
    axes: &mut DofAxes,
    contact: &Contact,
    dim: usize,
    cols: &mut Vec<usize>,
    vals: &mut Vec<[f64; 6]>,
) {
    columns_by_dim(model, x_world_body, s_body, axes, contact, dim, cols, vals);
}

/// [`columns_kernel`] with condim 3 (MJCF's default) a constant: its copy forms only the three
/// linear rows, without the tests on `dim` per dof (the same values).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn columns_by_dim(
    model: &Model,
    x_world_body: &[Transform],
    s_body: &[Motion],
    axes: &mut DofAxes,
    contact: &Contact,
    dim: usize,
    cols: &mut Vec<usize>,
    vals: &mut Vec<[f64; 6]>,
) {
    if dim == 3 {
        columns_kernel(model, x_world_body, s_body, axes, contact, 3, cols, vals);
    } else {
        columns_kernel(model, x_world_body, s_body, axes, contact, dim, cols, vals);
    }
}

#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn columns_kernel(
    model: &Model,
    x_world_body: &[Transform],
    s_body: &[Motion],
    axes: &mut DofAxes,
    contact: &Contact,
    dim: usize,
    cols: &mut Vec<usize>,
    vals: &mut Vec<[f64; 6]>,
) {
    let p = contact.pos;
    let f = contact.frame;
    let dirs = [f.row(0).transpose(), f.row(1).transpose(), f.row(2).transpose()];
    let bodies = contact.geom.map(|g| model.geoms[g].body);
    // Bodies are numbered parents first: the path with the larger body index steps up until the
    // two meet (the bodies visited strictly descend, and with each joint's dofs taken last to
    // first so do the columns). The first walk counts the dofs, the second fills the columns
    // from the end: ascending without a reversal.
    let [mut a, mut b] = bodies;
    let mut count = 0;
    while a != b {
        let step = if a > b { &mut a } else { &mut b };
        count += model.joint_of(*step).kind.nv();
        *step = model.bodies[*step].parent;
    }
    cols.clear();
    cols.resize(count, 0);
    vals.clear();
    vals.resize(count, [0.0; 6]);
    let mut next = count;
    // Geom 1's body counts negative, geom 2's positive.
    let [mut a, mut b] = bodies;
    while a != b {
        let (step, sign) = if a > b { (&mut a, -1.0) } else { (&mut b, 1.0) };
        let body = *step;
        let j = model.joint_of(body);
        let x = &x_world_body[body];
        let r = p - x.pos;
        for k in (j.dof_adr..j.dof_adr + j.kind.nv()).rev() {
            let (ang, lin_origin) = axes.get(k, x, &s_body[k]);
            let lin = lin_origin + ang.cross(&r);
            let v = frame_values(&dirs, &lin, &ang, dim, sign);
            if v[..dim].iter().any(|&x| x != 0.0) {
                next -= 1;
                cols[next] = k;
                vals[next] = v;
            }
        }
        let parent = model.bodies[body].parent;
        debug_assert!(parent < body, "bodies are numbered parents first");
        *step = parent;
    }
    // Columns dropped as all zero left room at the front.
    if next > 0 {
        cols.copy_within(next.., 0);
        vals.copy_within(next.., 0);
        cols.truncate(count - next);
        vals.truncate(count - next);
    }
    debug_assert!(cols.windows(2).all(|w| w[0] < w[1]), "dofs are numbered in body order");
}
