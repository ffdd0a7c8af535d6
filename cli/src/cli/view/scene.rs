//! What the viewer page draws, as the JSON the page reads (`cli/assets/viewer.js`): the model's
//! geoms (primitives with their size and `rgba`, meshes written once as base64 little-endian
//! `Float32` vertices and `Uint32` triangle indices), its link and site frames, its joints; and per
//! frame only poses: a pose (position, quaternion) per pose slot — every compiled body, then every
//! mocap body — the joint values, and the contacts (point and force) of that state.
//!
//! A geom's world pose is its slot's pose composed with its fixed pose in the slot
//! (`Geom::x_body_geom`), as lagrange's collision pass composes them (MuJoCo's `geom_xpos`); a
//! mesh's vertices are in the geom frame (`collision::GeomMesh::triangles`). The contacts of a
//! frame are those of `forward` at the frame's state, read through
//! `constraint::contact_force::contacts` (MuJoCo's `mj_contactForce`).

use base64::Engine as _;
use lagrange::constraint::contact_force::contacts;
use lagrange::forward::forward;
use lagrange::model::spec::Shape;
use lagrange::model::FrameKind;
use lagrange::spatial::Transform;
use lagrange::{Data, Model};
use serde_json::{json, Value};

/// Numbers per pose in a frame: position x, y, z, then the quaternion x, y, z, w (three.js's order).
pub const POSE_LEN: usize = 7;
/// Numbers per contact in a frame: the point x, y, z, then the force on the second geom's body
/// x, y, z (world frame; flipped to act on the first geom's body when the second is the world).
pub const CONTACT_LEN: usize = 6;

/// The frames of a trajectory: per frame its time, poses, joint values and contacts.
#[derive(Default)]
pub struct Frames {
    /// Time of each frame (s).
    pub time: Vec<f64>,
    /// `POSE_LEN` numbers per pose slot per frame.
    pub poses: Vec<f32>,
    /// `nq` joint values per frame.
    pub qpos: Vec<f32>,
    /// `CONTACT_LEN` numbers per contact, frame after frame.
    pub contacts: Vec<f32>,
    /// Where each frame's contacts start in `contacts` (in contacts), and the total at the end.
    pub contact_start: Vec<u32>,
}

impl Frames {
    /// The number of frames.
    pub fn len(&self) -> usize {
        self.time.len()
    }

    /// The frames as the page's JSON (numbers base64-encoded Float32).
    pub fn to_json(&self) -> Value {
        let mut start = self.contact_start.clone();
        start.push((self.contacts.len() / CONTACT_LEN) as u32);
        json!({
            "n": self.len(),
            "time": self.time,
            "poses": b64_f32(&self.poses),
            "qpos": b64_f32(&self.qpos),
            "contacts": b64_f32(&self.contacts),
            "contact_start": start,
        })
    }

    /// The last frame alone, as the live mode streams it (plain numbers).
    pub fn last_json(&self, nslot: usize, nq: usize) -> Option<Value> {
        let k = self.len().checked_sub(1)?;
        let c0 = self.contact_start[k] as usize * CONTACT_LEN;
        Some(json!({
            "time": self.time[k],
            "poses": &self.poses[k * nslot * POSE_LEN..(k + 1) * nslot * POSE_LEN],
            "qpos": &self.qpos[k * nq..(k + 1) * nq],
            "contacts": &self.contacts[c0..],
        }))
    }
}

/// Records the frames of a trajectory: sets each state in its own `Data`, runs `forward` and
/// keeps the poses and contacts.
pub struct Recorder {
    data: Data,
    /// The frames recorded so far.
    pub frames: Frames,
}

impl Recorder {
    /// A recorder for `model` (its `Data` allocated once).
    pub fn new(model: &Model) -> Self {
        Self { data: Data::new(model), frames: Frames::default() }
    }

    /// Records the state (`qpos`, `qvel`, `act`, `ctrl`) at `time` as a frame. Lengths are the
    /// model's (the caller's state comes from a `Data` of the same model or a checked file).
    pub fn record(
        &mut self,
        model: &Model,
        time: f64,
        qpos: &[f64],
        qvel: &[f64],
        act: &[f64],
        ctrl: &[f64],
    ) {
        let d = &mut self.data;
        d.time = time;
        d.qpos.as_mut_slice().copy_from_slice(qpos);
        d.qvel.as_mut_slice().copy_from_slice(qvel);
        d.act.as_mut_slice().copy_from_slice(act);
        d.ctrl.as_mut_slice().copy_from_slice(ctrl);
        forward(model, d);
        let f = &mut self.frames;
        f.time.push(time);
        for x in &d.x_world_body {
            push_pose(&mut f.poses, x);
        }
        for m in 0..d.mocap_pos.len() {
            push_pose(&mut f.poses, &d.mocap_pose(m));
        }
        f.qpos.extend(qpos.iter().map(|&x| x as f32));
        f.contact_start.push((f.contacts.len() / CONTACT_LEN) as u32);
        for c in contacts(model, d).filter(|c| c.active) {
            let sign = if c.body[1] == 0 { -1.0 } else { 1.0 };
            let (p, force) = (c.pos(), c.force_world() * sign);
            f.contacts.extend([p.x, p.y, p.z, force.x, force.y, force.z].map(|x| x as f32));
        }
    }
}

fn push_pose(out: &mut Vec<f32>, x: &Transform) {
    let [w, qx, qy, qz] = x.quat_wxyz();
    out.extend([x.pos.x, x.pos.y, x.pos.z, qx, qy, qz, w].map(|v| v as f32));
}

fn pose_json(x: &Transform) -> Value {
    let [w, qx, qy, qz] = x.quat_wxyz();
    json!({"pos": [x.pos.x, x.pos.y, x.pos.z], "quat": [qx, qy, qz, w]})
}

/// Base64 of the little-endian bytes of `values`.
pub fn b64_f32(values: &[f32]) -> String {
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

fn b64_u32(values: &[u32]) -> String {
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

/// Whether the model came from a URDF file (its `<collision>` geoms are then hidden by default:
/// they double the `<visual>` ones).
fn is_urdf(model: &Model) -> bool {
    model.source.as_ref().and_then(|p| p.extension()).is_some_and(|e| e.eq_ignore_ascii_case("urdf"))
}

/// The static part of the page's scene: geoms, meshes, frames, joints, the number of pose slots,
/// and a force scale for the contact arrows. Mesh files that cannot be read are left out with a
/// warning each (returned).
pub fn scene_json(model: &Model) -> (Value, Vec<String>) {
    let mut warnings = Vec::new();
    let urdf = is_urdf(model);
    let nbody = model.bodies.len();
    let mut meshes: Vec<Value> = Vec::new();
    let mut mesh_ids: Vec<(*const lagrange::collision::GeomMesh, usize)> = Vec::new();
    let mut geoms = Vec::new();
    for (i, g) in model.geoms.iter().enumerate() {
        let slot = g.mocap.map_or(g.body, |m| nbody + m);
        let (kind, size): (&str, Vec<f64>) = match &g.shape {
            Shape::Box { size } => ("box", size.iter().copied().collect()),
            Shape::Sphere { radius } => ("sphere", vec![*radius]),
            Shape::Capsule { radius, length } => ("capsule", vec![*radius, *length]),
            Shape::Cylinder { radius, length } => ("cylinder", vec![*radius, *length]),
            Shape::Ellipsoid { radii } => ("ellipsoid", radii.iter().copied().collect()),
            Shape::Plane { size } => ("plane", size.iter().copied().collect()),
            Shape::Hfield { name, .. } => {
                warnings.push(format!("geom {i} (height field '{name}') is not drawn"));
                continue;
            }
            Shape::Mesh { .. } => ("mesh", Vec::new()),
        };
        let mut mesh = Value::Null;
        if let Some(m) = &g.mesh {
            let key = std::sync::Arc::as_ptr(m);
            if let Some((_, id)) = mesh_ids.iter().find(|(k, _)| *k == key) {
                mesh = json!(id);
            } else {
                match m.triangles() {
                    Ok(t) => {
                        let v: Vec<f32> =
                            t.vertices.iter().flat_map(|p| [p.x as f32, p.y as f32, p.z as f32]).collect();
                        let idx: Vec<u32> = t.triangles.iter().flatten().copied().collect();
                        meshes.push(json!({"vertices": b64_f32(&v), "indices": b64_u32(&idx)}));
                        mesh_ids.push((key, meshes.len() - 1));
                        mesh = json!(meshes.len() - 1);
                    }
                    Err(e) => {
                        warnings.push(format!("mesh {}: {e}; not drawn", m.source()));
                        continue;
                    }
                }
            }
        } else if kind == "mesh" {
            continue;
        }
        let rgba = g.material_rgba.filter(|_| g.rgba == [0.5, 0.5, 0.5, 1.0]).unwrap_or(g.rgba);
        // MuJoCo's viewer shows groups 0-2; a URDF's collision shapes double its visuals.
        let visible = if urdf { !g.collision } else { g.group <= 2 };
        let mut v = pose_json(&g.x_body_geom);
        v["slot"] = json!(slot);
        v["name"] = json!(g.name);
        v["type"] = json!(kind);
        v["size"] = json!(size);
        v["rgba"] = json!(rgba);
        v["group"] = json!(g.group);
        v["collision"] = json!(g.collision);
        v["visible"] = json!(visible);
        v["mesh"] = mesh;
        v["link"] = json!(g.link);
        // The world's own geoms (the floor, walls); a robot's base welded to the world is not.
        let world = g.body == 0 && g.mocap.is_none() && (g.link == model.bodies[0].name || kind == "plane");
        v["world"] = json!(world);
        geoms.push(v);
    }
    // A link or body none of whose geoms is shown by default (a model whose visual meshes were
    // left out) shows the ones it has.
    let links: Vec<Value> = geoms.iter().map(|g| g["link"].clone()).collect();
    for link in links {
        let of_link = |g: &&mut Value| g["link"] == link;
        if !geoms.iter_mut().filter(of_link).any(|g| g["visible"] == json!(true)) {
            for g in geoms.iter_mut().filter(of_link) {
                g["visible"] = json!(true);
            }
        }
    }
    let frames: Vec<Value> = model
        .frames
        .iter()
        .filter(|f| matches!(f.kind, FrameKind::Link | FrameKind::Site))
        .map(|f| {
            let mut v = pose_json(&f.x_body_frame);
            v["name"] = json!(f.name);
            v["kind"] = json!(if f.kind == FrameKind::Site { "site" } else { "link" });
            v["slot"] = json!(f.mocap.map_or(f.body, |m| nbody + m));
            v
        })
        .collect();
    let joints: Vec<Value> = model
        .joints
        .iter()
        .map(|j| json!({"name": j.name, "qpos_adr": j.qpos_adr, "nq": j.kind.nq()}))
        .collect();
    // The arrows' scale (1/N): the page draws a force of the model's whole weight as long as the
    // radius of the model's bounding box.
    let weight = model.bodies.iter().map(|b| b.mass()).sum::<f64>() * model.gravity.norm();
    let force_scale = if weight > 0.0 && weight.is_finite() { 1.0 / weight } else { 0.1 };
    let scene = json!({
        "model": model.name,
        "source": model.source.as_ref().map(|p| p.display().to_string()),
        "nslot": nbody + model.mocap_pose0.len(),
        "nq": model.nq,
        "geoms": geoms,
        "meshes": meshes,
        "frames": frames,
        "joints": joints,
        "force_scale": force_scale,
    });
    (scene, warnings)
}
