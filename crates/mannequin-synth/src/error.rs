//! What stops a synthetic subject being made, saying what to fix: settings out of range, a body
//! model or motion that cannot be posed or dressed, or a dataset file that cannot be written.

use std::path::PathBuf;

use mannequin_body::BodyError;
use mannequin_data::DataError;

#[derive(Debug, thiserror::Error)]
pub enum SynthError {
    #[error(transparent)]
    Data(#[from] DataError),
    #[error(transparent)]
    Body(#[from] BodyError),
    #[error("{path}: {reason}")]
    File { path: PathBuf, reason: String },
    #[error("{0}")]
    Invalid(String),
}

impl SynthError {
    pub fn file(path: impl Into<PathBuf>, reason: impl Into<String>) -> Self {
        Self::File { path: path.into(), reason: reason.into() }
    }

    /// An operating-system error while touching `path`.
    pub fn os(path: impl Into<PathBuf>, e: std::io::Error) -> Self {
        Self::File { path: path.into(), reason: e.to_string() }
    }
}
