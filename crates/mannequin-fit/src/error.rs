//! Fitting errors: one line each, naming the input or the model at fault.

#[derive(Debug, thiserror::Error)]
pub enum FitError {
    #[error("person model {model}: {reason}")]
    Model { model: &'static str, reason: String },
    #[error("{what}: {reason}")]
    Input { what: String, reason: String },
    /// What a picture holds (or lacks), said of the picture as a whole.
    #[error("{0}")]
    Picture(String),
    #[error(transparent)]
    Body(#[from] mannequin_body::BodyError),
    #[error(transparent)]
    Data(#[from] mannequin_data::DataError),
    #[error(transparent)]
    Io(#[from] mannequin_io::IoError),
}

impl FitError {
    pub(crate) fn input(what: impl Into<String>, reason: impl Into<String>) -> Self {
        Self::Input { what: what.into(), reason: reason.into() }
    }
}
