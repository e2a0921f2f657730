//! Garment errors: one line each, naming the field or file at fault.

#[derive(Debug, thiserror::Error)]
pub enum GarmentError {
    /// `known`: the names there are.
    #[error("category: unknown name {name:?}; the categories are {}", known.join(", "))]
    UnknownCategory { name: String, known: &'static [&'static str] },
    /// `known`: the names there are.
    #[error("size: unknown name {name:?}; the sizes are {}", known.join(", "))]
    UnknownSize { name: String, known: &'static [&'static str] },
    #[error("{field}: {reason}")]
    Invalid { field: String, reason: String },
    #[error("{path}: {reason}")]
    File { path: String, reason: String },
    #[error(transparent)]
    Body(#[from] mannequin_body::BodyError),
    #[error("{garment} {when}: {error}")]
    Simulation { garment: String, when: String, error: mannequin_cloth::ClothError },
    #[error("draping: {0}")]
    Cloth(#[from] mannequin_cloth::ClothError),
    #[error(transparent)]
    Io(#[from] mannequin_io::IoError),
    #[error(transparent)]
    Data(#[from] mannequin_data::DataError),
}

impl GarmentError {
    pub(crate) fn invalid(field: impl Into<String>, reason: impl Into<String>) -> Self {
        Self::Invalid { field: field.into(), reason: reason.into() }
    }
}
