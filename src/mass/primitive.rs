//! Closed-form mass properties of the MJCF/URDF primitives, solid and shell, with the formulas
//! MuJoCo uses (`mjCGeom::GetVolume` and `mjCGeom::SetInertia`), so that bodies whose inertia comes
//! from geoms agree with MuJoCo to round-off. Every shape is centred at its frame origin, with its
//! symmetry axes along the frame axes (capsules and cylinders along z).

use super::Distribution;
use crate::spatial::{Mat3, RigidInertia, Vec3};
use std::f64::consts::PI;

/// A primitive shape in MuJoCo's size convention (half-lengths).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Primitive {
    /// A sphere.
    Sphere {
        /// Radius (m).
        radius: f64,
    },
    /// A cylinder of half-length `half_length` along z capped by two hemispheres.
    Capsule {
        /// Radius of the cylinder and the caps (m).
        radius: f64,
        /// Half-length of the cylindrical part (m).
        half_length: f64,
    },
    /// A cylinder along z.
    Cylinder {
        /// Radius (m).
        radius: f64,
        /// Half-length (m).
        half_length: f64,
    },
    /// A box with half-extents along x, y, z.
    Box {
        /// Half-extents along x, y, z (m).
        half_extents: Vec3,
    },
    /// An ellipsoid.
    Ellipsoid {
        /// Semi-axes along x, y, z (m).
        radii: Vec3,
    },
}

/// Volume (solid) or surface area (shell) of a primitive.
pub fn primitive_measure(p: &Primitive, d: Distribution) -> f64 {
    use Distribution::*;
    match (*p, d) {
        (Primitive::Sphere { radius: r }, Volume) => 4.0 * PI * r * r * r / 3.0,
        (Primitive::Sphere { radius: r }, Shell) => 4.0 * PI * r * r,
        (Primitive::Capsule { radius: r, half_length }, Volume) => {
            PI * (r * r * 2.0 * half_length + 4.0 * r * r * r / 3.0)
        }
        (Primitive::Capsule { radius: r, half_length }, Shell) => {
            4.0 * PI * r * r + 2.0 * PI * r * 2.0 * half_length
        }
        (Primitive::Cylinder { radius: r, half_length }, Volume) => PI * r * r * 2.0 * half_length,
        (Primitive::Cylinder { radius: r, half_length }, Shell) => {
            2.0 * PI * r * r + 2.0 * PI * r * 2.0 * half_length
        }
        (Primitive::Box { half_extents: s }, Volume) => 8.0 * s.x * s.y * s.z,
        (Primitive::Box { half_extents: s }, Shell) => 8.0 * (s.x * s.y + s.y * s.z + s.z * s.x),
        (Primitive::Ellipsoid { radii: s }, Volume) => 4.0 * PI * s.x * s.y * s.z / 3.0,
        (Primitive::Ellipsoid { radii: s }, Shell) => {
            // Thomsen's approximation of the ellipsoid's area (relative error ≤ 1.06 %), as MuJoCo.
            let p = 1.6075;
            let t = (s.x * s.y).powf(p) + (s.y * s.z).powf(p) + (s.z * s.x).powf(p);
            4.0 * PI * (t / 3.0).powf(1.0 / p)
        }
    }
}

/// Mass properties of a primitive of total mass `mass`, about its centre, in its own axes.
pub fn primitive_inertia(p: &Primitive, d: Distribution, mass: f64) -> RigidInertia {
    let diag = principal_moments(p, d, mass);
    RigidInertia::from_com(mass, Vec3::zeros(), Mat3::from_diagonal(&diag))
}

/// Principal moments about the centre (docs/physics.md (51)–(53) for rods, disks and spheres; the capsule is
/// a cylinder plus two hemispheres shifted by the parallel-axis theorem, eq. 56).
fn principal_moments(p: &Primitive, d: Distribution, m: f64) -> Vec3 {
    use Distribution::*;
    match (*p, d) {
        (Primitive::Sphere { radius: r }, Volume) => Vec3::repeat(2.0 * m * r * r / 5.0),
        (Primitive::Sphere { radius: r }, Shell) => Vec3::repeat(2.0 * m * r * r / 3.0),
        (Primitive::Capsule { radius: r, half_length }, Volume) => {
            let h = 2.0 * half_length;
            // Mass split in proportion to the volumes of the ball and the cylinder.
            let m_ball = m * 4.0 * r / (4.0 * r + 3.0 * h);
            let m_cyl = m - m_ball;
            let i_ball = 2.0 * m_ball * r * r / 5.0;
            let ixy = m_cyl * (3.0 * r * r + h * h) / 12.0 + i_ball + m_ball * h * (3.0 * r + 2.0 * h) / 8.0;
            Vec3::new(ixy, ixy, m_cyl * r * r / 2.0 + i_ball)
        }
        (Primitive::Capsule { radius: r, half_length }, Shell) => {
            let h = 2.0 * half_length;
            let a_ball = 4.0 * PI * r * r;
            let a_cyl = 2.0 * PI * r * h;
            let m_ball = m * a_ball / (a_ball + a_cyl);
            let m_cyl = m - m_ball;
            let i_ball = 2.0 * m_ball * r * r / 3.0;
            // Each hemispherical shell's centre of mass sits r/2 from its rim.
            let hs_com = r / 2.0;
            let hs_pos = half_length + hs_com;
            let ixy =
                m_cyl * (6.0 * r * r + h * h) / 12.0 + i_ball + m_ball * (hs_pos * hs_pos - hs_com * hs_com);
            Vec3::new(ixy, ixy, m_cyl * r * r + i_ball)
        }
        (Primitive::Cylinder { radius: r, half_length }, Volume) => {
            let h = 2.0 * half_length;
            let ixy = m * (3.0 * r * r + h * h) / 12.0;
            Vec3::new(ixy, ixy, m * r * r / 2.0)
        }
        (Primitive::Cylinder { radius: r, half_length }, Shell) => {
            let h = 2.0 * half_length;
            let a_disk = PI * r * r;
            let a_side = 2.0 * PI * r * h;
            let m_disk = m * a_disk / (2.0 * a_disk + a_side);
            let m_side = m - 2.0 * m_disk;
            let disk_x = m_disk * r * r / 4.0 + m_disk * half_length * half_length;
            let ixy = m_side * (6.0 * r * r + h * h) / 12.0 + 2.0 * disk_x;
            Vec3::new(ixy, ixy, m_side * r * r + m_disk * r * r)
        }
        (Primitive::Box { half_extents: s }, Volume) => {
            let (x2, y2, z2) = (s.x * s.x, s.y * s.y, s.z * s.z);
            Vec3::new(m * (y2 + z2) / 3.0, m * (x2 + z2) / 3.0, m * (x2 + y2) / 3.0)
        }
        (Primitive::Box { half_extents: s }, Shell) => {
            let (lx, ly, lz) = (2.0 * s.x, 2.0 * s.y, 2.0 * s.z);
            let (a0, a1, a2) = (lx * ly, ly * lz, lz * lx);
            let total = 2.0 * (a0 + a1 + a2);
            // Two faces of each orientation: 0 ⊥ z, 1 ⊥ x, 2 ⊥ y (thin plates, docs/physics.md §3.1).
            let (m0, m1, m2) = (m * a0 / total, m * a1 / total, m * a2 / total);
            let ix = m0 * ly * ly / 12.0 + m1 * (ly * ly + lz * lz) / 12.0 + m2 * lz * lz / 12.0;
            let iy = m0 * lx * lx / 12.0 + m1 * lz * lz / 12.0 + m2 * (lx * lx + lz * lz) / 12.0;
            let iz = m0 * (lx * lx + ly * ly) / 12.0 + m1 * ly * ly / 12.0 + m2 * lx * lx / 12.0;
            let (x2, y2, z2) = (s.x * s.x, s.y * s.y, s.z * s.z);
            Vec3::new(
                2.0 * (m0 * z2 + m2 * y2 + ix),
                2.0 * (m0 * z2 + m1 * x2 + iy),
                2.0 * (m1 * x2 + m2 * y2 + iz),
            )
        }
        (Primitive::Ellipsoid { radii: s }, Volume) => {
            let (x2, y2, z2) = (s.x * s.x, s.y * s.y, s.z * s.z);
            Vec3::new(m * (y2 + z2) / 5.0, m * (x2 + z2) / 5.0, m * (x2 + y2) / 5.0)
        }
        (Primitive::Ellipsoid { radii: s }, Shell) => {
            // MuJoCo's approximation: a solid ellipsoid grown by ε minus the solid one.
            let eps = 1e-6;
            let va = 4.0 * PI * s.x * s.y * s.z / 3.0;
            let e = s + Vec3::repeat(eps);
            let vb = 4.0 * PI * e.x * e.y * e.z / 3.0;
            let rho = m / (vb - va);
            let solid = |mass: f64, r: &Vec3| {
                let (x2, y2, z2) = (r.x * r.x, r.y * r.y, r.z * r.z);
                Vec3::new(mass * (y2 + z2) / 5.0, mass * (x2 + z2) / 5.0, mass * (x2 + y2) / 5.0)
            };
            solid(vb * rho, &e) - solid(va * rho, &s)
        }
    }
}
