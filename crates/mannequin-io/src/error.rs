//! Errors that name the file and the field, so a user knows what to fix.

use std::path::PathBuf;

/// A problem inside one array's bytes, before the file name is known.
#[derive(Debug, thiserror::Error)]
pub enum NpyError {
    #[error("{0}")]
    Format(String),
}

/// A problem inside a pickle's bytes, before the file name is known.
#[derive(Debug, thiserror::Error)]
#[error("at byte {offset}: {reason}")]
pub struct PickleError {
    pub offset: usize,
    pub reason: String,
}

/// A problem with a file on disk, naming the file and (where known) the array key.
#[derive(Debug, thiserror::Error)]
pub enum IoError {
    #[error("{path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("{path}: not a readable .npz archive: {reason}")]
    Archive { path: PathBuf, reason: String },
    #[error("{path}: {reason}")]
    Pickle { path: PathBuf, reason: String },
    #[error("{path}: missing key '{key}' (present: {present})")]
    MissingKey { path: PathBuf, key: String, present: String },
    #[error("{path}: field '{key}': {reason}")]
    Field { path: PathBuf, key: String, reason: String },
    /// A checkpoint that cannot resume this run (another run's, or one without a record).
    #[error("{path}: {reason}")]
    Checkpoint { path: PathBuf, reason: String },
}
