//! Typed loader errors. Every message names the file (and line where known), the element, what is
//! wrong and how to fix it (docs/architecture.md, "Errors").

use crate::model::SourceLoc;
use thiserror::Error;

/// Why a model could not be loaded or compiled.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum LoadError {
    #[error("{file}: cannot read the file: {source}; check the path and that the file is readable")]
    Io {
        file: String,
        #[source]
        source: std::io::Error,
    },
    #[error("{file}:{line}:{col}: malformed XML: {detail}. Fix the XML syntax at that position")]
    Xml { file: String, line: u32, col: u32, detail: String },
    #[error("{loc}: <{element}>: {detail}")]
    Invalid { loc: SourceLoc, element: String, detail: String },
    #[error("{loc}: joint '{joint}': unknown joint type '{found}'; use one of revolute, continuous, prismatic, fixed, floating, planar (or spherical)")]
    UnknownJointType { loc: SourceLoc, joint: String, found: String },
    #[error("{loc}: joint '{joint}': {role} link '{link}' is not defined; add <link name=\"{link}\"> or fix the name")]
    MissingLink { loc: SourceLoc, joint: String, role: &'static str, link: String },
    #[error("{loc}: joint '{joint}': link '{link}' already has parent joint '{other}'; a link can have only one parent joint (loops need an equality constraint, not a second joint)")]
    TwoParents { loc: SourceLoc, joint: String, link: String, other: String },
    #[error("{loc}: joint '{joint}': the links {} form a cycle; a URDF must be a tree: remove or re-parent one joint of the loop (loops need an equality constraint, not a joint)", list(.links))]
    Cycle { loc: SourceLoc, joint: String, links: Vec<String> },
    #[error("{file}: the model has {} root links ({}); it must have exactly one link that is no joint's child: connect the others with joints or delete them", roots.len(), list(.roots))]
    MultipleRoots { file: String, roots: Vec<String> },
    #[error("{file}: the model has no links; add at least one <link name=\"...\">")]
    Empty { file: String },
    #[error("{loc}: {element} '{name}' is defined twice; names must be unique: rename one of them")]
    DuplicateName { loc: SourceLoc, element: &'static str, name: String },
    #[error("{loc}: joint '{joint}': axis is zero; give a nonzero <axis xyz=\"...\">")]
    ZeroAxis { loc: SourceLoc, joint: String },
    #[error("{loc}: {what} '{link}': negative mass {mass}; mass must be ≥ 0 kg: fix {}", mass_attribute(.what))]
    NegativeMass { loc: SourceLoc, what: LinkWord, link: String, mass: f64 },
    #[error("{loc}: {what} '{link}': non-physical inertia: {detail}; an inertia tensor must be symmetric positive semi-definite with principal moments satisfying the triangle inequality (I1 + I2 ≥ I3): fix {}, or set LoadOptions::accept_nonphysical_inertia to use them as written (as Pinocchio does)", inertia_attribute(.what))]
    NonPhysicalInertia { loc: SourceLoc, what: LinkWord, link: String, detail: String },
    #[error("{loc}: link '{link}': cannot resolve '{uri}': package '{package}' not found (searched: {}); add the folder holding '{package}/' to LoadOptions::package_dirs or to ROS_PACKAGE_PATH", searched_list(.searched))]
    PackageNotFound {
        loc: SourceLoc,
        link: String,
        uri: String,
        package: String,
        /// The folders searched, in order (boxed to keep `LoadError` small).
        searched: Box<[String]>,
    },
    #[error("{loc}: link '{link}': mesh file '{path}' does not exist; fix the filename, or point LoadOptions::package_dirs or ROS_PACKAGE_PATH at the right package for a package:// path")]
    MeshNotFound { loc: SourceLoc, link: String, path: String },
    #[error("{loc}: {what} '{link}': the mass properties of mesh '{path}' are needed (the {what}'s inertia comes from its geoms) but {reason}")]
    MeshMass { loc: SourceLoc, what: LinkWord, link: String, path: String, reason: String },
    #[error("{loc}: {what} '{link}': mesh '{path}' collides by its convex hull, but {reason}; {}, or fix the mesh", hull_fix(.what))]
    MeshHull { loc: SourceLoc, what: LinkWord, link: String, path: String, reason: String },
    #[error("{loc}: <include>: include cycle: {}; remove one of these includes", .chain.join(" includes "))]
    IncludeCycle { loc: SourceLoc, chain: Vec<String> },
    #[error(
        "{loc}: <include>: cannot read '{path}': {reason}; MuJoCo looks for an included file in the main model's folder, then beside the including file"
    )]
    IncludeNotFound { loc: SourceLoc, path: String, reason: String },
    #[error("{loc}: <{element}>: unknown default class '{class}'; define <default class=\"{class}\"> or fix the name")]
    UnknownClass { loc: SourceLoc, element: String, class: String },
    #[error("{loc}: <{element}>: attribute '{attribute}' {detail}")]
    BadAttribute { loc: SourceLoc, element: String, attribute: String, detail: String },
    #[error("{loc}: <{element}>: unknown {kind} '{target}'; define it or fix the name")]
    UnknownReference { loc: SourceLoc, element: String, kind: &'static str, target: String },
    #[error("{loc}: <{element}>: {what} is not supported yet and would change the dynamics; {fix}")]
    Unsupported { loc: SourceLoc, element: String, what: String, fix: String },
    #[error("{loc}: <{element}>: file '{path}' does not exist; fix the file name or <compiler meshdir/assetdir> (relative paths start at the model file's folder)")]
    AssetNotFound { loc: SourceLoc, element: String, path: String },
    #[error("{file}: unsupported model format (expected a URDF file, root element <robot>, named .urdf, or an MJCF file, root element <mujoco>, named .xml)")]
    UnsupportedFormat { file: String },
}

/// What a link is called in its file: a URDF `<link>` or an MJCF `<body>`; messages use the file's
/// own terms.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LinkWord {
    Link,
    Body,
}

impl std::fmt::Display for LinkWord {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            LinkWord::Link => "link",
            LinkWord::Body => "body",
        })
    }
}

/// Where a mass is written, in the file's terms.
fn mass_attribute(what: &LinkWord) -> &'static str {
    if *what == LinkWord::Body {
        "<inertial mass=\"...\"> or the geom's mass/density"
    } else {
        "<mass value=\"...\">"
    }
}

/// Where an inertia tensor is written, in the file's terms.
fn inertia_attribute(what: &LinkWord) -> &'static str {
    if *what == LinkWord::Body {
        "<inertial diaginertia/fullinertia> (or the geoms it comes from)"
    } else {
        "the <inertia> values"
    }
}

/// How to keep a mesh out of collisions, in the file's terms.
fn hull_fix(what: &LinkWord) -> &'static str {
    if *what == LinkWord::Body {
        "give the geom contype=\"0\" conaffinity=\"0\" if it is only drawn"
    } else {
        "move it from <collision> to <visual> if it is only drawn"
    }
}

/// `["a", "b"]` → `'a', 'b'`.
fn list(names: &[String]) -> String {
    names.iter().map(|n| format!("'{n}'")).collect::<Vec<_>>().join(", ")
}

/// The searched folders of a `package://` lookup, or a note that there were none.
fn searched_list(dirs: &[String]) -> String {
    if dirs.is_empty() {
        "no folders: LoadOptions::package_dirs is empty and ROS_PACKAGE_PATH is unset".to_string()
    } else {
        list(dirs)
    }
}
