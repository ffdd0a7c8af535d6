//! Equality constraints (MJCF `<equality>`, MuJoCo's `eq_*` arrays) and URDF `<mimic>` joint
//! couplings, as typed elements with resolved indices. The rows they produce are built by the
//! constraint layer (`crate::constraint`).

use super::SourceLoc;
use crate::spatial::Transform;

/// MuJoCo's default `solref` (time constant, damping ratio).
pub const DEFAULT_SOLREF: [f64; 2] = [0.02, 1.0];
/// MuJoCo's default `solimp` (dmin, dmax, width, midpoint, power).
pub const DEFAULT_SOLIMP: [f64; 5] = [0.9, 0.95, 0.001, 0.5, 2.0];

/// One equality constraint.
#[derive(Clone, Debug, PartialEq)]
pub struct Equality {
    /// Its `name` (MJCF), or a generated one (`mimic:<joint>` for URDF mimics); may be empty.
    pub name: String,
    pub kind: EqualityKind,
    /// Whether it is active at the start (`active`, MuJoCo's `eq_active0`).
    pub active: bool,
    /// Soft-constraint parameters (used by the soft mode only).
    pub solref: [f64; 2],
    pub solimp: [f64; 5],
    pub loc: SourceLoc,
}

/// What an equality constraint ties together. Bodies and sites are named by their index in
/// [`Model::frames`](super::Model) (an MJCF body is a frame of kind `Link`, the world is the frame
/// `world`, a site a frame of kind `Site`); joints and tendons by their index in
/// [`Model::joints`](super::Model) and [`Model::tendons`](super::Model).
#[derive(Clone, Debug, PartialEq)]
pub enum EqualityKind {
    /// Two points coincide (3 rows; MuJoCo `connect`). Body semantic: `anchor` is the point in
    /// `frame1` coordinates, and its position in `frame2` is taken at `qpos0`. Site semantic
    /// (`anchor` = None): the origins of the two site frames coincide.
    Connect { frame1: usize, frame2: usize, anchor: Option<[f64; 3]> },
    /// Two frames are welded (6 rows, 3 without rotation when `torquescale` is 0; MuJoCo `weld`).
    /// Body semantic: `anchor` is a point in `frame2` coordinates; `relpose` the pose of frame2's
    /// anchor frame in frame1 (None: taken at `qpos0`, MuJoCo's all-zero quaternion default).
    /// Site semantic (`sites`): the two site frames coincide.
    Weld {
        frame1: usize,
        frame2: usize,
        anchor: [f64; 3],
        relpose: Option<Transform>,
        torquescale: f64,
        sites: bool,
    },
    /// `q1 − q1₀ = a₀ + a₁ x + a₂ x² + a₃ x³ + a₄ x⁴` with `x = q2 − q2₀` (MuJoCo `joint`; hinge and
    /// slide joints only; without `joint2`, `q1 − q1₀ = a₀`). `₀` is `qpos0`.
    Joint { joint1: usize, joint2: Option<usize>, polycoef: [f64; 5] },
    /// The same polynomial between fixed-tendon lengths, relative to their lengths at `qpos0`
    /// (MuJoCo `tendon`).
    Tendon { tendon1: usize, tendon2: Option<usize>, polycoef: [f64; 5] },
    /// URDF `<mimic>`: `q[joint] = multiplier · q[leader] + offset` (absolute joint values).
    Mimic { joint: usize, leader: usize, multiplier: f64, offset: f64 },
}

impl EqualityKind {
    /// Number of constraint rows it contributes when active.
    pub fn nrow(&self) -> usize {
        match self {
            EqualityKind::Connect { .. } => 3,
            EqualityKind::Weld { torquescale, .. } => {
                if *torquescale == 0.0 {
                    3
                } else {
                    6
                }
            }
            EqualityKind::Joint { .. } | EqualityKind::Tendon { .. } | EqualityKind::Mimic { .. } => 1,
        }
    }
    /// The kind's name as the `forward` output and `info` print it.
    pub fn name(&self) -> &'static str {
        match self {
            EqualityKind::Connect { .. } => "connect",
            EqualityKind::Weld { .. } => "weld",
            EqualityKind::Joint { .. } => "joint",
            EqualityKind::Tendon { .. } => "tendon",
            EqualityKind::Mimic { .. } => "mimic",
        }
    }
}
