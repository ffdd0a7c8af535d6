//! Resolution of file references in model files (`package://`, `file://`, relative and absolute
//! paths) to paths on disk, shared by the URDF and MJCF loaders.

use std::path::{Path, PathBuf};

/// Why a file reference could not be turned into a path.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ResolveError {
    /// `package://NAME/...` where no searched folder holds the package `NAME`.
    PackageNotFound {
        /// The package name.
        package: String,
        /// The folders searched, in order (the caller's folders, then `ROS_PACKAGE_PATH`).
        searched: Vec<String>,
    },
    /// A malformed reference (empty package name, unsupported URI scheme, ...); the string says
    /// what is wrong and how to fix it.
    BadUri(String),
}

/// The folders searched for `package://` references: `package_dirs` in order, then each folder of
/// the `ROS_PACKAGE_PATH` environment variable (read at every call; colon-separated on Unix).
pub fn package_search_dirs(package_dirs: &[PathBuf]) -> Vec<PathBuf> {
    let mut dirs: Vec<PathBuf> = package_dirs.to_vec();
    if let Some(ros) = std::env::var_os("ROS_PACKAGE_PATH") {
        dirs.extend(std::env::split_paths(&ros).filter(|d| !d.as_os_str().is_empty()));
    }
    dirs
}

/// Resolves a file reference from a model file to a path on disk.
///
/// - `package://NAME/rest`: each folder `D` of `search_dirs` (see [`package_search_dirs`]) is
///   tried in order; `D` resolves if `D/NAME/rest` exists, or if `D`'s own last component is
///   `NAME` and `D/rest` exists. If no folder holds the file but one holds the package (`D/NAME`
///   is a folder, or `D` is named `NAME`), the path inside the first such package is returned, so
///   the caller reports a missing file rather than a missing package. Otherwise
///   [`ResolveError::PackageNotFound`].
/// - `file:///abs/path` → `/abs/path`; `file://rel` → `rel` relative to `base_dir`.
/// - an absolute path is returned as is; a relative path is taken relative to `base_dir` (the
///   folder of the model file).
///
/// The returned path is not checked for existence except where the search needs it.
pub fn resolve_uri(uri: &str, base_dir: &Path, search_dirs: &[PathBuf]) -> Result<PathBuf, ResolveError> {
    if let Some(rest) = uri.strip_prefix("package://") {
        // `package:///NAME/path` (an empty host, as some files write) means `package://NAME/path`.
        let rest = rest.strip_prefix('/').unwrap_or(rest);
        let (package, rel) = rest.split_once('/').unwrap_or((rest, ""));
        if package.is_empty() {
            return Err(ResolveError::BadUri(format!(
                "'{uri}' has no package name; write package://PACKAGE/path/to/file"
            )));
        }
        let rel = rel.trim_start_matches('/');
        let named_package = |d: &Path| d.file_name().is_some_and(|n| n == package);
        for d in search_dirs {
            let candidate = d.join(package).join(rel);
            if candidate.exists() {
                return Ok(candidate);
            }
            if named_package(d) {
                let candidate = d.join(rel);
                if candidate.exists() {
                    return Ok(candidate);
                }
            }
        }
        // The package exists but not the file: return the path the file would have.
        for d in search_dirs {
            if d.join(package).is_dir() {
                return Ok(d.join(package).join(rel));
            }
            if named_package(d) && d.is_dir() {
                return Ok(d.join(rel));
            }
        }
        return Err(ResolveError::PackageNotFound {
            package: package.to_string(),
            searched: search_dirs.iter().map(|d| d.display().to_string()).collect(),
        });
    }
    if let Some(rest) = uri.strip_prefix("file://") {
        // `file:///abs` leaves `/abs`; `file://localhost/abs` names the local host.
        let rest = rest.strip_prefix("localhost").filter(|r| r.starts_with('/')).unwrap_or(rest);
        if rest.is_empty() {
            return Err(ResolveError::BadUri(format!("'{uri}' names no file; write file:///absolute/path")));
        }
        return Ok(base_dir.join(rest));
    }
    if let Some((scheme, _)) = uri.split_once("://") {
        if !scheme.is_empty() && scheme.chars().all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c)) {
            return Err(ResolveError::BadUri(format!(
                "'{uri}' uses the unsupported scheme '{scheme}://'; use package://, file:// or a path \
                 relative to the model file"
            )));
        }
    }
    if uri.is_empty() {
        return Err(ResolveError::BadUri("the filename is empty; give the path of the mesh file".into()));
    }
    Ok(base_dir.join(uri))
}

/// The folder that relative references in the model file at `path` are resolved against.
pub fn base_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn file_and_relative_references() {
        let base = Path::new("/models/robot");
        assert_eq!(resolve_uri("file:///a/b.stl", base, &[]), Ok(PathBuf::from("/a/b.stl")));
        assert_eq!(resolve_uri("meshes/b.stl", base, &[]), Ok(PathBuf::from("/models/robot/meshes/b.stl")));
        assert_eq!(resolve_uri("/abs/b.stl", base, &[]), Ok(PathBuf::from("/abs/b.stl")));
        assert!(matches!(resolve_uri("http://x/y.stl", base, &[]), Err(ResolveError::BadUri(_))));
        assert!(matches!(resolve_uri("package:///", base, &[]), Err(ResolveError::BadUri(_))));
        // `package:///NAME/...` (empty host) reads as `package://NAME/...`.
        assert!(matches!(
            resolve_uri("package:///nope_pkg_xyz/y.stl", base, &[]),
            Err(ResolveError::PackageNotFound { package, .. }) if package == "nope_pkg_xyz"
        ));
        match resolve_uri("package://nope_pkg_xyz/y.stl", base, &[PathBuf::from("/nonexistent")]) {
            Err(ResolveError::PackageNotFound { package, searched }) => {
                assert_eq!(package, "nope_pkg_xyz");
                assert_eq!(searched, vec!["/nonexistent".to_string()]);
            }
            other => panic!("{other:?}"),
        }
    }
}
