//! What `cloth simulate` writes for the frames recorded: garment.pc2 (a Blender point cache),
//! garment.npz (positions, faces, fps), scene.glb (the skinned body playing the motion with the
//! garment as morph targets) and metrics.json.

use std::path::Path;

use mannequin_body::{BodyModel, Motion, skeletal_animation, skinned_body};
use mannequin_io::{NpyArray, NpzWriter};
use mannequin_mesh::{MorphSequence, PointCache, TriMesh, write_scene_glb};

use super::metrics::FrameMetrics;
use crate::phase_times::PhaseTimes;
use crate::simulate_error::SimulateError;

/// The four outputs for `frames` of `garment` on `model` (shape `betas`) playing `motion`, into
/// `dir`, with the frames' `metrics` beside the material's `strain_limit`; returns the metrics'
/// summary.
pub(super) fn write_outputs(
    dir: &Path,
    garment: &TriMesh,
    (model, betas, motion): (&BodyModel, &[f32], &Motion),
    frames: &[Vec<[f32; 3]>],
    (metrics, strain_limit): (&[FrameMetrics], f32),
    phases: &PhaseTimes,
) -> Result<serde_json::Value, SimulateError> {
    let (f, v) = (frames.len(), garment.vertex_count());
    PointCache { start: 0.0, sampling: 1.0, frames: frames.to_vec() }.write(&dir.join("garment.pc2"))?;

    let mut npz = NpzWriter::new();
    npz.add("positions", NpyArray::f32(vec![f, v, 3], frames.iter().flatten().flatten().copied().collect()));
    let faces: Vec<i64> = garment.faces.iter().flatten().map(|&i| i as i64).collect();
    npz.add("faces", NpyArray::i64(vec![garment.face_count(), 3], faces));
    npz.add("fps", NpyArray::f64(vec![1], vec![motion.fps as f64]));
    npz.write(dir.join("garment.npz"))?;

    let skinned = skinned_body(model, betas)?;
    let poses = motion.poses_for(model)?;
    let pl = model.pose_len();
    let animation =
        skeletal_animation(model.num_joints(), &poses[..f * pl], &motion.trans[..3 * f], motion.fps)?;
    let mut mesh = garment.clone();
    mesh.positions = frames[0].clone();
    let cache = MorphSequence { name: "garment".into(), mesh, frames: frames.to_vec(), fps: motion.fps };
    write_scene_glb(dir.join("scene.glb"), &skinned, Some(&animation), &[cache])?;

    let m = metrics;
    let phases: serde_json::Map<String, serde_json::Value> =
        phases.named().into_iter().map(|(name, d)| (name.to_string(), d.as_secs_f64().into())).collect();
    let total_ms: f64 = m.iter().map(|x| x.simulation_ms).sum();
    let summary = serde_json::json!({
        "frames": f,
        "fps": motion.fps,
        "max_vertices_inside_body": m.iter().map(|x| x.vertices_inside_body).max(),
        "max_self_intersecting_pairs": m.iter().map(|x| x.self_intersecting_pairs).max(),
        "max_edge_strain": m.iter().map(|x| x.max_edge_strain).fold(0.0f32, f32::max),
        "mean_edge_strain": m.iter().map(|x| x.mean_edge_strain).sum::<f32>() / f as f32,
        "max_p99_edge_stretch": m.iter().map(|x| x.p99_edge_stretch).fold(0.0f32, f32::max),
        "strain_limit": strain_limit,
        "simulation_s": total_ms / 1e3,
        "ms_per_frame": total_ms / f as f64,
        "phase_s": phases,
        "per_frame": m,
    });
    let text = serde_json::to_string_pretty(&summary)
        .map_err(|e| SimulateError::invalid("metrics", e.to_string()))?;
    let path = dir.join("metrics.json");
    mannequin_io::write_atomic(&path, text.as_bytes())
        .map_err(|e| SimulateError::Write { path: path.display().to_string(), reason: e.to_string() })?;
    Ok(summary)
}
