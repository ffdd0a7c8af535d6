//! Why a mesh cannot be read, or cannot give mass properties.
//!
//! The messages are clauses written to follow "the mass properties of mesh 'PATH' are needed ...
//! but" (`LoadError::MeshMass` supplies the file and the body); each one names the defect and the
//! fix. The path is kept in the variants that know it, for programs that want it.

use std::path::PathBuf;
use thiserror::Error;

/// Advice appended to every defect that makes a mesh unusable as a solid.
const SOLID_FIX: &str = "give the body (URDF: the link) an explicit <inertial>";

/// Why a mesh cannot be read or cannot give mass properties.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum MeshError {
    /// The file could not be opened or read.
    #[error("the file cannot be read: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// The file's format is not one the reader decodes (COLLADA `.dae` among them).
    #[error(
        "its format ('{extension}') is not supported: mass properties are computed from STL \
         (binary or ASCII), OBJ and MuJoCo MSH files; convert the mesh (e.g. with MeshLab or \
         Blender) or {SOLID_FIX}"
    )]
    UnsupportedFormat { path: PathBuf, extension: String },
    /// The file is not a well-formed file of its format.
    #[error("it is not a valid {format} file: {}{detail}", match line { Some(l) => format!("line {l}: "), None => String::new() })]
    Parse { path: PathBuf, format: &'static str, line: Option<usize>, detail: String },
    /// The scale has a non-finite component.
    #[error("its scale ({x}, {y}, {z}) is not finite; give finite scale factors")]
    BadScale { x: f64, y: f64, z: f64 },
    /// A vertex coordinate is NaN or infinite.
    #[error("vertex {index} has a non-finite coordinate; fix the file or {SOLID_FIX}")]
    NonFiniteVertex { index: usize },
    /// A triangle refers to a vertex that does not exist.
    #[error(
        "triangle {triangle} refers to vertex {vertex}, but the mesh has {count} vertices; fix the file"
    )]
    VertexIndexOutOfRange { triangle: usize, vertex: u32, count: usize },
    /// Fewer than 4 vertices: no solid (MuJoCo: "at least 4 vertices required").
    #[error("it has {count} vertices, and a mesh needs at least 4 to enclose a volume; {SOLID_FIX}")]
    TooFewVertices { count: usize },
    /// The surface area is zero: every triangle is degenerate (MuJoCo: "mesh surface area is too
    /// small").
    #[error(
        "its surface area ({area:.3e} m²) is zero: every triangle is degenerate (repeated or \
         collinear vertices); fix the mesh or {SOLID_FIX}"
    )]
    ZeroArea { area: f64 },
    /// The convex hull cannot be built (all vertices coplanar or collinear, or the hull
    /// algorithm failed).
    #[error("its convex hull cannot be computed ({detail}); use <mesh inertia=\"shell\"> or {SOLID_FIX}")]
    Hull { detail: String },
    /// The surface has holes large enough to leave its volume undetermined.
    #[error(
        "it is not closed: {edges} boundary edge(s) (edges used by an odd number of triangles) \
         form {holes} hole(s) of total area {hole_area:.3e} m², e.g. at the edge from {} to {}, \
         which leave its volume uncertain by up to {:.1e} of its value; close the holes (e.g. \
         MeshLab 'Close Holes'), or use <mesh inertia=\"shell\"> (mass on the surface) or \
         inertia=\"convex\" (the solid hull), or {SOLID_FIX}",
        fmt_point(.example.0), fmt_point(.example.1), .relative
    )]
    Open { edges: usize, holes: usize, hole_area: f64, relative: f64, example: ([f64; 3], [f64; 3]) },
    /// Neighbouring triangles are wound in opposite senses (MuJoCo: "faces of mesh have
    /// inconsistent orientation").
    #[error(
        "its triangles are not consistently oriented: {edges} edge(s) are traversed twice in the \
         same direction, e.g. the edge from {} to {}; re-orient the faces coherently (e.g. \
         MeshLab 'Re-Orient all faces coherently'), or use <mesh inertia=\"legacy\"> (MuJoCo's \
         default, which tolerates it) or inertia=\"shell\", or {SOLID_FIX}",
        fmt_point(.example.0), fmt_point(.example.1)
    )]
    Misoriented { edges: usize, example: ([f64; 3], [f64; 3]) },
    /// The enclosed volume is negative: the mesh is inside out. Never flipped silently.
    #[error(
        "its signed volume is negative ({volume:.6e} m³): the triangles are wound clockwise seen \
         from outside (an inside-out mesh); reverse the winding of every triangle (e.g. MeshLab \
         'Invert Faces Orientation'), or {SOLID_FIX}"
    )]
    NegativeVolume { volume: f64 },
    /// The volume is too small to carry mass: a flat or degenerate solid (MuJoCo: "mesh volume is
    /// too small ... Try setting inertia to shell").
    #[error(
        "its volume ({volume:.3e} m³) is too small to carry mass (a flat or degenerate mesh); use \
         <mesh inertia=\"shell\"> (mass on the surface) or {SOLID_FIX}"
    )]
    VolumeTooSmall { volume: f64 },
    /// The computed inertia is not that of a physical body (MuJoCo: "eigenvalue of mesh inertia
    /// must be positive" / "eigenvalues of mesh inertia violate A + B >= C"); happens for
    /// self-intersecting meshes.
    #[error(
        "its inertia is not physical (principal moments per unit density {moments:?} {why}), \
         which happens for self-intersecting meshes; repair the mesh, use <mesh inertia=\"convex\">, \
         or {SOLID_FIX}"
    )]
    NonPhysicalInertia { moments: [f64; 3], why: &'static str },
}

fn fmt_point(p: [f64; 3]) -> String {
    format!("({:.6}, {:.6}, {:.6})", p[0], p[1], p[2])
}
