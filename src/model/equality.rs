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
    /// What it ties together.
    pub kind: EqualityKind,
    /// Whether it is active at the start (`active`, MuJoCo's `eq_active0`).
    pub active: bool,
    /// Soft-constraint parameters (used by the soft mode only): `solref` (time constant, damping
    /// ratio).
    pub solref: [f64; 2],
    /// `solimp` (dmin, dmax, width, midpoint, power; soft mode only).
    pub solimp: [f64; 5],
    /// Where it is written (the `<mimic>` element for URDF mimics).
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
    Connect {
        /// The first body or site (index in `Model::frames`).
        frame1: usize,
        /// The second body or site (index in `Model::frames`).
        frame2: usize,
        /// The point in `frame1` coordinates (m); `None` for sites.
        anchor: Option<[f64; 3]>,
    },
    /// Two frames are welded (6 rows, 3 without rotation when `torquescale` is 0; MuJoCo `weld`).
    /// Body semantic: `anchor` is a point in `frame2` coordinates; `relpose` the pose of frame2's
    /// anchor frame in frame1 (None: taken at `qpos0`, MuJoCo's all-zero quaternion default).
    /// Site semantic (`sites`): the two site frames coincide.
    Weld {
        /// The first body or site (index in `Model::frames`).
        frame1: usize,
        /// The second body or site (index in `Model::frames`).
        frame2: usize,
        /// The anchor point in `frame2` coordinates (m).
        anchor: [f64; 3],
        /// Pose of frame2's anchor frame in frame1 (`None`: taken at `qpos0`).
        relpose: Option<Transform>,
        /// Weight of the rotational rows relative to the translational ones (0: position only).
        torquescale: f64,
        /// Site semantic: the two site frames coincide.
        sites: bool,
    },
    /// `q1 − q1₀ = a₀ + a₁ x + a₂ x² + a₃ x³ + a₄ x⁴` with `x = q2 − q2₀` (MuJoCo `joint`; hinge and
    /// slide joints only; without `joint2`, `q1 − q1₀ = a₀`). `₀` is `qpos0`.
    Joint {
        /// The constrained joint (index in `Model::joints`).
        joint1: usize,
        /// The joint it follows (index in `Model::joints`), if any.
        joint2: Option<usize>,
        /// The polynomial's coefficients a₀…a₄.
        polycoef: [f64; 5],
    },
    /// The same polynomial between fixed-tendon lengths, relative to their lengths at `qpos0`
    /// (MuJoCo `tendon`).
    Tendon {
        /// The constrained tendon (index in `Model::tendons`).
        tendon1: usize,
        /// The tendon it follows (index in `Model::tendons`), if any.
        tendon2: Option<usize>,
        /// The polynomial's coefficients a₀…a₄.
        polycoef: [f64; 5],
    },
    /// URDF `<mimic>`: `q[joint] = multiplier · q[leader] + offset` (absolute joint values).
    Mimic {
        /// The following joint (index in `Model::joints`).
        joint: usize,
        /// The joint it follows (index in `Model::joints`).
        leader: usize,
        /// URDF `multiplier`.
        multiplier: f64,
        /// URDF `offset` (rad or m).
        offset: f64,
    },
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
