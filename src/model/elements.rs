//! Model elements beyond the kinematic tree: keyframes, and the elements the engine keeps but does
//! not simulate (sensors, spatial tendons, …) so that `lagrange info` can list them.

use super::SourceLoc;

/// A named state (MJCF `<key>`): absent vectors mean the model's `qpos0` / zeros.
#[derive(Clone, Debug, PartialEq)]
pub struct Keyframe {
    pub name: String,
    pub loc: SourceLoc,
    pub time: f64,
    pub qpos: Option<Vec<f64>>,
    pub qvel: Option<Vec<f64>>,
    pub ctrl: Option<Vec<f64>>,
}

/// An element parsed and kept, not simulated yet: an actuator, sensor, equality constraint,
/// tendon, contact pair or exclusion.
#[derive(Clone, Debug, PartialEq)]
pub struct Element {
    /// The section it came from: `actuator`, `sensor`, `equality`, `tendon`, `contact`.
    pub category: String,
    /// Its element name (`motor`, `position`, `connect`, `weld`, `jointpos`, `pair`, ...).
    pub kind: String,
    /// Its `name`, empty if unnamed.
    pub name: String,
    /// The objects it acts on (joint, body, site, tendon, geom names), in file order.
    pub targets: Vec<String>,
    /// All its attributes after default classes were applied, in file order.
    pub attributes: Vec<(String, String)>,
    pub loc: SourceLoc,
}
