//! A mesh written in the format its file extension names: `.obj` or binary `.ply`, atomically.

use std::path::{Path, PathBuf};

use crate::{MeshFileError, TriMesh};

/// Why a mesh was not written by extension.
#[derive(Debug, thiserror::Error)]
pub enum MeshWriteError {
    #[error("{}: unknown mesh format; expected a .obj or .ply extension", .0.display())]
    UnknownFormat(PathBuf),
    #[error(transparent)]
    File(#[from] MeshFileError),
}

/// Writes `mesh` to `path` as `.obj` or `.ply`, by the extension (any case).
pub fn write_mesh(path: &Path, mesh: &TriMesh) -> Result<(), MeshWriteError> {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("obj") => crate::obj::write_obj(path, mesh)?,
        Some("ply") => crate::ply::write(path, mesh, None)?,
        _ => return Err(MeshWriteError::UnknownFormat(path.to_path_buf())),
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_extension_picks_the_format() {
        let dir = std::env::temp_dir().join(format!("mq-mesh-file-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mesh = TriMesh::new(vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2]]);
        write_mesh(&dir.join("a.OBJ"), &mesh).unwrap();
        assert!(std::fs::read_to_string(dir.join("a.OBJ")).unwrap().contains("\nf "));
        write_mesh(&dir.join("a.ply"), &mesh).unwrap();
        assert!(std::fs::read(dir.join("a.ply")).unwrap().starts_with(b"ply\n"));
        let refused = write_mesh(&dir.join("a.stl"), &mesh).unwrap_err().to_string();
        assert!(
            refused.ends_with("a.stl: unknown mesh format; expected a .obj or .ply extension"),
            "{refused}"
        );
        std::fs::remove_dir_all(dir).unwrap();
    }
}
