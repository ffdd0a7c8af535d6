//! Typed loader errors. Every message names the file (and line where known), the element, what is
//! wrong and how to fix it (docs/architecture.md, "Errors").

use crate::model::SourceLoc;
use thiserror::Error;

/// Why a model could not be loaded or compiled.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum LoadError {
    /// The model file could not be read.
    #[error("{file}: cannot read the file: {source}; check the path and that the file is readable")]
    Io {
        /// The path as given.
        file: String,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// The file is not well-formed XML (URDF or MJCF, an MJCF `<include>`d file included).
    #[error("{file}:{line}:{col}: malformed XML: {detail}. Fix the XML syntax at that position")]
    Xml {
        /// The file being parsed.
        file: String,
        /// Line of the error (1-based).
        line: u32,
        /// Column of the error (1-based).
        col: u32,
        /// The XML parser's message.
        detail: String,
    },
    /// An element breaks a rule of the format or of the engine; `detail` says which and how to
    /// fix it.
    #[error("{loc}: <{element}>: {detail}")]
    Invalid {
        /// File and line of the element.
        loc: SourceLoc,
        /// The element's tag.
        element: String,
        /// What is wrong and how to fix it.
        detail: String,
    },
    /// A URDF `<joint type>` that is none of URDF's joint types.
    #[error("{loc}: joint '{joint}': unknown joint type '{found}'; use one of revolute, continuous, prismatic, fixed, floating, planar (or spherical)")]
    UnknownJointType {
        /// File and line of the `<joint>`.
        loc: SourceLoc,
        /// The joint's name.
        joint: String,
        /// The type as written.
        found: String,
    },
    /// A URDF joint's `<parent link>` or `<child link>` names no `<link>`.
    #[error("{loc}: joint '{joint}': {role} link '{link}' is not defined; add <link name=\"{link}\"> or fix the name")]
    MissingLink {
        /// File and line of the `<joint>`.
        loc: SourceLoc,
        /// The joint's name.
        joint: String,
        /// `"parent"` or `"child"`.
        role: &'static str,
        /// The link name that was not found.
        link: String,
    },
    /// A URDF link is the child of two joints.
    #[error("{loc}: joint '{joint}': link '{link}' already has parent joint '{other}'; a link can have only one parent joint (loops need an equality constraint, not a second joint)")]
    TwoParents {
        /// File and line of the second `<joint>`.
        loc: SourceLoc,
        /// The second joint's name.
        joint: String,
        /// The child link.
        link: String,
        /// The joint that already has `link` as its child.
        other: String,
    },
    /// URDF joints form a closed loop of links.
    #[error("{loc}: joint '{joint}': the links {} form a cycle; a URDF must be a tree: remove or re-parent one joint of the loop (loops need an equality constraint, not a joint)", list(.links))]
    Cycle {
        /// File and line of a `<joint>` of the loop.
        loc: SourceLoc,
        /// That joint's name.
        joint: String,
        /// The links of the loop.
        links: Vec<String>,
    },
    /// A URDF has more than one link that is no joint's child.
    #[error("{file}: the model has {} root links ({}); it must have exactly one link that is no joint's child: connect the others with joints or delete them", roots.len(), list(.roots))]
    MultipleRoots {
        /// The model file.
        file: String,
        /// The names of the root links.
        roots: Vec<String>,
    },
    /// The model has no links.
    #[error("{file}: the model has no links; add at least one <link name=\"...\">")]
    Empty {
        /// The model file.
        file: String,
    },
    /// Two elements of one kind (link, joint, MJCF default class) share a name.
    #[error("{loc}: {element} '{name}' is defined twice; names must be unique: rename one of them")]
    DuplicateName {
        /// File and line of the second definition.
        loc: SourceLoc,
        /// The kind of element (`"link"`, `"joint"`, `"default class"`).
        element: &'static str,
        /// The repeated name.
        name: String,
    },
    /// A hinge, slide, revolute, prismatic or planar joint has a zero (or non-finite) axis.
    #[error("{loc}: joint '{joint}': axis is zero; give a nonzero <axis xyz=\"...\">")]
    ZeroAxis {
        /// File and line of the joint.
        loc: SourceLoc,
        /// The joint's name.
        joint: String,
    },
    /// A link's or body's mass is negative.
    #[error("{loc}: {what} '{link}': negative mass {mass}; mass must be ≥ 0 kg: fix {}", mass_attribute(.what))]
    NegativeMass {
        /// File and line of the `<inertial>`.
        loc: SourceLoc,
        /// Whether the file says link (URDF) or body (MJCF).
        what: LinkWord,
        /// The link's or body's name.
        link: String,
        /// The mass as written (kg).
        mass: f64,
    },
    /// A link's or body's mass properties are not physical (non-finite, non-symmetric, a negative
    /// principal moment, or moments violating the triangle inequality), unless accepted by
    /// `LoadOptions::accept_nonphysical_inertia`
    /// ([`MassRules::accept_nonphysical`](crate::model::spec::MassRules::accept_nonphysical)).
    #[error("{loc}: {what} '{link}': non-physical inertia: {detail}; an inertia tensor must be symmetric positive semi-definite with principal moments satisfying the triangle inequality (I1 + I2 ≥ I3): fix {}, or set LoadOptions::accept_nonphysical_inertia to use them as written (as Pinocchio does)", inertia_attribute(.what))]
    NonPhysicalInertia {
        /// File and line of the `<inertial>` (or of the link when the mass comes from geoms).
        loc: SourceLoc,
        /// Whether the file says link (URDF) or body (MJCF).
        what: LinkWord,
        /// The link's or body's name.
        link: String,
        /// Which check failed, with the values.
        detail: String,
    },
    /// A URDF `package://` mesh path names a package found in none of the searched folders.
    #[error("{loc}: link '{link}': cannot resolve '{uri}': package '{package}' not found (searched: {}); add the folder holding '{package}/' to LoadOptions::package_dirs or to ROS_PACKAGE_PATH", searched_list(.searched))]
    PackageNotFound {
        /// File and line of the geometry element.
        loc: SourceLoc,
        /// The link the mesh belongs to.
        link: String,
        /// The mesh `filename` as written.
        uri: String,
        /// The package name taken from `uri`.
        package: String,
        /// The folders searched, in order (boxed to keep `LoadError` small).
        searched: Box<[String]>,
    },
    /// A URDF mesh file resolves to a path that does not exist (collision meshes only; a missing
    /// visual mesh is dropped with a warning).
    #[error("{loc}: link '{link}': mesh file '{path}' does not exist; fix the filename, or point LoadOptions::package_dirs or ROS_PACKAGE_PATH at the right package for a package:// path")]
    MeshNotFound {
        /// File and line of the geometry element.
        loc: SourceLoc,
        /// The link the mesh belongs to.
        link: String,
        /// The resolved path.
        path: String,
    },
    /// A mesh's mass properties are needed (the link's inertia comes from its geoms) but could not
    /// be computed ([`MeshError`](crate::mass::MeshError)).
    #[error("{loc}: {what} '{link}': the mass properties of mesh '{path}' are needed (the {what}'s inertia comes from its geoms) but {reason}")]
    MeshMass {
        /// File and line of the geom.
        loc: SourceLoc,
        /// Whether the file says link (URDF) or body (MJCF).
        what: LinkWord,
        /// The link's or body's name.
        link: String,
        /// The mesh file.
        path: String,
        /// Why the mass properties failed.
        reason: String,
    },
    /// A colliding mesh geom's convex hull could not be built.
    #[error("{loc}: {what} '{link}': mesh '{path}' collides by its convex hull, but {reason}; {}, or fix the mesh", hull_fix(.what))]
    MeshHull {
        /// File and line of the geom.
        loc: SourceLoc,
        /// Whether the file says link (URDF) or body (MJCF).
        what: LinkWord,
        /// The link's or body's name.
        link: String,
        /// The mesh file.
        path: String,
        /// Why the hull failed.
        reason: String,
    },
    /// MJCF `<include>`s include each other in a loop.
    #[error("{loc}: <include>: include cycle: {}; remove one of these includes", .chain.join(" includes "))]
    IncludeCycle {
        /// File and line of the `<include>` that closes the loop.
        loc: SourceLoc,
        /// The files of the loop, in include order.
        chain: Vec<String>,
    },
    /// An MJCF `<include file>` could not be read.
    #[error(
        "{loc}: <include>: cannot read '{path}': {reason}; MuJoCo looks for an included file in the main model's folder, then beside the including file"
    )]
    IncludeNotFound {
        /// File and line of the `<include>`.
        loc: SourceLoc,
        /// The path tried.
        path: String,
        /// The operating system's error.
        reason: String,
    },
    /// An MJCF element's `class` (or its parent's `childclass`) names no `<default class>`.
    #[error("{loc}: <{element}>: unknown default class '{class}'; define <default class=\"{class}\"> or fix the name")]
    UnknownClass {
        /// File and line of the element.
        loc: SourceLoc,
        /// The element's tag.
        element: String,
        /// The class name.
        class: String,
    },
    /// An MJCF attribute has a bad value (not a number, wrong count, out of range, unknown
    /// keyword, …).
    #[error("{loc}: <{element}>: attribute '{attribute}' {detail}")]
    BadAttribute {
        /// File and line of the element.
        loc: SourceLoc,
        /// The element's tag.
        element: String,
        /// The attribute's name.
        attribute: String,
        /// What is wrong with the value, starting with a verb (`is …`).
        detail: String,
    },
    /// An element names an object (joint, body, site, geom, tendon, mesh, …) that does not exist.
    #[error("{loc}: <{element}>: unknown {kind} '{target}'; define it or fix the name")]
    UnknownReference {
        /// File and line of the referring element.
        loc: SourceLoc,
        /// The referring element's tag.
        element: String,
        /// The kind of object named (`"joint"`, `"mesh"`, …).
        kind: &'static str,
        /// The name that was not found.
        target: String,
    },
    /// An MJCF feature the engine does not handle and whose omission would change the dynamics.
    #[error("{loc}: <{element}>: {what} is not supported yet and would change the dynamics; {fix}")]
    Unsupported {
        /// File and line of the element.
        loc: SourceLoc,
        /// The element's tag.
        element: String,
        /// The feature.
        what: String,
        /// How to rewrite the model without it.
        fix: String,
    },
    /// An MJCF asset file (`<mesh file>`) does not exist.
    #[error("{loc}: <{element}>: file '{path}' does not exist; fix the file name or <compiler meshdir/assetdir> (relative paths start at the model file's folder)")]
    AssetNotFound {
        /// File and line of the asset element.
        loc: SourceLoc,
        /// The asset element's tag.
        element: String,
        /// The resolved path.
        path: String,
    },
    /// The file is neither URDF nor MJCF (by extension, or by root element for text).
    #[error("{file}: unsupported model format (expected a URDF file, root element <robot>, named .urdf, or an MJCF file, root element <mujoco>, named .xml)")]
    UnsupportedFormat {
        /// The file (`<string>` for text).
        file: String,
    },
}

/// What a link is called in its file: a URDF `<link>` or an MJCF `<body>`; messages use the file's
/// own terms.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LinkWord {
    /// URDF: `link`.
    Link,
    /// MJCF: `body`.
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
