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
        /// The mesh file.
        path: PathBuf,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// The file's format is not one the reader decodes (COLLADA `.dae` among them).
    #[error(
        "its format ('{extension}') is not supported: mass properties are computed from STL \
         (binary or ASCII), OBJ and MuJoCo MSH files; convert the mesh (e.g. with MeshLab or \
         Blender) or {SOLID_FIX}"
    )]
    UnsupportedFormat {
        /// The mesh file.
        path: PathBuf,
        /// Its extension with the dot (`.dae`), or `no extension`.
        extension: String,
    },
    /// The file is not a well-formed file of its format.
    #[error("it is not a valid {format} file: {}{detail}", match line { Some(l) => format!("line {l}: "), None => String::new() })]
    Parse {
        /// The mesh file.
        path: PathBuf,
        /// The format it was read as (`ASCII STL`, `binary STL`, `OBJ`, …).
        format: &'static str,
        /// The line of the defect (1-based) in text formats, where known.
        line: Option<usize>,
        /// What is wrong.
        detail: String,
    },
    /// The scale has a non-finite component.
    #[error("its scale ({x}, {y}, {z}) is not finite; give finite scale factors")]
    BadScale {
        /// Scale factor along x.
        x: f64,
        /// Scale factor along y.
        y: f64,
        /// Scale factor along z.
        z: f64,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error("vertex {index} has a non-finite coordinate; fix the file or {SOLID_FIX}")]
    NonFiniteVertex {
        /// The vertex (0-based index in [`TriangleMesh::vertices`](crate::mass::TriangleMesh)).
        index: usize,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error(
        "triangle {triangle} refers to vertex {vertex}, but the mesh has {count} vertices; fix the file"
    )]
    VertexIndexOutOfRange {
        /// The triangle (0-based).
        triangle: usize,
        /// The vertex index it names (0-based).
        vertex: u32,
        /// The number of vertices.
        count: usize,
    },
    /// Fewer than 4 vertices: no solid (MuJoCo: "at least 4 vertices required").
    #[error("it has {count} vertices, and a mesh needs at least 4 to enclose a volume; {SOLID_FIX}")]
    TooFewVertices {
        /// The number of vertices.
        count: usize,
    },
    /// The surface area is zero: every triangle is degenerate (MuJoCo: "mesh surface area is too
    /// small").
    #[error(
        "its surface area ({area:.3e} m²) is zero: every triangle is degenerate (repeated or \
         collinear vertices); fix the mesh or {SOLID_FIX}"
    )]
    ZeroArea {
        /// The total surface area (m², scale applied).
        area: f64,
    },
    /// The convex hull cannot be built (all vertices coplanar or collinear, or the hull
    /// algorithm failed).
    #[error("its convex hull cannot be computed ({detail}); use <mesh inertia=\"shell\"> or {SOLID_FIX}")]
    Hull {
        /// Why the hull failed.
        detail: String,
    },
    /// The surface has holes large enough to leave its volume undetermined.
    #[error(
        "it is not closed: {edges} boundary edge(s) (edges used by an odd number of triangles) \
         form {holes} hole(s) of total area {hole_area:.3e} m², e.g. at the edge from {} to {}, \
         which leave its volume uncertain by up to {:.1e} of its value; close the holes (e.g. \
         MeshLab 'Close Holes'), or use <mesh inertia=\"shell\"> (mass on the surface) or \
         inertia=\"convex\" (the solid hull), or {SOLID_FIX}",
        fmt_point(.example.0), fmt_point(.example.1), .relative
    )]
    Open {
        /// Number of boundary edges (used by an odd number of triangles).
        edges: usize,
        /// Number of holes (closed loops of boundary edges).
        holes: usize,
        /// Total area of the holes (m²).
        hole_area: f64,
        /// Bound on the volume's uncertainty relative to the volume (diameter · hole area / 3 / |V|).
        relative: f64,
        /// One boundary edge, as its two end points (m, mesh frame).
        example: ([f64; 3], [f64; 3]),
    },
    /// Neighbouring triangles are wound in opposite senses (MuJoCo: "faces of mesh have
    /// inconsistent orientation").
    #[error(
        "its triangles are not consistently oriented: {edges} edge(s) are traversed twice in the \
         same direction, e.g. the edge from {} to {}; re-orient the faces coherently (e.g. \
         MeshLab 'Re-Orient all faces coherently'), or use <mesh inertia=\"legacy\"> (MuJoCo's \
         default, which tolerates it) or inertia=\"shell\", or {SOLID_FIX}",
        fmt_point(.example.0), fmt_point(.example.1)
    )]
    Misoriented {
        /// Number of edges traversed twice in the same direction.
        edges: usize,
        /// One such edge, as its two end points (m, mesh frame).
        example: ([f64; 3], [f64; 3]),
    },
    /// The enclosed volume is negative: the mesh is inside out. Never flipped silently.
    #[error(
        "its signed volume is negative ({volume:.6e} m³): the triangles are wound clockwise seen \
         from outside (an inside-out mesh); reverse the winding of every triangle (e.g. MeshLab \
         'Invert Faces Orientation'), or {SOLID_FIX}"
    )]
    NegativeVolume {
        /// The signed volume (m³).
        volume: f64,
    },
    /// The volume is too small to carry mass: a flat or degenerate solid (MuJoCo: "mesh volume is
    /// too small ... Try setting inertia to shell").
    #[error(
        "its volume ({volume:.3e} m³) is too small to carry mass (a flat or degenerate mesh); use \
         <mesh inertia=\"shell\"> (mass on the surface) or {SOLID_FIX}"
    )]
    VolumeTooSmall {
        /// The volume (m³).
        volume: f64,
    },
    /// The computed inertia is not that of a physical body (MuJoCo: "eigenvalue of mesh inertia
    /// must be positive" / "eigenvalues of mesh inertia violate A + B >= C"); happens for
    /// self-intersecting meshes.
    #[error(
        "its inertia is not physical (principal moments per unit density {moments:?} {why}), \
         which happens for self-intersecting meshes; repair the mesh, use <mesh inertia=\"convex\">, \
         or {SOLID_FIX}"
    )]
    NonPhysicalInertia {
        /// The principal moments per unit density (m⁵ for solids, m⁴ for shells).
        moments: [f64; 3],
        /// Which check failed (`are not all positive`, `violate I₁ + I₂ ≥ I₃`).
        why: &'static str,
    },
}

fn fmt_point(p: [f64; 3]) -> String {
    format!("({:.6}, {:.6}, {:.6})", p[0], p[1], p[2])
}
