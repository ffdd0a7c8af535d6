//! Sensors (MJCF `<sensor>`, MuJoCo's `sensordata`; MuJoCo documentation "XML Reference →
//! sensor" and engine_sensor.c): what a robot's encoders, IMUs, force–torque cells, touch pads,
//! rangefinders and pose trackers read, computed from the state and the last `forward`'s
//! quantities into `Data::sensordata` at MuJoCo's addresses (`Sensor::adr`, `Sensor::dim`).
//!
//! [`forward`](crate::forward::forward) ends with the sensor stage when the model has sensors and
//! `<flag sensor>` is on; a model without sensors computes none, and the quantities only some
//! sensors need (body velocities, subtree momenta) are formed only when such a sensor exists.
//! A step of the Euler, implicit, implicitfast and RK4 steppers (what [`step`](crate::integrate::step)
//! and `Simulation` run for MJCF `<option integrator>`) leaves the sensors of the state the step
//! started from, as `mj_step` does (its `mj_forward` runs before the integration); the adaptive
//! and variational steppers leave `sensordata` as it was (call `forward` to refresh it).
//!
//! Each type follows MuJoCo's definition (the stage files cite theirs); `cutoff` clamps as MuJoCo's
//! `apply_cutoff` does; `noise` is metadata (MuJoCo does not apply it). Sensors lagrange does not
//! compute keep their place with zeros and say why ([`Sensor::not_computed`]; `lagrange info` lists
//! them).

mod acceleration;
mod contact_sensor;
mod geometry;
pub(crate) mod objects;
mod position;
mod subtree;
mod touch;
mod types;
mod velocity;

pub use types::{
    ContactSensorSpec, Sensor, SensorDataType, SensorObject, SensorStage, SensorType, CONTACT_FIELDS,
    RAY_FIELDS,
};

use crate::kinematics::{forward_kinematics_sensed_unchecked, forward_velocities_unchecked};
use crate::model::{Data, Model};
use objects::Quat;
use subtree::Subtree;

/// What the sensor stage needs, derived once from the model's sensors.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SensorNeeds {
    /// Any sensor is computed.
    pub any: bool,
    /// Body velocities (velocity-stage sensors reading frames or sites).
    pub velocities: bool,
    /// Body quaternions composed as MuJoCo's `xquat` (framequat).
    pub quats: bool,
    /// Subtree centres of mass.
    pub subtree_com: bool,
    /// Subtree linear velocities (and angular momenta when `subtree_angmom`).
    pub subtree_velocities: bool,
    /// Subtree angular momenta (a `subtreeangmom` sensor).
    pub subtree_angmom: bool,
    /// Kinetic energy.
    pub kinetic: bool,
    /// Body accelerations and interaction forces (MuJoCo's `mj_rnePostConstraint`).
    pub rne_post: bool,
    /// Of those, the external and interaction wrenches too (`cfrc_ext`, `cfrc_int`: force and
    /// torque sensors); accelerometers and frame accelerations read `cacc` alone.
    pub rne_post_wrenches: bool,
}

impl SensorNeeds {
    /// The needs of `model`'s computed sensors.
    pub fn of(model: &Model) -> Self {
        use SensorType::*;
        let computed = || model.sensors.iter().filter(|s| s.is_computed() && model.options.flags.sensor);
        let has = |f: &dyn Fn(SensorType) -> bool| computed().any(|s| f(s.kind));
        // Contact sensors reporting velocities (linvel, angvel: the last two fields).
        let contact_velocities = computed().any(|s| s.contact.is_some_and(|c| c.dataspec >> 7 != 0));
        SensorNeeds {
            any: computed().next().is_some(),
            velocities: has(&|k| {
                matches!(
                    k,
                    Velocimeter | Gyro | FrameLinVel | FrameAngVel | SubtreeLinVel | SubtreeAngMom | EKinetic
                )
            }) || contact_velocities,
            quats: has(&|k| k == FrameQuat),
            subtree_com: has(&|k| matches!(k, SubtreeCom | SubtreeLinVel | SubtreeAngMom | InsideSite)),
            subtree_velocities: has(&|k| matches!(k, SubtreeLinVel | SubtreeAngMom)),
            subtree_angmom: has(&|k| k == SubtreeAngMom),
            kinetic: has(&|k| k == EKinetic),
            rne_post: has(&|k| matches!(k, Accelerometer | Force | Torque | FrameLinAcc | FrameAngAcc)),
            rne_post_wrenches: has(&|k| matches!(k, Force | Torque)),
        }
    }
}

/// The sensor stage's scratch, kept in `Data` (sized by `Data::new`: the stage allocates nothing).
#[derive(Clone, Debug, Default)]
pub(crate) struct SensorWork {
    /// The compiled bodies' orientations as MuJoCo's `xquat`.
    pub quats: Vec<Quat>,
    /// Subtree quantities per MuJoCo body.
    pub subtree: Subtree,
    /// The kinetic energy at the state (when an `e_kinetic` sensor exists).
    pub kinetic: f64,
    /// The state's time (the clock sensor).
    pub time: f64,
    /// The contact sensor's matches.
    pub matches: Vec<contact_sensor::Match>,
    /// The touch sensors, formed together in one pass over the contacts.
    pub touch: touch::TouchSites,
}

impl SensorWork {
    /// Buffers for `model`.
    pub fn new(model: &Model) -> Self {
        let has_contact_sensor = model.sensors.iter().any(|s| s.kind == SensorType::Contact);
        SensorWork {
            quats: vec![[1.0, 0.0, 0.0, 0.0]; model.nbody()],
            subtree: Subtree::new(model),
            kinetic: 0.0,
            time: 0.0,
            matches: Vec::with_capacity(if has_contact_sensor {
                model.max_contacts().min(crate::model::INITIAL_CONTACTS)
            } else {
                0
            }),
            touch: touch::TouchSites::new(model),
        }
    }
}

/// MuJoCo's `apply_cutoff`: real values clamped to ±cutoff, positive ones above at cutoff; axes,
/// quaternions, contact and from-to sensors untouched.
fn apply_cutoff(s: &Sensor, out: &mut [f64]) {
    if s.cutoff <= 0.0 || matches!(s.kind, SensorType::Contact | SensorType::GeomFromTo) {
        return;
    }
    for x in out {
        match s.datatype {
            SensorDataType::Real => *x = x.clamp(-s.cutoff, s.cutoff),
            SensorDataType::Positive => *x = x.min(s.cutoff),
            _ => {}
        }
    }
}

/// The sensor stage at (`q`, `v`, `time`) after a `forward` there: every computed sensor into
/// `data.sensordata`. Nothing when the model has no computed sensor.
pub(crate) fn compute_at(model: &Model, data: &mut Data, q: &[f64], v: &[f64], time: f64) {
    let needs = &model.plan.sensor_needs;
    if !needs.any || data.forward_skip.sensors {
        return;
    }
    // The link and site frames (the joint-anchor frames no sensor reads are left as they were).
    forward_kinematics_sensed_unchecked(model, data, q);
    // Body velocities: for the velocity sensors, and the accelerations' velocity terms (RNEA's or
    // ABA's of the same evaluation when they are still those of (q, v): `Data::velocity_stamp`).
    if (needs.velocities || needs.rne_post) && !data.velocity_stamp.matches(q, v) {
        forward_velocities_unchecked(model, data, v);
    }
    let mut work = std::mem::take(&mut data.sensor_work);
    let mut sensordata = std::mem::take(&mut data.sensordata);
    work.time = time;
    if needs.quats {
        objects::body_quats(model, q, &mut work.quats);
    }
    if needs.subtree_com {
        subtree::subtree_com(model, data, &mut work.subtree);
    }
    if needs.subtree_velocities {
        subtree::subtree_velocities(model, data, &mut work.subtree, needs.subtree_angmom);
    }
    if needs.rne_post {
        // The subtree centres of mass, when the subtree sensors formed them, are rne_post's too.
        let subtree = &work.subtree;
        let centres = needs.subtree_com.then_some((
            subtree.xipos.as_slice(),
            subtree.mass.as_slice(),
            subtree.com.as_slice(),
        ));
        crate::dynamics::rne_post::rne_post_constraint_at(
            model,
            data,
            q,
            v,
            needs.rne_post_wrenches,
            true,
            centres,
        );
    }
    if needs.kinetic {
        let bodies: f64 =
            (1..model.nbody()).map(|b| model.bodies[b].inertia.kinetic_energy(&data.v_body[b])).sum();
        let armature: f64 = model.dof_armature.iter().zip(v).map(|(a, vi)| 0.5 * a * vi * vi).sum();
        work.kinetic = bodies + armature;
    }
    touch::touch_all(model, data, &work.touch, sensordata.as_mut_slice());
    let inside_site = |f: usize, p: &crate::spatial::Vec3| geometry::inside_site_zone(model, data, f, p);
    for s in model.sensors.iter().filter(|s| s.is_computed()) {
        let out = &mut sensordata.as_mut_slice()[s.adr..s.adr + s.dim];
        match (s.stage, s.contact) {
            (_, Some(spec)) => {
                contact_sensor::compute(model, data, s, &spec, &inside_site, &mut work.matches, out)
            }
            // Formed above, all together.
            _ if touch::is_touch_site(s) => {}
            _ if matches!(
                s.kind,
                SensorType::Touch
                    | SensorType::Rangefinder
                    | SensorType::InsideSite
                    | SensorType::GeomDist
                    | SensorType::GeomNormal
                    | SensorType::GeomFromTo
            ) =>
            {
                geometry::compute(model, data, &work, s, out)
            }
            (SensorStage::Position, _) => position::compute(model, data, &work, s, q, out),
            (SensorStage::Velocity, _) => velocity::compute(model, data, &work, s, v, out),
            (SensorStage::Acceleration, _) => acceleration::compute(model, data, s, out),
        }
        apply_cutoff(s, out);
    }
    data.sensordata = sensordata;
    data.sensor_work = work;
}

impl Model {
    /// The sensor named `name` (or labelled `TYPE#ID` when unnamed), if any.
    pub fn sensor(&self, name: &str) -> Option<&Sensor> {
        self.sensors
            .iter()
            .find(|s| s.name == name)
            .or_else(|| self.sensors.iter().find(|s| s.label() == name))
    }
}

impl Data {
    /// The values of sensor `name` from the last `forward` (or step), a slice of
    /// [`sensordata`](Data::sensordata).
    ///
    /// # Errors
    /// [`InputError::Name`](crate::error::InputError::Name) when the model has no such sensor.
    ///
    /// # Example
    /// ```
    /// use lagrange::prelude::*;
    /// let model = Model::from_str(r#"<mujoco><worldbody><body><joint name="hinge" axis="0 1 0"/>
    ///     <geom size="0.1" mass="1"/></body></worldbody>
    ///     <sensor><jointpos name="angle" joint="hinge"/></sensor></mujoco>"#)?;
    /// let mut data = Data::new(&model);
    /// data.qpos[0] = 0.3;
    /// forward(&model, &mut data);
    /// assert_eq!(data.sensor(&model, "angle")?, &[0.3]);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn sensor(&self, model: &Model, name: &str) -> Result<&[f64], crate::error::InputError> {
        let s = model.sensor(name).ok_or_else(|| {
            crate::error::InputError::unknown_name(
                "Data::sensor",
                "sensor",
                name,
                model.sensors.iter().map(|s| s.name.as_str()).filter(|n| !n.is_empty()),
            )
        })?;
        Ok(&self.sensordata.as_slice()[s.adr..s.adr + s.dim])
    }
}
