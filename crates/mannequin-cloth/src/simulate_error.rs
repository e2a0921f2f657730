//! Errors of a simulating run (`cloth simulate`, and the dressing built on it): its inputs, its
//! limits, its checkpoint and its outputs, one line each with the file or field at fault.

use mannequin_body::BodyError;
use mannequin_io::IoError;
use mannequin_mesh::MeshFileError;

use crate::error::ClothError;
use mannequin_io::run_record::START_OVER;

#[derive(Debug, thiserror::Error)]
pub enum SimulateError {
    #[error("{field}: {reason}")]
    Invalid { field: String, reason: String },
    #[error("reading {path}: {reason}")]
    Read { path: String, reason: String },
    #[error("writing {path}: {reason}")]
    Write { path: String, reason: String },
    /// `inner` said of `context` (a file, a frame): one line, as `anyhow`'s context reads.
    #[error("{context}: {inner}")]
    In { context: String, inner: Box<SimulateError> },
    /// A checkpoint of another run, or one that is not what this run saves.
    #[error("{0}; {START_OVER}")]
    Refused(IoError),
    /// The run stopped at `error`; the frames before it were written.
    #[error("{error}; kept the {frames} frames before it in {out}")]
    Kept { error: Box<SimulateError>, frames: usize, out: String },
    #[error(transparent)]
    Cloth(#[from] ClothError),
    #[error(transparent)]
    Body(#[from] BodyError),
    #[error(transparent)]
    MeshFile(#[from] MeshFileError),
    #[error(transparent)]
    Io(#[from] IoError),
}

impl SimulateError {
    pub fn invalid(field: impl Into<String>, reason: impl Into<String>) -> Self {
        Self::Invalid { field: field.into(), reason: reason.into() }
    }

    /// This error said of `context`.
    pub fn of(self, context: impl Into<String>) -> Self {
        Self::In { context: context.into(), inner: Box::new(self) }
    }
}
