//! Joint limits as unilateral rows (MuJoCo documentation, "Computation → Constraint model →
//! Limits"; MuJoCo's `mj_instantiateLimit`): a row exists while a joint is at or beyond a bound.
//!
//! - hinge / slide: distance `q − lower` with J = +e_dof at the lower bound, `upper − q` with
//!   J = −e_dof at the upper bound (one side at a time); J̇ = 0.
//! - ball: a cone on the rotation angle θ = |log(q)| (MuJoCo: the limit is on the angle of the
//!   joint's rotation, the larger `range` entry is the cone's half-angle): distance θ_max − θ with
//!   J = −nᵀ on the three body-frame angular-velocity dofs, n the rotation axis, since
//!   θ̇ = nᵀ ω for the body-frame ω (the right Jacobian of SO(3) maps n to itself). Its J̇v is
//!   −½ cot(θ/2) |n × ω|² (the derivative of n along the motion, ṅ = (J_r⁻¹ ω − n θ̇)/θ).
//!
//! Negative distance is penetration; the row's force is λ ≥ 0 (complementarity in the solver).

use crate::error::InputError;
use crate::model::{Data, JointKind, Model};
use crate::spatial::Vec3;

/// Distance (rad or m) within which a limit row is active: the position projection leaves q on
/// the bound only up to round-off, and the velocity projection that follows must still see it.
pub const LIMIT_ACTIVE_DISTANCE: f64 = 1e-10;

/// Below this rotation angle (rad) a ball joint's axis is undefined; a cone limit that small is
/// refused by nobody but is never active there (θ_max ≥ this in any sensible model).
const BALL_AXIS_EPS: f64 = 1e-12;

/// Which kind of limit a joint has.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LimitKind {
    /// A hinge or slide joint with `[lower, upper]`.
    Scalar {
        /// `[lower, upper]` (rad or m).
        range: [f64; 2],
    },
    /// A ball joint whose rotation angle may not exceed `max_angle` (rad).
    Cone {
        /// The cone's half-angle (rad).
        max_angle: f64,
    },
}

/// A limited joint: a unilateral row when it reaches a bound.
#[derive(Clone, Debug, PartialEq)]
pub struct LimitRow {
    /// Index in `Model::joints`.
    pub joint: usize,
    /// The joint's first index in `qpos`.
    pub qpos_adr: usize,
    /// The joint's first index in `qvel`.
    pub dof_adr: usize,
    /// Its bounds.
    pub kind: LimitKind,
    /// The model's nq and nv (the lengths of the configurations and velocities it reads).
    nq: usize,
    nv: usize,
}

impl LimitRow {
    /// The limit row of joint `j` of `model`, if it is limited (hinge, slide or ball).
    pub fn of_joint(model: &Model, j: usize) -> Option<Self> {
        let joint = model.joints.get(j)?;
        let range = joint.limits?;
        let kind = match joint.kind {
            JointKind::Ball => LimitKind::Cone { max_angle: range[0].max(range[1]) },
            _ if joint.kind.nv() == 1 => LimitKind::Scalar { range },
            _ => return None,
        };
        Some(Self {
            joint: j,
            qpos_adr: joint.qpos_adr,
            dof_adr: joint.dof_adr,
            kind,
            nq: model.nq,
            nv: model.nv,
        })
    }

    /// The active side at configuration `q`: (row direction, distance), the direction being the
    /// J row over the joint's dofs (one entry for hinge/slide, the three of the ball), or None
    /// while the joint is inside its range (distance > [`LIMIT_ACTIVE_DISTANCE`]).
    ///
    /// # Errors
    /// [`InputError::Length`] when q is not nq long.
    pub fn active(&self, q: &[f64]) -> Result<Option<(Vec3, f64)>, InputError> {
        InputError::check_len("LimitRow::active", "q", q.len(), self.nq, "nq")?;
        Ok(self.active_unchecked(q))
    }

    /// [`active`](Self::active) without the length check.
    pub(crate) fn active_unchecked(&self, q: &[f64]) -> Option<(Vec3, f64)> {
        match self.kind {
            LimitKind::Scalar { range } => {
                let x = q[self.qpos_adr];
                let (lower, upper) = (x - range[0], range[1] - x);
                if lower <= LIMIT_ACTIVE_DISTANCE {
                    Some((Vec3::new(1.0, 0.0, 0.0), lower))
                } else if upper <= LIMIT_ACTIVE_DISTANCE {
                    Some((Vec3::new(-1.0, 0.0, 0.0), upper))
                } else {
                    None
                }
            }
            LimitKind::Cone { max_angle } => {
                let (angle, axis) = quat_angle_axis(&q[self.qpos_adr..self.qpos_adr + 4]);
                let dist = max_angle - angle;
                (dist <= LIMIT_ACTIVE_DISTANCE && angle > BALL_AXIS_EPS).then_some((-axis, dist))
            }
        }
    }

    /// The row of the nearer side at configuration `q`, active or not: (direction, distance).
    pub(crate) fn nearest(&self, q: &[f64]) -> (Vec3, f64) {
        match self.kind {
            LimitKind::Scalar { range } => {
                let x = q[self.qpos_adr];
                let (lower, upper) = (x - range[0], range[1] - x);
                if lower <= upper {
                    (Vec3::new(1.0, 0.0, 0.0), lower)
                } else {
                    (Vec3::new(-1.0, 0.0, 0.0), upper)
                }
            }
            LimitKind::Cone { max_angle } => {
                let (angle, axis) = quat_angle_axis(&q[self.qpos_adr..self.qpos_adr + 4]);
                (-axis, max_angle - angle)
            }
        }
    }

    /// The row at configuration `q` as [`Data`]'s rows are chosen: by [`active`](Self::active), or,
    /// while the step's rows are frozen and the joint's row is among them, the nearer side.
    pub(crate) fn row(&self, data: &Data, q: &[f64]) -> Option<(Vec3, f64)> {
        self.active_unchecked(q).or_else(|| data.lifecycle.keeps_limit(self.joint).then(|| self.nearest(q)))
    }

    /// Number of dofs the row spans.
    pub fn ndof(&self) -> usize {
        match self.kind {
            LimitKind::Scalar { .. } => 1,
            LimitKind::Cone { .. } => 3,
        }
    }

    /// J̇ v of the active row with direction `dir` at (q, v) (0 for hinge and slide).
    ///
    /// # Errors
    /// [`InputError::Length`] when q is not nq long or v not nv long.
    pub fn jdotv(&self, q: &[f64], v: &[f64]) -> Result<f64, InputError> {
        InputError::check_len("LimitRow::jdotv", "q", q.len(), self.nq, "nq")?;
        InputError::check_len("LimitRow::jdotv", "v", v.len(), self.nv, "nv")?;
        Ok(self.jdotv_unchecked(q, v))
    }

    /// [`jdotv`](Self::jdotv) without the length checks.
    pub(crate) fn jdotv_unchecked(&self, q: &[f64], v: &[f64]) -> f64 {
        match self.kind {
            LimitKind::Scalar { .. } => 0.0,
            LimitKind::Cone { .. } => {
                let (angle, axis) = quat_angle_axis(&q[self.qpos_adr..self.qpos_adr + 4]);
                let d = self.dof_adr;
                let omega = Vec3::new(v[d], v[d + 1], v[d + 2]);
                // d/dt(−nᵀω) at ω̇ = 0.
                -0.5 * (0.5 * angle).tan().recip() * axis.cross(&omega).norm_squared()
            }
        }
    }

    /// Writes the row into `efc_*` row `r` (J, φ, id, type) for the active side (`dir`, `dist`).
    pub(crate) fn write_row(&self, data: &mut Data, r: usize, dir: &Vec3, dist: f64) {
        data.efc_id[r] = self.joint;
        data.efc_type[r] = crate::model::EfcType::LimitJoint;
        // Row r of J cleared through its storage (every nrows-th entry): no index
        // checks per entry.
        let stride = data.efc_j.nrows();
        for x in data.efc_j.as_mut_slice()[r..].iter_mut().step_by(stride) {
            *x = 0.0;
        }
        for k in 0..self.ndof() {
            data.efc_j[(r, self.dof_adr + k)] = dir[k];
        }
        data.efc_pos[r] = dist;
    }
}

/// Rotation angle θ ∈ [0, π] and unit axis of a unit quaternion [w, x, y, z] (the axis is
/// arbitrary at θ = 0): θ = 2 atan2(|v|, |w|), the axis flipped with w's sign so that q and −q
/// give the same rotation.
///
/// # Errors
/// [`InputError::Length`] when `quat` does not hold 4 values.
pub fn ball_angle_axis(quat: &[f64]) -> Result<(f64, Vec3), InputError> {
    InputError::check_len("ball_angle_axis", "quat", quat.len(), 4, "4")?;
    Ok(quat_angle_axis(quat))
}

/// [`ball_angle_axis`] of the first 4 values of `quat`.
pub(crate) fn quat_angle_axis(quat: &[f64]) -> (f64, Vec3) {
    let sign = if quat[0] < 0.0 { -1.0 } else { 1.0 };
    let v = Vec3::new(quat[1], quat[2], quat[3]) * sign;
    let s = v.norm();
    if s == 0.0 {
        return (0.0, Vec3::new(1.0, 0.0, 0.0));
    }
    (2.0 * s.atan2(quat[0].abs()), v / s)
}
