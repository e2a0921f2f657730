//! Dressing errors: what goes wrong loading garments, simulating them on a body, checkpointing
//! and writing the scene, one line each with the file or field at fault. A bad setting, a file
//! that cannot be read or written, is the simulating run's own error ([`SimulateError`]).

use mannequin_body::BodyError;
use mannequin_cloth::{ClothError, SimulateError};
use mannequin_io::IoError;
use mannequin_mesh::MeshFileError;

use crate::error::GarmentError;

#[derive(Debug, thiserror::Error)]
pub enum DressError {
    /// `inner` said of `context` (a file, a garment): one line, as `anyhow`'s context reads.
    #[error("{context}: {inner}")]
    In { context: String, inner: Box<DressError> },
    #[error(transparent)]
    Garment(#[from] GarmentError),
    #[error(transparent)]
    Cloth(#[from] ClothError),
    #[error(transparent)]
    Simulate(#[from] SimulateError),
    #[error(transparent)]
    Body(#[from] BodyError),
    #[error(transparent)]
    MeshFile(#[from] MeshFileError),
    #[error(transparent)]
    Io(#[from] IoError),
}

impl DressError {
    /// This error said of `context`.
    pub(crate) fn of(self, context: impl Into<String>) -> Self {
        Self::In { context: context.into(), inner: Box::new(self) }
    }
}
