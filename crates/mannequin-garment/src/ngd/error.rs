//! What goes wrong reconstructing garments from a dataset: each error names the file, folder or
//! option at fault; a cause it wraps follows it (as a chain of sources), as the command line
//! prints it.

use std::path::{Path, PathBuf};

use mannequin_body::{BodyError, LoadBodyError};
use mannequin_data::DataError;
use mannequin_io::IoError;
use mannequin_io::staging::StagingError;
use mannequin_mesh::MeshFileError;

use crate::dress_error::DressError;
use crate::error::GarmentError;

#[derive(Debug, thiserror::Error)]
pub enum NgdError {
    /// A dataset or kept file that cannot be used as it is.
    #[error("{}: {reason}", path.display())]
    File { path: PathBuf, reason: String },
    /// An option naming something it cannot (`--garments upper:cape`).
    #[error("{flag}: {reason}")]
    Flag { flag: String, reason: String },
    #[error(
        "{}: the dataset has no label legend (subject.json with \"labels\"); garment fit needs label maps",
        path.display()
    )]
    NoLegend { path: PathBuf, source: std::io::Error },
    #[error("{}: not JSON", path.display())]
    NotJson { path: PathBuf, source: serde_json::Error },
    #[error("reading {}", path.display())]
    ReadMesh { path: PathBuf, source: MeshFileError },
    #[error("creating {}", path.display())]
    CreateFolder { path: PathBuf, source: std::io::Error },
    #[error("writing {}", path.display())]
    Write { path: PathBuf, source: std::io::Error },
    #[error("writing {}", path.display())]
    WriteArchive { path: PathBuf, source: IoError },
    #[error(transparent)]
    Garment(#[from] GarmentError),
    #[error(transparent)]
    Dress(#[from] DressError),
    #[error(transparent)]
    Data(#[from] DataError),
    #[error(transparent)]
    Body(#[from] LoadBodyError),
    #[error(transparent)]
    Pose(#[from] BodyError),
    #[error(transparent)]
    Staging(#[from] StagingError),
    #[error(transparent)]
    Mesh(#[from] MeshFileError),
    #[error(transparent)]
    Io(#[from] IoError),
    #[error(transparent)]
    Json(#[from] serde_json::Error),
}

impl NgdError {
    pub(crate) fn file(path: impl AsRef<Path>, reason: impl Into<String>) -> Self {
        Self::File { path: path.as_ref().to_path_buf(), reason: reason.into() }
    }

    pub(crate) fn flag(flag: &str, reason: impl Into<String>) -> Self {
        Self::Flag { flag: flag.to_string(), reason: reason.into() }
    }
}
