//! What the simulating commands' checkpoints share: the run's settings stored beside the state,
//! so a checkpoint of another run is refused naming what changed, and point arrays in and out.

use std::path::Path;

use anyhow::{Context, Result, anyhow};
use mannequin_cloth::{ClothState, check_positions};
use mannequin_io::{NpyArray, Npz, NpzWriter};
use mannequin_mesh::points;
use serde::Serialize;

/// The checkpoint's file name in a command's output folder.
pub const CHECKPOINT: &str = "checkpoint.npz";

/// The hash of a file's bytes: tells an edited input from the one a checkpoint ran.
pub fn file_hash(path: &Path) -> Result<String> {
    let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    Ok(mannequin_io::fingerprint::hash_bytes(&bytes))
}

/// Stores `run` (everything that changes the result) as the checkpoint's record.
pub fn add_run<T: Serialize>(w: &mut NpzWriter, run: &T) -> Result<()> {
    mannequin_io::run_record::write_run(w, run);
    Ok(())
}

/// Refuses a checkpoint whose record is not `run`, naming the settings that differ.
pub fn check_run<T: Serialize>(npz: &Npz, _path: &Path, run: &T) -> Result<()> {
    mannequin_io::run_record::check_run(npz, run, &[])
        .map_err(|e| anyhow!("{e}; use --restart to start over, or another --out"))
}

/// `frames` (each of `vertices` points) as one [frames, vertices, 3] array.
pub fn frames_array(frames: &[Vec<[f32; 3]>], vertices: usize) -> NpyArray {
    let flat = frames.iter().flatten().flatten().copied().collect();
    NpyArray::f32(vec![frames.len(), vertices, 3], flat)
}

/// The [frames, vertices, 3] array under `key`, checked against `vertices` and
/// [`mannequin_cloth::MAX_COORDINATE`].
pub fn read_frames(npz: &Npz, key: &str, vertices: usize) -> Result<Vec<Vec<[f32; 3]>>> {
    let values = read_points(npz, key, &[None, Some(vertices), Some(3)])?;
    check_positions(key, &values).map_err(|e| anyhow!("{}: {e}", npz.path.display()))?;
    Ok(values.chunks_exact(vertices.max(1)).map(<[_]>::to_vec).collect())
}

/// The points of the array under `key`, whose shape must match `shape` (ending in 3).
fn read_points(npz: &Npz, key: &str, shape: &[Option<usize>]) -> Result<Vec<[f32; 3]>> {
    let (_, values) = npz.f64_with_shape(key, shape)?;
    Ok(points(&values.into_iter().map(|x| x as f32).collect::<Vec<_>>()))
}

/// The cloth simulator's state as "positions" and "velocities" [vertices, 3] arrays.
pub fn add_state(w: &mut NpzWriter, state: &ClothState) {
    for (key, values) in [("positions", &state.positions), ("velocities", &state.velocities)] {
        let flat = values.iter().flatten().copied().collect();
        w.add(key, NpyArray::f32(vec![values.len(), 3], flat));
    }
}

/// The state [`add_state`] stored, checked against `vertices` and the physical bounds
/// ([`ClothState::check`]).
pub fn read_state(npz: &Npz, vertices: usize) -> Result<ClothState> {
    let read = |key: &str| read_points(npz, key, &[Some(vertices), Some(3)]);
    let state = ClothState { positions: read("positions")?, velocities: read("velocities")? };
    state.check(vertices).map_err(|e| anyhow!("{}: {e}", npz.path.display()))?;
    Ok(state)
}
