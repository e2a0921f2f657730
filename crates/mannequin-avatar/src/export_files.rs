//! An avatar's mesh as the files an export writes, made whole in memory and checked before any
//! is written (so an export that fails writes none): a skinned `.glb` at the bind pose, or an
//! `.obj`/`.ply` at a pose with a file per garment layer beside it; each with vertex colour baked
//! from the Gaussians.

use std::path::{Path, PathBuf};

use mannequin_body::Motion;
use mannequin_mesh::gltf::scene_glb_bytes;
use mannequin_mesh::{MeshFileError, TriMesh};

use crate::avatar::{Avatar, Posed};
use crate::error::AvatarError;
use crate::export::{skinned_layers, vertex_colours};
use crate::params::host_rows;

/// One file of an export, made and checked.
pub enum ExportFile {
    /// An `.obj` or `.ply` mesh, already validated.
    Mesh(TriMesh),
    /// A file's bytes.
    Bytes(Vec<u8>),
}

/// How the mesh is exported.
pub enum MeshExport<'a> {
    /// A skinned `.glb` at the bind pose, with `motion` as its animation.
    Glb { motion: Option<&'a Motion> },
    /// An `.obj` or `.ply` at the pose: the personalised canonical mesh V_s exactly when
    /// `canonical`.
    Posed { canonical: bool },
}

/// Why the mesh files were not made.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    #[error(transparent)]
    Avatar(#[from] AvatarError),
    #[error(transparent)]
    File(#[from] MeshFileError),
}

/// The mesh files of `avatar` at `posed`, `output` first (then its garment layers, for
/// `.obj`/`.ply`).
pub fn mesh_files(
    avatar: &Avatar,
    posed: &Posed,
    how: MeshExport,
    output: &Path,
) -> Result<Vec<(PathBuf, ExportFile)>, ExportError> {
    let canonical = match how {
        MeshExport::Glb { motion } => {
            let (body, layers) = skinned_layers(avatar, posed)?;
            let animation = motion.map(|m| avatar.animation(m)).transpose()?;
            let bytes = scene_glb_bytes(output, &body, &layers, animation.as_ref(), &[])?;
            return Ok(vec![(output.to_path_buf(), ExportFile::Bytes(bytes))]);
        }
        MeshExport::Posed { canonical } => canonical,
    };
    let vertices = if canonical { &posed.personalised } else { &posed.vertices };
    let mut mesh = TriMesh::new(host_rows(vertices.clone()), avatar.canonical.faces.clone());
    mesh.colors = Some(vertex_colours(avatar, posed)?);
    // A layer is part of the mesh: valid if the whole is.
    mesh.validate().map_err(|e| AvatarError::file(output, e.to_string()))?;
    let mut files = Vec::new();
    for name in avatar.canonical.garment_names() {
        let part = avatar.canonical.layer_mesh(name, &mesh).ok_or_else(|| {
            AvatarError::Invalid(format!("the canonical mesh has no garment layer '{name}'"))
        })?;
        files.push((layer_path(output, name), ExportFile::Mesh(part)));
    }
    files.insert(0, (output.to_path_buf(), ExportFile::Mesh(mesh)));
    Ok(files)
}

/// Where a layer of `output` goes: `<stem>.<layer>.<extension>` beside it.
pub fn layer_path(output: &Path, layer: &str) -> PathBuf {
    let stem = output.file_stem().map_or_else(|| "mesh".into(), |s| s.to_string_lossy().into_owned());
    let extension = output.extension().map_or_else(String::new, |e| format!(".{}", e.to_string_lossy()));
    output.with_file_name(format!("{stem}.{layer}{extension}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_layer_goes_beside_its_mesh() {
        assert_eq!(layer_path(Path::new("out/a.obj"), "skirt"), Path::new("out/a.skirt.obj"));
        assert_eq!(layer_path(Path::new("a.PLY"), "shirt"), Path::new("a.shirt.PLY"));
    }
}
