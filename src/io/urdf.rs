//! URDF loader (placeholder until the loader lands in this session).
use super::{LoadError, LoadOptions};
use crate::model::spec::ModelSpec;
use std::path::Path;

/// Parses URDF text into a spec.
pub fn parse(_text: &str, path: &Path, _options: &LoadOptions) -> Result<ModelSpec, LoadError> {
    Err(LoadError::UnsupportedFormat { file: path.display().to_string() })
}
