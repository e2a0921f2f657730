//! How well each dressed frame went, per garment: vertices inside the body, triangles crossing
//! the layers under it, edge strain and stretch; written as metrics.json with the stage times.

use std::ops::Range;
use std::path::Path;

use mannequin_cloth::{SimulateError, quality};
use rayon::prelude::*;
use serde::Serialize;

use super::worn::Worn;
use crate::dress_error::DressError;

/// Per garment and motion frame, what went wrong where.
#[derive(Debug, Clone, Serialize)]
pub struct FrameMetrics {
    pub frame: usize,
    pub vertices_inside_body: usize,
    /// Triangle pairs crossing the layers under this one.
    pub crossings_with_inner_layers: usize,
    /// Pairs of this garment's own triangles that cross each other.
    pub self_intersecting_pairs: usize,
    pub max_edge_strain: f32,
    pub mean_edge_strain: f32,
    /// The 99th percentile of the edges' stretch (compression left out).
    pub p99_edge_stretch: f32,
}

/// Every garment's metrics at the motion's frames (`motion`, of the schedule): `worn` at
/// `layers` (per garment, per schedule frame) on `body` (per schedule frame, and its triangles).
pub(super) fn measure(
    worn: &[Worn],
    layers: &[Vec<Vec<[f32; 3]>>],
    (body_frames, body_faces): (&[Vec<[f32; 3]>], &[[u32; 3]]),
    motion: Range<usize>,
) -> Vec<Vec<FrameMetrics>> {
    worn.iter()
        .enumerate()
        .map(|(i, w)| {
            let rest = w.dressed.rest();
            let faces = &w.garment.mesh.faces;
            // Frames are independent: measure them in parallel.
            motion
                .clone()
                .into_par_iter()
                .map(|k| {
                    let positions = &layers[i][k];
                    let (max_edge_strain, mean_edge_strain) = quality::edge_strain(&rest, positions, faces);
                    let crossings_with_inner_layers = (0..i)
                        .map(|j| {
                            quality::crossing_pairs(
                                positions,
                                faces,
                                &layers[j][k],
                                &worn[j].garment.mesh.faces,
                            )
                        })
                        .sum();
                    FrameMetrics {
                        frame: k - motion.start,
                        vertices_inside_body: quality::vertices_inside_body(
                            positions,
                            &body_frames[k],
                            body_faces,
                        ),
                        crossings_with_inner_layers,
                        self_intersecting_pairs: quality::self_intersecting_pairs(positions, faces),
                        max_edge_strain,
                        mean_edge_strain,
                        p99_edge_stretch: quality::stretch_quantile(&rest, positions, faces, 0.99),
                    }
                })
                .collect()
        })
        .collect()
}

/// `dir/metrics.json`: per garment its summary and per-frame `metrics`, with the clip's frames,
/// `fps` and the seconds each stage took.
pub(super) fn write_metrics(
    dir: &Path,
    worn: &[Worn],
    metrics: &[Vec<FrameMetrics>],
    fps: f32,
    stage_s: &serde_json::Map<String, serde_json::Value>,
) -> Result<(), DressError> {
    let garments: Vec<serde_json::Value> = worn
        .iter()
        .zip(metrics)
        .map(|(w, m)| {
            serde_json::json!({
                "name": w.name,
                "category": w.garment.recipe.category.name(),
                "material": w.material,
                "strain_limit": w.material.strain_limit,
                "vertices": w.garment.vertex_count(),
                "max_vertices_inside_body": m.iter().map(|x| x.vertices_inside_body).max(),
                "max_crossings_with_inner_layers": m.iter().map(|x| x.crossings_with_inner_layers).max(),
                "max_self_intersecting_pairs": m.iter().map(|x| x.self_intersecting_pairs).max(),
                "max_edge_strain": m.iter().map(|x| x.max_edge_strain).fold(0.0f32, f32::max),
                "mean_edge_strain": m.iter().map(|x| x.mean_edge_strain).sum::<f32>() / m.len().max(1) as f32,
                "max_p99_edge_stretch": m.iter().map(|x| x.p99_edge_stretch).fold(0.0f32, f32::max),
                "per_frame": m,
            })
        })
        .collect();
    let summary = serde_json::json!({
        "frames": metrics.first().map_or(0, Vec::len),
        "fps": fps,
        "stage_s": stage_s,
        "garments": garments,
    });
    let path = dir.join("metrics.json");
    let write = |text: String| mannequin_io::write_atomic(&path, text.as_bytes()).map_err(|e| e.to_string());
    serde_json::to_string_pretty(&summary)
        .map_err(|e| e.to_string())
        .and_then(write)
        .map_err(|reason| SimulateError::Write { path: path.display().to_string(), reason })?;
    for g in summary["garments"].as_array().into_iter().flatten() {
        tracing::info!(
            "{}: at most {} vertices inside the body, {} crossings with inner layers, {} with itself; \
             strain mean {:.3}, max {:.3}; 99 % of edges stretched under {:.3} (the material's limit: {})",
            g["name"],
            g["max_vertices_inside_body"],
            g["max_crossings_with_inner_layers"],
            g["max_self_intersecting_pairs"],
            g["mean_edge_strain"].as_f64().unwrap_or(0.0),
            g["max_edge_strain"].as_f64().unwrap_or(0.0),
            g["max_p99_edge_stretch"].as_f64().unwrap_or(0.0),
            g["strain_limit"]
        );
    }
    tracing::info!("stages (s): {}", summary["stage_s"]);
    Ok(())
}
