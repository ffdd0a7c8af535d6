//! Fluid forces on bodies moving through a medium of `<option density viscosity wind>` (MuJoCo
//! documentation, "Computation → Fluid forces"; `mj_fluid`, `mj_inertiaBoxFluidModel`,
//! `mj_ellipsoidFluidModel` in engine_passive.c, the geom coefficients of `mjCGeom::SetFluidCoefs`
//! in user_objects.cc). Derivations in docs/fluid.md.
//!
//! Every MuJoCo body with mass feels one of two models, chosen per body:
//! - **inertia box** (the default): the body is replaced by the box with its mass and principal
//!   moments, centred at its centre of mass along its principal axes. In that frame, with ω and v
//!   the body's angular and linear velocity relative to the wind, the wrench is viscous (Stokes:
//!   a sphere of the boxes' mean side `d`, `−π d³ μ ω`, `−3π d μ v`) plus quadratic drag
//!   (`−½ ρ b_y b_z |v_x| v_x` per axis, `−ρ b_x (b_y⁴ + b_z⁴) |ω_x| ω_x / 64` per axis);
//! - **ellipsoid** (when any of the body's geoms sets `fluidshape="ellipsoid"`): each such geom,
//!   as the ellipsoid of its semi-axes, in its own frame, feels added-mass (gyroscopic) forces,
//!   Magnus and Kutta lift, blunt and slender drag and angular drag, with the geom's `fluidcoef`;
//!   the body's other geoms feel nothing.
//!
//! The wrench of each body (or geom) acts at its frame's origin and enters `qfrc_fluid` through
//! the Jacobian at that point (MuJoCo's `mj_applyFT`); `qfrc_fluid` is added to `qfrc_passive`.
//! The added-mass terms that need the acceleration are left out, as in MuJoCo.

use crate::kinematics::{body_poses, for_each_ancestor_dof_at, forward_velocities_unchecked};
use crate::model::spec::Shape;
use crate::model::{Data, FrameKind, Model};
use crate::spatial::{quat_to_matrix, Mat3, Transform, Vec3};
use std::f64::consts::PI;

/// MuJoCo's `mjMINVAL`.
const MINVAL: f64 = 1e-15;
/// MuJoCo's `mjEPS`.
const EPS: f64 = 1e-14;

/// One geom of the ellipsoid model: where it sits on its compiled body, its semi-axes and
/// MuJoCo's `geom_fluid` coefficients.
#[derive(Clone, Debug, PartialEq)]
pub struct FluidGeom {
    /// The geom (index in `Model::geoms`).
    pub geom: usize,
    /// Semi-axes of the equivalent ellipsoid (MuJoCo's `mju_geomSemiAxes`), metres.
    pub semiaxes: [f64; 3],
    /// Blunt drag, slender drag, angular drag, Kutta lift, Magnus lift (`fluidcoef`).
    pub coef: [f64; 5],
    /// The added mass per unit density along the geom's axes (m³; MuJoCo's `virtual_mass`).
    pub virtual_mass: [f64; 3],
    /// The added moment of inertia per unit density about the geom's axes (m⁵;
    /// `virtual_inertia`).
    pub virtual_inertia: [f64; 3],
}

/// How a body meets the fluid.
#[derive(Clone, Debug, PartialEq)]
pub enum FluidShape {
    /// The inertia-box model with the box's full side lengths along the principal axes.
    InertiaBox {
        /// Side lengths of the equivalent box (m).
        sides: [f64; 3],
    },
    /// The ellipsoid model over the body's geoms with `fluidshape="ellipsoid"` (indices into
    /// [`FluidModel::geoms`]).
    Ellipsoid {
        /// First geom of the body in [`FluidModel::geoms`].
        first: usize,
        /// Number of its geoms.
        count: usize,
    },
}

/// One MuJoCo body the fluid acts on.
#[derive(Clone, Debug, PartialEq)]
pub struct FluidBody {
    /// The MuJoCo body id (index in `Model::links`).
    pub link: usize,
    /// The compiled body it moves with (index in `Model::bodies`, never 0).
    pub body: usize,
    /// The body's inertial frame (centre of mass, principal axes) in the compiled body's frame.
    pub x_body_inertial: Transform,
    /// Which model and its data.
    pub shape: FluidShape,
}

/// The fluid model of a compiled model: the medium and the bodies it acts on (part of the
/// [`Plan`](crate::forward::Plan), built once).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FluidModel {
    /// Density of the medium (kg/m³, `<option density>`).
    pub density: f64,
    /// Dynamic viscosity of the medium (Pa·s, `<option viscosity>`).
    pub viscosity: f64,
    /// Velocity of the medium in the world (m/s, `<option wind>`).
    pub wind: Vec3,
    /// The bodies, in MuJoCo's body order.
    pub bodies: Vec<FluidBody>,
    /// The ellipsoid model's geoms, body by body.
    pub geoms: Vec<FluidGeom>,
    /// Geoms with `fluidshape="ellipsoid"` whose shape has no semi-axes here (meshes, planes,
    /// height fields): their bodies are left out, listed by `info`.
    pub unsupported: Vec<usize>,
}

impl FluidModel {
    /// The fluid model of `model`, or None when the medium has neither density nor viscosity
    /// (MuJoCo's early return) or both springs and dampers are switched off (`<flag spring
    /// damper>`, which skip every passive force).
    pub fn new(model: &Model) -> Option<Self> {
        let o = &model.options;
        if (o.density == 0.0 && o.viscosity == 0.0) || (!o.flags.spring && !o.flags.damper) {
            return None;
        }
        let mut fluid = FluidModel {
            density: o.density,
            viscosity: o.viscosity,
            wind: Vec3::new(o.wind[0], o.wind[1], o.wind[2]),
            ..Default::default()
        };
        for (link, &f) in model.links.frame.iter().enumerate() {
            let frame = &model.frames[f];
            debug_assert_eq!(frame.kind, FrameKind::Link);
            // Bodies without mass are skipped (MuJoCo); bodies welded to the world or carried by
            // a mocap body have no degree of freedom to push.
            if frame.inertia.mass < MINVAL || frame.body == 0 || frame.mocap.is_some() {
                continue;
            }
            let q = model.links.iquat[link];
            let r_frame_inertial = quat_to_matrix(q[0], q[1], q[2], q[3]);
            let x_frame_inertial = Transform::new(r_frame_inertial, frame.inertia.com());
            let x_body_inertial = frame.x_body_frame * x_frame_inertial;
            let ellipsoid: Vec<usize> = (0..model.geoms.len())
                .filter(|&g| model.links.of_geom[g] == link && model.geoms[g].fluid.is_some())
                .collect();
            let shape = if ellipsoid.is_empty() {
                FluidShape::InertiaBox {
                    sides: box_sides(frame.inertia.mass, &frame.inertia.i_com(), &r_frame_inertial),
                }
            } else {
                let first = fluid.geoms.len();
                for &g in &ellipsoid {
                    let geom = &model.geoms[g];
                    let Some(semiaxes) = semi_axes(&geom.shape) else {
                        fluid.unsupported.push(g);
                        continue;
                    };
                    let (virtual_mass, virtual_inertia) = added_mass(&semiaxes);
                    fluid.geoms.push(FluidGeom {
                        geom: g,
                        semiaxes,
                        coef: geom.fluid.unwrap_or_default(),
                        virtual_mass,
                        virtual_inertia,
                    });
                }
                FluidShape::Ellipsoid { first, count: fluid.geoms.len() - first }
            };
            fluid.bodies.push(FluidBody { link, body: frame.body, x_body_inertial, shape });
        }
        Some(fluid)
    }

    /// Bodies under the inertia-box model and geoms under the ellipsoid model.
    pub fn counts(&self) -> (usize, usize) {
        let boxes = self.bodies.iter().filter(|b| matches!(b.shape, FluidShape::InertiaBox { .. })).count();
        (boxes, self.geoms.len())
    }
}

/// The side lengths of the box with the body's mass and principal moments (MuJoCo's
/// `mj_inertiaBoxFluidModel`: `b_x = √(6 (I_y + I_z − I_x) / m)`, a moment sum below `mjMINVAL`
/// clamped to it), the moments read along the principal axes `r_frame_inertial`.
fn box_sides(mass: f64, i_com: &Mat3, r_frame_inertial: &Mat3) -> [f64; 3] {
    let d = r_frame_inertial.transpose() * i_com * r_frame_inertial;
    let i = [d[(0, 0)], d[(1, 1)], d[(2, 2)]];
    let side = |a: usize, b: usize, c: usize| ((i[b] + i[c] - i[a]).max(MINVAL) / mass * 6.0).sqrt();
    [side(0, 1, 2), side(1, 0, 2), side(2, 0, 1)]
}

/// The semi-axes of a geom's equivalent ellipsoid (MuJoCo's `mju_geomSemiAxes`); None for shapes
/// without `geom_size` semi-axes here (planes, height fields, meshes).
fn semi_axes(shape: &Shape) -> Option<[f64; 3]> {
    match shape {
        Shape::Sphere { radius } => Some([*radius; 3]),
        Shape::Capsule { radius, length } => Some([*radius, *radius, 0.5 * length + radius]),
        Shape::Cylinder { radius, length } => Some([*radius, *radius, 0.5 * length]),
        Shape::Box { size } => Some([0.5 * size.x, 0.5 * size.y, 0.5 * size.z]),
        Shape::Ellipsoid { radii } => Some([radii.x, radii.y, radii.z]),
        _ => None,
    }
}

/// 15-point Gauss–Kronrod weights on [0, 1] (MuJoCo's `kronrod_w`).
const KRONROD_W: [f64; 15] = [
    0.01146766, 0.03154605, 0.05239501, 0.07032663, 0.08450236, 0.09517529, 0.10221647, 0.10474107,
    0.10221647, 0.09517529, 0.08450236, 0.07032663, 0.05239501, 0.03154605, 0.01146766,
];
/// The nodes mapped to [0, ∞) by l = x³/(1 − x)² (MuJoCo's `kronrod_l`).
const KRONROD_L: [f64; 15] = [
    7.865151709349917e-08,
    1.7347976913907274e-05,
    0.0003548008144506193,
    0.002846636252924549,
    0.014094260903596077,
    0.053063261727396636,
    0.17041978741317773,
    0.5,
    1.4036301548686991,
    3.9353484827022642,
    11.644841677041734,
    39.53187807410903,
    177.5711362220801,
    1429.4772912937397,
    54087.416549217705,
];
/// dl/dx at the nodes (MuJoCo's `kronrod_d`).
const KRONROD_D: [f64; 15] = [
    5.538677720489877e-05,
    0.002080868285293228,
    0.016514126520723166,
    0.07261900344370877,
    0.23985243401862602,
    0.6868318249020725,
    1.8551129519182894,
    5.0,
    14.060031152313941,
    43.28941239611009,
    156.58546376397112,
    747.9826085305024,
    5827.4042950027115,
    116754.0197944512,
    25482945.327264845,
];

/// The ellipsoid's added-mass integral κ_x = d_x d_y d_z ∫₀^∞ dl / ((d_x² + l)^{3/2} (d_y² + l)^{1/2}
/// (d_z² + l)^{1/2}) (Lamb's α₀), by MuJoCo's quadrature (`GetAddedMassKappa`): l scaled by
/// (d_x³ d_y d_z)^{2/5}, the nodes above.
fn kappa(dx: f64, dy: f64, dz: f64) -> f64 {
    let (ix, iy, iz) = (1.0 / (dx * dx), 1.0 / (dy * dy), 1.0 / (dz * dz));
    let scale = (dx * dx * dx * dy * dz).powf(0.4);
    let mut sum = 0.0;
    for k in 0..15 {
        let l = scale * KRONROD_L[k];
        let ax = 1.0 + l * ix;
        let denom = ax * (ax * (1.0 + l * iy) * (1.0 + l * iz)).sqrt();
        sum += scale * KRONROD_D[k] / denom * KRONROD_W[k];
    }
    sum * ix
}

/// The added mass and added moments of inertia per unit density of an ellipsoid with semi-axes
/// `d` (MuJoCo's `mjCGeom::SetFluidCoefs`): m_i = V κ_i / (2 − κ_i), and
/// I_x = V (d_y² − d_z²)² |κ_z − κ_y| / (5 |2 (d_y² − d_z²) + (d_y² + d_z²)(κ_y − κ_z)|), cyclic.
fn added_mass(d: &[f64; 3]) -> ([f64; 3], [f64; 3]) {
    let (dx, dy, dz) = (d[0], d[1], d[2]);
    let volume = 4.0 / 3.0 * PI * dx * dy * dz;
    let k = [kappa(dx, dy, dz), kappa(dy, dz, dx), kappa(dz, dx, dy)];
    let sq = |x: f64| x * x;
    let fac = |a: f64, b: f64, ka: f64, kb: f64| {
        sq(a * a - b * b) * (kb - ka).abs()
            / (2.0 * (a * a - b * b) + (a * a + b * b) * (ka - kb)).abs().max(EPS)
    };
    let inertia = [
        volume * fac(dy, dz, k[1], k[2]) / 5.0,
        volume * fac(dz, dx, k[2], k[0]) / 5.0,
        volume * fac(dx, dy, k[0], k[1]) / 5.0,
    ];
    let mass = k.map(|ki| volume * ki / (2.0 - ki).max(EPS));
    (mass, inertia)
}

/// `data.qfrc_fluid` ← the fluid forces at (q, v), added to `data.qfrc_passive` (body poses and
/// velocities formed here).
pub(crate) fn fluid_forces(model: &Model, fluid: &FluidModel, data: &mut Data, q: &[f64], v: &[f64]) {
    data.qfrc_fluid.fill(0.0);
    body_poses(model, data, q);
    forward_velocities_unchecked(model, data, v);
    for fb in &fluid.bodies {
        match fb.shape {
            FluidShape::InertiaBox { sides } => {
                let (w, lin) = local_velocity(data, fb.body, &fb.x_body_inertial, &fluid.wind);
                let (torque, force) = inertia_box_wrench(fluid, &sides, &w, &lin);
                apply(model, data, fb.body, &fb.x_body_inertial, &torque, &force);
            }
            FluidShape::Ellipsoid { first, count } => {
                for fg in &fluid.geoms[first..first + count] {
                    let x_body_geom = model.geoms[fg.geom].x_body_geom;
                    let (w, lin) = local_velocity(data, fb.body, &x_body_geom, &fluid.wind);
                    let (torque, force) = ellipsoid_wrench(fluid, fg, &w, &lin);
                    apply(model, data, fb.body, &x_body_geom, &torque, &force);
                }
            }
        }
    }
    for k in 0..model.nv {
        data.qfrc_passive[k] += data.qfrc_fluid[k];
    }
}

/// The angular and linear velocity of frame `x_body_local` of compiled body `body` relative to
/// the wind, in the frame's axes (MuJoCo's `mj_objectVelocity` with `flg_local`, the wind rotated
/// into the frame and subtracted from the linear part).
fn local_velocity(data: &Data, body: usize, x_body_local: &Transform, wind: &Vec3) -> (Vec3, Vec3) {
    let vb = &data.v_body[body];
    let r = &x_body_local.rot;
    let w = r.tr_mul(&vb.ang);
    let lin = r.tr_mul(&(vb.lin + vb.ang.cross(&x_body_local.pos)));
    let r_world_local = data.x_world_body[body].rot * r;
    (w, lin - r_world_local.tr_mul(wind))
}

/// Adds the wrench (torque, force in the frame's axes, acting at its origin) of frame
/// `x_body_local` of compiled body `body` to `qfrc_fluid` (MuJoCo's `mj_applyFT`).
fn apply(model: &Model, data: &mut Data, body: usize, x_body_local: &Transform, torque: &Vec3, force: &Vec3) {
    let x_world = data.x_world_body[body] * *x_body_local;
    let (t_world, f_world) = (x_world.rot * torque, x_world.rot * force);
    let qfrc = &mut data.qfrc_fluid;
    for_each_ancestor_dof_at(model, &data.x_world_body, &data.s_body, body, &x_world.pos, |k, lin, ang| {
        qfrc[k] += lin.dot(&f_world) + ang.dot(&t_world);
    });
}

/// The inertia-box model's torque and force in the principal frame (MuJoCo's
/// `mj_inertiaBoxFluidModel`).
fn inertia_box_wrench(fluid: &FluidModel, b: &[f64; 3], w: &Vec3, v: &Vec3) -> (Vec3, Vec3) {
    let mut torque = Vec3::zeros();
    let mut force = Vec3::zeros();
    if fluid.viscosity > 0.0 {
        let d = (b[0] + b[1] + b[2]) / 3.0;
        torque = w * (-PI * d * d * d * fluid.viscosity);
        force = v * (-3.0 * PI * d * fluid.viscosity);
    }
    if fluid.density > 0.0 {
        let rho = fluid.density;
        force[0] -= 0.5 * rho * b[1] * b[2] * v[0].abs() * v[0];
        force[1] -= 0.5 * rho * b[0] * b[2] * v[1].abs() * v[1];
        force[2] -= 0.5 * rho * b[0] * b[1] * v[2].abs() * v[2];
        let p4 = |x: f64| x * x * x * x;
        torque[0] -= rho * b[0] * (p4(b[1]) + p4(b[2])) * w[0].abs() * w[0] / 64.0;
        torque[1] -= rho * b[1] * (p4(b[0]) + p4(b[2])) * w[1].abs() * w[1] / 64.0;
        torque[2] -= rho * b[2] * (p4(b[0]) + p4(b[1])) * w[2].abs() * w[2] / 64.0;
    }
    (torque, force)
}

/// The ellipsoid model's torque and force on one geom in its frame (MuJoCo's
/// `mj_ellipsoidFluidModel`: `mj_addedMassForces` without accelerations, then
/// `mj_viscousForces`).
fn ellipsoid_wrench(fluid: &FluidModel, g: &FluidGeom, w: &Vec3, v: &Vec3) -> (Vec3, Vec3) {
    let rho = fluid.density;
    let s = &g.semiaxes;
    let [blunt, slender, angular, kutta, magnus] = g.coef;
    // Added mass: the fluid's momentum carried along, p = ρ m_a v, L = ρ I_a ω; the force
    // p × ω, the torque p × v + L × ω.
    let p = Vec3::new(
        rho * g.virtual_mass[0] * v[0],
        rho * g.virtual_mass[1] * v[1],
        rho * g.virtual_mass[2] * v[2],
    );
    let l = Vec3::new(
        rho * g.virtual_inertia[0] * w[0],
        rho * g.virtual_inertia[1] * w[1],
        rho * g.virtual_inertia[2] * w[2],
    );
    let mut force = p.cross(w);
    let mut torque = p.cross(v) + l.cross(w);

    let volume = 4.0 / 3.0 * PI * s[0] * s[1] * s[2];
    let d_max = s[0].max(s[1]).max(s[2]);
    let d_min = s[0].min(s[1]).min(s[2]);
    let d_mid = s[0] + s[1] + s[2] - d_max - d_min;
    let a_max = PI * d_max * d_mid;
    // Magnus lift ρ C_M V ω × v.
    let magnus_force = w.cross(v) * (magnus * rho * volume);
    // The area the ellipsoid projects along v and the cosine between v and that section's normal.
    let sq = |x: f64| x * x;
    let p4 = |x: f64| sq(x) * sq(x);
    let proj_denom = p4(s[1] * s[2]) * sq(v[0]) + p4(s[2] * s[0]) * sq(v[1]) + p4(s[0] * s[1]) * sq(v[2]);
    let proj_num = sq(s[1] * s[2] * v[0]) + sq(s[2] * s[0] * v[1]) + sq(s[0] * s[1] * v[2]);
    let a_proj = PI * (proj_denom / proj_num.max(MINVAL)).sqrt();
    let normal = Vec3::new(sq(s[1] * s[2]) * v[0], sq(s[2] * s[0]) * v[1], sq(s[0] * s[1]) * v[2]);
    let speed = v.norm();
    let cos_alpha = proj_num / (speed * proj_denom).max(MINVAL);
    // Kutta lift: circulation Γ = C_K ρ cos α A_proj (n × v), force Γ × v.
    let circulation = normal.cross(v) * (kutta * rho * cos_alpha * a_proj);
    let kutta_force = circulation.cross(v);
    // Stokes drag of the sphere of mean diameter, plus blunt and slender quadratic drag.
    let d_sphere = 2.0 / 3.0 * (s[0] + s[1] + s[2]);
    let lin_visc = 3.0 * PI * d_sphere;
    let ang_visc = PI * d_sphere * d_sphere * d_sphere;
    let max_moment = |dir: usize| 8.0 / 15.0 * PI * s[dir] * p4(s[(dir + 1) % 3].max(s[(dir + 2) % 3]));
    let i_max = 8.0 / 15.0 * PI * d_mid * p4(d_max);
    let ii = [max_moment(0), max_moment(1), max_moment(2)];
    let mom = Vec3::new(
        w[0] * (angular * ii[0] + slender * (i_max - ii[0])),
        w[1] * (angular * ii[1] + slender * (i_max - ii[1])),
        w[2] * (angular * ii[2] + slender * (i_max - ii[2])),
    );
    let drag_lin = fluid.viscosity * lin_visc + rho * speed * (a_proj * blunt + slender * (a_max - a_proj));
    let drag_ang = fluid.viscosity * ang_visc + rho * mom.norm();
    torque -= w * drag_ang;
    force += magnus_force + kutta_force - v * drag_lin;
    (torque, force)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kappa_of_a_sphere_is_two_thirds() {
        // Lamb: α₀ = 2/3 for a sphere, so its added mass is half the displaced volume.
        assert!((kappa(0.3, 0.3, 0.3) - 2.0 / 3.0).abs() < 1e-6);
        let (m, i) = added_mass(&[0.3; 3]);
        let v = 4.0 / 3.0 * PI * 0.027;
        assert!((m[0] / v - 0.5).abs() < 1e-5, "{m:?}");
        assert!(i.iter().all(|&x| x == 0.0));
    }
}
