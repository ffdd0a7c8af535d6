//! The fuzz targets, one per input format: each writes a mutated file into a copy of the seed tree
//! (so relative mesh and include paths of the seed still resolve), loads it the way a user's file
//! is loaded — load → compile → one `forward` at a random state — and reports what it saw.
//!
//! A target's verdict on one input is [`Outcome`]: refused with a typed error (fine), loaded and
//! finite (fine), or loaded with a non-finite quantity (a finding). Panics are caught by the
//! caller; stack overflows and hangs by the supervisor (see `main.rs`).

use lagrange::forward::forward;
use lagrange::io::{load, LoadOptions};
use lagrange::mass::{convex_hull, mesh_inertia, read_mesh, MeshInertia};
use lagrange::model::JointKind;
use lagrange::{Data, Model};
use rand::rngs::SmallRng;
use rand::Rng;
use std::path::{Path, PathBuf};

/// An input format under test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    Urdf,
    Mjcf,
    Stl,
    Obj,
    Msh,
}

impl Target {
    pub const ALL: [Target; 5] = [Target::Urdf, Target::Mjcf, Target::Stl, Target::Obj, Target::Msh];

    pub fn name(self) -> &'static str {
        match self {
            Target::Urdf => "urdf",
            Target::Mjcf => "mjcf",
            Target::Stl => "stl",
            Target::Obj => "obj",
            Target::Msh => "msh",
        }
    }

    pub fn parse(s: &str) -> Option<Target> {
        Target::ALL.into_iter().find(|t| t.name() == s)
    }

    /// File extensions of this target's seeds.
    fn extensions(self) -> &'static [&'static str] {
        match self {
            Target::Urdf => &["urdf"],
            Target::Mjcf => &["xml"],
            Target::Stl => &["stl"],
            Target::Obj => &["obj"],
            Target::Msh => &["msh"],
        }
    }

    pub fn is_xml(self) -> bool {
        matches!(self, Target::Urdf | Target::Mjcf)
    }
}

/// What one input did.
pub enum Outcome {
    /// Refused with an error (the message's first words, digits dropped, for novelty).
    Refused(String),
    /// Loaded, and every derived number was finite.
    Loaded,
    /// Loaded, but a quantity is not finite: a finding.
    NonFinite(String),
}

/// A seed file: its path relative to the seed tree, and its bytes.
pub struct Seed {
    pub rel: PathBuf,
    pub bytes: Vec<u8>,
}

/// The seeds of `target` under `root`'s `models/` and `tests/data/`.
pub fn seeds(root: &Path, target: Target) -> Vec<Seed> {
    let mut out = Vec::new();
    for top in ["models", "tests/data"] {
        let mut stack = vec![root.join(top)];
        while let Some(dir) = stack.pop() {
            let Ok(entries) = std::fs::read_dir(&dir) else { continue };
            let mut entries: Vec<_> = entries.flatten().map(|e| e.path()).collect();
            entries.sort();
            for p in entries {
                if p.is_dir() {
                    stack.push(p);
                    continue;
                }
                let ext = p.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
                if target.extensions().contains(&ext.as_str()) {
                    if let (Ok(bytes), Ok(rel)) = (std::fs::read(&p), p.strip_prefix(root)) {
                        out.push(Seed { rel: rel.to_path_buf(), bytes });
                    }
                }
            }
        }
    }
    out
}

/// Copies `models/` and `tests/data/` of `root` into `work` (the tree the inputs are written into).
pub fn copy_seed_tree(root: &Path, work: &Path) -> std::io::Result<()> {
    for top in ["models", "tests/data"] {
        let mut stack = vec![PathBuf::from(top)];
        while let Some(rel) = stack.pop() {
            std::fs::create_dir_all(work.join(&rel))?;
            for e in std::fs::read_dir(root.join(&rel))?.flatten() {
                let r = rel.join(e.file_name());
                if e.path().is_dir() {
                    stack.push(r);
                } else {
                    std::fs::copy(e.path(), work.join(&r))?;
                }
            }
        }
    }
    Ok(())
}

/// The MJCF scenes that load a fuzzed mesh, one per `<mesh inertia>` mode, written next to it.
pub fn write_mesh_scenes(dir: &Path, target: Target) -> std::io::Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for mode in ["legacy", "exact", "convex", "shell"] {
        let path = dir.join(format!("__scene_{}_{mode}.xml", target.name()));
        std::fs::write(
            &path,
            format!(
                r#"<mujoco><asset><mesh name="m" file="__fuzz.{}" inertia="{mode}"/></asset>
<worldbody><geom type="plane" size="1 1 .1"/><body pos="0 0 .5"><freejoint/><geom type="mesh" mesh="m"/></body>
<body pos="1 0 .5"><joint type="hinge"/><geom type="mesh" mesh="m" contype="0" conaffinity="0"/></body></worldbody></mujoco>"#,
                target.name()
            ),
        )?;
        out.push(path);
    }
    Ok(out)
}

/// Loads the model file at `path`, then evaluates `forward` at a random state.
pub fn run_model(path: &Path, rng: &mut SmallRng) -> Outcome {
    match load(path, &LoadOptions::default()) {
        Err(e) => Outcome::Refused(signature(&e.to_string())),
        Ok(model) => check_model(&model, rng),
    }
}

/// Reads the mesh at `path`, computes its topology, its mass properties in every mode and its
/// hull, then loads it in a scene (`scene`) and evaluates `forward` there.
pub fn run_mesh(path: &Path, scene: &Path, rng: &mut SmallRng) -> Outcome {
    let mesh = match read_mesh(path, &lagrange::spatial::Vec3::new(1.0, 1.0, 1.0)) {
        Err(e) => return Outcome::Refused(signature(&e.to_string())),
        Ok(m) => m,
    };
    let _ = mesh.topology();
    for mode in [MeshInertia::Legacy, MeshInertia::Exact, MeshInertia::Convex, MeshInertia::Shell] {
        if let Ok((measure, inertia)) = mesh_inertia(&mesh, mode) {
            let numbers = [measure, inertia.mass].into_iter().chain(inertia.h.iter().copied());
            if !numbers.chain(inertia.i_origin.iter().copied()).all(f64::is_finite) {
                return Outcome::NonFinite(format!(
                    "mesh_inertia({mode:?}) returned Ok with a non-finite value"
                ));
            }
        }
    }
    let _ = convex_hull(&mesh.vertices);
    run_model(scene, rng)
}

/// Every number of a loaded model is finite, and so is `forward` at a random state.
fn check_model(model: &Model, rng: &mut SmallRng) -> Outcome {
    for b in &model.bodies {
        let i = &b.inertia;
        let finite = [i.mass].iter().chain(i.h.iter()).chain(i.i_origin.iter()).all(|x| x.is_finite());
        if !finite {
            return Outcome::NonFinite(format!("body '{}': non-finite mass properties", b.name));
        }
        let x = &b.x_parent_joint;
        if !x.pos.iter().chain(x.rot.iter()).all(|v| v.is_finite()) {
            return Outcome::NonFinite(format!("body '{}': non-finite pose", b.name));
        }
    }
    if !model.qpos0.iter().all(|x| x.is_finite()) {
        return Outcome::NonFinite("non-finite qpos0".into());
    }
    let mut q = model.qpos0.clone();
    for j in &model.joints {
        let a = j.qpos_adr;
        match j.kind {
            JointKind::Free | JointKind::Ball => {
                let r = if matches!(j.kind, JointKind::Free) { a + 3..a + 7 } else { a..a + 4 };
                for x in &mut q[r.clone()] {
                    *x = rng.random_range(-1.0..1.0);
                }
                let n = q[r.clone()].iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-3);
                q[r].iter_mut().for_each(|x| *x /= n);
            }
            _ => {
                for x in &mut q[a..a + j.kind.nq()] {
                    *x += rng.random_range(-0.5..0.5);
                }
            }
        }
    }
    // A singular mass matrix is reported at load (a warning naming the joints; MuJoCo refuses
    // such a model) and stops a simulation at its first step. `forward` regularizes it as
    // MuJoCo's mj_factorI does, but the soft solve on pivots of 1e-15 may take its whole
    // iteration budget — seconds on a chain of hundreds of massless links with hundreds of
    // contacts (a fuzzer "hang"): such models are checked at load only.
    let singular =
        model.warnings.iter().any(|w| w.contains("moves nothing") || w.contains("repeats the motion"));
    if singular {
        return Outcome::Loaded;
    }
    let v: Vec<f64> = (0..model.nv).map(|_| rng.random_range(-1.0..1.0)).collect();
    let mut data = Data::new(model);
    data.qpos.copy_from_slice(&q);
    data.qvel.copy_from_slice(&v);
    forward(model, &mut data);
    if !data.qacc.iter().all(|x| x.is_finite()) {
        return Outcome::NonFinite(format!(
            "forward: non-finite qacc at a random state q = {q:?}, v = {v:?}"
        ));
    }
    Outcome::Loaded
}

/// The kind of an error message: its first 48 characters with digits and quoted names dropped.
fn signature(message: &str) -> String {
    let mut s = String::new();
    let mut quoted = false;
    for c in message.chars() {
        if c == '\'' || c == '"' {
            quoted = !quoted;
            continue;
        }
        if !quoted && !c.is_ascii_digit() {
            s.push(c);
        }
        if s.len() >= 48 {
            break;
        }
    }
    // Drop the file:line prefix.
    s.split_once(": ").map(|(_, rest)| rest.to_string()).unwrap_or(s)
}
