//! A dressing's checkpoint: its record (everything that changes the simulation), and per layer
//! (inner first) its frames so far and the cloth's state. A checkpoint of another run is refused
//! naming what changed.

use std::path::Path;

use mannequin_cloth::run_checkpoint::{add_state, check_run, frames_array, read_frames, read_state};
use mannequin_io::{Npz, NpzWriter};
use serde::{Deserialize, Serialize};

use super::worn::Worn;
use crate::dress_error::DressError;
use crate::garment::Garment;
use crate::transfer::Dressed;
use crate::wear::{LayerProgress, WearProgress};

/// Everything that changes the simulation; a checkpoint of another run is refused.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(super) struct DressRun {
    /// Each layer's name and template hash, inner first.
    pub garments: Vec<String>,
    pub body: String,
    pub betas: Vec<f32>,
    pub motion: String,
    pub fps: f32,
    pub frames: usize,
    pub substeps: u32,
    pub settle: f32,
    pub self_collision: bool,
}

/// The hash of what a template brings to a run: recipe, mesh and binding to the body.
pub(super) fn template_hash(g: &Garment) -> String {
    let mut bytes = serde_json::to_vec(&g.recipe).unwrap_or_default();
    let floats =
        g.mesh.positions.iter().chain(&g.offsets).flatten().chain(g.binding.iter().flat_map(|b| &b.bary));
    bytes.extend(floats.flat_map(|x| x.to_le_bytes()));
    let indices = g.mesh.faces.iter().flatten().chain(g.binding.iter().map(|b| &b.face));
    bytes.extend(indices.flat_map(|i| i.to_le_bytes()));
    mannequin_io::fingerprint::hash_bytes(&bytes)
}

/// Layer i's frames as `frames_<i>` and its state as `positions_<i>` and `velocities_<i>`.
pub(super) fn write_checkpoint(
    path: &Path,
    run: &DressRun,
    progress: &WearProgress,
    worn: &[Worn],
) -> Result<(), DressError> {
    let mut w = NpzWriter::uncompressed();
    mannequin_io::run_record::write_run(&mut w, run);
    for (i, (layer, worn)) in progress.layers.iter().zip(worn).enumerate() {
        w.add(&format!("frames_{i}"), frames_array(&layer.frames, worn.garment.vertex_count()));
        add_state(&mut w, &layer.state, &format!("_{i}"));
    }
    w.write(path)?;
    Ok(())
}

/// The progress a checkpoint of `run` holds for `layers` on a schedule of `schedule` frames; an
/// error naming what differs for another run's, or the field that is not what this run saves.
pub(super) fn read_checkpoint(
    path: &Path,
    run: &DressRun,
    layers: &[(&str, &Dressed)],
    schedule: usize,
) -> Result<WearProgress, DressError> {
    let npz = Npz::read(path)?;
    check_run(&npz, run)?;
    let mut progress = WearProgress::default();
    for (i, (_, layer)) in layers.iter().enumerate() {
        let vertices = layer.garment().vertex_count();
        let frames = read_frames(&npz, &format!("frames_{i}"), vertices)?;
        let state = read_state(&npz, vertices, &format!("_{i}"))?;
        progress.layers.push(LayerProgress { frames, state });
    }
    progress.check(layers, schedule).map_err(|e| DressError::from(e).of(path.display().to_string()))?;
    Ok(progress)
}
