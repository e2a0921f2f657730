//! Errors that say which input is wrong and what was expected.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum SplatError {
    /// The camera cannot form an image (zero size, bad intrinsics, non-rigid extrinsic, …).
    #[error("camera: {0}")]
    Camera(String),
    /// An input array has the wrong length for the number of Gaussians or channels.
    #[error("{field}: expected {expected} values, found {found}")]
    Shape { field: &'static str, expected: usize, found: usize },
    /// A per-Gaussian value outside its domain (a non-positive scale, an opacity above 1, …).
    #[error("{field} of Gaussian {index} is {value}: {expected}")]
    Domain { field: &'static str, index: usize, value: f64, expected: &'static str },
    /// A render option that makes no sense (a background of the wrong length, …).
    #[error("render options: {0}")]
    Options(String),
    /// A `.ply` file that cannot be read as 3D Gaussian splats.
    #[error("{path}: {reason}")]
    Ply { path: PathBuf, reason: String },
    /// A camera file that cannot be read as a camera.
    #[error("{path}: {reason}")]
    CameraFile { path: PathBuf, reason: String },
    #[error("{path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
}
