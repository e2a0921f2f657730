//! Errors that name the file and say what was expected, so a user can fix their dataset.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum DataError {
    #[error(transparent)]
    Io(#[from] mannequin_io::IoError),
    #[error(transparent)]
    Mesh(#[from] mannequin_mesh::MeshFileError),
    #[error(transparent)]
    Staging(#[from] mannequin_io::staging::StagingError),
    #[error("{path}: {reason}")]
    File { path: PathBuf, reason: String },
    #[error("{0}")]
    Invalid(String),
}

impl DataError {
    pub fn file(path: impl Into<PathBuf>, reason: impl Into<String>) -> Self {
        Self::File { path: path.into(), reason: reason.into() }
    }

    /// An operating-system error while touching `path`.
    pub fn os(path: impl Into<PathBuf>, e: std::io::Error) -> Self {
        Self::File { path: path.into(), reason: e.to_string() }
    }
}
