//! What a simulating run's checkpoint holds besides its record: the cloth's state and the frames
//! simulated so far as `[.., 3]` arrays, each read back checked against the run's vertex count
//! and the physical bounds; and the record itself, refusing another run's checkpoint by name.

use std::path::Path;

use mannequin_io::{NpyArray, Npz, NpzWriter};
use mannequin_mesh::points;
use serde::Serialize;

use crate::simulate_error::SimulateError;
use crate::state::{ClothState, check_positions};

/// The checkpoint's file name in a run's output folder.
pub const CHECKPOINT: &str = "checkpoint.npz";

/// The hash of a file's bytes: tells an edited input from the one a checkpoint ran.
pub fn file_hash(path: &Path) -> Result<String, SimulateError> {
    let bytes = std::fs::read(path)
        .map_err(|e| SimulateError::Read { path: path.display().to_string(), reason: e.to_string() })?;
    Ok(mannequin_io::fingerprint::hash_bytes(&bytes))
}

/// Refuses a checkpoint whose record is not `run`, naming the settings that differ.
pub fn check_run<T: Serialize>(npz: &Npz, run: &T) -> Result<(), SimulateError> {
    mannequin_io::run_record::check_run(npz, run, &[]).map_err(SimulateError::Refused)
}

/// `frames` (each of `vertices` points) as one [frames, vertices, 3] array.
pub fn frames_array(frames: &[Vec<[f32; 3]>], vertices: usize) -> NpyArray {
    let flat = frames.iter().flatten().flatten().copied().collect();
    NpyArray::f32(vec![frames.len(), vertices, 3], flat)
}

/// The [frames, vertices, 3] array under `key`, checked against `vertices` and
/// [`crate::MAX_COORDINATE`].
pub fn read_frames(npz: &Npz, key: &str, vertices: usize) -> Result<Vec<Vec<[f32; 3]>>, SimulateError> {
    let values = read_points(npz, key, &[None, Some(vertices), Some(3)])?;
    check_positions(key, &values).map_err(|e| SimulateError::from(e).of(npz.path.display().to_string()))?;
    Ok(values.chunks_exact(vertices.max(1)).map(<[_]>::to_vec).collect())
}

/// The points of the array under `key`, whose shape must match `shape` (ending in 3).
fn read_points(npz: &Npz, key: &str, shape: &[Option<usize>]) -> Result<Vec<[f32; 3]>, SimulateError> {
    let (_, values) = npz.f64_with_shape(key, shape)?;
    Ok(points(&values.into_iter().map(|x| x as f32).collect::<Vec<_>>()))
}

/// The cloth simulator's state as "positions" and "velocities" [vertices, 3] arrays, each name
/// followed by `suffix` (a run of several cloths tells theirs apart by it).
pub fn add_state(w: &mut NpzWriter, state: &ClothState, suffix: &str) {
    for (key, values) in [("positions", &state.positions), ("velocities", &state.velocities)] {
        let flat = values.iter().flatten().copied().collect();
        w.add(&format!("{key}{suffix}"), NpyArray::f32(vec![values.len(), 3], flat));
    }
}

/// The state [`add_state`] stored with `suffix`, checked against `vertices` and the physical
/// bounds ([`ClothState::check`]).
pub fn read_state(npz: &Npz, vertices: usize, suffix: &str) -> Result<ClothState, SimulateError> {
    let read = |key: &str| read_points(npz, &format!("{key}{suffix}"), &[Some(vertices), Some(3)]);
    let state = ClothState { positions: read("positions")?, velocities: read("velocities")? };
    // Named by its arrays: a checkpoint of several cloths holds several states.
    let arrays = format!("{} (positions{suffix}, velocities{suffix})", npz.path.display());
    state.check(vertices).map_err(|e| SimulateError::from(e).of(arrays))?;
    Ok(state)
}
