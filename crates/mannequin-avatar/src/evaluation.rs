//! Scoring a trained avatar: render it on a dataset's test sets (novel views and, where the
//! dataset has them, novel poses), score the renders against the ground truth, and gather image
//! and geometry metrics in the shape `mannequin eval --json` writes.

use std::path::{Path, PathBuf};

use burn::tensor::Device;
use mannequin_data::Dataset;
use mannequin_data::evaluation::{EvalOptions, EvalSummary, FrameScores, evaluate};
use serde::Serialize;

use crate::avatar::Avatar;
use crate::error::AvatarError;
use crate::predict::predict_split;

/// Image scores of one test set.
#[derive(Debug, Serialize)]
pub struct ImageScores {
    pub frames: usize,
    pub psnr: f64,
    pub ssim: f64,
    pub lpips: Option<f64>,
}

/// Geometry over every test frame with a ground-truth mesh or normal map.
#[derive(Debug, Serialize)]
pub struct GeometryScores {
    pub chamfer_cm: Option<f64>,
    pub p2s_cm: Option<f64>,
    pub normal_consistency: Option<f64>,
    pub normal_angle_deg: Option<f64>,
    pub normal_mse_x1e3: Option<f64>,
}

#[derive(Debug, Serialize)]
pub struct AvatarScores {
    pub model: PathBuf,
    pub data: PathBuf,
    pub novel_view: ImageScores,
    pub novel_pose: Option<ImageScores>,
    pub geometry: GeometryScores,
}

/// The test sets of a dataset folder: `test/novel_view` and `test/novel_pose` as written by
/// `mannequin synth`, or else the folder's own test split as the novel views.
fn test_sets(data: &Path) -> Vec<(&'static str, PathBuf)> {
    let nested = |name: &str| data.join("test").join(name);
    let mut sets = vec![(
        "novel_view",
        if nested("novel_view").is_dir() { nested("novel_view") } else { data.to_path_buf() },
    )];
    if nested("novel_pose").is_dir() {
        sets.push(("novel_pose", nested("novel_pose")));
    }
    sets
}

fn mean(values: impl Iterator<Item = Option<f64>>) -> Option<f64> {
    let v: Vec<f64> = values.flatten().collect();
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

fn image_scores(s: &EvalSummary) -> ImageScores {
    ImageScores { frames: s.frames, psnr: s.psnr, ssim: s.ssim, lpips: s.lpips }
}

/// Renders and scores every test set; predictions are kept under `MODEL/eval/<set>/`.
/// `on_set(name, frames)` is called before each set, `on_frame` after each render and each score.
pub fn evaluate_avatar(
    model: &Path,
    data: &Path,
    options: &EvalOptions,
    on_set: &dyn Fn(&str, usize),
    on_frame: &dyn Fn(),
) -> Result<AvatarScores, AvatarError> {
    let avatar = Avatar::load(model, &Device::flex())?;
    let mut summaries = Vec::new();
    for (name, dir) in test_sets(data) {
        let dataset = Dataset::open(&dir, 1)?;
        let frames = dataset.split("test")?.frames.len();
        let out = model.join("eval").join(name);
        on_set(name, frames);
        predict_split(&avatar, &dataset, "test", &out, on_frame)?;
        let summary = evaluate(&out, &dir, options, &|_| on_frame())?;
        summaries.push((name, summary));
    }
    let all: Vec<&FrameScores> = summaries.iter().flat_map(|(_, s)| &s.per_frame).collect();
    let geometry = GeometryScores {
        chamfer_cm: mean(all.iter().map(|s| s.chamfer_cm)),
        p2s_cm: mean(all.iter().map(|s| s.p2s_cm)),
        normal_consistency: mean(all.iter().map(|s| s.normal_consistency)),
        normal_angle_deg: mean(all.iter().map(|s| s.normal_angle_deg)),
        normal_mse_x1e3: mean(all.iter().map(|s| s.normal_mse_x1e3)),
    };
    let find = |n: &str| summaries.iter().find(|(name, _)| *name == n).map(|(_, s)| image_scores(s));
    Ok(AvatarScores {
        model: model.to_path_buf(),
        data: data.to_path_buf(),
        novel_view: find("novel_view").expect("novel_view is always a test set"),
        novel_pose: find("novel_pose"),
        geometry,
    })
}
