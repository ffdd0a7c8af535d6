//! The model *spec*: what a loader parsed, before the compile step (DESIGN.md, layer 3) resolves
//! it into a [`Model`](super::Model). Links are a tree in depth-first file order; fixed joints are
//! still present here.

use super::{Mimic, SourceLoc};
use crate::spatial::{Mat3, Transform, Vec3};
use std::path::PathBuf;

/// A parsed model, ready to compile.
#[derive(Clone, Debug, Default)]
pub struct ModelSpec {
    pub name: String,
    /// The file the model came from.
    pub source: Option<PathBuf>,
    /// Gravity in the world frame.
    pub gravity: Vec3,
    /// Links in depth-first file order: every link's parent comes before it; `links[0]` is the
    /// root, attached to the world by its `joint` (fixed, or free when floating).
    pub links: Vec<LinkSpec>,
}

/// One link (URDF) or body (MJCF) with the joint that attaches it to its parent.
#[derive(Clone, Debug)]
pub struct LinkSpec {
    pub name: String,
    pub loc: SourceLoc,
    /// Index of the parent link in [`ModelSpec::links`]; `None` for the root (parent = world).
    pub parent: Option<usize>,
    pub joint: JointSpec,
    pub inertial: Option<InertialSpec>,
    pub geoms: Vec<GeomSpec>,
}

/// Joint types as model files name them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointType {
    Fixed,
    Revolute,
    Continuous,
    Prismatic,
    Floating,
    Planar,
    Ball,
}

/// The joint between a link and its parent.
#[derive(Clone, Debug)]
pub struct JointSpec {
    pub name: String,
    pub loc: SourceLoc,
    pub jtype: JointType,
    /// Pose of the joint frame in the parent link frame (URDF `<origin>`).
    pub x_parent_joint: Transform,
    /// Axis in the joint frame as written (the compile step normalizes it; zero is an error).
    pub axis: Vec3,
    pub limits: Option<[f64; 2]>,
    pub damping: f64,
    pub friction: f64,
    pub armature: f64,
    pub mimic: Option<Mimic>,
}

impl JointSpec {
    /// A joint of type `jtype` at the identity placement with axis x and no limits.
    pub fn new(name: &str, jtype: JointType, loc: SourceLoc) -> Self {
        Self {
            name: name.to_string(),
            loc,
            jtype,
            x_parent_joint: Transform::identity(),
            axis: Vec3::x(),
            limits: None,
            damping: 0.0,
            friction: 0.0,
            armature: 0.0,
            mimic: None,
        }
    }
}

/// Mass properties as written: mass, the pose of the inertial frame in the link frame (its origin
/// is the centre of mass), and the inertia tensor about the centre of mass in inertial-frame axes.
#[derive(Clone, Debug)]
pub struct InertialSpec {
    pub mass: f64,
    pub x_link_inertial: Transform,
    pub inertia: Mat3,
    pub loc: SourceLoc,
}

/// Geometric shapes kept from model files.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    Box {
        size: Vec3,
    },
    Cylinder {
        radius: f64,
        length: f64,
    },
    Capsule {
        radius: f64,
        length: f64,
    },
    Sphere {
        radius: f64,
    },
    /// A mesh file, resolved to a path on disk, with its scale.
    Mesh {
        path: PathBuf,
        scale: Vec3,
    },
}

/// A visual or collision geometry of a link.
#[derive(Clone, Debug)]
pub struct GeomSpec {
    pub x_link_geom: Transform,
    pub shape: Shape,
    pub collision: bool,
}
