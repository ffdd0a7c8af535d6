//! Constraint rows of equality constraints and mimic couplings: the [`ConstraintModel`] fixes, once
//! per model, which rows exist and the geometry they need (MuJoCo's `mj_setConst` takes the
//! missing anchors and relative poses at `qpos0`; MuJoCo documentation, "XML Reference →
//! equality"); [`ConstraintModel::positions`] and [`ConstraintModel::velocities`] fill the rows
//! `efc_j`, `efc_pos` (φ), `efc_vel` (J v) and `efc_jdotv` (J̇ v) at a state.
//!
//! Conventions (all vectors in world coordinates):
//! - connect: φ = p_A − p_B, the two anchor points; J = J_A − J_B (point Jacobians).
//! - weld: the 3 rows of connect for the frame origins, then φ_rot = s · R_B log(R_Bᵀ R_A) with
//!   J_rot = s · (J_ω,A − J_ω,B), s = `torquescale` (no rotation rows when s = 0). MuJoCo writes
//!   the rotation rows in quaternion form, `imag(q_B⁻¹ q_A)`; both vanish together and their
//!   Jacobians span the same rows, so the constrained acceleration is the same.
//! - joint / tendon / mimic: φ = x₁ − r₁ − P(x₂ − r₂), P(x) = a₀ + a₁x + … + a₄x⁴, with x the joint
//!   value or fixed-tendon length and r its reference (qpos0 for MJCF, 0 for a URDF mimic).

use super::contact::{contact_jdotv, contact_rows, CONTACT_ACTIVE_DISTANCE};
use super::friction_loss::FrictionRow;
use super::limits::LimitRow;
use crate::collision::{collide, CollisionModel, EXACT_REACH};
use crate::error::{check, InputError};
use crate::kinematics::body_poses;
use crate::kinematics::{
    bias_accelerations_unchecked, for_each_ancestor_dof_at, forward_kinematics_unchecked,
    forward_velocities_unchecked, point_bias_acceleration,
};
use crate::model::{Data, EfcType, EqualityKind, Model, TendonKind};
use crate::spatial::{Mat3, Transform, Vec3};

/// A scalar coordinate of a joint or tendon coupling: a hinge/slide joint, or a fixed tendon's
/// length Σ coef · q.
#[derive(Clone, Debug, PartialEq)]
pub enum ScalarCoord {
    /// A hinge or slide joint's value.
    Joint {
        /// Its index in `qpos`.
        qpos_adr: usize,
        /// Its index in `qvel`.
        dof_adr: usize,
    },
    /// A fixed tendon's length.
    Tendon {
        /// (qpos address, dof address, coefficient) of each joint of a fixed tendon.
        terms: Vec<(usize, usize, f64)>,
    },
}

impl ScalarCoord {
    fn value(&self, q: &[f64]) -> f64 {
        match self {
            ScalarCoord::Joint { qpos_adr, .. } => q[*qpos_adr],
            ScalarCoord::Tendon { terms } => terms.iter().map(|&(a, _, c)| c * q[a]).sum(),
        }
    }
    fn rate(&self, v: &[f64]) -> f64 {
        match self {
            ScalarCoord::Joint { dof_adr, .. } => v[*dof_adr],
            ScalarCoord::Tendon { terms } => terms.iter().map(|&(_, d, c)| c * v[d]).sum(),
        }
    }
    /// Adds `scale` · ∂x/∂q to a Jacobian row.
    fn add_jacobian(&self, scale: f64, mut row: impl FnMut(usize, f64)) {
        match self {
            ScalarCoord::Joint { dof_adr, .. } => row(*dof_adr, scale),
            ScalarCoord::Tendon { terms } => terms.iter().for_each(|&(_, d, c)| row(d, scale * c)),
        }
    }
}

/// The geometry of one equality constraint's rows, with everything fixed at `qpos0` resolved.
/// Bodies are compiled bodies (indices in `Model::bodies`), points and frames in their coordinates.
#[derive(Clone, Debug, PartialEq)]
pub enum RowGeometry {
    /// Point `r_a` of body `a` coincides with point `r_b` of body `b` (3 rows).
    Points {
        /// Body A (index in `Model::bodies`).
        a: usize,
        /// The point in body A's coordinates (m).
        r_a: Vec3,
        /// Body B (index in `Model::bodies`).
        b: usize,
        /// The point in body B's coordinates (m).
        r_b: Vec3,
    },
    /// Frame `x_a` of body `a` coincides with frame `x_b` of body `b` (3 + 3 rows; rotation rows
    /// scaled by `torquescale`, absent when it is 0).
    Frames {
        /// Body A (index in `Model::bodies`).
        a: usize,
        /// The frame's pose in body A.
        x_a: Transform,
        /// Body B (index in `Model::bodies`).
        b: usize,
        /// The frame's pose in body B.
        x_b: Transform,
        /// Scale of the rotation rows (MJCF `torquescale`).
        torquescale: f64,
    },
    /// x₁ − ref₁ = P(x₂ − ref₂) (1 row).
    Scalar {
        /// x₁: the constrained coordinate.
        first: ScalarCoord,
        /// x₂: the coordinate it follows (`None`: x₁ − ref₁ = a₀).
        second: Option<ScalarCoord>,
        /// The polynomial's coefficients a₀…a₄ (a URDF mimic: offset, multiplier, 0, 0, 0).
        polycoef: [f64; 5],
        /// x₁'s reference (its value at `qpos0`; 0 for a URDF mimic).
        ref1: f64,
        /// x₂'s reference (its value at `qpos0`; 0 for a URDF mimic or without `second`).
        ref2: f64,
    },
}

impl RowGeometry {
    fn nrow(&self) -> usize {
        match self {
            RowGeometry::Points { .. } => 3,
            RowGeometry::Frames { torquescale, .. } => {
                if *torquescale == 0.0 {
                    3
                } else {
                    6
                }
            }
            RowGeometry::Scalar { .. } => 1,
        }
    }
}

/// One equality constraint's rows.
#[derive(Clone, Debug, PartialEq)]
pub struct EqualityRows {
    /// Index in `Model::equalities`.
    pub id: usize,
    /// What its rows constrain.
    pub geometry: RowGeometry,
    /// For the two sides (a, b) of a connect or weld, the mocap body they are anchored on (their
    /// body is then the world and their anchor in the mocap body's frame), if any.
    pub mocap: [Option<usize>; 2],
}

impl EqualityRows {
    /// The world pose of side `side`'s (0: a, 1: b) body frame: its body's, or its mocap body's.
    pub(crate) fn side_pose(&self, data: &Data, side: usize, body: usize) -> Transform {
        match self.mocap[side] {
            Some(m) => data.mocap_pose(m),
            None => data.x_world_body[body],
        }
    }
}

/// Which constraint rows a model has and their fixed geometry (built once per model).
#[derive(Clone, Debug, Default)]
pub struct ConstraintModel {
    /// The geoms' collision shapes (contacts come from `Model::collision_pairs`).
    pub collision: CollisionModel,
    /// Equality constraints and URDF mimics with rows (all of them unless `<flag equality>` or
    /// `constraint` is off).
    pub equalities: Vec<EqualityRows>,
    /// Degrees of freedom with dry friction (`frictionloss`), one row each, always active.
    pub friction: Vec<FrictionRow>,
    /// Limited joints, one entry each (rows when a bound is within the margin).
    pub limits: Vec<LimitRow>,
    /// Tendons (fixed or spatial) with a length range: a row per bound within the tendon's
    /// margin, soft mode only (the exact mode has no tendon rows: `Plan::new` empties this list
    /// there and lists the limits as not simulated).
    pub tendon_limits: Vec<usize>,
    /// Tendons with dry friction (`frictionloss` > 0): one row each, always present, soft mode
    /// only (emptied by `Plan::new` in exact mode, like `tendon_limits`).
    pub tendon_friction: Vec<usize>,
}

/// P(x) and P′(x), P″(x) of MuJoCo's quartic `polycoef`.
fn poly(c: &[f64; 5], x: f64) -> (f64, f64, f64) {
    let p = c[0] + x * (c[1] + x * (c[2] + x * (c[3] + x * c[4])));
    let dp = c[1] + x * (2.0 * c[2] + x * (3.0 * c[3] + x * 4.0 * c[4]));
    let ddp = 2.0 * c[2] + x * (6.0 * c[3] + x * 12.0 * c[4]);
    (p, dp, ddp)
}

/// log(R): the rotation vector of a rotation matrix, through its quaternion (closed form) as
/// θ n = 2 atan2(|v|, w) v/|v| — finite at and near the identity, where `acos` of the trace is
/// not (a trace rounded above 3 gives NaN).
fn rotation_vector(r: &Mat3) -> Vec3 {
    let [w, x, y, z] = Transform::new(*r, Vec3::zeros()).quat_wxyz();
    let v = Vec3::new(x, y, z);
    let s = v.norm();
    if s < 1e-8 {
        // 2 atan2(s, w)/s = 2/w (1 − s²/(3w²) + …): the series to round-off.
        v * (2.0 / w) * (1.0 - s * s / (3.0 * w * w))
    } else {
        v * (2.0 * s.atan2(w) / s)
    }
}

impl ConstraintModel {
    /// The rows of `model`'s equality constraints (those switched off by `<flag equality>` and
    /// all of them when `<flag constraint>` is off are left out). Anchors and relative poses that
    /// the file leaves to `qpos0` are taken there (forward kinematics on a scratch `Data`).
    pub fn new(model: &Model) -> Self {
        let flags = &model.options.flags;
        if !flags.constraint {
            return Self::default();
        }
        let collision = if model.collision_pairs.is_empty() {
            CollisionModel::default()
        } else {
            CollisionModel::new(model)
        };
        let limits = if flags.limit {
            (0..model.joints.len()).filter_map(|j| LimitRow::of_joint(model, j)).collect()
        } else {
            Vec::new()
        };
        let tendon_limits = if flags.limit {
            (0..model.tendons.len()).filter(|&t| model.tendons[t].range.is_some()).collect()
        } else {
            Vec::new()
        };
        let friction = if flags.frictionloss { FrictionRow::of_model(model) } else { Vec::new() };
        let tendon_friction = if flags.frictionloss {
            (0..model.tendons.len()).filter(|&t| model.tendons[t].frictionloss > 0.0).collect()
        } else {
            Vec::new()
        };
        if model.equalities.is_empty() || !flags.equality {
            return Self {
                collision,
                equalities: Vec::new(),
                friction,
                limits,
                tendon_limits,
                tendon_friction,
            };
        }
        let mut data = Data::new(model);
        forward_kinematics_unchecked(model, &mut data, &model.qpos0);
        let frame = |f: usize| {
            let fr = &model.frames[f];
            (fr.body, fr.x_body_frame, data.x_world_frame[f])
        };
        let frame_mocap = |f: usize| model.frames[f].mocap;
        let scalar_joint = |j: usize| {
            let jt = &model.joints[j];
            ScalarCoord::Joint { qpos_adr: jt.qpos_adr, dof_adr: jt.dof_adr }
        };
        let scalar_tendon = |t: usize| match &model.tendons[t].kind {
            TendonKind::Fixed { joints } => ScalarCoord::Tendon {
                terms: joints
                    .iter()
                    .map(|&(j, c)| (model.joints[j].qpos_adr, model.joints[j].dof_adr, c))
                    .collect(),
            },
            // The loader refuses equalities on spatial tendons; an empty coordinate is inert.
            TendonKind::Spatial { .. } => ScalarCoord::Tendon { terms: Vec::new() },
        };
        let mut equalities = Vec::with_capacity(model.equalities.len());
        for (id, eq) in model.equalities.iter().enumerate() {
            let geometry = match &eq.kind {
                EqualityKind::Connect { frame1, frame2, anchor } => {
                    let (a, x_a1, x_w1) = frame(*frame1);
                    let (b, x_b2, _) = frame(*frame2);
                    match anchor {
                        Some(p) => {
                            let p1 = Vec3::from(*p);
                            let p_world = x_w1.act_point(&p1);
                            let x_world_b = match frame_mocap(*frame2) {
                                Some(m) => data.mocap_pose(m),
                                None => data.x_world_body[b],
                            };
                            let r_b = x_world_b.inverse().act_point(&p_world);
                            RowGeometry::Points { a, r_a: x_a1.act_point(&p1), b, r_b }
                        }
                        None => RowGeometry::Points { a, r_a: x_a1.pos, b, r_b: x_b2.pos },
                    }
                }
                EqualityKind::Weld { frame1, frame2, anchor, relpose, torquescale, sites } => {
                    let (a, x_a1, x_w1) = frame(*frame1);
                    let (b, x_b2, x_w2) = frame(*frame2);
                    let (x_a, x_b) = if *sites {
                        (x_a1, x_b2)
                    } else {
                        // Frame B: body2's frame moved to the anchor; frame A: where B must be in
                        // body1's frame (relpose, or B's pose in frame1 at qpos0).
                        let x_2_anchor = Transform::from_translation(Vec3::from(*anchor));
                        let x_1_target = match relpose {
                            Some(x) => *x,
                            None => x_w1.inverse() * (x_w2 * x_2_anchor),
                        };
                        (x_a1 * x_1_target, x_b2 * x_2_anchor)
                    };
                    RowGeometry::Frames { a, x_a, b, x_b, torquescale: *torquescale }
                }
                EqualityKind::Joint { joint1, joint2, polycoef } => {
                    let q0 = |j: usize| model.qpos0[model.joints[j].qpos_adr];
                    RowGeometry::Scalar {
                        first: scalar_joint(*joint1),
                        second: joint2.map(scalar_joint),
                        polycoef: *polycoef,
                        ref1: q0(*joint1),
                        ref2: joint2.map_or(0.0, q0),
                    }
                }
                EqualityKind::Tendon { tendon1, tendon2, polycoef } => {
                    let first = scalar_tendon(*tendon1);
                    let second = tendon2.map(scalar_tendon);
                    let ref1 = first.value(&model.qpos0);
                    let ref2 = second.as_ref().map_or(0.0, |s| s.value(&model.qpos0));
                    RowGeometry::Scalar { first, second, polycoef: *polycoef, ref1, ref2 }
                }
                EqualityKind::Mimic { joint, leader, multiplier, offset } => RowGeometry::Scalar {
                    first: scalar_joint(*joint),
                    second: Some(scalar_joint(*leader)),
                    polycoef: [*offset, *multiplier, 0.0, 0.0, 0.0],
                    ref1: 0.0,
                    ref2: 0.0,
                },
            };
            let mocap = match &eq.kind {
                EqualityKind::Connect { frame1, frame2, .. } | EqualityKind::Weld { frame1, frame2, .. } => {
                    [frame_mocap(*frame1), frame_mocap(*frame2)]
                }
                _ => [None, None],
            };
            equalities.push(EqualityRows { id, geometry, mocap });
        }
        Self { collision, equalities, friction, limits, tendon_limits, tendon_friction }
    }

    /// Whether the model has no constraint rows at all (no equality, friction loss, joint or
    /// tendon limit, nor candidate collision pair).
    pub fn is_empty(&self) -> bool {
        self.equalities.is_empty()
            && self.friction.is_empty()
            && self.limits.is_empty()
            && self.tendon_limits.is_empty()
            && self.tendon_friction.is_empty()
            && !self.has_collision()
    }

    /// Whether the model has candidate collision pairs (a collision pass each `forward`).
    pub fn has_collision(&self) -> bool {
        !self.collision.shapes.is_empty()
    }

    /// The contacts at configuration `q` into `Data::contacts` (body poses first), if the model
    /// has candidate pairs; returns whether any touches (a row in exact mode).
    ///
    /// # Errors
    /// [`InputError::Length`] when q is not nq long or `data` was made for another model.
    pub fn collide(&self, model: &Model, data: &mut Data, q: &[f64]) -> Result<bool, InputError> {
        check::data("ConstraintModel::collide", model, data)?;
        check::q("ConstraintModel::collide", model, q)?;
        data.poses_stamp.clear();
        data.velocity_stamp.clear();
        Ok(self.collide_unchecked(model, data, q))
    }

    /// [`collide`](Self::collide) without the argument checks.
    pub(crate) fn collide_unchecked(&self, model: &Model, data: &mut Data, q: &[f64]) -> bool {
        if !self.has_collision() {
            return false;
        }
        body_poses(model, data, q);
        collide(model, &self.collision, data, EXACT_REACH);
        data.contacts.iter().any(|c| c.dist <= CONTACT_ACTIVE_DISTANCE || data.contact_is_frozen(c))
    }

    /// Whether any row other than a contact's is active at configuration `q`: an active equality,
    /// a friction-loss row, or a joint at or beyond a limit. Cheap (no kinematics): `forward`
    /// takes the ABA path when none is (and no contact touches).
    pub(crate) fn any_active(&self, data: &Data, q: &[f64]) -> bool {
        !self.friction.is_empty()
            || self.equalities.iter().any(|e| data.eq_active[e.id])
            || self.limits.iter().any(|l| l.row(data, q).is_some())
    }

    /// Rows of the active constraints at configuration `q` in MuJoCo's order — equality, dof
    /// friction, limits, contacts (from `Data::contacts`, which the caller fills at the same q):
    /// `nefc`, `efc_id`, `efc_type`, `efc_j`, `efc_pos`. Equality rows come first (the solvers rely
    /// on it). With `full` false only the rows with a position meaning are written (equalities,
    /// limits, contact normals: the position projection). Needs body poses and motion subspaces at
    /// q (forward kinematics, or CRBA's first pass).
    ///
    /// # Errors
    /// [`InputError::Length`] when q is not nq long or `data` was made for another model.
    pub fn positions(&self, model: &Model, data: &mut Data, q: &[f64], full: bool) -> Result<(), InputError> {
        check::data("ConstraintModel::positions", model, data)?;
        check::q("ConstraintModel::positions", model, q)?;
        self.positions_unchecked(model, data, q, full);
        Ok(())
    }

    /// [`positions`](Self::positions) without the argument checks.
    pub(crate) fn positions_unchecked(&self, model: &Model, data: &mut Data, q: &[f64], full: bool) {
        // The soft mode's record of J's nonzeros no longer describes efc_j (soft/jacobian.rs).
        data.soft.j_recorded = false;
        let mut r = self.equality_rows(model, data, q);
        if full {
            for f in &self.friction {
                f.write_row(data, r);
                r += 1;
            }
        }
        for l in &self.limits {
            if let Some((dir, dist)) = l.row(data, q) {
                l.write_row(data, r, &dir, dist);
                r += 1;
            }
        }
        data.nefc = contact_rows(model, data, r, full);
    }

    /// The rows of the active equality constraints from row 0 on (`efc_id`, `efc_type`, `efc_j`,
    /// `efc_pos`); returns the number of rows. Weld rotation rows in rotation-vector form (module
    /// doc).
    pub(crate) fn equality_rows(&self, model: &Model, data: &mut Data, q: &[f64]) -> usize {
        let mut r = 0;
        for e in &self.equalities {
            if !data.sleep.equality_has_rows(model, e.id, data.eq_active[e.id]) {
                continue;
            }
            let n = e.geometry.nrow();
            for i in r..r + n {
                data.efc_id[i] = e.id;
                data.efc_type[i] = EfcType::Equality;
                // Row i of J cleared through its storage (every nrows-th entry): no index
                // checks per entry.
                let stride = data.efc_j.nrows();
                for x in data.efc_j.as_mut_slice()[i..].iter_mut().step_by(stride) {
                    *x = 0.0;
                }
            }
            match &e.geometry {
                RowGeometry::Points { a, r_a, b, r_b } => {
                    let p_a = e.side_pose(data, 0, *a).act_point(r_a);
                    let p_b = e.side_pose(data, 1, *b).act_point(r_b);
                    let phi = p_a - p_b;
                    for k in 0..3 {
                        data.efc_pos[r + k] = phi[k];
                    }
                    point_rows(model, data, r, *a, &p_a, 1.0, 1.0, false);
                    point_rows(model, data, r, *b, &p_b, -1.0, 1.0, false);
                }
                RowGeometry::Frames { a, x_a, b, x_b, torquescale } => {
                    let x_wa = e.side_pose(data, 0, *a) * *x_a;
                    let x_wb = e.side_pose(data, 1, *b) * *x_b;
                    let phi = x_wa.pos - x_wb.pos;
                    for k in 0..3 {
                        data.efc_pos[r + k] = phi[k];
                    }
                    let rotation = n == 6;
                    if rotation {
                        let phi_rot =
                            x_wb.rot * rotation_vector(&(x_wb.rot.transpose() * x_wa.rot)) * *torquescale;
                        for k in 0..3 {
                            data.efc_pos[r + 3 + k] = phi_rot[k];
                        }
                    }
                    point_rows(model, data, r, *a, &x_wa.pos, 1.0, *torquescale, rotation);
                    point_rows(model, data, r, *b, &x_wb.pos, -1.0, *torquescale, rotation);
                }
                RowGeometry::Scalar { first, second, polycoef, ref1, ref2 } => {
                    let (p, dp) = match second {
                        Some(s) => {
                            let (p, dp, _) = poly(polycoef, s.value(q) - ref2);
                            (p, dp)
                        }
                        None => (polycoef[0], 0.0),
                    };
                    data.efc_pos[r] = first.value(q) - ref1 - p;
                    let mut row = data.efc_j.row_mut(r);
                    first.add_jacobian(1.0, |d, c| row[d] += c);
                    if let Some(s) = second {
                        s.add_jacobian(-dp, |d, c| row[d] += c);
                    }
                }
            }
            r += n;
        }
        r
    }

    /// `efc_vel` = J v and `efc_jdotv` = J̇ v of the rows of [`positions`](Self::positions) at the
    /// same q. Needs the body velocities (`v_body`, e.g. from RNEA or `forward_velocities`);
    /// computes the bias accelerations itself.
    pub(crate) fn velocities(&self, model: &Model, data: &mut Data, q: &[f64], v: &[f64]) {
        bias_accelerations_unchecked(model, data, v);
        let mut r = 0;
        for e in &self.equalities {
            if !data.sleep.equality_has_rows(model, e.id, data.eq_active[e.id]) {
                continue;
            }
            let n = e.geometry.nrow();
            match &e.geometry {
                RowGeometry::Points { a, r_a, b, r_b } => {
                    let (va, aa, _) = point_motion(data, *a, r_a);
                    let (vb, ab, _) = point_motion(data, *b, r_b);
                    for k in 0..3 {
                        data.efc_vel[r + k] = va[k] - vb[k];
                        data.efc_jdotv[r + k] = aa[k] - ab[k];
                    }
                }
                RowGeometry::Frames { a, x_a, b, x_b, torquescale } => {
                    let (va, aa, (wa, alpha_a)) = point_motion(data, *a, &x_a.pos);
                    let (vb, ab, (wb, alpha_b)) = point_motion(data, *b, &x_b.pos);
                    for k in 0..3 {
                        data.efc_vel[r + k] = va[k] - vb[k];
                        data.efc_jdotv[r + k] = aa[k] - ab[k];
                    }
                    if n == 6 {
                        for k in 0..3 {
                            data.efc_vel[r + 3 + k] = torquescale * (wa[k] - wb[k]);
                            data.efc_jdotv[r + 3 + k] = torquescale * (alpha_a[k] - alpha_b[k]);
                        }
                    }
                }
                RowGeometry::Scalar { first, second, polycoef, ref2, .. } => {
                    let (dp, ddp, rate2) = match second {
                        Some(s) => {
                            let (_, dp, ddp) = poly(polycoef, s.value(q) - ref2);
                            (dp, ddp, s.rate(v))
                        }
                        None => (0.0, 0.0, 0.0),
                    };
                    data.efc_vel[r] = first.rate(v) - dp * rate2;
                    data.efc_jdotv[r] = -ddp * rate2 * rate2;
                }
            }
            r += n;
        }
        // Friction, limit and contact rows: J v from the row itself, J̇ v by kind.
        while r < data.nefc {
            data.efc_vel[r] = (0..model.nv).map(|k| data.efc_j[(r, k)] * v[k]).sum();
            match data.efc_type[r] {
                EfcType::Equality | EfcType::FrictionDof | EfcType::FrictionTendon | EfcType::LimitTendon => {
                    data.efc_jdotv[r] = 0.0
                }
                EfcType::LimitJoint => {
                    let joint = data.efc_id[r];
                    let l = self.limits.iter().find(|l| l.joint == joint);
                    data.efc_jdotv[r] = l.map_or(0.0, |l| l.jdotv_unchecked(q, v));
                }
                EfcType::ContactFrictionless | EfcType::ContactElliptic | EfcType::ContactPyramidal => {
                    let dim = data.efc_block_len(r);
                    for i in r + 1..r + dim {
                        data.efc_vel[i] = (0..model.nv).map(|k| data.efc_j[(i, k)] * v[k]).sum();
                    }
                    contact_jdotv(model, data, r, dim, data.efc_id[r]);
                    r += dim;
                    continue;
                }
            }
            r += 1;
        }
    }

    /// Rows, `J v` and `J̇ v` at (q, v) from scratch: forward kinematics, body velocities, then
    /// [`positions`](Self::positions) and `velocities`.
    ///
    /// # Errors
    /// [`InputError::Length`] when q is not nq long, v not nv long, or `data` was made for
    /// another model.
    pub fn evaluate(&self, model: &Model, data: &mut Data, q: &[f64], v: &[f64]) -> Result<(), InputError> {
        check::data("ConstraintModel::evaluate", model, data)?;
        check::q("ConstraintModel::evaluate", model, q)?;
        check::v("ConstraintModel::evaluate", "v", model, v)?;
        data.poses_stamp.clear();
        data.velocity_stamp.clear();
        self.evaluate_unchecked(model, data, q, v);
        Ok(())
    }

    /// [`evaluate`](Self::evaluate) without the argument checks.
    pub(crate) fn evaluate_unchecked(&self, model: &Model, data: &mut Data, q: &[f64], v: &[f64]) {
        self.collide_unchecked(model, data, q);
        forward_kinematics_unchecked(model, data, q);
        forward_velocities_unchecked(model, data, v);
        self.positions_unchecked(model, data, q, true);
        self.velocities(model, data, q, v);
    }
}

/// Velocity and bias acceleration (world) of point `r_body` of body `b`, and the body's world
/// angular velocity and angular bias acceleration.
pub(crate) fn point_motion(data: &Data, b: usize, r_body: &Vec3) -> (Vec3, Vec3, (Vec3, Vec3)) {
    let vb = &data.v_body[b];
    let rot = &data.x_world_body[b].rot;
    let v_point = rot * (vb.lin + vb.ang.cross(r_body));
    let (a_point, alpha) = point_bias_acceleration(data, b, r_body);
    (v_point, a_point, (rot * vb.ang, alpha))
}

/// Adds `sign` × the point Jacobian of world point `p` on body `b` to rows r..r+3 of `efc_j`, and
/// with `rotation`, `sign · scale` × the angular Jacobian to rows r+3..r+6.
#[allow(clippy::too_many_arguments)]
fn point_rows(
    model: &Model,
    data: &mut Data,
    r: usize,
    b: usize,
    p: &Vec3,
    sign: f64,
    scale: f64,
    rotation: bool,
) {
    let Data { efc_j, x_world_body, s_body, .. } = data;
    for_each_ancestor_dof_at(model, x_world_body, s_body, b, p, |k, lin, ang| {
        for i in 0..3 {
            efc_j[(r + i, k)] += sign * lin[i];
            if rotation {
                efc_j[(r + 3 + i, k)] += sign * scale * ang[i];
            }
        }
    });
}
