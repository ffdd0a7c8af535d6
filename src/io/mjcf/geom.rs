//! `<geom>` and `<site>` placement and shape (MuJoCo's `mjCGeom::Compile`): `type` (sphere by
//! default), `size` in half-lengths, `fromto` (capsule, cylinder, box, ellipsoid: centre at the
//! midpoint, z along the segment, half-length |to − from|/2 into size[1] — size[2] for boxes and
//! ellipsoids, whose size[1] becomes size[0]), `mass` or `density` (1000 kg/m³ by default),
//! `shellinertia`, the mesh asset a mesh geom names, `group`, `rgba` and the `rgba` of the
//! `material` it names (what ray casting filters on); a site's `type` and `size` (MuJoCo's
//! defaults: a sphere of 0.005).

use super::assets::MeshAsset;
use super::attrs::Attrs;
use super::orientation::{rotation, z_to_matrix, AngleConvention};
use super::Compiler;
use crate::io::LoadError;
use crate::mass::{Distribution, GeomMass, Primitive};
use crate::model::spec::{GeomContact, GeomSpec, Shape, DEFAULT_GEOM_RGBA};
use crate::spatial::{Transform, Vec3};
use std::collections::HashMap;

const GEOM_TYPES: [&str; 9] =
    ["plane", "hfield", "sphere", "capsule", "ellipsoid", "cylinder", "box", "mesh", "sdf"];

/// The placement and size of a geom or site after `fromto`: pose in its parent frame and the size
/// vector (half-lengths), `size` holding the sizes read so far (the `size` attribute over the
/// defaults).
fn placement(
    a: &Attrs,
    gtype: &str,
    angles: &AngleConvention,
    mut size: [f64; 3],
) -> Result<(Transform, [f64; 3]), LoadError> {
    if let Some(ft) = a.array::<6>("fromto")? {
        if a.vec3("pos")?.is_some_and(|p| p != Vec3::zeros()) {
            return Err(
                a.error("fromto", "and 'pos' are both given; fromto already places the geom: remove pos")
            );
        }
        if !matches!(gtype, "capsule" | "cylinder" | "box" | "ellipsoid") {
            return Err(
                a.error("fromto", format!("needs a capsule, cylinder, box or ellipsoid, not a {gtype}"))
            );
        }
        let from = Vec3::new(ft[0], ft[1], ft[2]);
        let to = Vec3::new(ft[3], ft[4], ft[5]);
        let d = from - to;
        let half = d.norm() / 2.0;
        if half < 1e-14 {
            return Err(a.error("fromto", "has coincident end points"));
        }
        if matches!(gtype, "box" | "ellipsoid") {
            size[2] = half;
            size[1] = size[0];
        } else {
            size[1] = half;
        }
        return Ok((Transform::new(z_to_matrix(&d), (from + to) / 2.0), size));
    }
    let pos = a.vec3("pos")?.unwrap_or_default();
    Ok((Transform::new(rotation(a, angles)?, pos), size))
}

/// MuJoCo's site size where the file gives none (`mjCSite`: 0.005 for each entry).
const SITE_SIZE: f64 = 0.005;

/// A site: its pose in the parent frame and its shape (MuJoCo's `site_type`, `site_size`), None for
/// a mesh site (drawn only: no sensor can use its shape). `class` holds the attributes of the
/// site's default class alone: a partial `size` overrides the class's entry by entry, and entries
/// given by neither keep MuJoCo's 0.005 (`size="0.01"` on a box is 0.01 × 0.005 × 0.005).
pub(crate) fn site(
    a: &Attrs,
    class: &Attrs,
    angles: &AngleConvention,
) -> Result<(Transform, Option<Primitive>), LoadError> {
    let gtype = a.keyword("type", &GEOM_TYPES)?.unwrap_or_else(|| "sphere".into());
    if matches!(gtype.as_str(), "plane" | "hfield" | "sdf") {
        return Err(a.error("type", format!("is '{gtype}'; a site is a sphere, capsule, ellipsoid, cylinder, box or mesh (as MuJoCo requires)")));
    }
    let mut size = [SITE_SIZE; 3];
    a.fill_over(class, "size", &mut size)?;
    let (pose, size) = placement(a, &gtype, angles, size)?;
    let used = match gtype.as_str() {
        "sphere" => 1,
        "capsule" | "cylinder" => 2,
        "mesh" => 0,
        _ => 3,
    };
    if let Some(k) = size[..used].iter().position(|&s| s <= 0.0) {
        return Err(
            a.error("size", format!("of a {gtype} site has entry {k} = {}; it must be positive", size[k]))
        );
    }
    let shape = match gtype.as_str() {
        "sphere" => Some(Primitive::Sphere { radius: size[0] }),
        "capsule" => Some(Primitive::Capsule { radius: size[0], half_length: size[1] }),
        "cylinder" => Some(Primitive::Cylinder { radius: size[0], half_length: size[1] }),
        "box" => Some(Primitive::Box { half_extents: Vec3::from(size) }),
        "ellipsoid" => Some(Primitive::Ellipsoid { radii: Vec3::from(size) }),
        _ => None,
    };
    Ok((pose, shape))
}

/// A geom as a spec geom placed in its link (`x_link_parent`: pose of the enclosing frame).
pub(crate) fn geom(
    a: &Attrs,
    x_link_parent: &Transform,
    compiler: &Compiler,
    meshes: &HashMap<String, MeshAsset>,
    materials: &HashMap<String, [f32; 4]>,
    infer_inertia: bool,
) -> Result<GeomSpec, LoadError> {
    let gtype = a.keyword("type", &GEOM_TYPES)?.unwrap_or_else(|| "sphere".into());
    let mut size = [0.0; 3];
    if let Some(v) = a.some_numbers("size", 1, 3)? {
        size[..v.len()].copy_from_slice(&v);
    }
    let (x_parent_geom, size) = placement(a, &gtype, &compiler.angles, size)?;
    let positive = |n: usize| -> Result<(), LoadError> {
        if size[..n].iter().any(|&s| s <= 0.0) {
            return Err(a.error(
                "size",
                format!("of a {gtype} needs {n} positive value{}", if n > 1 { "s" } else { "" }),
            ));
        }
        Ok(())
    };
    let mut mesh_inertia = Default::default();
    let shape = match gtype.as_str() {
        "sphere" => {
            positive(1)?;
            Shape::Sphere { radius: size[0] }
        }
        "capsule" => {
            positive(2)?;
            Shape::Capsule { radius: size[0], length: 2.0 * size[1] }
        }
        "cylinder" => {
            positive(2)?;
            Shape::Cylinder { radius: size[0], length: 2.0 * size[1] }
        }
        "box" => {
            positive(3)?;
            Shape::Box { size: Vec3::new(2.0 * size[0], 2.0 * size[1], 2.0 * size[2]) }
        }
        "ellipsoid" => {
            positive(3)?;
            Shape::Ellipsoid { radii: Vec3::from(size) }
        }
        "plane" => Shape::Plane { size: Vec3::from(size) },
        "hfield" => {
            let Some(name) = a.text("hfield") else {
                return Err(a.error("hfield", "is missing: a height field geom must name an <hfield> asset"));
            };
            // The grid is filled in once the assets are read (`hfield::resolve`).
            Shape::Hfield { name: name.to_string(), field: Default::default() }
        }
        "mesh" => {
            let Some(name) = a.text("mesh") else {
                return Err(a.error("mesh", "is missing: a mesh geom must name a <mesh> asset"));
            };
            let Some(m) = meshes.get(name) else {
                return Err(LoadError::UnknownReference {
                    loc: a.loc.clone(),
                    element: "geom".into(),
                    kind: "mesh",
                    target: name.to_string(),
                });
            };
            mesh_inertia = m.inertia;
            Shape::Mesh { source: m.source.clone(), scale: m.scale }
        }
        other => {
            return Err(LoadError::Unsupported {
                loc: a.loc.clone(),
                element: "geom".into(),
                what: format!("geom type '{other}'"),
                fix: "use a mesh or a primitive".into(),
            });
        }
    };
    if a.has("mesh") && gtype != "mesh" {
        return Err(LoadError::Unsupported {
            loc: a.loc.clone(),
            element: "geom".into(),
            what: format!("a {gtype} fitted to a mesh (type=\"{gtype}\" with mesh=)"),
            fix: "give the primitive's size explicitly".into(),
        });
    }
    let group = a.int("group")?.unwrap_or(0);
    let shell = a.bool("shellinertia")?.unwrap_or(false);
    if shell && gtype == "mesh" {
        return Err(a.error(
            "shellinertia",
            "cannot be used on a mesh geom; set inertia=\"shell\" on the <mesh> asset instead (as MuJoCo requires)",
        ));
    }
    let in_groups = group >= compiler.inertia_groups[0] && group <= compiler.inertia_groups[1];
    let mass = if !infer_inertia || !in_groups {
        GeomMass::None
    } else if let Some(m) = a.real("mass")? {
        if m < 0.0 {
            return Err(a.error("mass", format!("is {m}; mass must be ≥ 0")));
        }
        GeomMass::Mass(m)
    } else {
        let rho = a.real("density")?.unwrap_or(1000.0);
        if rho < 0.0 {
            return Err(a.error("density", format!("is {rho}; density must be ≥ 0")));
        }
        GeomMass::Density(rho)
    };
    let contact = contact_parameters(a)?;
    let rgba = match a.array::<4>("rgba")? {
        Some(c) => c.map(|x| x as f32),
        None => DEFAULT_GEOM_RGBA,
    };
    let material_rgba = match a.text("material") {
        None => None,
        Some(name) => match materials.get(name) {
            Some(c) => Some(*c),
            None => {
                return Err(LoadError::UnknownReference {
                    loc: a.loc.clone(),
                    element: "geom".into(),
                    kind: "material",
                    target: name.to_string(),
                })
            }
        },
    };
    let fluid = match a.keyword("fluidshape", &["none", "ellipsoid"])?.as_deref() {
        Some("ellipsoid") => {
            // MuJoCo's defaults; a partial `fluidcoef` overrides the first entries.
            let mut coef = [0.5, 0.25, 1.5, 1.0, 1.0];
            a.fill("fluidcoef", &mut coef)?;
            Some(coef)
        }
        _ => None,
    };
    Ok(GeomSpec {
        name: a.text("name").unwrap_or("").to_string(),
        loc: a.loc.clone(),
        x_link_geom: *x_link_parent * x_parent_geom,
        shape,
        collision: contact.contype != 0 || contact.conaffinity != 0,
        mass,
        distribution: if shell { Distribution::Shell } else { Distribution::Volume },
        mesh_inertia,
        group: group as i32,
        rgba,
        material_rgba,
        contact,
        fluid,
    })
}

/// A geom's contact attributes with MuJoCo's defaults and checks (condim ∈ {1, 3, 4, 6}; bit masks
/// and margins non-negative; friction non-negative; solmix ≥ 0).
pub(crate) fn contact_parameters(a: &Attrs) -> Result<GeomContact, LoadError> {
    let mut c = GeomContact::default();
    let mask = |name: &str, default: u32| -> Result<u32, LoadError> {
        match a.int(name)? {
            None => Ok(default),
            Some(v) if (0..=i64::from(u32::MAX)).contains(&v) => Ok(v as u32),
            Some(v) => {
                Err(a.error(name, format!("is {v}; a collision bit mask is a non-negative 32-bit integer")))
            }
        }
    };
    c.contype = mask("contype", c.contype)?;
    c.conaffinity = mask("conaffinity", c.conaffinity)?;
    if let Some(d) = a.int("condim")? {
        if ![1, 3, 4, 6].contains(&d) {
            return Err(a.error("condim", format!("is {d}; MuJoCo's contact dimensions are 1, 3, 4 or 6")));
        }
        c.condim = d as u32;
    }
    c.priority = a.int("priority")?.map_or(0, |p| p as i32);
    if let Some(f) = a.some_numbers("friction", 1, 3)? {
        c.friction[..f.len()].copy_from_slice(&f);
    }
    if c.friction.iter().any(|&f| f < 0.0) {
        return Err(a.error("friction", format!("is {:?}; friction coefficients must be ≥ 0", c.friction)));
    }
    if let Some(m) = a.real("solmix")? {
        if m < 0.0 {
            return Err(a.error("solmix", format!("is {m}; the mixing weight must be ≥ 0")));
        }
        c.solmix = m;
    }
    // A partial solref (one value) keeps the default's second, as MuJoCo reads it.
    if let Some(r) = a.some_numbers("solref", 1, 2)? {
        c.solref[..r.len()].copy_from_slice(&r);
    }
    if let Some(i) = a.some_numbers("solimp", 1, 5)? {
        c.solimp[..i.len()].copy_from_slice(&i);
    }
    c.margin = a.real("margin")?.unwrap_or(0.0);
    c.gap = a.real("gap")?.unwrap_or(0.0);
    if c.margin < 0.0 || c.gap < 0.0 {
        return Err(a.error("margin", format!("is {} with gap {}; both must be ≥ 0", c.margin, c.gap)));
    }
    Ok(c)
}
