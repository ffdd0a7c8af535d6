//! Mass properties of triangle meshes in MuJoCo's four modes (`<mesh inertia="...">`), computed
//! the way `mjCMesh::Process` does (`ComputeFaceCentroid`, `ComputeVolume`,
//! `ComputeSurfaceArea`, `ComputeInertia`), so that bodies whose inertia comes from meshes agree
//! with MuJoCo to round-off — but with MuJoCo's silent cases turned into errors that name the
//! defect (see [`mesh_inertia`]).
//!
//! The integrals are exact for the polyhedron (no sampling): a closed surface is decomposed into
//! the tetrahedra spanned by each triangle and a reference point (the divergence theorem), each
//! with signed volume `V = (a − p)·((b − p) × (c − p)) / 6`, centroid `(a + b + c + p)/4`, and
//! second moment about its apex `∫ x xᵀ dV = V/20 (Σ a aᵀ + s sᵀ)` with `s = a + b + c` (apex at
//! the origin). For shells each triangle of area `A` contributes `∫ x xᵀ dA = A/12 (Σ a aᵀ + s sᵀ)`.
//! The inertia tensor follows from the second moments `S` as `I = tr(S) 1 − S` (docs/physics.md (68)–(69)).

use super::error::MeshError;
use super::fast_hash::{point_key, FastMap};
use super::topology;
use super::MeshInertia;
use crate::spatial::{Mat3, RigidInertia, Transform, Vec3};

/// MuJoCo's `mjMINVAL`: the smallest area (m²) and volume (m³) it accepts, and the smallest
/// `|(b − a) × (c − a)|` of a triangle that counts (`triangle()` in user_mesh.cc).
const MINVAL: f64 = 1e-15;

/// A volume below `FLAT_REL · area^{3/2}` is round-off of a flat surface, whatever its absolute
/// size (a sphere has `V / A^{3/2} ≈ 0.094`, a plate of thickness t and width w about `0.35 t/w`,
/// so this only rejects plates thinner than ~3e-12 of their width).
const FLAT_REL: f64 = 1e-12;

/// A surface whose holes, or (exact mode) wrongly wound triangles, could change its volume by more
/// than this fraction does not bound a definite solid (see [`super::Topology::hole_area`] and
/// [`super::Topology::misoriented_area`]). Pinholes and cracks of CAD exports stay below it (the
/// MuJoCo corpus: ≤ 6.4e-7), missing faces far above (≥ 8.6e-6, most above 1e-2); flipped sliver
/// triangles that MuJoCo's own orientation check skips (area under 3.2e-8) stay below it too.
const DEFECT_REL: f64 = 1e-6;

/// MuJoCo's tolerances on the triangle inequality of the principal moments (`mjCMesh::Process`:
/// `A + B ≥ C (1 − rtol) − atol`).
const TRIANGLE_RTOL: f64 = 1e-6;
const TRIANGLE_ATOL: f64 = 1e-9;

/// A triangle mesh in its file's coordinates, scale applied.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    /// Vertex positions (m).
    pub vertices: Vec<Vec3>,
    /// Triangles as indices into `vertices`, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

impl TriangleMesh {
    /// Multiplies every vertex by `scale` component-wise; a mirroring scale (negative product)
    /// reverses every triangle so that the winding stays counter-clockwise seen from outside, as
    /// MuJoCo does (`mjCMesh::Process`, "correct winding order for left-handed coordinate
    /// systems").
    pub fn apply_scale(&mut self, scale: &Vec3) {
        if *scale != Vec3::repeat(1.0) {
            for v in &mut self.vertices {
                v.component_mul_assign(scale);
            }
        }
        if scale.x * scale.y * scale.z < 0.0 {
            for t in &mut self.triangles {
                t.swap(1, 2);
            }
        }
    }

    /// The mesh moved rigidly: every vertex `v` becomes `x_a_b.rot · v + x_a_b.pos`.
    pub fn transformed(&self, x_a_b: &Transform) -> TriangleMesh {
        TriangleMesh {
            vertices: self.vertices.iter().map(|v| x_a_b.act_point(v)).collect(),
            triangles: self.triangles.clone(),
        }
    }

    /// Total area of the triangles (m²).
    pub fn surface_area(&self) -> f64 {
        self.triangles.iter().map(|t| 0.5 * self.cross(t).norm()).sum()
    }

    /// Signed enclosed volume (m³) by the divergence theorem about the origin; positive for a
    /// closed mesh wound counter-clockwise seen from outside. Indices must be in range.
    pub fn signed_volume(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = self.corners(t);
                a.dot(&b.cross(&c)) / 6.0
            })
            .sum()
    }

    /// The edge topology (closedness and orientation), see [`Topology`](crate::mass::Topology). Indices must be
    /// in range.
    pub fn topology(&self) -> topology::Topology {
        topology::analyze(self)
    }

    /// Length of the diagonal of the axis-aligned bounding box (0 for an empty mesh).
    pub fn diameter(&self) -> f64 {
        let Some(first) = self.vertices.first() else { return 0.0 };
        let (lo, hi) = self.vertices.iter().fold((*first, *first), |(lo, hi), v| (lo.inf(v), hi.sup(v)));
        (hi - lo).norm()
    }

    fn point(&self, i: u32) -> [f64; 3] {
        let v = self.vertices[i as usize];
        [v.x, v.y, v.z]
    }

    fn corners(&self, t: &[u32; 3]) -> [Vec3; 3] {
        t.map(|i| self.vertices[i as usize])
    }

    /// `(b − a) × (c − a)`: twice the area along the outward normal.
    fn cross(&self, t: &[u32; 3]) -> Vec3 {
        let [a, b, c] = self.corners(t);
        (b - a).cross(&(c - a))
    }

    /// Checks what every mode needs: finite vertices, indices in range, at least 4 vertices.
    fn validate(&self) -> Result<(), MeshError> {
        if let Some(index) = self.vertices.iter().position(|v| !v.iter().all(|x| x.is_finite())) {
            return Err(MeshError::NonFiniteVertex { index });
        }
        let n = self.vertices.len();
        for (k, t) in self.triangles.iter().enumerate() {
            if let Some(&vertex) = t.iter().find(|&&i| i as usize >= n) {
                return Err(MeshError::VertexIndexOutOfRange { triangle: k, vertex, count: n });
            }
        }
        if n < 4 {
            return Err(MeshError::TooFewVertices { count: n });
        }
        Ok(())
    }
}

/// Volume (or surface area for [`MeshInertia::Shell`]) and unit-density mass properties of a
/// mesh, in the mesh frame: the returned inertia has mass = the measure, first moment
/// `measure · c` and rotational inertia about the mesh origin.
///
/// The modes (MuJoCo `<mesh inertia>`, `mjtMeshInertia`; MuJoCo's default is `legacy`):
/// - [`MeshInertia::Exact`]: the solid the surface encloses. The surface must be closed
///   ([`MeshError::Open`]) and consistently oriented ([`MeshError::Misoriented`]: no edge run
///   twice in the same direction, MuJoCo's test), with positive volume
///   ([`MeshError::NegativeVolume`] — an inside-out mesh is never flipped silently). Defects that
///   cannot move the volume by more than 1e-6 of itself are tolerated: T-junctions, CAD pinholes,
///   wrongly wound sliver triangles (which MuJoCo's own test skips below 3.2e-8 in file units).
/// - [`MeshInertia::Legacy`]: MuJoCo's historical rule. The centre of mass and the volume are
///   sums over the tetrahedra of each triangle with the area-weighted centroid of the faces as
///   apex, each volume taken as `|V|`; the inertia (and the volume returned) are the same sums
///   with the centre of mass as apex. Equal to `Exact` for a closed mesh that is star-shaped about
///   those points (every convex mesh); larger otherwise, and it tolerates misoriented triangles —
///   that is its documented purpose, not a silent fix. The mesh must still be closed
///   ([`MeshError::Open`]): for a surface with holes the result depends on the apex and means
///   nothing; and it must not be inside out as a whole (negative signed volume,
///   [`MeshError::NegativeVolume`]), which MuJoCo would silently turn positive.
/// - [`MeshInertia::Convex`]: the solid convex hull of all vertices (parry3d's quickhull; MuJoCo
///   uses qhull). Any vertex cloud with volume works.
/// - [`MeshInertia::Shell`]: mass spread uniformly over the surface area (MJCF
///   `<mesh inertia="shell">`); open surfaces are fine.
///
/// A mesh without triangles is measured through its convex hull in every mode (MuJoCo copies the
/// hull's faces then). Every mode rejects zero surface area ([`MeshError::ZeroArea`]), volumes
/// below MuJoCo's 1e-15 m³ or numerically flat ([`MeshError::VolumeTooSmall`]) and
/// non-physical results ([`MeshError::NonPhysicalInertia`], MuJoCo's eigenvalue checks).
pub fn mesh_inertia(mesh: &TriangleMesh, mode: MeshInertia) -> Result<(f64, RigidInertia), MeshError> {
    measure(mesh, mode, false).map(|(result, _)| result)
}

/// [`mesh_inertia`] with MuJoCo 4.0's policy for open surfaces: in the `legacy` and `exact` modes
/// MuJoCo computes the volume integrals of a surface with holes anyway (the tetrahedra about its
/// apex), so this does too and returns the [`MeshError::Open`] defect beside the result, for the
/// caller to report as a warning. Every other defect is still an error.
pub fn mesh_inertia_as_mujoco(
    mesh: &TriangleMesh,
    mode: MeshInertia,
) -> Result<((f64, RigidInertia), Option<MeshError>), MeshError> {
    measure(mesh, mode, true)
}

/// [`mesh_inertia`] (`allow_open` false) and [`mesh_inertia_as_mujoco`] (true).
fn measure(
    mesh: &TriangleMesh,
    mode: MeshInertia,
    allow_open: bool,
) -> Result<((f64, RigidInertia), Option<MeshError>), MeshError> {
    mesh.validate()?;
    let mut open = None;
    let hull = if mesh.triangles.is_empty() { Some(convex_hull(&mesh.vertices)?) } else { None };
    // The surface: the mesh's own triangles (or the hull's when it has none).
    let surface = hull.as_ref().unwrap_or(mesh);
    let (area, face_centroid) = face_centroid(surface);
    if area.is_nan() || area < MINVAL {
        return Err(MeshError::ZeroArea { area });
    }
    let (measure, com, second_moment) = match mode {
        MeshInertia::Shell => {
            let (measure, s) = second_moments(surface, &face_centroid, Weight::Area);
            (measure, face_centroid, s)
        }
        MeshInertia::Exact | MeshInertia::Legacy | MeshInertia::Convex => {
            // The surface must bound a solid (the hull always does).
            let topo = (mode != MeshInertia::Convex).then(|| surface.topology());
            let own_hull;
            let solid = match (mode, &hull) {
                (MeshInertia::Convex, None) => {
                    own_hull = convex_hull(&mesh.vertices)?;
                    &own_hull
                }
                _ => surface,
            };
            let weight = if mode == MeshInertia::Legacy { Weight::AbsVolume } else { Weight::Volume };
            let (volume, signed, com) = volume_and_centroid(solid, &face_centroid, weight);
            if let Some(t) = &topo {
                match check_defects(surface, t, mode, volume) {
                    Err(e @ MeshError::Open { .. }) if allow_open => open = Some(e),
                    other => other?,
                }
            }
            // An inside-out mesh is refused in every mode, legacy included: its |V| per
            // tetrahedron tolerates some wrongly wound triangles, not a surface turned inside out.
            // An open surface has no inside: legacy mode takes |V| per tetrahedron as MuJoCo does.
            let open_legacy = open.is_some() && mode == MeshInertia::Legacy;
            if signed < 0.0 && !open_legacy {
                return Err(MeshError::NegativeVolume { volume: signed });
            }
            if volume.is_nan() || volume < MINVAL || volume <= FLAT_REL * area.powf(1.5) {
                return Err(MeshError::VolumeTooSmall { volume });
            }
            let (measure, s) = second_moments(solid, &com, weight);
            (measure, com, s)
        }
    };
    // I = tr(S) 1 − S (docs/physics.md (68)–(69)), about the centre of mass.
    let i_com = Mat3::identity() * second_moment.trace() - second_moment;
    check_physical(&i_com)?;
    Ok(((measure, RigidInertia::from_com(measure, com, i_com)), open))
}

/// Refuses a surface whose wrongly wound triangles (exact mode) or holes (any solid mode; checked
/// last, so that [`mesh_inertia_as_mujoco`] can set that defect aside) could change its volume by
/// more than [`DEFECT_REL`]: holes of area `A_h` by up to `d·A_h/3`, flipped
/// triangles of area `A_f` by up to `2·d·A_f/3` (`d` the diameter).
fn check_defects(
    surface: &TriangleMesh,
    t: &topology::Topology,
    mode: MeshInertia,
    volume: f64,
) -> Result<(), MeshError> {
    let d = surface.diameter();
    let v = volume.abs();
    let too_large = |spread: f64| spread > 0.0 && (v.is_nan() || spread > DEFECT_REL * v);
    if mode == MeshInertia::Exact && too_large(2.0 * d * t.misoriented_area / 3.0) {
        let (a, b) = t.misoriented_example.unwrap_or_default();
        return Err(MeshError::Misoriented {
            edges: t.misoriented_edges,
            example: (surface.point(a), surface.point(b)),
        });
    }
    let hole_spread = d * t.hole_area / 3.0;
    if too_large(hole_spread) {
        let (a, b) = t.boundary_example.unwrap_or_default();
        return Err(MeshError::Open {
            edges: t.boundary_edges,
            holes: t.boundary_loops,
            hole_area: t.hole_area,
            relative: hole_spread / v,
            example: (surface.point(a), surface.point(b)),
        });
    }
    Ok(())
}

/// MuJoCo's checks on the principal moments: the smallest positive, and the triangle inequality
/// within its tolerances (`mjCMesh::Process`).
fn check_physical(i_com: &Mat3) -> Result<(), MeshError> {
    let (m, _) = super::principal_axes(i_com);
    let moments = [m.x, m.y, m.z];
    if moments.iter().any(|x| !x.is_finite()) || m.x <= 0.0 {
        return Err(MeshError::NonPhysicalInertia { moments, why: "are not all positive" });
    }
    if m.x + m.y < m.z * (1.0 - TRIANGLE_RTOL) - TRIANGLE_ATOL {
        return Err(MeshError::NonPhysicalInertia { moments, why: "violate I₁ + I₂ ≥ I₃" });
    }
    Ok(())
}

/// How a triangle's contribution is weighted.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Weight {
    /// The signed volume of the tetrahedron (triangle, apex).
    Volume,
    /// Its absolute value (MuJoCo's legacy mode).
    AbsVolume,
    /// The triangle's area (shells).
    Area,
}

/// Total area and area-weighted centroid of the triangles (`ComputeFaceCentroid`). Triangles
/// with `|(b − a) × (c − a)| < 1e-15` count as zero, as in MuJoCo.
fn face_centroid(m: &TriangleMesh) -> (f64, Vec3) {
    let mut area = 0.0;
    let mut moment = Vec3::zeros();
    for t in &m.triangles {
        let [a, b, c] = m.corners(t);
        let n = (b - a).cross(&(c - a)).norm();
        if n < MINVAL {
            continue;
        }
        let w = 0.5 * n;
        area += w;
        moment += (a + b + c) * (w / 3.0);
    }
    let centroid = if area >= MINVAL { moment / area } else { Vec3::zeros() };
    (area, centroid)
}

/// Volume (weighted as asked), signed volume, and centroid of the solid as the sum over the
/// tetrahedra (triangle, `apex`) (`ComputeVolume`): each tetrahedron's centroid is
/// `¾ (triangle centroid) + ¼ apex`.
fn volume_and_centroid(m: &TriangleMesh, apex: &Vec3, weight: Weight) -> (f64, f64, Vec3) {
    let (mut volume, mut signed) = (0.0, 0.0);
    let mut moment = Vec3::zeros();
    for t in &m.triangles {
        let [a, b, c] = m.corners(t);
        let n = (b - a).cross(&(c - a));
        if n.norm() < MINVAL {
            continue;
        }
        let center = (a + b + c) / 3.0;
        let s = (center - apex).dot(&n) / 6.0;
        let v = if weight == Weight::AbsVolume { s.abs() } else { s };
        signed += s;
        volume += v;
        moment += (center * 0.75 + apex * 0.25) * v;
    }
    let centroid = if volume.abs() >= MINVAL { moment / volume } else { *apex };
    (volume, signed, centroid)
}

/// Total weight (volume or area) and second moment `S = ∫ x xᵀ` about `origin`
/// (`ComputeInertia`): a tetrahedron with apex at the origin and corners a, b, c contributes
/// `V/20 (Σ a aᵀ + s sᵀ)`, a triangle `A/12 (Σ a aᵀ + s sᵀ)`, with `s = a + b + c`.
fn second_moments(m: &TriangleMesh, origin: &Vec3, weight: Weight) -> (f64, Mat3) {
    let mut total = 0.0;
    let mut s = Mat3::zeros();
    for t in &m.triangles {
        let [a, b, c] = m.corners(t).map(|v| v - origin);
        let n = (b - a).cross(&(c - a));
        let len = n.norm();
        if len < MINVAL {
            continue;
        }
        let (w, denom) = match weight {
            Weight::Area => (0.5 * len, 12.0),
            Weight::Volume => ((a + b + c).dot(&n) / 18.0, 20.0),
            Weight::AbsVolume => (((a + b + c).dot(&n) / 18.0).abs(), 20.0),
        };
        total += w;
        let sum = a + b + c;
        s +=
            (a * a.transpose() + b * b.transpose() + c * c.transpose() + sum * sum.transpose()) * (w / denom);
    }
    (total, s)
}

/// The convex hull of a vertex cloud as a closed, outward-wound triangle mesh (parry3d-f64's
/// quickhull), after MuJoCo's checks for colocated, collinear and coplanar vertices
/// (`mjCMesh::MakeGraph`).
pub fn convex_hull(vertices: &[Vec3]) -> Result<TriangleMesh, MeshError> {
    let err = |detail: &str| MeshError::Hull { detail: detail.to_string() };
    // Distinct points only (parry rejects duplicates).
    let mut seen: FastMap<[u64; 3], ()> =
        FastMap::with_capacity_and_hasher(vertices.len(), Default::default());
    let points: Vec<Vec3> =
        vertices.iter().filter(|v| seen.insert(point_key(v.x, v.y, v.z), ()).is_none()).copied().collect();
    if points.iter().any(|v| !v.iter().all(|x| x.is_finite())) {
        return Err(err("a vertex is not finite"));
    }
    if points.len() < 4 {
        return Err(err(&format!("it has {} distinct vertices, fewer than the 4 of a solid", points.len())));
    }
    let p0 = points[0];
    let Some(p1) = points.iter().find(|p| (*p - p0).norm() > MINVAL) else {
        return Err(err("all vertices are at one point"));
    };
    let e1 = p1 - p0;
    let normal = points.iter().find_map(|p| {
        let e2 = p - p0;
        let n = e1.cross(&e2);
        (n.norm() > MINVAL * e1.norm() * e2.norm()).then(|| n.normalize())
    });
    let Some(normal) = normal else {
        return Err(err("all vertices are on one line"));
    };
    if !points.iter().any(|p| (p - p0).dot(&normal).abs() > MINVAL) {
        return Err(err("all vertices are in one plane"));
    }
    let input: Vec<parry3d_f64::math::Vector> =
        points.iter().map(|p| parry3d_f64::math::Vector::new(p.x, p.y, p.z)).collect();
    // parry reports degenerate input as errors; its internal assertions are contained too.
    let result = std::panic::catch_unwind(|| parry3d_f64::transformation::try_convex_hull(&input));
    let (hv, hi) = match result {
        Ok(Ok(h)) => h,
        Ok(Err(e)) => return Err(MeshError::Hull { detail: format!("quickhull failed: {e}") }),
        Err(_) => return Err(err("quickhull failed on nearly degenerate input")),
    };
    let hull =
        TriangleMesh { vertices: hv.iter().map(|p| Vec3::new(p.x, p.y, p.z)).collect(), triangles: hi };
    let volume = hull.signed_volume();
    if volume.is_nan() || volume <= 0.0 || hull.triangles.len() < 4 {
        return Err(err("the hull has no volume"));
    }
    Ok(hull)
}
