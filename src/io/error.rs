//! Typed loader errors. Every message names the file (and line where known), the element, what is
//! wrong and how to fix it (DESIGN.md, "Style").

use crate::model::SourceLoc;
use thiserror::Error;

/// Why a model could not be loaded or compiled.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum LoadError {
    #[error("{file}: cannot read the file: {source}")]
    Io {
        file: String,
        #[source]
        source: std::io::Error,
    },
    #[error("{file}:{line}:{col}: malformed XML: {detail}. Fix the XML syntax at that position")]
    Xml { file: String, line: u32, col: u32, detail: String },
    #[error("{loc}: <{element}>: {detail}")]
    Invalid { loc: SourceLoc, element: String, detail: String },
    #[error("{loc}: joint '{joint}': unknown joint type '{found}'; use one of revolute, continuous, prismatic, fixed, floating, planar")]
    UnknownJointType { loc: SourceLoc, joint: String, found: String },
    #[error("{loc}: joint '{joint}': {role} link '{link}' is not defined; add <link name=\"{link}\"> or fix the name")]
    MissingLink { loc: SourceLoc, joint: String, role: &'static str, link: String },
    #[error("{loc}: joint '{joint}': link '{link}' already has parent joint '{other}'; a link can have only one parent joint (loops need an equality constraint, not a second joint)")]
    TwoParents { loc: SourceLoc, joint: String, link: String, other: String },
    #[error("{file}: the links {links:?} form a cycle (through joint '{joint}'); a URDF must be a tree")]
    Cycle { file: String, joint: String, links: Vec<String> },
    #[error("{file}: the model has {} root links ({roots:?}); it must have exactly one link that is no joint's child: connect the others with joints", roots.len())]
    MultipleRoots { file: String, roots: Vec<String> },
    #[error("{file}: the model has no links")]
    Empty { file: String },
    #[error("{loc}: {element} '{name}' is defined twice; names must be unique")]
    DuplicateName { loc: SourceLoc, element: &'static str, name: String },
    #[error("{loc}: joint '{joint}': axis is zero; give a nonzero <axis xyz=\"...\">")]
    ZeroAxis { loc: SourceLoc, joint: String },
    #[error("{loc}: link '{link}': negative mass {mass}; mass must be ≥ 0 kg")]
    NegativeMass { loc: SourceLoc, link: String, mass: f64 },
    #[error("{loc}: link '{link}': non-physical inertia: {detail}; an inertia tensor must be symmetric positive semi-definite with principal moments satisfying the triangle inequality (I1 + I2 ≥ I3)")]
    NonPhysicalInertia { loc: SourceLoc, link: String, detail: String },
    #[error("{loc}: link '{link}': cannot resolve '{uri}': package '{package}' not found in {searched:?}; pass --package-dir DIR (the folder holding '{package}/') or set ROS_PACKAGE_PATH")]
    PackageNotFound { loc: SourceLoc, link: String, uri: String, package: String, searched: Vec<String> },
    #[error("{loc}: link '{link}': mesh file '{path}' does not exist")]
    MeshNotFound { loc: SourceLoc, link: String, path: String },
    #[error("{file}: unsupported model format (expected .urdf or .xml)")]
    UnsupportedFormat { file: String },
}
