//! Model elements beyond the kinematic tree: keyframes, and the elements the engine keeps but does
//! not simulate (sensors, spatial tendons, …) so that `lagrange info` can list them.

use super::SourceLoc;

/// A named state (MJCF `<key>`): absent vectors mean the model's `qpos0` / zeros.
#[derive(Clone, Debug, PartialEq)]
pub struct Keyframe {
    /// Its `name` (may be empty).
    pub name: String,
    /// Where it is written.
    pub loc: SourceLoc,
    /// Simulation time (s).
    pub time: f64,
    /// Joint positions, `nq` values in MuJoCo's qpos layout.
    pub qpos: Option<Vec<f64>>,
    /// Joint velocities, `nv` values in MuJoCo's qvel layout.
    pub qvel: Option<Vec<f64>>,
    /// Controls, one per actuator (MuJoCo's `ctrl`).
    pub ctrl: Option<Vec<f64>>,
    /// Actuator activations (MuJoCo's `act`, one per activation state, `na`).
    pub act: Option<Vec<f64>>,
    /// Mocap body positions, 3 per mocap body (MJCF `mpos`; MuJoCo's `key_mpos`).
    pub mpos: Option<Vec<f64>>,
    /// Mocap body orientations, quaternions w x y z, 4 per mocap body (MJCF `mquat`).
    pub mquat: Option<Vec<f64>>,
}

impl Keyframe {
    /// Writes the parts of the state this keyframe gives into `q`, `v`, `ctrl` and `act` (its
    /// `ctrl` and `act` only when they have one value per actuator and per activation, as
    /// MuJoCo's `mj_resetDataKeyframe`); the rest is left as it is.
    pub fn apply(&self, q: &mut Vec<f64>, v: &mut Vec<f64>, ctrl: &mut Vec<f64>, act: &mut Vec<f64>) {
        if let Some(x) = &self.qpos {
            q.clone_from(x);
        }
        if let Some(x) = &self.qvel {
            v.clone_from(x);
        }
        if let Some(x) = self.ctrl.as_ref().filter(|c| c.len() == ctrl.len()) {
            ctrl.clone_from(x);
        }
        if let Some(x) = self.act.as_ref().filter(|a| a.len() == act.len()) {
            act.clone_from(x);
        }
    }
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
    /// Where it is written.
    pub loc: SourceLoc,
}
