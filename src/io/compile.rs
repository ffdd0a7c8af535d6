//! The compile step: [`ModelSpec`] → [`Model`]. Checks physical validity, normalizes axes, fuses
//! fixed joints into their parent body (inertia composed, every link kept as a [`Frame`]), and lays
//! out q and v in depth-first file order (docs/architecture.md, "Layers"); then resolves the equality
//! constraints, mimics, tendons, actuators and contact pairs against the tree
//! (`io::compile_elements`).

use crate::io::{LinkWord, LoadError};
use crate::model::spec::{InertialSpec, JointSpec, JointType, LinkSpec, MassRules, ModelSpec, Shape};
use crate::model::{
    Body, Frame, FrameKind, Geom, HingeAxis, Joint, JointKind, Model, SourceLoc, Spring, NO_DOF,
};
use crate::spatial::{Mat3, RigidInertia, Transform, Vec3};
use std::collections::HashMap;

/// Relative tolerance for the symmetry, sign and triangle-inequality checks of inertia tensors.
const INERTIA_TOL: f64 = 1e-9;
/// Inertia (kg·m²) below which a principal moment is round-off: MuJoCo's `mjMINVAL`.
const ROUNDOFF_MINVAL: f64 = 1e-15;

/// The most numbers the actuators' control histories may take together (`Data::history`,
/// 128 MiB): a bound on a file's `nsample` that would exhaust memory.
const MAX_HISTORY: usize = 1 << 24;

/// Compiles a spec into a model.
pub fn compile(spec: &ModelSpec) -> Result<Model, LoadError> {
    let file = spec.source.as_ref().map(|p| p.display().to_string()).unwrap_or_default();
    if spec.links.is_empty() {
        return Err(LoadError::Empty { file });
    }
    check_unique_names(spec)?;
    crate::io::plausibility::check_spec(spec)?;
    let word = crate::io::plausibility::link_word(spec);
    let welded = welded_to_world(spec);
    let mut meshes = crate::io::geom_mass::MeshCache::default();
    let mut hulls = crate::io::geom_hull::HullCache::default();
    // The lazily read triangles and hulls of mesh geoms, one per file and scale.
    let mut geom_meshes: HashMap<
        (crate::mass::MeshSource, [u64; 3]),
        std::sync::Arc<crate::collision::GeomMesh>,
    > = HashMap::new();
    let mut warnings = spec.warnings.clone();
    // Pass 0: every link's own mass properties (explicit or from its geoms), with the compiler's
    // bounds; then `settotalmass` scales the moving links.
    let mut link_inertias = Vec::with_capacity(spec.links.len());
    let mut geom_masses = Vec::with_capacity(spec.links.len());
    for (li, link) in spec.links.iter().enumerate() {
        let computed =
            link_mass(link, word, &spec.mass_rules, &mut meshes, &mut warnings).and_then(|(i, m)| {
                crate::io::plausibility::check_derived(link, word, &i)?;
                Ok((i, m))
            });
        let (inertia, masses) = match computed {
            Ok(x) => x,
            // A link welded to the world never moves: its mass never enters the dynamics, so a
            // mass that cannot be computed (an open visual mesh, a non-physical tensor) is no
            // reason to refuse the model.
            Err(e) if welded[li] => {
                warnings.push(format!(
                    "{e} [ignored: {word} '{}' is welded to the world, so its mass never enters the dynamics; it is taken as zero]",
                    link.name
                ));
                (RigidInertia::zero(), vec![0.0; link.geoms.len()])
            }
            Err(e) => return Err(e),
        };
        link_inertias.push(inertia);
        geom_masses.push(masses);
    }
    if let Some(total) = spec.mass_rules.total_mass {
        scale_total_mass(spec, &mut link_inertias, &mut geom_masses, total);
    }

    let mut bodies = vec![Body {
        name: "world".to_string(),
        parent: 0,
        x_parent_joint: Transform::identity(),
        inertia: RigidInertia::zero(),
    }];
    let mut joints: Vec<Joint> = Vec::new();
    let mut frames: Vec<Frame> = Vec::new();
    let mut geoms: Vec<Geom> = Vec::new();
    // For each link: the body it belongs to and its pose in that body's frame.
    let mut link_body: Vec<(usize, Transform)> = Vec::with_capacity(spec.links.len());
    // Per link, the mocap body it is fused into (welded to the world, posed from `Data`).
    let mut link_mocap: Vec<Option<usize>> = Vec::with_capacity(spec.links.len());
    let mut mocap_pose0: Vec<Transform> = Vec::new();
    // Per compiled body: the link (file body) it belongs to, and the first compiled body of it.
    let (mut body_owner, mut body_root) = (vec![usize::MAX], vec![0usize]);
    let (mut nq, mut nv) = (0, 0);
    // The spec link each frame and geom is made from (MuJoCo's body table, `Links`).
    let (mut frame_spec_link, mut geom_spec_link) = (Vec::new(), Vec::new());
    // MuJoCo's frame of each geom in its body (a mesh's moved to the mesh's inertial frame; None
    // for a mesh whose frame is not computed, one that does not collide) and of each site.
    let (mut geom_local, mut site_local): (Vec<Option<Transform>>, Vec<Option<Transform>>) =
        (Vec::new(), Vec::new());

    // Pass 1, links in depth-first order: create a body per movable joint, fuse fixed ones.
    for (li, link) in spec.links.iter().enumerate() {
        let (parent_body, x_pbody_plink) = match link.parent {
            Some(p) if p >= li => {
                return Err(LoadError::Invalid {
                    loc: link.loc.clone(),
                    element: "link".into(),
                    detail: format!("link '{}' comes before its parent in the spec (loader bug)", link.name),
                });
            }
            Some(p) => link_body[p],
            None => (0, Transform::identity()),
        };
        let x_pbody_joint = x_pbody_plink * link.joint.x_parent_joint;
        match joint_kind(&link.joint)? {
            None => link_body.push((parent_body, x_pbody_joint)),
            Some(kind) => {
                let b = bodies.len();
                // The file body this compiled body belongs to: an MJCF body with several joints is
                // a chain of joint links followed by the body's own link.
                let owner = if link.kind == FrameKind::Joint {
                    (li..spec.links.len()).find(|&k| spec.links[k].kind != FrameKind::Joint).unwrap_or(li)
                } else {
                    li
                };
                let root = if parent_body != 0 && body_owner[parent_body] == owner {
                    body_root[parent_body]
                } else {
                    b
                };
                body_owner.push(owner);
                body_root.push(root);
                bodies.push(Body {
                    name: link.name.clone(),
                    parent: parent_body,
                    x_parent_joint: x_pbody_joint,
                    inertia: RigidInertia::zero(),
                });
                let j = &link.joint;
                let (jnq, jnv) = (kind.nq(), kind.nv());
                joints.push(Joint {
                    name: j.name.clone(),
                    kind,
                    body: b,
                    parent: parent_body,
                    qpos_adr: nq,
                    dof_adr: nv,
                    limits: j.limits,
                    actuator_force_range: j.actuator_force_range,
                    effort_limit: j.effort_limit,
                    damping: j.damping,
                    friction: j.friction,
                    armature: j.armature,
                    stiffness: j.stiffness,
                    spring_ref: j.spring_ref,
                    soft: j.soft,
                    actuator_gravcomp: j.actuator_gravcomp,
                });
                nq += jnq;
                nv += jnv;
                link_body.push((b, Transform::identity()));
            }
        }
        let (body, x_body_link) = link_body[li];
        // A mocap body starts a mocap subtree; its welded descendants belong to it. Its frames and
        // geoms are posed relative to the mocap frame.
        let mocap = if link.mocap {
            mocap_pose0.push(x_body_link);
            Some(mocap_pose0.len() - 1)
        } else {
            link.parent.and_then(|p| link_mocap[p])
        };
        if mocap.is_some() && body != 0 {
            return Err(LoadError::Unsupported {
                loc: link.loc.clone(),
                element: "body".into(),
                what: format!("body '{}' moves on a joint below a mocap body", link.name),
                fix: "attach it to the world or to a body with a free joint (moving bodies under mocap bodies are not simulated yet)".into(),
            });
        }
        link_mocap.push(mocap);
        // Mass properties of the link, moved into its body's frame.
        let i_link = link_inertias[li];
        bodies[body].inertia += &i_link.transformed(&x_body_link);
        let x_body_link = match mocap {
            Some(m) => mocap_pose0[m].inverse() * x_body_link,
            None => x_body_link,
        };
        frame_spec_link.extend(std::iter::repeat_n(li, 1 + link.frames.len()));
        geom_spec_link.extend(std::iter::repeat_n(li, link.geoms.len()));
        frames.push(Frame {
            name: link.name.clone(),
            kind: link.kind,
            body,
            x_body_frame: x_body_link,
            inertia: i_link,
            mocap,
            site: None,
        });
        site_local.push(None);
        for f in &link.frames {
            site_local.push((f.kind == FrameKind::Site).then_some(f.x_link_frame));
            frames.push(Frame {
                name: f.name.clone(),
                kind: f.kind,
                body,
                x_body_frame: x_body_link * f.x_link_frame,
                inertia: RigidInertia::zero(),
                mocap,
                site: f.site,
            });
        }
        for (g, &mass) in link.geoms.iter().zip(&geom_masses[li]) {
            let hull_graph = crate::io::geom_hull::geom_hull(g, word, &link.name, &mut hulls, &mut warnings)?;
            let unreadable = matches!(g.shape, Shape::Mesh { .. }) && hull_graph.is_none();
            geom_local.push(match (&g.shape, &hull_graph) {
                (Shape::Mesh { .. }, None) => None,
                (_, h) => Some(g.x_link_geom * mesh_frame(h.as_ref())),
            });
            geoms.push(Geom {
                name: g.name.clone(),
                link: link.name.clone(),
                body,
                x_body_geom: x_body_link * g.x_link_geom,
                mocap,
                shape: g.shape.clone(),
                collision: g.collision && !unreadable,
                mass,
                contact: g.contact,
                hull_graph,
                group: g.group,
                rgba: g.rgba,
                material_rgba: g.material_rgba,
                fluid: g.fluid,
                mesh: match &g.shape {
                    Shape::Mesh { source, scale } => Some(
                        geom_meshes
                            .entry((
                                source.clone(),
                                [scale.x.to_bits(), scale.y.to_bits(), scale.z.to_bits()],
                            ))
                            .or_insert_with(|| {
                                std::sync::Arc::new(crate::collision::GeomMesh::new(source.clone(), *scale))
                            })
                            .clone(),
                    ),
                    _ => None,
                },
            });
        }
    }

    let gravcomp = body_gravcomp(spec, &link_body, &link_inertias);

    if spec.mass_rules.require_moving_mass {
        check_moving_mass(spec, &bodies, &link_body, &mut warnings);
    }

    // Pass 2: per-dof tables (λ for the sparse factorization, armature, damping).
    let mut dof_parent = vec![NO_DOF; nv];
    let mut dof_body = vec![0; nv];
    let mut dof_armature = vec![0.0; nv];
    let mut dof_damping = vec![0.0; nv];
    let mut dof_effort_limit = vec![f64::INFINITY; nv];
    for j in &joints {
        let parent_last = if j.parent == 0 {
            NO_DOF
        } else {
            let pj = &joints[j.parent - 1];
            pj.dof_adr + pj.kind.nv() - 1
        };
        for k in 0..j.kind.nv() {
            let d = j.dof_adr + k;
            dof_parent[d] = if k == 0 { parent_last } else { d - 1 };
            dof_body[d] = j.body;
            dof_armature[d] = j.armature;
            dof_damping[d] = j.damping;
            dof_effort_limit[d] = j.effort_limit.unwrap_or(f64::INFINITY);
        }
    }

    // Springs of one-dof joints; `<flag spring/damper="disable">` switches them off.
    let springs = if !spec.options.flags.spring {
        Vec::new()
    } else {
        joints
            .iter()
            .filter(|j| j.stiffness != 0.0 && j.kind.nq() == 1)
            .map(|j| Spring {
                qpos_adr: j.qpos_adr,
                dof_adr: j.dof_adr,
                stiffness: j.stiffness,
                rest: j.spring_ref,
            })
            .collect()
    };
    if !spec.options.flags.damper {
        dof_damping.iter_mut().for_each(|d| *d = 0.0);
    }

    // Pass 3: the reference configuration, joint by joint.
    let mut qpos0 = vec![0.0; nq];
    for (j, link) in joints.iter().zip(spec.links.iter().filter(|l| l.joint.jtype != JointType::Fixed)) {
        let q = &mut qpos0[j.qpos_adr..j.qpos_adr + j.kind.nq()];
        if link.joint.qpos0.is_empty() {
            j.kind.neutral(q);
        } else if link.joint.qpos0.len() == q.len() {
            q.copy_from_slice(&link.joint.qpos0);
        } else {
            return Err(LoadError::Invalid {
                loc: link.joint.loc.clone(),
                element: "joint".into(),
                detail: format!(
                    "joint '{}' has a reference configuration of {} values, its type needs {} (loader bug)",
                    j.name,
                    link.joint.qpos0.len(),
                    q.len()
                ),
            });
        }
    }

    let keyframes = complete_keyframes(spec, &joints, &qpos0, nv)?;
    for k in &keyframes {
        for (what, v, per) in [("mpos", &k.mpos, 3), ("mquat", &k.mquat, 4)] {
            if let Some(v) = v.as_ref().filter(|v| v.len() != per * mocap_pose0.len()) {
                return Err(LoadError::Invalid {
                    loc: k.loc.clone(),
                    element: "key".into(),
                    detail: format!(
                        "keyframe '{}': {what} has {} values, the model needs {} ({per} per mocap body, {} mocap bodies)",
                        k.name,
                        v.len(),
                        per * mocap_pose0.len(),
                        mocap_pose0.len()
                    ),
                });
            }
        }
    }

    let hinge_axis =
        std::iter::once(HingeAxis::Other).chain(joints.iter().map(|j| j.kind.hinge_axis())).collect();
    let placement_unrotated = bodies.iter().map(|b| b.x_parent_joint.rot == Mat3::identity()).collect();
    let kind_is_link: Vec<bool> = spec.links.iter().map(|l| l.kind == FrameKind::Link).collect();
    let spec_parent: Vec<Option<usize>> = spec.links.iter().map(|l| l.parent).collect();
    let mut links =
        crate::model::Links::build(&kind_is_link, &spec_parent, &frame_spec_link, &geom_spec_link);
    // Per spec link: MuJoCo's frame of its geom when exactly one of its geoms has mass (and that
    // frame is known), which a body whose inertia comes from its geoms copies as its inertial frame.
    let mut single_massive: Vec<Option<Transform>> = vec![None; spec.links.len()];
    {
        let mut first_geom = 0;
        for (li, masses) in geom_masses.iter().enumerate() {
            let mut massive = masses.iter().enumerate().filter(|&(_, &m)| m > 0.0);
            if let (Some((k, _)), None) = (massive.next(), massive.next()) {
                single_massive[li] = geom_local[first_geom + k];
            }
            first_geom += masses.len();
        }
    }
    // MuJoCo's body_iquat: an explicit diagonal <inertial> keeps its frame; a single geom's frame
    // when the inertia comes from it alone; otherwise the principal axes of the body's inertia as
    // MuJoCo's compiler finds them.
    links.iquat = links
        .frame
        .iter()
        .map(|&f| {
            let li = frame_spec_link[f];
            let link = &spec.links[li];
            let i_com = frames[f].inertia.i_com();
            match &link.inertial {
                // `diaginertia`: the file's frame as it is; `fullinertia`: its principal axes
                // found in the file's frame, as MuJoCo's compiler does.
                Some(i) if !link.inertia_from_geoms => {
                    let diagonal = (0..3).all(|r| (0..3).all(|c| r == c || i.inertia[(r, c)] == 0.0));
                    let q = crate::sensor::objects::rot_quat(&i.x_link_inertial.rot);
                    if diagonal {
                        q
                    } else {
                        crate::sensor::objects::mul_quat(
                            &q,
                            &crate::sensor::objects::principal_quat(&i.inertia),
                        )
                    }
                }
                // A single geom with mass: its frame, as MuJoCo copies it.
                _ if link.inertia_from_geoms && single_massive[li].is_some() => single_massive[li]
                    .map_or([1.0, 0.0, 0.0, 0.0], |s| crate::sensor::objects::rot_quat(&s.rot)),
                _ if frames[f].inertia.mass > 0.0 => crate::sensor::objects::principal_quat(&i_com),
                _ => [1.0, 0.0, 0.0, 0.0],
            }
        })
        .collect();
    place_same_frames(
        &mut geoms,
        &mut frames,
        &mut links,
        &geom_local,
        &site_local,
        &single_massive,
        &geom_spec_link,
    );
    let mut model = Model {
        gravcomp,
        name: spec.name.clone(),
        source: spec.source.clone(),
        gravity: spec.gravity,
        bodies,
        joints,
        frames,
        geoms,
        nq,
        nv,
        dof_run_start: crate::model::dof_run_starts(&dof_parent),
        dof_tree_start: crate::model::dof_tree_starts(&dof_parent),
        hinge_axis,
        placement_unrotated,
        dof_parent,
        dof_body,
        dof_armature,
        dof_damping,
        dof_effort_limit,
        springs,
        qpos0,
        options: spec.options.clone(),
        mocap_pose0,
        keyframes,
        equalities: Vec::new(),
        tendons: Vec::new(),
        actuators: Vec::new(),
        sensors: Vec::new(),
        nsensordata: 0,
        contact_pairs: Vec::new(),
        contact_excludes: Vec::new(),
        collision_pairs: Vec::new(),
        body_root,
        links,
        elements: spec.elements.clone(),
        warnings,
        plan: crate::forward::Plan::default(),
        sleep: Default::default(),
    };
    let mut e = crate::io::compile_elements::compile_elements(spec, &model)?;
    model.equalities = e.equalities;
    model.tendons = e.tendons;
    model.actuators = e.actuators;
    // Each control history's place in `Data::history`, in actuator order (MuJoCo's
    // `actuator_historyadr`).
    let mut history_adr = 0;
    for a in model.actuators.iter_mut() {
        let Some(h) = a.history.as_mut() else { continue };
        h.adr = history_adr;
        history_adr += 2 + 2 * h.nsample;
        if history_adr > MAX_HISTORY {
            return Err(LoadError::Invalid {
                loc: a.loc.clone(),
                element: "actuator".into(),
                detail: format!(
                    "the actuators' control histories (nsample) take more than {MAX_HISTORY} numbers \
                     ({} MB) by actuator '{}': keep fewer samples",
                    (MAX_HISTORY * 8) >> 20,
                    a.name
                ),
            });
        }
    }
    model.contact_pairs = e.contact_pairs;
    model.contact_excludes = e.contact_excludes;
    model.elements.append(&mut e.kept);
    model.warnings.append(&mut e.warnings);
    reflect_actuator_damping_armature(spec, &mut model);
    lengthrange_simulation(spec, &mut model)?;
    // Actuators of kinds the actuation stage does not simulate: listed by `info`, no force.
    for a in &model.actuators {
        if let Some(why) = crate::model::actuator::unsimulated_reason(&model, a) {
            let name = if a.name.is_empty() { String::new() } else { format!(" '{}'", a.name) };
            model.warnings.push(format!(
                "{}: <{}>{name}: {why} is not simulated; the actuator is listed by `info` and exerts no force",
                a.loc,
                a.shortcut.name()
            ));
        }
    }
    let names = crate::io::compile_elements::Names::new(spec, &model);
    let (sensors, nsensordata) = crate::io::compile_sensors::compile_sensors(&spec.elements, &names, &model)?;
    model.sensors = sensors;
    model.nsensordata = nsensordata;
    model.elements.retain(|e| e.category != "sensor");
    for s in model.sensors.iter().filter(|s| !s.is_computed()) {
        model.warnings.push(format!(
            "{}: <{}> '{}': not computed: {}",
            s.loc,
            s.kind.tag(),
            s.label(),
            s.not_computed.as_deref().unwrap_or("")
        ));
    }
    let joint_locs: Vec<SourceLoc> = spec
        .links
        .iter()
        .filter(|l| l.joint.jtype != JointType::Fixed)
        .map(|l| l.joint.loc.clone())
        .collect();
    if let Some(w) = crate::io::singular::check_mass_matrix(&model, &joint_locs, word) {
        model.warnings.push(w);
    }
    check_keyframe_act(&model)?;
    model.collision_pairs = crate::model::collision_pairs::candidate_pairs(&model);
    if model.collision_pairs.len() > crate::model::collision_pairs::MAX_COLLISION_PAIRS {
        return Err(LoadError::Invalid {
            loc: SourceLoc { file: spec.source.as_ref().map(|p| p.display().to_string()).unwrap_or_default(), line: 0 },
            element: "geom".into(),
            detail: format!(
                "more than {} candidate collision pairs (a resource limit); give geoms that need not touch contype=\"0\" conaffinity=\"0\", use <contact><exclude>, or disable contacts (LoadOptions::disabled_flags += contact)",
                crate::model::collision_pairs::MAX_COLLISION_PAIRS
            ),
        });
    }
    auto_spring_damper(spec, &mut model);
    crate::tendon::resolve_spring_lengths(&mut model);
    crate::model::lengthrange::set_acc0(&mut model);
    model.plan = crate::forward::Plan::new(&model, None);
    model.sleep = sleep_model(spec, &model, &link_body)?;
    Ok(model)
}

/// MuJoCo's trees, sleep policies and `dof_length` ([`crate::model::sleep::SleepModel`]), with
/// the file's `<body sleep>` policies checked: only on the root body of a tree.
fn sleep_model(
    spec: &ModelSpec,
    model: &Model,
    link_body: &[(usize, Transform)],
) -> Result<crate::model::sleep::SleepModel, LoadError> {
    let user: Vec<(usize, crate::model::sleep::SleepPolicy)> =
        spec.sleep.iter().map(|&(l, p)| (model.body_root[link_body[l].0], p)).collect();
    let mut data = crate::model::Data::scratch(model);
    let q = model.qpos0.clone();
    let v = vec![0.0; model.nv];
    crate::kinematics::forward_kinematics_unchecked(model, &mut data, &q);
    crate::tendon::compute(model, &mut data, &q, &v);
    crate::model::sleep::SleepModel::new(model, &user, &data.ten_j, &data.x_world_body).map_err(
        |(b, detail)| {
            let link =
                spec.sleep.iter().find(|&&(l, _)| model.body_root[link_body[l].0] == b).map(|&(l, _)| l);
            let loc = link.map_or_else(
                || SourceLoc {
                    file: spec.source.as_ref().map(|p| p.display().to_string()).unwrap_or_default(),
                    line: 0,
                },
                |l| spec.links[l].loc.clone(),
            );
            let name = link.map_or_else(|| model.bodies[b].name.clone(), |l| spec.links[l].name.clone());
            LoadError::Invalid { loc, element: "body".into(), detail: format!("body '{name}': {detail}") }
        },
    )
}

/// The actuators whose `actuator_lengthrange` neither the file nor a limit settles
/// (`model::lengthrange::resolve`) get it from the compiler's simulation
/// (`model::lengthrange_sim`), as MuJoCo's `mjCModel::LengthRange` after `mj_setConst`.
fn lengthrange_simulation(spec: &ModelSpec, model: &mut Model) -> Result<(), LoadError> {
    let which: Vec<usize> = spec
        .actuators
        .iter()
        .zip(&model.actuators)
        .enumerate()
        .filter(|(_, (s, a))| {
            crate::model::lengthrange::resolve(
                s,
                &a.transmission,
                &model.joints,
                &model.tendons,
                &spec.lengthrange,
            )
            .is_none()
        })
        .map(|(i, _)| i)
        .collect();
    crate::model::lengthrange_sim::simulate_ranges(model, &which, &spec.lengthrange)
}

/// MJCF `springdamper` (MuJoCo's `mjCModel::AutoSpringDamper`, user_model.cc): a joint given a
/// time constant τ and damping ratio ζ gets, from its inertia at `qpos0` m = ndof / Σ
/// `dof_invweight0` over its dofs, the stiffness m / (τ² ζ²) and the damping 2 m / τ (as a
/// soft constraint's `solref` maps to stiffness and damping), replacing the file's `stiffness`
/// and `damping`. Checked against MuJoCo 4.0.0's `jnt_stiffness` and `dof_damping`
/// (tests/mjcf_features.rs) and on dm_control's dog (validation/crossval_features.py).
fn auto_spring_damper(spec: &ModelSpec, model: &mut Model) {
    let params: Vec<(usize, [f64; 2])> = spec
        .links
        .iter()
        .filter(|l| l.joint.jtype != JointType::Fixed)
        .enumerate()
        .filter_map(|(j, l)| l.joint.springdamper.map(|p| (j, p)))
        .collect();
    if params.is_empty() {
        return;
    }
    const MINVAL: f64 = 1e-15;
    let weights = crate::constraint::soft::weights::InverseWeights::new(model);
    for (ji, [timeconst, dampratio]) in params {
        let (d, n) = (model.joints[ji].dof_adr, model.joints[ji].kind.nv());
        let inertia = n as f64 / weights.dof_invweight0[d..d + n].iter().sum::<f64>().max(MINVAL);
        let stiffness = inertia / (timeconst * timeconst * dampratio * dampratio).max(MINVAL);
        let damping = 2.0 * inertia / timeconst.max(MINVAL);
        if spec.options.flags.damper {
            // dof_damping holds the file's damping plus what actuators reflect onto the dof.
            let file_damping = model.joints[ji].damping;
            for k in d..d + n {
                model.dof_damping[k] += damping - file_damping;
            }
        }
        let joint = &mut model.joints[ji];
        joint.stiffness = stiffness;
        joint.damping = damping;
        if spec.options.flags.spring && joint.kind.nq() == 1 {
            let spring = Spring { qpos_adr: joint.qpos_adr, dof_adr: d, stiffness, rest: joint.spring_ref };
            match model.springs.binary_search_by_key(&d, |s| s.dof_adr) {
                Ok(i) => model.springs[i] = spring,
                Err(i) => model.springs.insert(i, spring),
            }
        }
    }
}

/// Actuator `damping` and `armature` (MuJoCo 4's `actuator_damping`, `actuator_armature`): on a
/// hinge or slide joint the transmission's moment is the constant gear, so they are the joint's
/// damping gear² · damping (a passive force, off with `<flag damper="disable">`) and armature
/// gear² · armature, added to `dof_damping` and `dof_armature` (checked against MuJoCo 4.0.0's
/// `qfrc_passive` and M). On other transmissions they are not simulated, with a warning.
fn reflect_actuator_damping_armature(spec: &ModelSpec, model: &mut Model) {
    use crate::model::actuator::Transmission;
    for (s, a) in spec.actuators.iter().zip(&model.actuators) {
        if s.damping == 0.0 && s.armature == 0.0 {
            continue;
        }
        let joint = match a.transmission {
            Transmission::Joint(j) | Transmission::JointInParent(j) if model.joints[j].kind.nv() == 1 => j,
            _ => {
                model.warnings.push(format!(
                    "{}: <{}>: actuator damping and armature are simulated on hinge and slide joint transmissions only; ignored here",
                    s.loc,
                    s.shortcut.name()
                ));
                continue;
            }
        };
        let (dof, g2) = (model.joints[joint].dof_adr, a.gear[0] * a.gear[0]);
        if spec.options.flags.damper {
            model.dof_damping[dof] += g2 * s.damping;
        }
        model.dof_armature[dof] += g2 * s.armature;
    }
}

/// A keyframe's `act` must have one value per activation state (MuJoCo's `na`), as MuJoCo's
/// compiler requires.
fn check_keyframe_act(model: &Model) -> Result<(), LoadError> {
    let na = model.na();
    for k in &model.keyframes {
        if let Some(act) = k.act.as_ref().filter(|a| a.len() != na) {
            return Err(LoadError::Invalid {
                loc: k.loc.clone(),
                element: "key".into(),
                detail: format!(
                    "keyframe '{}': act has {} values, the model has {na} activation states (one per actuator with a dyntype other than 'none'); give {na} values or remove 'act'",
                    k.name,
                    act.len()
                ),
            });
        }
    }
    Ok(())
}

/// Keyframes with full vectors, as MuJoCo completes them: a missing `qpos` is `qpos0` and a short
/// one is padded from `qpos0`; a missing or short `qvel` is padded with zeros; quaternions are
/// normalized. Longer vectors are errors.
fn complete_keyframes(
    spec: &ModelSpec,
    joints: &[Joint],
    qpos0: &[f64],
    nv: usize,
) -> Result<Vec<crate::model::Keyframe>, LoadError> {
    let nq = qpos0.len();
    let mut out = Vec::with_capacity(spec.keyframes.len());
    for k in &spec.keyframes {
        for (what, v, n) in [("qpos", &k.qpos, nq), ("qvel", &k.qvel, nv)] {
            if let Some(v) = v {
                if v.len() > n {
                    return Err(LoadError::Invalid {
                        loc: k.loc.clone(),
                        element: "key".into(),
                        detail: format!(
                            "keyframe '{}': {what} has {} values, the model needs {n}; give one value per {}",
                            k.name,
                            v.len(),
                            if what == "qpos" {
                                "position coordinate (nq)"
                            } else {
                                "degree of freedom (nv)"
                            }
                        ),
                    });
                }
            }
        }
        let mut qpos = qpos0.to_vec();
        if let Some(q) = &k.qpos {
            qpos[..q.len()].copy_from_slice(q);
        }
        for j in joints {
            let quat = match j.kind {
                JointKind::Free => j.qpos_adr + 3..j.qpos_adr + 7,
                JointKind::Ball => j.qpos_adr..j.qpos_adr + 4,
                _ => continue,
            };
            let n = qpos[quat.clone()].iter().map(|x| x * x).sum::<f64>().sqrt();
            if n > 0.0 {
                qpos[quat].iter_mut().for_each(|x| *x /= n);
            }
        }
        let mut qvel = vec![0.0; nv];
        if let Some(v) = &k.qvel {
            qvel[..v.len()].copy_from_slice(v);
        }
        out.push(crate::model::Keyframe { qpos: Some(qpos), qvel: Some(qvel), ..k.clone() });
    }
    Ok(out)
}

/// Which links are welded to the world: the root when fixed, and every link reached from it
/// through fixed joints only.
fn welded_to_world(spec: &ModelSpec) -> Vec<bool> {
    let mut welded = vec![false; spec.links.len()];
    for (li, l) in spec.links.iter().enumerate() {
        let parent_welded = l.parent.is_none_or(|p| p < li && welded[p]);
        welded[li] = l.joint.jtype == JointType::Fixed && parent_welded;
    }
    welded
}

/// MuJoCo's check that every moving body has mass and inertia (`CheckBodyMassInertia`: at least
/// `mjMINVAL` = 1e-15, its welded children counted), as a warning: MuJoCo refuses such a body, but
/// when its descendants give its joints inertia the dynamics are defined (Pinocchio simulates it),
/// and a singular mass matrix is refused for both formats by
/// [`check_mass_matrix`](crate::io::singular::check_mass_matrix). Bodies made for joint anchors
/// are exempt: they stand for no MJCF body.
fn check_moving_mass(
    spec: &ModelSpec,
    bodies: &[Body],
    link_body: &[(usize, Transform)],
    warnings: &mut Vec<String>,
) {
    const MINVAL: f64 = 1e-15;
    let mut checked = vec![false; bodies.len()];
    checked[0] = true;
    // Each moving body once, named by the first MJCF body (link kind) fused into it.
    for (link, &(b, _)) in spec.links.iter().zip(link_body) {
        if checked[b] || link.kind != crate::model::FrameKind::Link {
            continue;
        }
        checked[b] = true;
        let body = &bodies[b];
        let moments = body.inertia.i_com().symmetric_eigenvalues();
        if body.inertia.mass < MINVAL || moments.min() < MINVAL {
            warnings.push(format!(
                "{}: body '{}': it moves but its mass ({:e} kg) or a principal moment ({:e} kg·m²) is below 1e-15; MuJoCo refuses such a model (\"mass and inertia of moving bodies must be larger than mjMINVAL\"), lagrange simulates it because the bodies it carries give its joints inertia; give it an <inertial> or a geom with mass to load it in MuJoCo",
                link.loc,
                link.name,
                body.inertia.mass,
                moments.min()
            ));
        }
    }
}

/// The gravity compensation of each compiled body from its links' `gravcomp` (links welded to
/// the world or a mocap body never move and are left out).
fn body_gravcomp(
    spec: &ModelSpec,
    link_body: &[(usize, Transform)],
    link_inertias: &[RigidInertia],
) -> Vec<crate::model::GravComp> {
    let mut out: Vec<crate::model::GravComp> = Vec::new();
    for &(li, fraction) in &spec.gravcomp {
        let (body, x_body_link) = link_body[li];
        let mass = fraction * link_inertias[li].mass;
        if body == 0 || mass == 0.0 {
            continue;
        }
        let com = x_body_link.pos + x_body_link.rot * link_inertias[li].com();
        match out.iter_mut().find(|g| g.body == body) {
            Some(g) => {
                let total = g.mass + mass;
                g.com = (g.com * g.mass + com * mass) / total;
                g.mass = total;
            }
            None => out.push(crate::model::GravComp { body, mass, com }),
        }
    }
    out
}

/// A link's own mass properties in link coordinates and the mass each of its geoms contributed:
/// from its geoms when the loader asks (MuJoCo `inertiafromgeom`) and some geom has mass, else its
/// checked `<inertial>`; then the compiler's lower bounds and inertia balancing ([`MassRules`]).
fn link_mass(
    link: &LinkSpec,
    word: LinkWord,
    rules: &MassRules,
    meshes: &mut crate::io::geom_mass::MeshCache,
    warnings: &mut Vec<String>,
) -> Result<(RigidInertia, Vec<f64>), LoadError> {
    // The world body keeps no mass and obeys no bounds (a URDF root welded to the world is one).
    let world_rules = MassRules { accept_nonphysical: rules.accept_nonphysical, ..MassRules::default() };
    let rules = if is_world(link) { &world_rules } else { rules };
    // Principal moments that are not physical are an error, or, when the loader was asked to
    // accept them, a warning with the tensor kept exactly as written (`None`: no rule fired).
    let settle =
        |loc: &SourceLoc, moments: Result<Option<Vec3>, String>, warnings: &mut Vec<String>| match moments {
            Ok(bounded) => Ok(bounded),
            Err(detail) => {
                let e = LoadError::NonPhysicalInertia {
                    loc: loc.clone(),
                    what: word,
                    link: link.name.clone(),
                    detail,
                };
                if !rules.accept_nonphysical {
                    return Err(e);
                }
                warnings.push(format!("{e} [kept as written: LoadOptions::accept_nonphysical_inertia]"));
                Ok(None)
            }
        };
    let mut geom_masses = vec![0.0; link.geoms.len()];
    if link.inertia_from_geoms {
        let mut sum = RigidInertia::zero();
        for (g, m) in link.geoms.iter().zip(geom_masses.iter_mut()) {
            let i_geom = crate::io::geom_mass::geom_inertia(g, word, &link.name, meshes, warnings)?;
            // MuJoCo ignores geoms of negligible mass (≤ mjEPS).
            if i_geom.mass > 1e-14 {
                *m = i_geom.mass;
                sum += &i_geom.transformed(&g.x_link_geom);
            }
        }
        if sum.mass > 0.0 {
            let (com, i_com) = (sum.com(), sum.i_com());
            let eig = i_com.symmetric_eigen();
            let bounded = settle(&link.loc, bounded_moments(eig.eigenvalues, rules), warnings)?;
            return Ok((
                inertia_with(sum, sum.mass.max(rules.bound_mass), com, &eig.eigenvectors, bounded),
                geom_masses,
            ));
        }
    }
    let Some(i) = &link.inertial else {
        // No mass anywhere: only the bounds can give the link some, at its origin.
        let zero = RigidInertia::zero();
        let bounded = settle(&link.loc, bounded_moments(Vec3::zeros(), rules), warnings)?;
        return Ok((
            inertia_with(zero, rules.bound_mass, Vec3::zeros(), &Mat3::identity(), bounded),
            geom_masses,
        ));
    };
    let (moments, axes) = check_inertial(word, &link.name, i)?;
    let bounded = settle(
        &i.loc,
        negative_moment(i, &moments).map_or_else(|| bounded_moments(moments, rules), Err),
        warnings,
    )?;
    let r = i.x_link_inertial.rot;
    let given = RigidInertia::from_com(i.mass, i.x_link_inertial.pos, r * i.inertia * r.transpose());
    Ok((
        inertia_with(given, i.mass.max(rules.bound_mass), i.x_link_inertial.pos, &(r * axes), bounded),
        geom_masses,
    ))
}

/// `original` if neither its mass nor its principal moments changed (keeping it bit for bit),
/// else the inertia rebuilt from `mass`, `com` and the new `moments` about `axes` (columns).
fn inertia_with(
    original: RigidInertia,
    mass: f64,
    com: Vec3,
    axes: &Mat3,
    moments: Option<Vec3>,
) -> RigidInertia {
    match moments {
        None if mass == original.mass => original,
        None => RigidInertia::from_com(mass, com, original.i_com()),
        Some(m) => RigidInertia::from_com(mass, com, axes * Mat3::from_diagonal(&m) * axes.transpose()),
    }
}

/// MuJoCo's `boundinertia` and `balanceinertia` on principal moments (`mjCBody::Compile`): the new
/// moments, or `None` when no rule fires. Moments that violate the triangle inequality are a defect
/// (its description) unless `balanceinertia` replaces them by their mean.
fn bounded_moments(moments: Vec3, rules: &MassRules) -> Result<Option<Vec3>, String> {
    let mut m = moments.map(|l| l.max(rules.bound_inertia));
    let tol = (INERTIA_TOL * m.max()).max(ROUNDOFF_MINVAL);
    let violated = (0..3).any(|k| m[k] > m[(k + 1) % 3] + m[(k + 2) % 3] + tol);
    if violated {
        if !rules.balance_inertia {
            let mut e: Vec<f64> = m.iter().copied().collect();
            e.sort_by(f64::total_cmp);
            return Err(format!(
                "principal moments {e:?} violate the triangle inequality ({} + {} < {}) (MJCF: <compiler balanceinertia=\"true\"> replaces them by their mean)",
                e[0], e[1], e[2]
            ));
        }
        m = Vec3::repeat(m.sum() / 3.0);
    }
    Ok((m != moments).then_some(m))
}

/// Whether the link is the world itself (no parent, welded): it keeps no mass and obeys no bounds.
fn is_world(l: &LinkSpec) -> bool {
    l.parent.is_none() && l.joint.jtype == JointType::Fixed
}

/// MuJoCo's `settotalmass`: scale the masses and inertias of all links but the world so that they
/// total `total` (`mj_setTotalmass`).
fn scale_total_mass(
    spec: &ModelSpec,
    inertias: &mut [RigidInertia],
    geom_masses: &mut [Vec<f64>],
    total: f64,
) {
    let sum: f64 =
        spec.links.iter().zip(inertias.iter()).filter(|(l, _)| !is_world(l)).map(|(_, i)| i.mass).sum();
    if sum <= 0.0 {
        return;
    }
    let s = total / sum;
    for ((l, i), gm) in spec.links.iter().zip(inertias.iter_mut()).zip(geom_masses.iter_mut()) {
        if !is_world(l) {
            *i = i.scaled(s);
            gm.iter_mut().for_each(|m| *m *= s);
        }
    }
}

fn check_unique_names(spec: &ModelSpec) -> Result<(), LoadError> {
    let mut links = HashMap::new();
    let mut joints = HashMap::new();
    for l in &spec.links {
        if links.insert(l.name.as_str(), ()).is_some() {
            return Err(LoadError::DuplicateName {
                loc: l.loc.clone(),
                element: "link",
                name: l.name.clone(),
            });
        }
        if !l.joint.name.is_empty() && joints.insert(l.joint.name.as_str(), ()).is_some() {
            return Err(LoadError::DuplicateName {
                loc: l.joint.loc.clone(),
                element: "joint",
                name: l.joint.name.clone(),
            });
        }
    }
    Ok(())
}

/// The movable joint kind of a spec joint (`None` for fixed), with its axis normalized.
fn joint_kind(j: &JointSpec) -> Result<Option<JointKind>, LoadError> {
    let axis = || {
        let n = j.axis.norm();
        if n.is_nan() || n <= 1e-12 || !n.is_finite() {
            Err(LoadError::ZeroAxis { loc: j.loc.clone(), joint: j.name.clone() })
        } else {
            Ok(j.axis / n)
        }
    };
    Ok(match j.jtype {
        JointType::Fixed => None,
        JointType::Revolute => Some(JointKind::Revolute { axis: axis()?, continuous: false }),
        JointType::Continuous => Some(JointKind::Revolute { axis: axis()?, continuous: true }),
        JointType::Prismatic => Some(JointKind::Prismatic { axis: axis()? }),
        JointType::Floating => Some(JointKind::Free),
        JointType::Ball => Some(JointKind::Ball),
        JointType::Planar => {
            let normal = axis()?;
            // In-plane axes: a right-handed orthonormal pair (axis1, axis2, normal); for the
            // usual normal z they are x and y.
            let seed = if normal.x.abs() < 0.9 { Vec3::x() } else { Vec3::y() };
            let axis1 = (seed - normal * normal.dot(&seed)).normalize();
            let axis2 = normal.cross(&axis1);
            Some(JointKind::Planar { axis1, axis2, normal })
        }
    })
}

/// Checks an `<inertial>` (finite, non-negative mass; finite symmetric tensor) and returns its
/// principal moments and axes (columns, in inertial-frame coordinates).
fn check_inertial(word: LinkWord, link: &str, i: &InertialSpec) -> Result<(Vec3, Mat3), LoadError> {
    let err = |detail: String| LoadError::NonPhysicalInertia {
        loc: i.loc.clone(),
        what: word,
        link: link.to_string(),
        detail,
    };
    if !i.mass.is_finite() || i.mass < 0.0 {
        if i.mass.is_finite() {
            return Err(LoadError::NegativeMass {
                loc: i.loc.clone(),
                what: word,
                link: link.to_string(),
                mass: i.mass,
            });
        }
        return Err(err(format!("mass is {}", i.mass)));
    }
    let m = &i.inertia;
    if m.iter().any(|x| !x.is_finite()) {
        return Err(err("an inertia entry is not a finite number".into()));
    }
    let scale = m.abs().max().max(f64::MIN_POSITIVE);
    if (m - m.transpose()).abs().max() > INERTIA_TOL * scale {
        return Err(err("the tensor is not symmetric".into()));
    }
    let eig = m.symmetric_eigen();
    Ok((eig.eigenvalues, eig.eigenvectors))
}

/// The defect of an `<inertial>` whose principal `moments` include a negative one, if any. Round-off
/// is accepted: a moment above `−max(INERTIA_TOL · scale, MINVAL)`, with `scale` the largest entry
/// and `MINVAL` MuJoCo's `mjMINVAL` (a tensor that is zero up to round-off, e.g. off-diagonal
/// entries of 1e-20 on a zero diagonal, is zero, not negative).
fn negative_moment(i: &InertialSpec, moments: &Vec3) -> Option<String> {
    let scale = i.inertia.abs().max();
    (moments.min() < -(INERTIA_TOL * scale).max(ROUNDOFF_MINVAL)).then(|| {
        let mut e: Vec<f64> = moments.iter().copied().collect();
        e.sort_by(f64::total_cmp);
        format!("principal moments {e:?} include a negative one")
    })
}

/// A mesh's MuJoCo frame in its geom frame (`MeshGraph::box_frame`), the identity for other geoms.
fn mesh_frame(hull: Option<&crate::io::geom_hull::GeomHull>) -> Transform {
    hull.map_or(Transform::identity(), |h| Transform::new(h.box_frame.1, h.box_frame.0))
}

/// Places geoms and sites as MuJoCo's `geom_sameframe` and `site_sameframe` do
/// ([`crate::io::sameframe`]) and records the flags in `links`. `geom_local` and `site_local`
/// are MuJoCo's frames of the geoms and sites in their bodies (None: not a site, or a mesh whose
/// frame is not computed, which keeps its own pose); `single_massive` is, per spec link, the
/// frame of the one geom its inertia was copied from. That geom keeps its pose exactly when it is
/// the inertial frame (MuJoCo's placement is then its own composition).
fn place_same_frames(
    geoms: &mut [Geom],
    frames: &mut [Frame],
    links: &mut crate::model::Links,
    geom_local: &[Option<Transform>],
    site_local: &[Option<Transform>],
    single_massive: &[Option<Transform>],
    geom_spec_link: &[usize],
) {
    use crate::io::sameframe::{classify, placed, SameFrame};
    let inertial = |frames: &[Frame], b: usize| {
        let i = &frames[links.frame[b]].inertia;
        (if i.mass > 0.0 { i.com() } else { Vec3::zeros() }, links.iquat[b])
    };
    links.geom_sameframe = vec![SameFrame::None; geoms.len()];
    for (g, geom) in geoms.iter_mut().enumerate() {
        let Some(local) = geom_local[g] else { continue };
        let b = links.of_geom[g];
        let (ipos, iquat) = inertial(frames, b);
        let flag = classify(&local, &ipos, &iquat);
        links.geom_sameframe[g] = flag;
        let copied = single_massive[geom_spec_link[g]].is_some_and(|s| s == local);
        if flag == SameFrame::None || (flag == SameFrame::Inertia && copied) {
            continue;
        }
        let x_body_link = frames[links.frame[b]].x_body_frame;
        geom.x_body_geom = x_body_link
            * placed(flag, &local, &ipos, &iquat)
            * mesh_frame(geom.hull_graph.as_ref()).inverse();
    }
    links.site_sameframe = vec![SameFrame::None; frames.len()];
    for f in 0..frames.len() {
        let Some(local) = site_local[f] else { continue };
        let b = links.of_frame[f];
        let (ipos, iquat) = inertial(frames, b);
        let flag = classify(&local, &ipos, &iquat);
        links.site_sameframe[f] = flag;
        if flag != SameFrame::None {
            frames[f].x_body_frame =
                frames[links.frame[b]].x_body_frame * placed(flag, &local, &ipos, &iquat);
        }
    }
}
