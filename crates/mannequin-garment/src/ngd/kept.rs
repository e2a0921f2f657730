//! A finished garment reconstruction kept beside its fit (`layer.npz`), with the record of what
//! made it, so a training run stopped after its first garments reads them back instead of
//! fitting them again.

use std::path::Path;

use mannequin_io::{NpyArray, Npz, NpzWriter};

use super::error::NgdError;
use super::pipeline::FittedGarment;

/// The file a finished reconstruction is kept in, in its fit's folder.
pub(crate) const KEPT: &str = "layer.npz";

/// Writes `fitted` to `path` with `record`, what made it.
pub(crate) fn keep(path: &Path, fitted: &FittedGarment, record: &str) -> Result<(), NgdError> {
    let mut w = NpzWriter::new();
    w.add("record", NpyArray::text(record));
    let v = fitted.positions.len();
    w.add("positions", NpyArray::f32(vec![v, 3], fitted.positions.iter().flatten().copied().collect()));
    let faces = fitted.faces.iter().flatten().map(|&i| i64::from(i)).collect();
    w.add("faces", NpyArray::i64(vec![fitted.faces.len(), 3], faces));
    w.add("weights", NpyArray::f32(vec![v, fitted.weights.len() / v.max(1)], fitted.weights.clone()));
    w.write(path).map_err(|source| NgdError::WriteArchive { path: path.to_path_buf(), source })
}

/// The garment `name` kept at `path` if it was made as `record` says; `None` if there is none or
/// it was made another way.
pub(crate) fn read_kept(path: &Path, record: &str, name: &str) -> Result<Option<FittedGarment>, NgdError> {
    if !path.exists() {
        return Ok(None);
    }
    let npz = Npz::read(path)?;
    if npz.text("record")? != record {
        return Ok(None);
    }
    let (_, positions) = npz.f64_with_shape("positions", &[None, Some(3)])?;
    let v = positions.len() / 3;
    let (_, faces) = npz.f64_with_shape("faces", &[None, Some(3)])?;
    let (_, weights) = npz.f64_with_shape("weights", &[Some(v), None])?;
    if let Some(f) = faces.iter().position(|&i| i < 0.0 || i as usize >= v) {
        return Err(NgdError::file(path, format!("faces: face {} indexes past the {v} vertices", f / 3)));
    }
    Ok(Some(FittedGarment {
        category: name.to_string(),
        positions: positions.chunks_exact(3).map(|p| [p[0] as f32, p[1] as f32, p[2] as f32]).collect(),
        faces: faces.chunks_exact(3).map(|f| [f[0] as u32, f[1] as u32, f[2] as u32]).collect(),
        weights: weights.into_iter().map(|w| w as f32).collect(),
    }))
}
