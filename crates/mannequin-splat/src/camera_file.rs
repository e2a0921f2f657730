//! A camera file read from disk ([`crate::camera_json`] gives its fields).

use std::path::Path;

use crate::{Camera, SplatError, parse_camera_json};

/// The camera in the JSON file at `path`, with its background colour.
pub fn read_camera(path: &Path) -> Result<(Camera, Vec<f64>), SplatError> {
    let bytes = std::fs::read(path)
        .map_err(|e| SplatError::CameraFile { path: path.to_path_buf(), reason: e.to_string() })?;
    parse_camera_json(path, &bytes)
}
