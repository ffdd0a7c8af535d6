//! The compile step for the elements around the tree: equality constraints, URDF mimics, tendons,
//! actuators, contact pairs and exclusions get their names resolved to indices of the compiled
//! [`Model`], with MuJoCo's compile-time checks (`mjCEquality::ResolveReferences`,
//! `mjCTendon::Compile`, `mjCActuator::Compile`, `mjCPair::Compile`).
//!
//! What a name resolves to: an MJCF body → its frame (kind `Link`) in `model.frames`, because a
//! body may be fused into its parent or carried by joint-anchor bodies, so constraints act on
//! frames; the world is the frame of body 0 named `world`; a site → its frame (kind `Site`); a
//! joint → `model.joints`; a tendon → `model.tendons`; a geom → `model.geoms`. Contact exclusions
//! and body transmissions name the compiled body (`model.bodies`) the MJCF body belongs to.
//! Contact pairs and exclusions come in MuJoCo's order: the lower MJCF body of each first, then
//! stably sorted by body pair (`mjCModel::Compile`).
//!
//! URDF `<mimic>` becomes an [`EqualityKind::Mimic`] named `mimic:<joint>`: both joints must be
//! revolute, continuous or prismatic; chains (a follows b, b follows c) are allowed, cycles are
//! not. A mimic on a fixed joint is ignored with a warning (reduced models lock a mimic joint by
//! making it fixed and keep its `<mimic>`).

use crate::io::LoadError;
use crate::model::actuator::ActuatorShortcut;
use crate::model::equality::{DEFAULT_SOLIMP, DEFAULT_SOLREF};
use crate::model::spec::Shape;
use crate::model::spec::{
    ActuatorSpec, ContactPairSpec, EqualitySpec, EqualitySpecKind, JointType, ModelSpec, TendonSpec,
    TendonSpecKind, TransmissionSpec,
};
use crate::model::{
    Actuator, ContactExclude, ContactPair, Element, Equality, EqualityKind, FrameKind, JointKind, Model,
    PathElement, SourceLoc, Tendon, TendonKind, WrapShape,
};
use std::collections::HashMap;

/// The resolved elements, ready to go into the model.
pub(crate) struct Elements {
    pub equalities: Vec<Equality>,
    pub tendons: Vec<Tendon>,
    pub actuators: Vec<Actuator>,
    pub contact_pairs: Vec<ContactPair>,
    pub contact_excludes: Vec<ContactExclude>,
    /// Elements that stay untyped (listed by `info`), e.g. equalities on spatial tendons.
    pub kept: Vec<Element>,
    pub warnings: Vec<String>,
}

/// Resolves every element of `spec` against `model` (its tree, frames and geoms compiled).
pub(crate) fn compile_elements(spec: &ModelSpec, model: &Model) -> Result<Elements, LoadError> {
    let names = Names::new(spec, model);
    let mut out = Elements {
        equalities: Vec::with_capacity(spec.equalities.len()),
        tendons: Vec::with_capacity(spec.tendons.len()),
        actuators: Vec::with_capacity(spec.actuators.len()),
        contact_pairs: Vec::with_capacity(spec.contact_pairs.len()),
        contact_excludes: Vec::with_capacity(spec.contact_excludes.len()),
        kept: Vec::new(),
        warnings: Vec::new(),
    };
    for t in &spec.tendons {
        out.tendons.push(tendon(t, &names)?);
    }
    for e in &spec.equalities {
        match equality(e, &names, spec)? {
            Some(eq) => out.equalities.push(eq),
            None => {
                let (tendon1, tendon2) = match &e.kind {
                    EqualitySpecKind::Tendon { tendon1, tendon2, .. } => (tendon1.clone(), tendon2.clone()),
                    _ => (String::new(), None),
                };
                out.warnings.push(format!(
                    "{}: <tendon>: equality {} couples a spatial tendon, which is not simulated; kept as a listed element",
                    e.loc,
                    quoted(&e.name)
                ));
                out.kept.push(Element {
                    category: "equality".into(),
                    kind: "tendon".into(),
                    name: e.name.clone(),
                    targets: std::iter::once(tendon1).chain(tendon2).collect(),
                    attributes: Vec::new(),
                    loc: e.loc.clone(),
                });
            }
        }
    }
    mimics(spec, &names, &mut out)?;
    for a in &spec.actuators {
        out.actuators.push(actuator(a, &names, spec, &out.tendons)?);
    }
    // MuJoCo's order: each pair with its lower MJCF body first, then stably sorted by the body
    // pair (its `signature`, `mjCModel::Compile`).
    let mut pairs = Vec::with_capacity(spec.contact_pairs.len());
    for p in &spec.contact_pairs {
        let mut p = pair(p, &names)?;
        let (mut b1, mut b2) = (names.geom_body_id(p.geom1), names.geom_body_id(p.geom2));
        if b1 > b2 {
            std::mem::swap(&mut p.geom1, &mut p.geom2);
            std::mem::swap(&mut b1, &mut b2);
        }
        pairs.push(((b1, b2), p));
    }
    pairs.sort_by_key(|(signature, _)| *signature);
    out.contact_pairs = pairs.into_iter().map(|(_, p)| p).collect();
    let mut excludes = Vec::with_capacity(spec.contact_excludes.len());
    for x in &spec.contact_excludes {
        let (f1, f2) =
            (names.body_frame(&x.body1, &x.loc, "exclude")?, names.body_frame(&x.body2, &x.loc, "exclude")?);
        let (mut b1, mut b2) = (names.body_id[&f1], names.body_id[&f2]);
        let mut x = ContactExclude {
            name: x.name.clone(),
            body1: model.frames[f1].body,
            body2: model.frames[f2].body,
            mujoco_body: [b1, b2],
            loc: x.loc.clone(),
        };
        if b1 > b2 {
            std::mem::swap(&mut x.body1, &mut x.body2);
            std::mem::swap(&mut b1, &mut b2);
            x.mujoco_body = [b1, b2];
        }
        excludes.push(((b1, b2), x));
    }
    excludes.sort_by_key(|(signature, _)| *signature);
    out.contact_excludes = excludes.into_iter().map(|(_, x)| x).collect();
    Ok(out)
}

/// `'name'`, or `(unnamed)`.
fn quoted(name: &str) -> String {
    if name.is_empty() {
        "(unnamed)".to_string()
    } else {
        format!("'{name}'")
    }
}

/// Name → index tables of the compiled model, and the spec joints that were fused away.
pub(crate) struct Names<'m> {
    model: &'m Model,
    links: HashMap<&'m str, usize>,
    sites: HashMap<&'m str, usize>,
    joints: HashMap<&'m str, usize>,
    geoms: HashMap<&'m str, usize>,
    tendons: HashMap<&'m str, usize>,
    /// Spec joints by name: (type, where they are written).
    spec_joints: HashMap<&'m str, (JointType, &'m SourceLoc)>,
    /// The world frame (MJCF `world`, frame of body 0).
    world: usize,
    /// MuJoCo's body id of each link frame (frame index → rank among the link frames).
    body_id: HashMap<usize, usize>,
}

impl<'m> Names<'m> {
    /// MuJoCo's id of an MJCF body (its rank among the link frames, `Model::links`).
    pub(crate) fn body_id_of(&self, name: &str, loc: &SourceLoc, element: &str) -> Result<usize, LoadError> {
        Ok(self.body_id[&self.body_frame(name, loc, element)?])
    }

    /// A site's frame.
    pub(crate) fn site_of(&self, name: &str, loc: &SourceLoc, element: &str) -> Result<usize, LoadError> {
        self.site(name, loc, element)
    }

    /// A geom's index.
    pub(crate) fn geom_of(&self, name: &str, loc: &SourceLoc, element: &str) -> Result<usize, LoadError> {
        self.geom(name, loc, element)
    }

    /// A movable joint's index.
    pub(crate) fn joint_of(&self, name: &str, loc: &SourceLoc, element: &str) -> Result<usize, LoadError> {
        self.joint(name, loc, element)
    }

    /// A tendon's index.
    pub(crate) fn tendon_of(&self, name: &str, loc: &SourceLoc, element: &str) -> Result<usize, LoadError> {
        self.tendon(name, loc, element)
    }

    pub(crate) fn new(spec: &'m ModelSpec, model: &'m Model) -> Self {
        let mut links = HashMap::new();
        let mut sites = HashMap::new();
        for (i, f) in model.frames.iter().enumerate() {
            let table = match f.kind {
                FrameKind::Link => &mut links,
                FrameKind::Site => &mut sites,
                FrameKind::Joint => continue,
            };
            table.entry(f.name.as_str()).or_insert(i);
        }
        let world = model
            .frames
            .iter()
            .position(|f| f.kind == FrameKind::Link && f.body == 0 && f.name == "world")
            .unwrap_or(0);
        Names {
            model,
            links,
            sites,
            joints: model.joints.iter().enumerate().map(|(i, j)| (j.name.as_str(), i)).collect(),
            geoms: model
                .geoms
                .iter()
                .enumerate()
                .filter(|(_, g)| !g.name.is_empty())
                .map(|(i, g)| (g.name.as_str(), i))
                .collect(),
            tendons: spec.tendons.iter().enumerate().map(|(i, t)| (t.name.as_str(), i)).collect(),
            spec_joints: spec
                .links
                .iter()
                .filter(|l| !l.joint.name.is_empty())
                .map(|l| (l.joint.name.as_str(), (l.joint.jtype, &l.joint.loc)))
                .collect(),
            world,
            body_id: model
                .frames
                .iter()
                .enumerate()
                .filter(|(_, f)| f.kind == FrameKind::Link)
                .enumerate()
                .map(|(rank, (i, _))| (i, rank))
                .collect(),
        }
    }

    /// MuJoCo's id of the body a geom belongs to (its link's rank among the link frames).
    fn geom_body_id(&self, g: usize) -> usize {
        self.links.get(self.model.geoms[g].link.as_str()).map_or(0, |f| self.body_id[f])
    }

    fn unknown(loc: &SourceLoc, element: &str, kind: &'static str, target: &str) -> LoadError {
        LoadError::UnknownReference {
            loc: loc.clone(),
            element: element.to_string(),
            kind,
            target: target.to_string(),
        }
    }

    /// The frame of an MJCF body (or URDF link).
    fn body_frame(&self, name: &str, loc: &SourceLoc, element: &str) -> Result<usize, LoadError> {
        self.links.get(name).copied().ok_or_else(|| Self::unknown(loc, element, "body", name))
    }

    /// The compiled body an MJCF body belongs to.
    fn body(&self, name: &str, loc: &SourceLoc, element: &str) -> Result<usize, LoadError> {
        Ok(self.model.frames[self.body_frame(name, loc, element)?].body)
    }

    fn site(&self, name: &str, loc: &SourceLoc, element: &str) -> Result<usize, LoadError> {
        self.sites.get(name).copied().ok_or_else(|| Self::unknown(loc, element, "site", name))
    }

    fn geom(&self, name: &str, loc: &SourceLoc, element: &str) -> Result<usize, LoadError> {
        self.geoms.get(name).copied().ok_or_else(|| Self::unknown(loc, element, "geom", name))
    }

    fn tendon(&self, name: &str, loc: &SourceLoc, element: &str) -> Result<usize, LoadError> {
        self.tendons.get(name).copied().ok_or_else(|| Self::unknown(loc, element, "tendon", name))
    }

    /// A movable joint; a joint fused away (fixed) has no coordinate and is an error.
    fn joint(&self, name: &str, loc: &SourceLoc, element: &str) -> Result<usize, LoadError> {
        if let Some(&j) = self.joints.get(name) {
            return Ok(j);
        }
        match self.spec_joints.get(name) {
            Some((JointType::Fixed, _)) => Err(LoadError::Invalid {
                loc: loc.clone(),
                element: element.to_string(),
                detail: format!(
                    "joint '{name}' is fixed (fused into its parent body), so it has no coordinate to act on; make it movable or remove the reference"
                ),
            }),
            _ => Err(Self::unknown(loc, element, "joint", name)),
        }
    }

    /// A hinge or slide joint (one coordinate), as joint equalities and fixed tendons need;
    /// `what` names the user and `fix` says what to do instead.
    fn scalar_joint(
        &self,
        name: &str,
        loc: &SourceLoc,
        element: &str,
        what: &str,
        fix: &str,
    ) -> Result<usize, LoadError> {
        let j = self.joint(name, loc, element)?;
        match self.model.joints[j].kind {
            JointKind::Revolute { .. } | JointKind::Prismatic { .. } => Ok(j),
            ref k => Err(LoadError::Invalid {
                loc: loc.clone(),
                element: element.to_string(),
                detail: format!(
                    "joint '{name}' is a {} joint; {what} takes hinge and slide joints only (one coordinate each): {fix}",
                    k.type_name()
                ),
            }),
        }
    }
}

/// The error for an equality whose two objects are the same.
fn repeated(e: &EqualitySpec, element: &str, what: &str, name: &str) -> LoadError {
    LoadError::Invalid {
        loc: e.loc.clone(),
        element: element.to_string(),
        detail: format!(
            "equality {}: {what} '{name}' is constrained to itself; name two different objects{}",
            quoted(&e.name),
            if what == "body" { " (without body2 the second is the world)" } else { "" }
        ),
    }
}

/// One equality constraint; `None` for a tendon equality on a spatial tendon (not simulated).
fn equality(e: &EqualitySpec, n: &Names, spec: &ModelSpec) -> Result<Option<Equality>, LoadError> {
    let loc = &e.loc;
    let bodies = |element: &str, body1: &str, body2: &Option<String>| -> Result<(usize, usize), LoadError> {
        let f1 = n.body_frame(body1, loc, element)?;
        let f2 = match body2 {
            Some(b) => n.body_frame(b, loc, element)?,
            None => n.world,
        };
        if f1 == f2 {
            return Err(repeated(e, element, "body", body1));
        }
        Ok((f1, f2))
    };
    let sites = |element: &str, site1: &str, site2: &str| -> Result<(usize, usize), LoadError> {
        let (s1, s2) = (n.site(site1, loc, element)?, n.site(site2, loc, element)?);
        if s1 == s2 {
            return Err(repeated(e, element, "site", site1));
        }
        Ok((s1, s2))
    };
    let kind = match &e.kind {
        EqualitySpecKind::ConnectBodies { body1, body2, anchor } => {
            let (frame1, frame2) = bodies("connect", body1, body2)?;
            EqualityKind::Connect { frame1, frame2, anchor: Some(*anchor) }
        }
        EqualitySpecKind::ConnectSites { site1, site2 } => {
            let (frame1, frame2) = sites("connect", site1, site2)?;
            EqualityKind::Connect { frame1, frame2, anchor: None }
        }
        EqualitySpecKind::WeldBodies { body1, body2, anchor, relpose, torquescale } => {
            let (frame1, frame2) = bodies("weld", body1, body2)?;
            EqualityKind::Weld {
                frame1,
                frame2,
                anchor: *anchor,
                relpose: *relpose,
                torquescale: *torquescale,
                sites: false,
            }
        }
        EqualitySpecKind::WeldSites { site1, site2, torquescale } => {
            let (frame1, frame2) = sites("weld", site1, site2)?;
            EqualityKind::Weld {
                frame1,
                frame2,
                anchor: [0.0; 3],
                relpose: None,
                torquescale: *torquescale,
                sites: true,
            }
        }
        EqualitySpecKind::Joint { joint1, joint2, polycoef } => {
            const WHAT: &str = "a joint equality";
            const FIX: &str =
                "couple hinge or slide joints, or tie the bodies with a connect or weld constraint";
            let j1 = n.scalar_joint(joint1, loc, "joint", WHAT, FIX)?;
            let j2 = match joint2 {
                Some(j) => Some(n.scalar_joint(j, loc, "joint", WHAT, FIX)?),
                None => None,
            };
            if j2 == Some(j1) {
                return Err(repeated(e, "joint", "joint", joint1));
            }
            EqualityKind::Joint { joint1: j1, joint2: j2, polycoef: *polycoef }
        }
        EqualitySpecKind::Tendon { tendon1, tendon2, polycoef } => {
            let t1 = n.tendon(tendon1, loc, "tendon")?;
            let t2 = match tendon2 {
                Some(t) => Some(n.tendon(t, loc, "tendon")?),
                None => None,
            };
            if t2 == Some(t1) {
                return Err(repeated(e, "tendon", "tendon", tendon1));
            }
            let spatial = |t: usize| matches!(spec.tendons[t].kind, TendonSpecKind::Spatial { .. });
            if spatial(t1) || t2.is_some_and(spatial) {
                return Ok(None);
            }
            EqualityKind::Tendon { tendon1: t1, tendon2: t2, polycoef: *polycoef }
        }
    };
    Ok(Some(Equality {
        name: e.name.clone(),
        kind,
        active: e.active,
        solref: e.solref,
        solimp: e.solimp,
        loc: e.loc.clone(),
    }))
}

/// The URDF mimics, in joint order, as equality constraints.
fn mimics(spec: &ModelSpec, n: &Names, out: &mut Elements) -> Result<(), LoadError> {
    let invalid = |loc: &SourceLoc, detail: String| LoadError::Invalid {
        loc: loc.clone(),
        element: "mimic".into(),
        detail,
    };
    let one_dof =
        |t: JointType| matches!(t, JointType::Revolute | JointType::Continuous | JointType::Prismatic);
    let type_name = |t: JointType| format!("{t:?}").to_lowercase();
    // follower joint index → (leader joint index, the mimic's location)
    let mut leader_of: HashMap<usize, (usize, &SourceLoc)> = HashMap::new();
    let mut order = Vec::new();
    for link in &spec.links {
        let j = &link.joint;
        let Some(m) = &j.mimic else { continue };
        if j.jtype == JointType::Fixed {
            out.warnings.push(format!(
                "{}: <mimic>: joint '{}' is fixed, so its <mimic joint=\"{}\"> has nothing to couple; ignored",
                m.loc, j.name, m.leader
            ));
            continue;
        }
        if !one_dof(j.jtype) {
            return Err(invalid(
                &m.loc,
                format!(
                    "joint '{}' is {}; only revolute, continuous and prismatic joints can mimic another joint: remove the <mimic>",
                    j.name,
                    type_name(j.jtype)
                ),
            ));
        }
        if m.leader == j.name {
            return Err(invalid(
                &m.loc,
                format!(
                    "joint '{}' mimics itself; name the joint it follows in <mimic joint=\"...\">",
                    j.name
                ),
            ));
        }
        let Some(&(leader_type, _)) = n.spec_joints.get(m.leader.as_str()) else {
            return Err(invalid(
                &m.loc,
                format!(
                    "joint '{}' mimics joint '{}', which is not defined; fix the name in <mimic joint=\"...\"> or remove the <mimic>",
                    j.name, m.leader
                ),
            ));
        };
        if leader_type == JointType::Fixed {
            return Err(invalid(
                &m.loc,
                format!(
                    "joint '{}' mimics joint '{}', which is fixed (fused into its parent), so it has no coordinate to follow; make '{}' revolute or prismatic, or remove the <mimic>",
                    j.name, m.leader, m.leader
                ),
            ));
        }
        if !one_dof(leader_type) {
            return Err(invalid(
                &m.loc,
                format!(
                    "joint '{}' mimics joint '{}', which is {}; a mimic follows a revolute, continuous or prismatic joint: remove the <mimic>",
                    j.name,
                    m.leader,
                    type_name(leader_type)
                ),
            ));
        }
        let follower = n.joint(&j.name, &m.loc, "mimic")?;
        let leader = n.joint(&m.leader, &m.loc, "mimic")?;
        leader_of.insert(follower, (leader, &m.loc));
        order.push((follower, leader, m));
    }
    // Cycles: follow each chain of leaders; coming back to a joint of the same walk closes one.
    for &(start, _, _) in &order {
        let mut walk = vec![start];
        let mut cur = start;
        while let Some(&(next, _)) = leader_of.get(&cur) {
            if let Some(pos) = walk.iter().position(|&w| w == next) {
                let cycle: Vec<usize> = walk[pos..].to_vec();
                let names: Vec<String> =
                    cycle.iter().map(|&j| format!("'{}'", n.model.joints[j].name)).collect();
                let chain: Vec<String> = cycle
                    .iter()
                    .map(|&j| {
                        let (l, _) = leader_of[&j];
                        format!("{} mimics {}", n.model.joints[j].name, n.model.joints[l].name)
                    })
                    .collect();
                let first = *cycle.iter().min().unwrap_or(&start);
                return Err(invalid(
                    leader_of[&first].1,
                    format!(
                        "the mimic joints {} form a cycle ({}); a chain of mimics must end at a joint that mimics none: remove one <mimic>",
                        names.join(", "),
                        chain.join(", ")
                    ),
                ));
            }
            walk.push(next);
            cur = next;
        }
    }
    for (follower, leader, m) in order {
        out.equalities.push(Equality {
            name: format!("mimic:{}", n.model.joints[follower].name),
            kind: EqualityKind::Mimic { joint: follower, leader, multiplier: m.multiplier, offset: m.offset },
            active: true,
            solref: DEFAULT_SOLREF,
            solimp: DEFAULT_SOLIMP,
            loc: m.loc.clone(),
        });
    }
    Ok(())
}

/// One tendon: a fixed tendon's joints must be hinge or slide joints.
fn tendon(t: &TendonSpec, n: &Names) -> Result<Tendon, LoadError> {
    let kind = match &t.kind {
        TendonSpecKind::Fixed { joints } => {
            let mut terms = Vec::with_capacity(joints.len());
            for (joint, coef, loc) in joints {
                let fix = format!("remove the term from tendon {}", quoted(&t.name));
                terms.push((n.scalar_joint(joint, loc, "joint", "a fixed tendon", &fix)?, *coef));
            }
            TendonKind::Fixed { joints: terms }
        }
        TendonSpecKind::Spatial { path } => TendonKind::Spatial {
            path: path
                .iter()
                .map(
                    |(element, name, _)| {
                        if element == "pulley" {
                            format!("pulley {name}")
                        } else {
                            name.clone()
                        }
                    },
                )
                .collect(),
            wraps: spatial_path(t, path, n)?,
        },
    };
    Ok(Tendon {
        name: t.name.clone(),
        kind,
        range: t.range,
        soft: t.soft,
        actuator_force_range: t.actuator_force_range,
        stiffness: t.stiffness,
        spring_length: t.spring_length,
        damping: t.damping,
        frictionloss: t.frictionloss,
        loc: t.loc.clone(),
    })
}

/// A spatial tendon's path resolved and checked as MuJoCo's compiler does: it starts and ends
/// with a site, a geom (sphere or cylinder) sits between two sites, a pulley (divisor > 0)
/// follows a site and is followed by one.
fn spatial_path(
    t: &TendonSpec,
    path: &[(String, String, Option<String>)],
    n: &Names,
) -> Result<Vec<PathElement>, LoadError> {
    let invalid =
        |detail: String| LoadError::Invalid { loc: t.loc.clone(), element: "spatial".into(), detail };
    let who = quoted(&t.name);
    let is_site = |i: usize| path.get(i).is_some_and(|(e, _, _)| e == "site");
    if path.len() < 2 || !is_site(0) || !is_site(path.len() - 1) {
        return Err(invalid(format!(
            "tendon {who}'s path must start and end with a <site> (MuJoCo's rule); it has {} elements",
            path.len()
        )));
    }
    let mut out = Vec::with_capacity(path.len());
    for (i, (element, name, side)) in path.iter().enumerate() {
        out.push(match element.as_str() {
            "site" => PathElement::Site(n.site(name, &t.loc, "spatial")?),
            "geom" => {
                if !is_site(i - 1) || !is_site(i + 1) {
                    return Err(invalid(format!(
                        "geom '{name}' in tendon {who} must sit between two <site>s (MuJoCo's rule)"
                    )));
                }
                let geom = n.geom(name, &t.loc, "spatial")?;
                let (shape, radius) = match n.model.geoms[geom].shape {
                    Shape::Sphere { radius } => (WrapShape::Sphere, radius),
                    Shape::Cylinder { radius, .. } => (WrapShape::Cylinder, radius),
                    _ => {
                        return Err(invalid(format!(
                            "geom '{name}' in tendon {who} is neither a sphere nor a cylinder; MuJoCo wraps tendons around those only"
                        )))
                    }
                };
                let sidesite = side.as_deref().map(|s| n.site(s, &t.loc, "spatial")).transpose()?;
                PathElement::Geom { geom, shape, radius, sidesite }
            }
            "pulley" => {
                let divisor: f64 = name.trim().parse().unwrap_or(f64::NAN);
                if divisor.is_nan() || divisor <= 0.0 {
                    return Err(invalid(format!(
                        "a pulley in tendon {who} has divisor '{name}'; give a positive number"
                    )));
                }
                if !is_site(i - 1) || !is_site(i + 1) {
                    return Err(invalid(format!(
                        "a pulley in tendon {who} must come between two <site>s (it starts a new branch)"
                    )));
                }
                PathElement::Pulley { divisor }
            }
            other => return Err(invalid(format!("<{other}> is not a path element of a spatial tendon"))),
        });
    }
    Ok(out)
}

/// One actuator: its transmission resolved, and `inheritrange` turned into a control (or, for
/// `intvelocity`, activation) range from the target's range (`mjCActuator::Compile`).
fn actuator(
    a: &ActuatorSpec,
    n: &Names,
    spec: &ModelSpec,
    tendons: &[Tendon],
) -> Result<Actuator, LoadError> {
    use crate::model::actuator::Transmission;
    let (loc, element) = (&a.loc, a.shortcut.name());
    let transmission = match &a.transmission {
        TransmissionSpec::Joint(j) => Transmission::Joint(n.joint(j, loc, element)?),
        TransmissionSpec::JointInParent(j) => Transmission::JointInParent(n.joint(j, loc, element)?),
        TransmissionSpec::Tendon(t) => Transmission::Tendon(n.tendon(t, loc, element)?),
        TransmissionSpec::Site { site, refsite } => Transmission::Site {
            site: n.site(site, loc, element)?,
            refsite: match refsite {
                Some(r) => Some(n.site(r, loc, element)?),
                None => None,
            },
        },
        TransmissionSpec::Body(b) => Transmission::Body(n.body(b, loc, element)?),
        TransmissionSpec::SliderCrank { cranksite, slidersite, cranklength } => Transmission::SliderCrank {
            cranksite: n.site(cranksite, loc, element)?,
            slidersite: n.site(slidersite, loc, element)?,
            cranklength: *cranklength,
        },
    };
    let (mut ctrlrange, mut actrange) = (a.ctrlrange, a.actrange);
    if let Some(fraction) = a.inheritrange {
        let no_range = |what: &str| {
            LoadError::Invalid {
            loc: loc.clone(),
            element: element.to_string(),
            detail: format!(
                "actuator {}: inheritrange takes the range of its target, but {what}; give ctrlrange instead, or limit the target",
                quoted(&a.name)
            ),
        }
        };
        let target = match &transmission {
            Transmission::Joint(j) => {
                let joint = &n.model.joints[*j];
                if !matches!(joint.kind, JointKind::Revolute { .. } | JointKind::Prismatic { .. }) {
                    return Err(no_range(&format!("joint '{}' is not a hinge or slide joint", joint.name)));
                }
                joint.limits.ok_or_else(|| no_range(&format!("joint '{}' has no range", joint.name)))?
            }
            Transmission::Tendon(t) => tendons[*t]
                .range
                .ok_or_else(|| no_range(&format!("tendon '{}' has no range", spec.tendons[*t].name)))?,
            _ => return Err(no_range("its transmission is not a joint or a tendon")),
        };
        let (mean, radius) = (0.5 * (target[1] + target[0]), 0.5 * (target[1] - target[0]) * fraction);
        let range = Some([mean - radius, mean + radius]);
        if a.shortcut == ActuatorShortcut::IntVelocity {
            actrange = range;
        } else {
            ctrlrange = range;
        }
    }
    // A range the simulation finds keeps the written one until compile runs it.
    let lengthrange =
        crate::model::lengthrange::resolve(a, &transmission, &n.model.joints, tendons, &spec.lengthrange)
            .unwrap_or(a.lengthrange);
    Ok(Actuator {
        name: a.name.clone(),
        shortcut: a.shortcut,
        transmission,
        gear: a.gear,
        dyntype: a.dyntype,
        gaintype: a.gaintype,
        biastype: a.biastype,
        dynprm: a.dynprm,
        gainprm: a.gainprm,
        biasprm: a.biasprm,
        ctrlrange,
        forcerange: a.forcerange,
        actrange,
        actearly: a.actearly,
        lengthrange,
        acc0: 0.0,
        history: a.history,
        loc: a.loc.clone(),
    })
}

fn pair(p: &ContactPairSpec, n: &Names) -> Result<ContactPair, LoadError> {
    Ok(ContactPair {
        name: p.name.clone(),
        geom1: n.geom(&p.geom1, &p.loc, "pair")?,
        geom2: n.geom(&p.geom2, &p.loc, "pair")?,
        condim: p.condim,
        friction: p.friction,
        solref: p.solref,
        solreffriction: p.solreffriction,
        solimp: p.solimp,
        margin: p.margin,
        gap: p.gap,
        loc: p.loc.clone(),
    })
}
