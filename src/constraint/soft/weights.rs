//! The inverse weights of the soft constraint model, fixed at `qpos0` (MuJoCo's `mj_setConst`;
//! MuJoCo documentation, "Computation → Soft constraints": the regularizer R scales with an
//! approximation of the diagonal of J M⁻¹ Jᵀ built from these):
//!
//! - `body_invweight0` of every MuJoCo body (an MJCF body, fused or not): with J the 6 × nv
//!   Jacobian of its centre of mass (linear rows of the point, angular rows), A = J M⁻¹ Jᵀ at
//!   `qpos0`; the translational weight is the mean of A's first three diagonal entries, the
//!   rotational one the mean of the last three; zero for bodies welded to the world;
//! - `dof_invweight0`: (M⁻¹)_dd for a hinge or slide, the mean of the three diagonal entries of
//!   its block for a ball, and of the translational and rotational blocks for a free joint;
//! - `tendon_invweight0`: J_t M⁻¹ J_tᵀ of a tendon (J_t its `ten_J` row at `qpos0`);
//! - `meaninertia`: the mean of M's diagonal at `qpos0`, which scales the solvers' tolerance.

use crate::dynamics::{crba_unchecked, factorize_mass_matrix, solve_with_factor_span_unchecked, tree_span};
use crate::kinematics::{for_each_ancestor_dof, forward_kinematics_unchecked};
use crate::model::{Data, FrameKind, JointKind, Model};
use crate::spatial::Vec3;

/// The soft model's constants of one model.
#[derive(Clone, Debug, Default)]
pub struct InverseWeights {
    /// Per frame of kind `Link` (indexed by frame): [translational, rotational] weight of that
    /// MuJoCo body; zero for other frames.
    pub frame_invweight0: Vec<[f64; 2]>,
    /// Per geom: the index of the frame of its MuJoCo body.
    pub geom_frame: Vec<usize>,
    /// Per dof: its inverse weight at `qpos0` (MuJoCo's `dof_invweight0`).
    pub dof_invweight0: Vec<f64>,
    /// Per tendon: J_t M⁻¹ J_tᵀ at `qpos0` (MuJoCo's `tendon_invweight0`).
    pub tendon_invweight0: Vec<f64>,
    /// The mean of M's diagonal at `qpos0` (MuJoCo's `meaninertia`).
    pub meaninertia: f64,
}

impl InverseWeights {
    /// The weights of `model` at `qpos0`.
    pub fn new(model: &Model) -> Self {
        let nv = model.nv;
        let mut data = Data::scratch(model);
        forward_kinematics_unchecked(model, &mut data, &model.qpos0);
        crba_unchecked(model, &mut data, &model.qpos0);
        factorize_mass_matrix(model, &mut data);
        // The tendons' ten_J rows at qpos0 (forward kinematics above is at qpos0).
        crate::tendon::lengths_and_jacobians(model, &mut data, &model.qpos0);
        let tendon_rows: Vec<Vec<f64>> =
            (0..model.tendons.len()).map(|t| data.ten_j.row(t).iter().copied().collect()).collect();
        let meaninertia =
            if nv > 0 { (0..nv).map(|k| data.mass_matrix[(k, k)]).sum::<f64>() / nv as f64 } else { 1.0 };
        let mut form = QuadraticForm { model, factor: &data.mass_factor, y: vec![0.0; nv] };
        let mut frame_invweight0 = vec![[0.0; 2]; model.frames.len()];
        let mut simple_dofs: Vec<(usize, f64)> = Vec::new();
        // A body's 6 Jacobian rows, zero outside the dofs written last.
        let mut rows = vec![vec![0.0; nv]; 6];
        for (f, frame) in model.frames.iter().enumerate() {
            if frame.kind != FrameKind::Link || frame.body == 0 {
                continue;
            }
            if let Some(dofs) = simple_slider(model, &data, f) {
                // MuJoCo's "simple" body: its weights are those of a free point mass.
                let w = 1.0 / frame.inertia.mass.max(1e-15);
                frame_invweight0[f] = [w, 0.0];
                simple_dofs.extend(dofs.into_iter().map(|d| (d, w)));
                continue;
            }
            let x = data.x_world_frame[f];
            let com = if frame.inertia.mass > 0.0 { x.act_point(&frame.inertia.com()) } else { x.pos };
            let (mut first, mut last) = (usize::MAX, 0);
            for_each_ancestor_dof(model, &data.x_world_body, &data.s_body, frame.body, |k, s| {
                let lin: Vec3 = s.lin + s.ang.cross(&com);
                for i in 0..3 {
                    rows[i][k] = lin[i];
                    rows[3 + i][k] = s.ang[i];
                }
                (first, last) = (first.min(k), last.max(k));
            });
            if first > last {
                continue;
            }
            let a: [f64; 6] = std::array::from_fn(|i| form.of(&rows[i], first, last));
            frame_invweight0[f] = [(a[0] + a[1] + a[2]) / 3.0, (a[3] + a[4] + a[5]) / 3.0];
            for r in &mut rows {
                r[first..=last].fill(0.0);
            }
        }
        let mut unit = vec![0.0; nv];
        let mut dof_invweight0 = vec![0.0; nv];
        for j in &model.joints {
            let d = j.dof_adr;
            let a: Vec<f64> = (d..d + j.kind.nv())
                .map(|k| {
                    unit[k] = 1.0;
                    let w = form.of(&unit, k, k);
                    unit[k] = 0.0;
                    w
                })
                .collect();
            match j.kind {
                JointKind::Free => {
                    let (t, r) = ((a[0] + a[1] + a[2]) / 3.0, (a[3] + a[4] + a[5]) / 3.0);
                    dof_invweight0[d..d + 3].fill(t);
                    dof_invweight0[d + 3..d + 6].fill(r);
                }
                JointKind::Ball => dof_invweight0[d..d + 3].fill((a[0] + a[1] + a[2]) / 3.0),
                _ => dof_invweight0[d..d + a.len()].copy_from_slice(&a),
            }
        }
        for (d, w) in simple_dofs {
            dof_invweight0[d] = w;
        }
        let tendon_invweight0 = tendon_rows
            .iter()
            .map(|r| match (r.iter().position(|&a| a != 0.0), r.iter().rposition(|&a| a != 0.0)) {
                (Some(first), Some(last)) => form.of(r, first, last),
                _ => 0.0,
            })
            .collect();
        let geom_frame = model.geoms.iter().map(|g| body_frame(model, g.body, Some(&g.link))).collect();
        Self { frame_invweight0, geom_frame, dof_invweight0, tendon_invweight0, meaninertia }
    }

    /// [translational, rotational] weight of the MuJoCo body of frame `f` (a body or a site).
    pub fn of_frame(&self, model: &Model, f: usize) -> [f64; 2] {
        let frame = &model.frames[f];
        let link = if frame.kind == FrameKind::Link { f } else { body_frame(model, frame.body, None) };
        self.frame_invweight0[link]
    }
}

/// The frame of the MuJoCo body on compiled body `b`: the link named `name` if given, else the
/// body's first link frame (a site's MJCF body is the body it is on unless a jointless child body
/// was fused into it; the weights are the same up to the fused body's centre of mass).
fn body_frame(model: &Model, b: usize, name: Option<&str>) -> usize {
    let links = || model.frames.iter().enumerate().filter(|(_, f)| f.kind == FrameKind::Link && f.body == b);
    name.and_then(|n| links().find(|(_, f)| f.name == n).map(|(i, _)| i))
        .or_else(|| links().next().map(|(i, _)| i))
        .unwrap_or(0)
}

/// The dofs of the MuJoCo body of link frame `f` if MuJoCo treats it as a "simple" body with
/// sliders only (its `body_simple` = 2, whose weights are 1/mass): its centre of mass and
/// principal axes are the body frame's, it hangs from the world (or a body welded to it), it has
/// no child bodies, and its joints are slides along body-frame coordinate axes.
fn simple_slider(model: &Model, data: &Data, f: usize) -> Option<Vec<usize>> {
    let frame = &model.frames[f];
    let b = frame.body;
    let i = frame.inertia.i_com();
    let inertia_aligned = (0..3).all(|r| (0..3).all(|c| r == c || i[(r, c)].abs() <= 1e-12 * i.norm()));
    if frame.inertia.mass <= 0.0 || frame.inertia.com().norm() > 1e-12 || !inertia_aligned {
        return None;
    }
    let has_link = |body: usize| model.frames.iter().any(|g| g.kind == FrameKind::Link && g.body == body);
    // The compiled chain of this body's joints: b and the link-less bodies above it.
    let mut chain = vec![b];
    let mut top = b;
    while model.bodies[top].parent != 0 && !has_link(model.bodies[top].parent) {
        top = model.bodies[top].parent;
        chain.push(top);
    }
    let only_link =
        model.frames.iter().enumerate().all(|(g, fr)| g == f || fr.kind != FrameKind::Link || fr.body != b);
    let childless = model.bodies.iter().all(|body| body.parent != b);
    if model.bodies[top].parent != 0 || !only_link || !childless {
        return None;
    }
    let rot_world_link = data.x_world_frame[f].rot;
    let mut dofs = Vec::new();
    for &c in &chain {
        let j = model.joint_of(c);
        if !matches!(j.kind, JointKind::Prismatic { .. }) {
            return None;
        }
        let axis = rot_world_link.transpose() * data.s_world[j.dof_adr].lin;
        if (0..3).filter(|&k| axis[k].abs() > 1e-10).count() != 1 {
            return None;
        }
        dofs.push(j.dof_adr);
    }
    Some(dofs)
}

/// r M⁻¹ rᵀ with the mass matrix factor at `qpos0`, for rows that are zero outside dofs
/// `first ..= last`: solved on the span of the trees those dofs belong to (M⁻¹ rᵀ is zero
/// outside it), the full solve's arithmetic on those dofs in time proportional to the span, so
/// that a scene of many free bodies compiles in time linear in them.
struct QuadraticForm<'a> {
    model: &'a Model,
    factor: &'a nalgebra::DMatrix<f64>,
    /// nv numbers, zero between calls.
    y: Vec<f64>,
}

impl QuadraticForm<'_> {
    fn of(&mut self, r: &[f64], first: usize, last: usize) -> f64 {
        let (lo, hi) = tree_span(self.model, first, last);
        let y = &mut self.y;
        y[lo..hi].copy_from_slice(&r[lo..hi]);
        solve_with_factor_span_unchecked(self.model, self.factor, y, (lo, hi));
        let q = r[lo..hi].iter().zip(&y[lo..hi]).map(|(a, b)| a * b).sum();
        y[lo..hi].fill(0.0);
        q
    }
}
