//! The sensor catalogue: MuJoCo's sensor types (`mjtSensor`) with their MJCF tags, the stage each
//! needs (`sensorNeedstage`), their data type (`sensorDatatype`) and dimension (`mjs_sensorDim`),
//! as MuJoCo 4.0's compiler (`user_objects.cc`, `mjCSensor::Compile`) assigns them.

use crate::model::SourceLoc;

/// A sensor type (MuJoCo's `mjtSensor`), named by its MJCF tag.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[allow(missing_docs)] // each variant is the MJCF tag it names (see `tag`)
pub enum SensorType {
    Touch,
    Accelerometer,
    Velocimeter,
    Gyro,
    Force,
    Torque,
    Magnetometer,
    Rangefinder,
    CamProjection,
    JointPos,
    JointVel,
    TendonPos,
    TendonVel,
    ActuatorPos,
    ActuatorVel,
    ActuatorFrc,
    JointActuatorFrc,
    TendonActuatorFrc,
    BallQuat,
    BallAngVel,
    JointLimitPos,
    JointLimitVel,
    JointLimitFrc,
    TendonLimitPos,
    TendonLimitVel,
    TendonLimitFrc,
    FramePos,
    FrameQuat,
    FrameXAxis,
    FrameYAxis,
    FrameZAxis,
    FrameLinVel,
    FrameAngVel,
    FrameLinAcc,
    FrameAngAcc,
    SubtreeCom,
    SubtreeLinVel,
    SubtreeAngMom,
    InsideSite,
    GeomDist,
    GeomNormal,
    GeomFromTo,
    Contact,
    Tactile,
    EPotential,
    EKinetic,
    Clock,
    User,
    Plugin,
}

/// The MJCF tag of every type, in one table (the parser and `tag` read it).
const TAGS: [(SensorType, &str); 49] = {
    use SensorType::*;
    [
        (Touch, "touch"),
        (Accelerometer, "accelerometer"),
        (Velocimeter, "velocimeter"),
        (Gyro, "gyro"),
        (Force, "force"),
        (Torque, "torque"),
        (Magnetometer, "magnetometer"),
        (Rangefinder, "rangefinder"),
        (CamProjection, "camprojection"),
        (JointPos, "jointpos"),
        (JointVel, "jointvel"),
        (TendonPos, "tendonpos"),
        (TendonVel, "tendonvel"),
        (ActuatorPos, "actuatorpos"),
        (ActuatorVel, "actuatorvel"),
        (ActuatorFrc, "actuatorfrc"),
        (JointActuatorFrc, "jointactuatorfrc"),
        (TendonActuatorFrc, "tendonactuatorfrc"),
        (BallQuat, "ballquat"),
        (BallAngVel, "ballangvel"),
        (JointLimitPos, "jointlimitpos"),
        (JointLimitVel, "jointlimitvel"),
        (JointLimitFrc, "jointlimitfrc"),
        (TendonLimitPos, "tendonlimitpos"),
        (TendonLimitVel, "tendonlimitvel"),
        (TendonLimitFrc, "tendonlimitfrc"),
        (FramePos, "framepos"),
        (FrameQuat, "framequat"),
        (FrameXAxis, "framexaxis"),
        (FrameYAxis, "frameyaxis"),
        (FrameZAxis, "framezaxis"),
        (FrameLinVel, "framelinvel"),
        (FrameAngVel, "frameangvel"),
        (FrameLinAcc, "framelinacc"),
        (FrameAngAcc, "frameangacc"),
        (SubtreeCom, "subtreecom"),
        (SubtreeLinVel, "subtreelinvel"),
        (SubtreeAngMom, "subtreeangmom"),
        (InsideSite, "insidesite"),
        (GeomDist, "distance"),
        (GeomNormal, "normal"),
        (GeomFromTo, "fromto"),
        (Contact, "contact"),
        (Tactile, "tactile"),
        (EPotential, "e_potential"),
        (EKinetic, "e_kinetic"),
        (Clock, "clock"),
        (User, "user"),
        (Plugin, "plugin"),
    ]
};

/// The stage whose quantities a sensor reads (MuJoCo's `mjtStage`, `sensor_needstage`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum SensorStage {
    /// Positions (`mjSTAGE_POS`).
    Position,
    /// Velocities (`mjSTAGE_VEL`).
    Velocity,
    /// Accelerations and forces (`mjSTAGE_ACC`).
    Acceleration,
}

/// How the cutoff applies to a sensor's values (MuJoCo's `mjtDataType`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SensorDataType {
    /// Clamped to [−cutoff, cutoff].
    Real,
    /// Clamped above at cutoff (touch, insidesite).
    Positive,
    /// A unit vector: no cutoff (frame axes, geom normals).
    Axis,
    /// A unit quaternion: no cutoff.
    Quaternion,
}

impl SensorType {
    /// The type of an MJCF sensor tag (`distance`, `normal` and `fromto` are the geom-distance
    /// sensors), or None for a tag MuJoCo does not have.
    pub fn from_tag(tag: &str) -> Option<SensorType> {
        TAGS.iter().find(|(_, t)| *t == tag).map(|(s, _)| *s)
    }

    /// The MJCF tag of the type.
    pub fn tag(self) -> &'static str {
        TAGS.iter().find(|(s, _)| *s == self).map_or("?", |(_, t)| t)
    }

    /// The stage MuJoCo computes the type in (`sensorNeedstage`; user sensors say theirs).
    pub fn stage(self) -> SensorStage {
        use SensorType::*;
        match self {
            Touch | Accelerometer | Force | Torque | ActuatorFrc | JointActuatorFrc | TendonActuatorFrc
            | JointLimitFrc | TendonLimitFrc | FrameLinAcc | FrameAngAcc | Contact | Tactile => {
                SensorStage::Acceleration
            }
            Velocimeter | Gyro | JointVel | TendonVel | ActuatorVel | BallAngVel | JointLimitVel
            | TendonLimitVel | FrameLinVel | FrameAngVel | SubtreeLinVel | SubtreeAngMom => {
                SensorStage::Velocity
            }
            _ => SensorStage::Position,
        }
    }

    /// The data type, which decides how the cutoff applies (`sensorDatatype`).
    pub fn datatype(self) -> SensorDataType {
        use SensorType::*;
        match self {
            Touch | InsideSite => SensorDataType::Positive,
            FrameXAxis | FrameYAxis | FrameZAxis | GeomNormal => SensorDataType::Axis,
            BallQuat | FrameQuat => SensorDataType::Quaternion,
            _ => SensorDataType::Real,
        }
    }

    /// The number of values of the fixed-size types (`mjs_sensorDim`); None for the types whose
    /// size depends on options (rangefinder, contact, user, plugin, tactile) or on the actuator.
    pub fn fixed_dim(self) -> Option<usize> {
        use SensorType::*;
        match self {
            Touch | JointPos | JointVel | TendonPos | TendonVel | JointActuatorFrc | TendonActuatorFrc
            | JointLimitPos | JointLimitVel | JointLimitFrc | TendonLimitPos | TendonLimitVel
            | TendonLimitFrc | InsideSite | GeomDist | EPotential | EKinetic | Clock => Some(1),
            CamProjection => Some(2),
            BallQuat | FrameQuat => Some(4),
            GeomFromTo => Some(6),
            Accelerometer | Velocimeter | Gyro | Force | Torque | Magnetometer | BallAngVel | FramePos
            | FrameXAxis | FrameYAxis | FrameZAxis | FrameLinVel | FrameAngVel | FrameLinAcc
            | FrameAngAcc | SubtreeCom | SubtreeLinVel | SubtreeAngMom | GeomNormal => Some(3),
            Rangefinder | ActuatorPos | ActuatorVel | ActuatorFrc | Contact | Tactile | User | Plugin => None,
        }
    }
}

/// The object a sensor measures, or its reference frame (MuJoCo's `sensor_objtype`/`objid`,
/// `sensor_reftype`/`refid`), resolved to lagrange's indices.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SensorObject {
    /// None (`mjOBJ_UNKNOWN`).
    None,
    /// A body's inertial frame: its centre of mass and principal axes (`mjOBJ_BODY`; MuJoCo
    /// body id, `Model::links`).
    Body(usize),
    /// A body's own frame (`mjOBJ_XBODY`; MuJoCo body id). The contact sensor's `subtree1/2`.
    XBody(usize),
    /// A geom (`mjOBJ_GEOM`; index in `Model::geoms`).
    Geom(usize),
    /// A site (`mjOBJ_SITE`; index in `Model::frames`).
    Site(usize),
    /// A joint (index in `Model::joints`).
    Joint(usize),
    /// A tendon (index in `Model::tendons`).
    Tendon(usize),
    /// An actuator (index in `Model::actuators`).
    Actuator(usize),
}

/// The contact sensor's options (MuJoCo's `intprm`: `data` fields, `reduce`, `num`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ContactSensorSpec {
    /// The fields of each slot (bits of [`CONTACT_FIELDS`] in its order: found, force, torque,
    /// dist, pos, normal, tangent, linvel, angvel).
    pub dataspec: u32,
    /// The reduction: 0 none (first found), 1 mindist, 2 maxforce, 3 netforce.
    pub reduce: u8,
    /// The number of slots.
    pub num: usize,
}

/// The contact sensor's fields (MJCF `data` keywords) and their sizes, in MuJoCo 4.0's order
/// (`mjtConDataField`).
pub const CONTACT_FIELDS: [(&str, usize); 9] = [
    ("found", 1),
    ("force", 3),
    ("torque", 3),
    ("dist", 1),
    ("pos", 3),
    ("normal", 3),
    ("tangent", 3),
    ("linvel", 3),
    ("angvel", 3),
];

/// The rangefinder's fields (MJCF `data` keywords) and their sizes, in MuJoCo's order.
pub const RAY_FIELDS: [(&str, usize); 6] =
    [("dist", 1), ("dir", 3), ("origin", 3), ("point", 3), ("normal", 3), ("depth", 1)];

/// One sensor of the model, in MuJoCo's order, with its slice of `Data::sensordata`.
#[derive(Clone, Debug, PartialEq)]
pub struct Sensor {
    /// Its `name` (may be empty: [`Sensor::label`] names it then).
    pub name: String,
    /// Its type.
    pub kind: SensorType,
    /// The object it measures.
    pub object: SensorObject,
    /// The reference frame or second object, if any.
    pub reference: SensorObject,
    /// Its first value's index in `Data::sensordata` (MuJoCo's `sensor_adr`).
    pub adr: usize,
    /// Its number of values (MuJoCo's `sensor_dim`).
    pub dim: usize,
    /// The stage it needs.
    pub stage: SensorStage,
    /// How the cutoff applies.
    pub datatype: SensorDataType,
    /// Values are clamped to ±cutoff as [`SensorDataType`] says; 0 = none (MuJoCo's `cutoff`).
    pub cutoff: f64,
    /// The noise standard deviation of the file: metadata only (MuJoCo does not apply it).
    pub noise: f64,
    /// The contact sensor's options.
    pub contact: Option<ContactSensorSpec>,
    /// The rangefinder's fields (bits of [`RAY_FIELDS`]).
    pub ray_dataspec: u32,
    /// Why lagrange does not compute it (its values stay 0), or None when it does.
    pub not_computed: Option<String>,
    /// Where it is written.
    pub loc: SourceLoc,
    /// Its index among the model's sensors (MuJoCo's sensor id).
    pub id: usize,
}

impl Sensor {
    /// The name it is reported under: its `name`, or `TAG#ID` for an unnamed sensor
    /// (e.g. `touch#3`).
    pub fn label(&self) -> String {
        if self.name.is_empty() {
            format!("{}#{}", self.kind.tag(), self.id)
        } else {
            self.name.clone()
        }
    }

    /// Whether lagrange computes it.
    pub fn is_computed(&self) -> bool {
        self.not_computed.is_none()
    }
}
