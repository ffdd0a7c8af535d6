//! Loaders: model files → [`ModelSpec`] → (compile) → [`Model`] (docs/architecture.md, "Layers").
//! Loaders never touch dynamics code.

pub mod compile;
mod compile_elements;
mod compile_sensors;
mod error;
mod geom_hull;
pub mod geom_mass;
mod lines;
pub mod mjcf;
pub mod package;
pub mod plausibility;
pub mod sameframe;
mod singular;
pub mod urdf;

pub use error::{LinkWord, LoadError};

use crate::model::spec::ModelSpec;
use crate::Model;
pub use compile::compile;
use std::path::{Path, PathBuf};

/// Options shared by all loaders (the CLI's `--package-dir` and `--floating`).
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// Folders searched for `package://NAME/...` (each holds `NAME/`, or is itself `NAME`),
    /// before the folders of `ROS_PACKAGE_PATH`.
    pub package_dirs: Vec<PathBuf>,
    /// Attach the URDF root link to the world with a free joint named `root_joint` (like
    /// Pinocchio's free-flyer) instead of welding it.
    pub floating: bool,
    /// Use inertia tensors that violate the triangle inequality or have slightly negative
    /// principal moments as written (as Pinocchio does), with a warning each, instead of
    /// rejecting the model (CLI `--accept-nonphysical-inertia`).
    pub accept_nonphysical_inertia: bool,
    /// `<option><flag>` switches to turn off, by MJCF name (`limit`, `equality`, `constraint`,
    /// `spring`, `damper`, `gravity`, …), for both formats (CLI `--disable FLAG`).
    pub disabled_flags: Vec<String>,
    /// Clamp the joint torques applied to each URDF joint (actuator plus applied forces) to its
    /// `<limit effort>` (CLI `--clamp-effort`). MJCF models say it with `actuatorfrcrange`.
    pub clamp_effort: bool,
    /// The most contacts one collision pass keeps ([`Options::max_contacts`](crate::model::Options::max_contacts);
    /// CLI `--max-contacts N`): None keeps the model's default budget.
    pub max_contacts: Option<usize>,
}

/// Loads a model file, choosing the loader by extension (`.urdf`, or `.xml` for MJCF).
pub fn load(path: &Path, options: &LoadOptions) -> Result<Model, LoadError> {
    let mut spec = load_spec(path, options)?;
    disable_flags(&mut spec, &options.disabled_flags)?;
    spec.options.max_contacts = options.max_contacts.or(spec.options.max_contacts);
    compile(&spec)
}

/// Turns off the named `<option><flag>` switches in a parsed spec (before compile, which reads
/// `spring` and `damper`; `gravity` zeroes the gravity vector, as the MJCF loader does).
fn disable_flags(spec: &mut ModelSpec, names: &[String]) -> Result<(), LoadError> {
    for name in names {
        match spec.options.flags.get_mut(name) {
            Some(flag) => *flag = false,
            None => {
                return Err(LoadError::Invalid {
                    loc: crate::model::SourceLoc {
                        file: spec.source.as_ref().map(|p| p.display().to_string()).unwrap_or_default(),
                        line: 0,
                    },
                    element: "option".into(),
                    detail: format!(
                        "LoadOptions::disabled_flags += {name}: not a MuJoCo <flag>; use one of constraint, equality, limit, frictionloss, contact, spring, damper, gravity, actuation, …"
                    ),
                });
            }
        }
    }
    if !spec.options.flags.gravity {
        spec.gravity = crate::spatial::Vec3::zeros();
    }
    Ok(())
}

/// Parses a model file into a spec without compiling it.
pub fn load_spec(path: &Path, options: &LoadOptions) -> Result<ModelSpec, LoadError> {
    let file = path.display().to_string();
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    let text =
        std::fs::read_to_string(path).map_err(|source| LoadError::Io { file: file.clone(), source })?;
    match ext.as_str() {
        "urdf" => urdf::parse(&text, path, options),
        "xml" | "mjcf" => mjcf::parse_str(&text, path, options),
        _ => Err(LoadError::UnsupportedFormat { file }),
    }
}

/// Parses URDF text (e.g. an embedded model); `path` names it in messages and anchors relative
/// mesh paths.
pub fn load_urdf_str(text: &str, path: &Path, options: &LoadOptions) -> Result<Model, LoadError> {
    compile(&urdf::parse(text, path, options)?)
}

/// Loads a URDF or MJCF model from text with `options`, telling the format by its root element
/// (`<robot>` or `<mujoco>`); `path` names it in messages and anchors relative mesh and include
/// paths (the Python bindings' `Model.from_string` with load options, and the model a
/// distributed rollout ships to its workers).
///
/// # Errors
/// [`LoadError`] naming the line, element and what is wrong;
/// [`LoadError::UnsupportedFormat`] when the root element is neither.
///
/// # Example
/// ```
/// use lagrange::io::{load_str, LoadOptions};
/// let options = LoadOptions { disabled_flags: vec!["gravity".into()], ..Default::default() };
/// let xml = "<mujoco><worldbody><body><freejoint/><geom size='0.1'/></body></worldbody></mujoco>";
/// let model = load_str(xml, std::path::Path::new("ball.xml"), &options)?;
/// assert_eq!((model.nv, model.gravity.z), (6, 0.0));
/// assert!(load_str("<html/>", std::path::Path::new("page.xml"), &options).is_err());
/// # Ok::<(), lagrange::io::LoadError>(())
/// ```
pub fn load_str(text: &str, path: &Path, options: &LoadOptions) -> Result<Model, LoadError> {
    let mut spec = match format_of(text) {
        Some("urdf") => urdf::parse(text, path, options)?,
        Some(_) => mjcf::parse_str(text, path, options)?,
        None => return Err(LoadError::UnsupportedFormat { file: path.display().to_string() }),
    };
    disable_flags(&mut spec, &options.disabled_flags)?;
    spec.options.max_contacts = options.max_contacts.or(spec.options.max_contacts);
    compile(&spec)
}

/// The format of a model text, from its root element: `<robot>` is URDF, `<mujoco>` MJCF.
fn format_of(text: &str) -> Option<&'static str> {
    let mut rest = text;
    loop {
        let start = rest.find('<')?;
        rest = &rest[start + 1..];
        if rest.starts_with('?') || rest.starts_with('!') {
            // An XML declaration, comment or doctype: skip to its end.
            let end = if rest.starts_with("!--") { rest.find("-->")? + 3 } else { rest.find('>')? + 1 };
            rest = &rest[end..];
            continue;
        }
        let name: String =
            rest.chars().take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':').collect();
        return match name.as_str() {
            "robot" => Some("urdf"),
            "mujoco" => Some("xml"),
            _ => None,
        };
    }
}

impl Model {
    /// Loads a URDF or MJCF file, telling the format by its root element (`<robot>` or
    /// `<mujoco>`), with the default [`LoadOptions`] (use [`load`] for others). Meshes and
    /// includes are found relative to the file.
    ///
    /// # Errors
    /// [`LoadError`] naming the file, line, element and what is wrong.
    ///
    /// # Example
    /// ```
    /// let model = lagrange::Model::from_file("models/ur5/ur5.urdf")?;
    /// assert_eq!(model.nv, 6);
    /// # Ok::<(), lagrange::io::LoadError>(())
    /// ```
    pub fn from_file(path: impl AsRef<Path>) -> Result<Model, LoadError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path)
            .map_err(|source| LoadError::Io { file: path.display().to_string(), source })?;
        let options = LoadOptions::default();
        let spec = match format_of(&text) {
            Some("urdf") => urdf::parse(&text, path, &options)?,
            Some(_) => mjcf::parse_str(&text, path, &options)?,
            None => return Err(LoadError::UnsupportedFormat { file: path.display().to_string() }),
        };
        compile(&spec)
    }

    /// Loads a URDF or MJCF model from text, telling the format by its root element. Relative
    /// mesh and include paths are taken from the current directory.
    ///
    /// # Errors
    /// [`LoadError`] naming the line, element and what is wrong.
    ///
    /// # Example
    /// ```
    /// let model = lagrange::Model::from_str(
    ///     r#"<robot name="r"><link name="a"><inertial><mass value="1"/>
    ///        <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link></robot>"#,
    /// )?;
    /// assert_eq!(model.nv, 0);
    /// # Ok::<(), lagrange::io::LoadError>(())
    /// ```
    #[allow(clippy::should_implement_trait)]
    pub fn from_str(text: &str) -> Result<Model, LoadError> {
        let options = LoadOptions::default();
        match format_of(text) {
            Some("urdf") => compile(&urdf::parse(text, Path::new("<string>.urdf"), &options)?),
            Some(_) => compile(&mjcf::parse_str(text, Path::new("<string>.xml"), &options)?),
            None => Err(LoadError::UnsupportedFormat { file: "<string>".into() }),
        }
    }
}
