//! Body-model errors: each names the file (or input) and the field, and says what was expected.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum BodyError {
    #[error(transparent)]
    Io(#[from] mannequin_io::IoError),
    #[error("{path}: field '{field}': {reason}")]
    Field { path: PathBuf, field: String, reason: String },
    #[error("{what}: {reason}")]
    Input { what: String, reason: String },
}

impl BodyError {
    pub fn field(path: impl Into<PathBuf>, field: &str, reason: impl Into<String>) -> Self {
        Self::Field { path: path.into(), field: field.to_string(), reason: reason.into() }
    }

    pub fn input(what: impl Into<String>, reason: impl Into<String>) -> Self {
        Self::Input { what: what.into(), reason: reason.into() }
    }
}
