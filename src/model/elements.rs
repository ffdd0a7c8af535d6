//! Model elements beyond the kinematic tree: simulation options, keyframes, and the elements the
//! engine keeps but does not simulate yet (so that `lagrange info` can list them).

use super::SourceLoc;

/// Simulation options (MJCF `<option>`).
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// Time step (s); MuJoCo's default 0.002.
    pub timestep: f64,
    /// The integrator the file asks for (`Euler`, `RK4`, `implicit`, `implicitfast`).
    pub integrator: String,
    /// `<flag>` entries that differ from MuJoCo's defaults, as `name=enable|disable`.
    pub flags: Vec<(String, bool)>,
}

impl Default for Options {
    fn default() -> Self {
        Self { timestep: 0.002, integrator: "Euler".to_string(), flags: Vec::new() }
    }
}

impl Options {
    /// Whether a `<flag>` of `<option>` switched `name` off.
    pub fn disabled(&self, name: &str) -> bool {
        self.flags.iter().any(|(n, on)| n == name && !on)
    }
}

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
