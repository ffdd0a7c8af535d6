//! `lagrange.Model`: a compiled model (MuJoCo's `mjModel`), loaded from a URDF or MJCF file or
//! text with the load options as keyword arguments; sizes, names, keyframes, options and
//! `name2id`. A model pickles as its source (an absolute file path, or the text) and load
//! options, which is how a distributed rollout ships it once to each worker.

use crate::error;
use lagrange::constraint::ConstraintMode;
use lagrange::io::LoadOptions;
use lagrange::model::FrameKind;
use lagrange::Model;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use std::path::PathBuf;
use std::sync::Arc;

/// Where a model came from, enough to load it again elsewhere.
#[derive(Clone, Debug)]
pub enum Source {
    /// A file, by absolute path.
    File(PathBuf),
    /// Text, with the path that anchors its relative includes and meshes.
    Text(String, PathBuf),
}

/// The load options as given (LoadOptions has no Clone of its own fields to Python).
#[derive(Clone, Debug, Default)]
pub struct Options {
    package_dirs: Vec<String>,
    floating: bool,
    accept_nonphysical_inertia: bool,
    disable: Vec<String>,
    clamp_effort: bool,
    constraints: Option<String>,
    max_contacts: Option<usize>,
}

impl Options {
    fn to_load_options(&self) -> LoadOptions {
        LoadOptions {
            package_dirs: self.package_dirs.iter().map(PathBuf::from).collect(),
            floating: self.floating,
            accept_nonphysical_inertia: self.accept_nonphysical_inertia,
            disabled_flags: self.disable.clone(),
            clamp_effort: self.clamp_effort,
            max_contacts: self.max_contacts,
        }
    }
}

/// A compiled model: sizes, names, keyframes and options (MuJoCo's mjModel).
///
/// Load with `Model.from_file(path, **options)` or `Model.from_string(xml, **options)`; the
/// options are `package_dirs` (folders for `package://` URIs), `floating` (a URDF root on a free
/// joint), `accept_nonphysical_inertia`, `disable` (MJCF `<flag>` names to turn off),
/// `clamp_effort`, `constraints` ('soft' or 'exact') and `max_contacts` (the most contacts one
/// collision pass keeps, instead of the default budget; the CLI's `--max-contacts`).
#[pyclass(name = "Model", module = "lagrange", frozen)]
pub struct PyModel {
    /// The model, shared with rollouts' worker threads.
    pub inner: Arc<Model>,
    source: Source,
    options: Options,
}

/// Builds [`Options`] from the keyword arguments.
fn options_of(
    package_dirs: Option<Vec<String>>,
    floating: bool,
    accept_nonphysical_inertia: bool,
    disable: Option<Vec<String>>,
    clamp_effort: bool,
    constraints: Option<String>,
    max_contacts: Option<usize>,
) -> Options {
    Options {
        package_dirs: package_dirs.unwrap_or_default(),
        floating,
        accept_nonphysical_inertia,
        disable: disable.unwrap_or_default(),
        clamp_effort,
        constraints,
        max_contacts,
    }
}

/// The constraint mode named `name` ('exact' or 'soft').
fn constraint_mode(name: &str) -> PyResult<ConstraintMode> {
    match name {
        "exact" => Ok(ConstraintMode::Exact),
        "soft" => Ok(ConstraintMode::Soft),
        other => Err(error::bad(format!("constraints: '{other}' is neither 'exact' nor 'soft'"))),
    }
}

impl PyModel {
    /// Loads `source` with `options` (the GIL released: meshes can take a while).
    fn load(py: Python<'_>, source: Source, options: Options) -> PyResult<Self> {
        let load_options = options.to_load_options();
        let mode = options.constraints.as_deref().map(constraint_mode).transpose()?;
        let mut model = py
            .detach(|| match &source {
                Source::File(path) => {
                    let text = std::fs::read_to_string(path).map_err(|e| lagrange::io::LoadError::Io {
                        file: path.display().to_string(),
                        source: e,
                    })?;
                    lagrange::io::load_str(&text, path, &load_options)
                }
                Source::Text(text, path) => lagrange::io::load_str(text, path, &load_options),
            })
            .map_err(error::load)?;
        if let Some(mode) = mode {
            model.set_constraint_mode(mode);
        }
        Ok(PyModel { inner: Arc::new(model), source, options })
    }

    /// MuJoCo's body ids: the link frames in order.
    fn body_frames(&self) -> impl Iterator<Item = &lagrange::model::Frame> {
        self.inner.frames.iter().filter(|f| f.kind == FrameKind::Link)
    }

    /// MuJoCo's site ids: the site frames in order.
    fn site_frames(&self) -> impl Iterator<Item = &lagrange::model::Frame> {
        self.inner.frames.iter().filter(|f| f.kind == FrameKind::Site)
    }
}

#[pymethods]
impl PyModel {
    /// Loads a URDF or MJCF file (told apart by the root element); relative includes and meshes
    /// are found beside the file. Raises `lagrange.LoadError` with file:line on a bad file.
    #[staticmethod]
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (path, *, package_dirs=None, floating=false, accept_nonphysical_inertia=false, disable=None, clamp_effort=false, constraints=None, max_contacts=None))]
    fn from_file(
        py: Python<'_>,
        path: PathBuf,
        package_dirs: Option<Vec<String>>,
        floating: bool,
        accept_nonphysical_inertia: bool,
        disable: Option<Vec<String>>,
        clamp_effort: bool,
        constraints: Option<String>,
        max_contacts: Option<usize>,
    ) -> PyResult<Self> {
        let path = std::path::absolute(&path).unwrap_or(path);
        let options = options_of(
            package_dirs,
            floating,
            accept_nonphysical_inertia,
            disable,
            clamp_effort,
            constraints,
            max_contacts,
        );
        Self::load(py, Source::File(path), options)
    }

    /// Loads a URDF or MJCF model from text; `base` (default: the current directory) anchors
    /// relative includes and meshes.
    #[staticmethod]
    #[pyo3(signature = (xml, *, base=None, package_dirs=None, floating=false, accept_nonphysical_inertia=false, disable=None, clamp_effort=false, constraints=None, max_contacts=None))]
    #[allow(clippy::too_many_arguments)]
    fn from_string(
        py: Python<'_>,
        xml: String,
        base: Option<PathBuf>,
        package_dirs: Option<Vec<String>>,
        floating: bool,
        accept_nonphysical_inertia: bool,
        disable: Option<Vec<String>>,
        clamp_effort: bool,
        constraints: Option<String>,
        max_contacts: Option<usize>,
    ) -> PyResult<Self> {
        let dir = base.unwrap_or_else(|| PathBuf::from("."));
        let dir = std::path::absolute(&dir).unwrap_or(dir);
        let name = if xml.contains("<robot") { "<string>.urdf" } else { "<string>.xml" };
        let options = options_of(
            package_dirs,
            floating,
            accept_nonphysical_inertia,
            disable,
            clamp_effort,
            constraints,
            max_contacts,
        );
        Self::load(py, Source::Text(xml, dir.join(name)), options)
    }

    /// Loads a pickled model again (its source and options); used by `pickle`.
    #[staticmethod]
    fn _restore(
        py: Python<'_>,
        kind: &str,
        text: String,
        path: PathBuf,
        opts: &Bound<'_, PyDict>,
    ) -> PyResult<Self> {
        let get = |key: &str| opts.get_item(key);
        let options = Options {
            package_dirs: get("package_dirs")?.map(|v| v.extract()).transpose()?.unwrap_or_default(),
            floating: get("floating")?.map(|v| v.extract()).transpose()?.unwrap_or(false),
            accept_nonphysical_inertia: get("accept_nonphysical_inertia")?
                .map(|v| v.extract())
                .transpose()?
                .unwrap_or(false),
            disable: get("disable")?.map(|v| v.extract()).transpose()?.unwrap_or_default(),
            clamp_effort: get("clamp_effort")?.map(|v| v.extract()).transpose()?.unwrap_or(false),
            constraints: get("constraints")?.map(|v| v.extract()).transpose()?.flatten(),
            max_contacts: get("max_contacts")?.map(|v| v.extract()).transpose()?.flatten(),
        };
        let source = if kind == "file" { Source::File(path) } else { Source::Text(text, path) };
        Self::load(py, source, options)
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let this = slf.get();
        let opts = PyDict::new(py);
        opts.set_item("package_dirs", this.options.package_dirs.clone())?;
        opts.set_item("floating", this.options.floating)?;
        opts.set_item("accept_nonphysical_inertia", this.options.accept_nonphysical_inertia)?;
        opts.set_item("disable", this.options.disable.clone())?;
        opts.set_item("clamp_effort", this.options.clamp_effort)?;
        opts.set_item("constraints", this.options.constraints.clone())?;
        opts.set_item("max_contacts", this.options.max_contacts)?;
        let (kind, text, path) = match &this.source {
            Source::File(path) => ("file", String::new(), path.clone()),
            Source::Text(text, path) => ("text", text.clone(), path.clone()),
        };
        let restore = slf.get_type().getattr("_restore")?;
        let args = (kind, text, path, opts).into_pyobject(py)?;
        PyTuple::new(py, [restore, args.into_any()])
    }

    /// The file the model was loaded from (None for a model from text).
    #[getter]
    fn path(&self) -> Option<PathBuf> {
        match &self.source {
            Source::File(path) => Some(path.clone()),
            Source::Text(..) => None,
        }
    }

    /// The constraint model `forward` solves: 'soft' (MuJoCo's, the default for MJCF) or
    /// 'exact' (rigid, the default for URDF); the `constraints=` load option chooses.
    #[getter]
    fn constraints(&self) -> &'static str {
        self.inner.plan.mode().name()
    }

    /// The model's name.
    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
    }
    /// Number of generalized coordinates (qpos).
    #[getter]
    fn nq(&self) -> usize {
        self.inner.nq
    }
    /// Number of degrees of freedom (qvel, qacc).
    #[getter]
    fn nv(&self) -> usize {
        self.inner.nv
    }
    /// Number of actuators (ctrl).
    #[getter]
    fn nu(&self) -> usize {
        self.inner.actuators.len()
    }
    /// Number of activation states (act).
    #[getter]
    fn na(&self) -> usize {
        self.inner.na()
    }
    /// Length of `Data.history` (MuJoCo's `nhistory`): the delayed actuators' control buffers.
    #[getter]
    fn nhistory(&self) -> usize {
        self.inner.nhistory()
    }
    /// Number of bodies in MuJoCo's numbering (for MJCF the world is body 0).
    #[getter]
    fn nbody(&self) -> usize {
        self.inner.links.len()
    }
    /// Number of joints.
    #[getter]
    fn njnt(&self) -> usize {
        self.inner.joints.len()
    }
    /// Number of geoms.
    #[getter]
    fn ngeom(&self) -> usize {
        self.inner.geoms.len()
    }
    /// Number of sites.
    #[getter]
    fn nsite(&self) -> usize {
        self.site_frames().count()
    }
    /// Number of mocap bodies.
    #[getter]
    fn nmocap(&self) -> usize {
        self.inner.mocap_pose0.len()
    }
    /// Number of sensors.
    #[getter]
    fn nsensor(&self) -> usize {
        self.inner.sensors.len()
    }
    /// Length of `Data.sensordata`.
    #[getter]
    fn nsensordata(&self) -> usize {
        self.inner.nsensordata
    }
    /// Number of keyframes.
    #[getter]
    fn nkey(&self) -> usize {
        self.inner.keyframes.len()
    }
    /// Total mass of the moving bodies (kg).
    #[getter]
    fn total_mass(&self) -> f64 {
        self.inner.total_mass()
    }
    /// The reference configuration (MuJoCo's qpos0).
    #[getter]
    fn qpos0(&self) -> Vec<f64> {
        self.inner.qpos0.clone()
    }
    /// Body names in MuJoCo's body order (the ids of `name2id("body", …)`, `Data.xpos`).
    #[getter]
    fn body_names(&self) -> Vec<String> {
        self.body_frames().map(|f| f.name.clone()).collect()
    }
    /// Joint names.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.inner.joints.iter().map(|j| j.name.clone()).collect()
    }
    /// Geom names ('' for unnamed geoms).
    #[getter]
    fn geom_names(&self) -> Vec<String> {
        self.inner.geoms.iter().map(|g| g.name.clone()).collect()
    }
    /// Site names.
    #[getter]
    fn site_names(&self) -> Vec<String> {
        self.site_frames().map(|f| f.name.clone()).collect()
    }
    /// Actuator names.
    #[getter]
    fn actuator_names(&self) -> Vec<String> {
        self.inner.actuators.iter().map(|a| a.name.clone()).collect()
    }
    /// Sensor names.
    #[getter]
    fn sensor_names(&self) -> Vec<String> {
        self.inner.sensors.iter().map(|s| s.name.clone()).collect()
    }
    /// Keyframe names.
    #[getter]
    fn key_names(&self) -> Vec<String> {
        self.inner.keyframes.iter().map(|k| k.name.clone()).collect()
    }
    /// Per sensor: (address in sensordata, dimension).
    #[getter]
    fn sensor_adr(&self) -> Vec<(usize, usize)> {
        self.inner.sensors.iter().map(|s| (s.adr, s.dim)).collect()
    }
    /// Per joint: (qpos address, dof address).
    #[getter]
    fn jnt_adr(&self) -> Vec<(usize, usize)> {
        self.inner.joints.iter().map(|j| (j.qpos_adr, j.dof_adr)).collect()
    }

    /// Keyframe `name` as a dict of what it sets: time, qpos, qvel, ctrl, act, mpos, mquat.
    fn keyframe<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyDict>> {
        let k = self
            .inner
            .keyframe_id(name)
            .ok_or_else(|| error::bad(format!("keyframe: the model has no keyframe named '{name}'")))?;
        let key = &self.inner.keyframes[k];
        let out = PyDict::new(py);
        out.set_item("name", &key.name)?;
        out.set_item("time", key.time)?;
        for (field, value) in [
            ("qpos", &key.qpos),
            ("qvel", &key.qvel),
            ("ctrl", &key.ctrl),
            ("act", &key.act),
            ("mpos", &key.mpos),
            ("mquat", &key.mquat),
        ] {
            if let Some(v) = value {
                out.set_item(field, numpy::PyArray1::from_slice(py, v))?;
            }
        }
        Ok(out)
    }

    /// The id of the element `name` of kind `kind` ('body', 'joint', 'geom', 'site', 'actuator',
    /// 'sensor', 'key', 'tendon', 'equality'), as MuJoCo's `mj_name2id`; -1 when there is none.
    fn name2id(&self, kind: &str, name: &str) -> PyResult<i64> {
        let m = &self.inner;
        let position = |mut it: Box<dyn Iterator<Item = &str> + '_>| it.position(|n| n == name);
        let found = match kind {
            "body" | "link" => position(Box::new(self.body_frames().map(|f| f.name.as_str()))),
            "joint" | "jnt" => position(Box::new(m.joints.iter().map(|j| j.name.as_str()))),
            "geom" => position(Box::new(m.geoms.iter().map(|g| g.name.as_str()))),
            "site" => position(Box::new(self.site_frames().map(|f| f.name.as_str()))),
            "actuator" => position(Box::new(m.actuators.iter().map(|a| a.name.as_str()))),
            "sensor" => position(Box::new(m.sensors.iter().map(|s| s.name.as_str()))),
            "key" | "keyframe" => position(Box::new(m.keyframes.iter().map(|k| k.name.as_str()))),
            "tendon" => position(Box::new(m.tendons.iter().map(|t| t.name.as_str()))),
            "equality" => position(Box::new(m.equalities.iter().map(|e| e.name.as_str()))),
            _ => {
                return Err(error::bad(format!(
                    "name2id: unknown kind '{kind}' (body, joint, geom, site, actuator, sensor, key, tendon, equality)"
                )))
            }
        };
        Ok(found.map_or(-1, |i| i as i64))
    }

    /// The simulation options (MuJoCo's `opt`): timestep, integrator, cone, solver, iterations,
    /// tolerance, impratio, gravity.
    #[getter]
    fn opt(&self) -> PyOptions {
        let o = &self.inner.options;
        let g = self.inner.gravity;
        PyOptions {
            timestep: o.timestep,
            integrator: format!("{:?}", o.integrator).to_lowercase(),
            cone: format!("{:?}", o.cone).to_lowercase(),
            solver: format!("{:?}", o.solver).to_lowercase(),
            iterations: o.iterations,
            tolerance: o.tolerance,
            impratio: o.impratio,
            gravity: [g.x, g.y, g.z],
        }
    }

    fn __repr__(&self) -> String {
        let m = &self.inner;
        format!(
            "lagrange.Model('{}', nq={}, nv={}, nu={}, na={}, nbody={})",
            m.name,
            m.nq,
            m.nv,
            m.actuators.len(),
            m.na(),
            m.links.len()
        )
    }
}

/// A model's simulation options (read-only; MuJoCo's `mjOption`).
#[pyclass(name = "Options", module = "lagrange", frozen, get_all)]
pub struct PyOptions {
    /// Step size (s).
    pub timestep: f64,
    /// Integrator name (euler, rk4, implicit, implicitfast, …).
    pub integrator: String,
    /// Friction cone (elliptic, pyramidal).
    pub cone: String,
    /// Soft-mode solver (newton, cg, pgs).
    pub solver: String,
    /// Solver iteration limit.
    pub iterations: u32,
    /// Solver tolerance.
    pub tolerance: f64,
    /// Ratio of frictional to normal impedance.
    pub impratio: f64,
    /// Gravity (m/s²), world frame.
    pub gravity: [f64; 3],
}

#[pymethods]
impl PyOptions {
    fn __repr__(&self) -> String {
        format!(
            "lagrange.Options(timestep={}, integrator='{}', cone='{}', solver='{}', iterations={}, tolerance={}, gravity={:?})",
            self.timestep, self.integrator, self.cone, self.solver, self.iterations, self.tolerance, self.gravity
        )
    }
}
