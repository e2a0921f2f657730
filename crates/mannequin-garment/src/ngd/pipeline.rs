//! One garment reconstructed from a dataset's label maps and normal maps (NGD, issue 20;
//! `mannequin garment fit`). The category's template, carried to the dataset's body shape with
//! its skinning weights (GRBF), is the base. Writes the fitted garment at rest (`garment.obj`),
//! and `fit.json`: the mask IoU of every training frame before and after, the losses, where the
//! time went, and, where the dataset has the garment's ground-truth meshes, Chamfer distance and
//! normal consistency before and after on training frames and on the held-out test frames; and
//! the scene of the training frames (`fitted.glb`, `<category>.pc2`).

use std::path::Path;
use std::time::Instant;

use mannequin_body::{BodyModel, load_body};
use mannequin_data::{Dataset, Split};
use mannequin_io::progress::bar;
use mannequin_mesh::{MorphSequence, TriMesh};

use super::error::NgdError;
use super::evaluation::Evaluation;
use super::legend::{label_index, label_legend, outer_labels};
use super::reconstruction::{Reconstruction, TrainingFrame};
use super::scene::FramePose;
use super::settings::NgdSettings;
use super::target::Target;
use crate::category::Category;
use crate::garment_cache::load_or_make;
use crate::layered_scene::write_layered_scene;
use crate::transfer::Dressed;

/// Below this mean mask IoU over the first pass through the frames, the category is probably not
/// the garment in the label maps (the right template starts near 0.7).
const MISMATCH_IOU: f64 = 0.5;
/// The capture's frame rate as the scene plays it (the datasets do not record one).
const SCENE_FPS: f32 = 30.0;

/// A reconstructed garment at rest on the dataset's body, with its skinning weights (V × J).
#[derive(Debug, Clone, PartialEq)]
pub struct FittedGarment {
    pub category: String,
    pub positions: Vec<[f32; 3]>,
    pub faces: Vec<[u32; 3]>,
    pub weights: Vec<f32>,
}

/// Reconstructs the garment of `category` that `label_name` marks in the dataset at `data`, on
/// the body model `body` names, writing `garment.obj`, `fit.json`, `fitted.glb` and the point
/// cache into `out`.
pub fn reconstruct(
    data: &Path,
    category: &str,
    label_name: &str,
    body: &str,
    ngd: &NgdSettings,
    out: &Path,
) -> Result<FittedGarment, NgdError> {
    let start = Instant::now();
    let dataset = Dataset::open(data, ngd.downscale)?;
    let legend = label_legend(data)?;
    let label = label_index(data, &legend, label_name)?;
    let outer = outer_labels(&legend, category)?;
    let model = load_body(body)?;
    let train = dataset.split("train")?;
    if train.frames.is_empty() {
        return Err(NgdError::file(data, "the train split has no frames"));
    }
    // The targets first: a broken label map is refused before the template is made (seconds).
    let frames = train
        .frames
        .iter()
        .enumerate()
        .map(|(k, &f)| {
            let camera = dataset.camera(f).clone();
            let target = Target::read(data, &camera, f, label, legend.len(), &outer)?;
            Ok(TrainingFrame { target, camera, pose: FramePose::of(&train, k) })
        })
        .collect::<Result<Vec<_>, NgdError>>()?;
    let (_, garment) = load_or_make(category, &model, body, &ngd.size)?;
    let dressed = Dressed::new(&garment, &model, &train.poses.betas)?;
    let settings = ngd.reconstruction(data, frames.iter().all(|f| f.target.normals.is_some()))?;
    let poses: Vec<Vec<f32>> = frames.iter().map(|f| f.pose.pose.clone()).collect();
    let mut fit = Reconstruction::new(&dressed, settings, &poses)?;
    let evaluation = Evaluation::new(data, &dataset, category)?;
    let before = fit.mask_iou(&frames)?;
    let geometry_before = evaluation.measure(&fit)?;
    let progress = bar(ngd.steps as u64, "garment fit");
    let mut losses = Vec::with_capacity(ngd.steps);
    let mut first_pass = Vec::new();
    for _ in 0..ngd.steps {
        let report = fit.step(&frames)?;
        losses.push(report.losses);
        if first_pass.len() < frames.len() {
            first_pass.push(report.mask_iou);
            if first_pass.len() == frames.len() && mean(&first_pass) < MISMATCH_IOU {
                progress.suspend(|| {
                    tracing::warn!(
                        "the {} overlaps its label maps by a mean mask IoU of {:.2} over the first pass through the \
                         frames (below {MISMATCH_IOU}): the label '{label_name}' may not mark a garment of category {}",
                        category,
                        mean(&first_pass),
                        category
                    )
                });
            }
        }
        progress.inc(1);
    }
    progress.finish();
    let after = fit.mask_iou(&frames)?;
    let geometry_after = evaluation.measure(&fit)?;
    std::fs::create_dir_all(out)
        .map_err(|source| NgdError::CreateFolder { path: out.to_path_buf(), source })?;
    // The template's UVs hold while the topology is the template's.
    let uv = garment.mesh.uv.clone().filter(|_| fit.faces().len() == garment.mesh.faces.len());
    let mesh = TriMesh { positions: fit.rest(), faces: fit.faces().to_vec(), uv, colors: None };
    mannequin_mesh::obj::write_obj(out.join("garment.obj"), &mesh)?;
    let report = serde_json::json!({
        "category": category,
        "label": label_name,
        "settings": fit.settings(),
        "frames": train.frames,
        "faces": { "base": garment.mesh.faces.len(), "fitted": fit.faces().len() },
        "mask_iou_before": before,
        "mask_iou_after": after,
        "mean_mask_iou": { "before": mean(&before), "after": mean(&after) },
        "geometry": { "before": geometry_before, "after": geometry_after },
        "losses": losses,
        "regulariser": fit.regulariser(),
        "ms_per_step": fit.breakdown.per_step_ms(fit.steps_taken()),
        "seconds": start.elapsed().as_secs_f64(),
    });
    let path = out.join("fit.json");
    mannequin_io::write_atomic(&path, serde_json::to_string_pretty(&report)?.as_bytes())
        .map_err(|source| NgdError::Write { path: path.clone(), source })?;
    write_scene(out, &model, &train, &frames, &fit, category)?;
    let geometry = match (&geometry_before, &geometry_after) {
        (Some(b), Some(a)) => format!(
            "; against the ground truth on training frames, Chamfer {:.2} → {:.2} cm, normal consistency {:.3} → {:.3}",
            b.train.chamfer_cm, a.train.chamfer_cm, b.train.normal_consistency, a.train.normal_consistency
        ),
        _ => String::new(),
    };
    tracing::info!(
        "fitted the {} to {} frames: mask IoU {:.3} → {:.3}{geometry}; wrote {}",
        category,
        frames.len(),
        mean(&before),
        mean(&after),
        out.display()
    );
    Ok(FittedGarment {
        category: category.to_string(),
        positions: fit.rest(),
        faces: fit.faces().to_vec(),
        weights: fit.weights().to_vec(),
    })
}

/// `fitted.glb`: the skinned body playing the training frames' poses, with the fitted garment in
/// each (its dynamic field's shape for that pose, skinned) as morph targets in sync; and
/// `<category>.pc2`, the same frames as a Blender point cache. `mannequin view OUT` plays both.
fn write_scene(
    dir: &Path,
    model: &BodyModel,
    train: &Split,
    frames: &[TrainingFrame],
    fit: &Reconstruction,
    category: &str,
) -> Result<(), NgdError> {
    let posed: Vec<Vec<[f32; 3]>> =
        frames.iter().map(|f| Ok(fit.posed(&f.pose)?.positions)).collect::<Result<_, NgdError>>()?;
    let mut mesh = TriMesh::new(posed[0].clone(), fit.faces().to_vec());
    mesh.colors = Some(vec![Category::named(category)?.colour(); mesh.vertex_count()]);
    let layer = MorphSequence { name: category.to_string(), mesh, frames: posed, fps: SCENE_FPS };
    let poses: Vec<f32> = frames.iter().flat_map(|f| f.pose.pose.clone()).collect();
    let trans: Vec<f32> = frames.iter().flat_map(|f| f.pose.transl).collect();
    write_layered_scene(
        &dir.join("fitted.glb"),
        model,
        &train.poses.betas,
        (&poses, &trans, SCENE_FPS),
        &[layer],
    )?;
    Ok(())
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}
