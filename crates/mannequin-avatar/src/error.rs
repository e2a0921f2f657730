//! Errors that say which file, field or iteration went wrong, so a user can act on them.

use mannequin_io::run_record::START_OVER;
use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum AvatarError {
    #[error(transparent)]
    Io(#[from] mannequin_io::IoError),
    #[error(transparent)]
    Data(#[from] mannequin_data::DataError),
    #[error(transparent)]
    Body(#[from] mannequin_body::BodyError),
    #[error(transparent)]
    Splat(#[from] mannequin_splat::SplatError),
    #[error(transparent)]
    Gpu(#[from] mannequin_splat::GpuUnavailable),
    #[error(transparent)]
    HashGrid(#[from] crate::hash_grid::HashGridError),
    #[error("{path}: {reason}")]
    File { path: PathBuf, reason: String },
    #[error("{0}")]
    Invalid(String),
    #[error("the loss became {value} at iteration {iteration}; the last good checkpoint is {checkpoint}")]
    NonFiniteLoss { iteration: usize, value: f64, checkpoint: String },
    #[error(
        "the refined pose of frame {frame} stopped being finite; the last good checkpoint is {checkpoint}"
    )]
    NonFinitePose { frame: usize, checkpoint: String },
    /// A checkpoint that cannot be resumed, with the way out.
    #[error("{0}; {START_OVER}")]
    CannotResume(Box<AvatarError>),
}

impl AvatarError {
    pub fn file(path: impl Into<PathBuf>, reason: impl Into<String>) -> Self {
        Self::File { path: path.into(), reason: reason.into() }
    }

    /// A training error with the last good checkpoint named where it stops a run.
    pub fn with_checkpoint(self, last: String) -> Self {
        match self {
            Self::NonFiniteLoss { iteration, value, .. } => {
                Self::NonFiniteLoss { iteration, value, checkpoint: last }
            }
            Self::NonFinitePose { frame, .. } => Self::NonFinitePose { frame, checkpoint: last },
            e => e,
        }
    }

    /// This error, refusing a checkpoint, with the way out.
    pub fn cannot_resume(self) -> Self {
        Self::CannotResume(Box::new(self))
    }
}
