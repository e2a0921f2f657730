//! Fitting errors: one line each, naming the input or the model at fault.

use mannequin_io::run_record::START_OVER;
use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum FitError {
    #[error("person model {model}: {reason}")]
    Model { model: &'static str, reason: String },
    #[error("{what}: {reason}")]
    Input { what: String, reason: String },
    /// What a picture holds (or lacks), said of the picture as a whole.
    #[error("{0}")]
    Picture(String),
    /// A setting refused, said naming its flag.
    #[error("{0}")]
    Setting(String),
    /// A file or folder the pipeline could not make, read or remove: `doing` says which
    /// ("creating", "writing", ...).
    #[error("{doing} {}: {cause}", path.display())]
    File { doing: &'static str, path: PathBuf, cause: std::io::Error },
    /// A checkpoint that cannot resume this run.
    #[error("{0}; {START_OVER}")]
    Checkpoint(mannequin_io::IoError),
    #[error(transparent)]
    Body(#[from] mannequin_body::BodyError),
    #[error(transparent)]
    Data(#[from] mannequin_data::DataError),
    #[error(transparent)]
    Io(#[from] mannequin_io::IoError),
    #[error(transparent)]
    Video(#[from] mannequin_io::VideoError),
    #[error(transparent)]
    Mesh(#[from] mannequin_mesh::MeshFileError),
}

impl FitError {
    pub(crate) fn input(what: impl Into<String>, reason: impl Into<String>) -> Self {
        Self::Input { what: what.into(), reason: reason.into() }
    }

    /// `error` said of `what` (a file, or the step that failed).
    pub(crate) fn within(what: impl Into<String>, error: impl std::fmt::Display) -> Self {
        Self::input(what, error.to_string())
    }

    /// An I/O failure while `doing` something to `path`.
    pub(crate) fn file(doing: &'static str, path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> Self {
        let path = path.into();
        move |cause| Self::File { doing, path, cause }
    }
}
