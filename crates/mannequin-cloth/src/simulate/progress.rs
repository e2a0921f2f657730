//! Where a `cloth simulate` run stands, and the checkpoint that saves it: the run's record
//! (everything that changes the result), the next frame, the cloth's state, and the frames and
//! metrics recorded so far. A checkpoint of another run is refused naming what changed.

use std::path::Path;

use mannequin_body::Settling;
use mannequin_io::{NpyArray, Npz, NpzWriter};
use serde::{Deserialize, Serialize};

use super::metrics::FrameMetrics;
use crate::material::Material;
use crate::run_checkpoint::{add_state, check_run, frames_array, read_frames, read_state};
use crate::simulate_error::SimulateError;
use crate::state::ClothState;

/// Everything that changes the result; a checkpoint of another run is refused.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(super) struct ClothRun {
    pub garment: String,
    pub pins: String,
    pub motion: String,
    pub body: String,
    pub betas: Vec<f32>,
    pub fps: f32,
    pub frames: usize,
    pub material: Material,
    pub substeps: u32,
    pub settle: f32,
    pub self_collision: bool,
}

/// Where a run stands: the next schedule frame to reach, and what it has recorded.
pub(super) struct Progress {
    pub next: usize,
    pub frames: Vec<Vec<[f32; 3]>>,
    pub metrics: Vec<FrameMetrics>,
}

impl Progress {
    /// A run at its start: the schedule's first frame is the rest shape.
    pub fn start() -> Self {
        Self { next: 1, frames: Vec::new(), metrics: Vec::new() }
    }
}

pub(super) fn write_checkpoint(
    path: &Path,
    run: &ClothRun,
    state: &ClothState,
    progress: &Progress,
) -> Result<(), SimulateError> {
    let mut w = NpzWriter::new();
    mannequin_io::run_record::write_run(&mut w, run);
    w.add("next", NpyArray::i64(vec![1], vec![progress.next as i64]));
    add_state(&mut w, state, "");
    w.add("frames", frames_array(&progress.frames, state.positions.len()));
    let metrics = serde_json::to_string(&progress.metrics)
        .map_err(|e| SimulateError::invalid("metrics", e.to_string()))?;
    w.add("metrics", NpyArray::text(&metrics));
    w.write(path)?;
    Ok(())
}

/// The checkpoint's progress and state, if it is one of `run` on `schedule`; an error naming
/// the settings that differ if it is another run's, or the field that is not what this run
/// would have saved.
pub(super) fn read_checkpoint(
    path: &Path,
    run: &ClothRun,
    vertices: usize,
    schedule: &Settling,
) -> Result<(Progress, ClothState), SimulateError> {
    let npz = Npz::read(path)?;
    check_run(&npz, run)?;
    let at_fault =
        |field: &str, reason: String| SimulateError::invalid(field, reason).of(path.display().to_string());
    let last = schedule.len() - 1;
    let raw = npz.require("next")?.to_i64().filter(|n| n.len() == 1).map(|n| n[0]);
    let Some(next) = raw.and_then(|n| usize::try_from(n).ok()).filter(|n| (1..=last).contains(n)) else {
        return Err(at_fault(
            "next",
            format!(
                "{}; expected one frame number from 1 to {last} (the run's {} frames, settling included)",
                raw.map_or("not one whole number".into(), |n| n.to_string()),
                schedule.len()
            ),
        ));
    };
    let state = read_state(&npz, vertices, "")?;
    let frames = read_frames(&npz, "frames", vertices)?;
    let recorded = next.saturating_sub(schedule.settle);
    if frames.len() != recorded {
        return Err(at_fault(
            "frames",
            format!(
                "{} frames; expected {recorded}, the motion frames before frame {next} of the run",
                frames.len()
            ),
        ));
    }
    let metrics: Vec<FrameMetrics> = serde_json::from_str(npz.text("metrics")?)
        .map_err(|e| at_fault("metrics", format!("expected the per-frame metrics as JSON: {e}")))?;
    let wrong = |i: usize| i >= recorded || metrics.get(i).is_none_or(|m| !m.is_frame(i));
    if let Some(i) = (0..metrics.len().max(recorded)).find(|&i| wrong(i)) {
        return Err(at_fault(
            "metrics",
            format!(
                "entry {i} is not motion frame {i}'s; expected {recorded} entries of finite, \
                 non-negative measures"
            ),
        ));
    }
    Ok((Progress { next, frames, metrics }, state))
}
