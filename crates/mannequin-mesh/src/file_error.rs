//! One error type for every mesh file format, so a user always learns which file failed,
//! where in it, and what was expected there.

use std::path::PathBuf;

use crate::MeshError;

#[derive(Debug, thiserror::Error)]
pub enum MeshFileError {
    #[error("{path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    /// `at` locates the problem in the file's own terms: "line 12", "element vertex 3, property x".
    #[error("{path}: {at}: {expected}")]
    Format { path: PathBuf, at: String, expected: String },
    #[error("{path}: {source}")]
    Invalid { path: PathBuf, source: MeshError },
}

impl MeshFileError {
    pub(crate) fn io(path: &std::path::Path, source: std::io::Error) -> Self {
        Self::Io { path: path.to_path_buf(), source }
    }

    pub(crate) fn format(path: &std::path::Path, at: impl Into<String>, expected: impl Into<String>) -> Self {
        Self::Format { path: path.to_path_buf(), at: at.into(), expected: expected.into() }
    }

    pub(crate) fn invalid(path: &std::path::Path, source: MeshError) -> Self {
        Self::Invalid { path: path.to_path_buf(), source }
    }
}
