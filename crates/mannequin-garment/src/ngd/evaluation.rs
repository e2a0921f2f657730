//! How close a reconstruction is to the dataset's ground-truth garment meshes, where it has them:
//! Chamfer distance, point-to-surface distance and normal consistency, averaged over frames of
//! the training and the test split, and of a synthetic subject's novel poses (`test/novel_pose`:
//! walking, raising and crossing the arms, squatting), which the fit never saw. Novel views
//! would add nothing here: they show the training poses, whose geometry does not depend on the
//! camera.

use std::path::Path;

use mannequin_data::metrics::geometry::{GeometryMetrics, geometry_metrics};
use mannequin_data::{Dataset, layout};
use mannequin_mesh::TriMesh;
use serde::Serialize;

use super::error::NgdError;
use super::reconstruction::Reconstruction;
use super::scene::FramePose;

/// Frames evaluated against the ground truth, at most, per split.
const EVALUATED_FRAMES: usize = 12;
/// Surface samples per mesh for Chamfer and normal consistency.
const EVALUATION_SAMPLES: usize = 20_000;

/// The mean geometry metrics over evaluated frames of the training and test splits.
#[derive(Debug, Serialize)]
pub(crate) struct SplitGeometry {
    pub train: GeometryMetrics,
    pub test: Option<GeometryMetrics>,
    pub novel_pose: Option<GeometryMetrics>,
    pub frames: usize,
}

/// The frames whose ground-truth garment mesh the fit is compared with: up to
/// [`EVALUATED_FRAMES`] evenly spread through each split.
pub(crate) struct Evaluation {
    train: Vec<(FramePose, TriMesh)>,
    test: Vec<(FramePose, TriMesh)>,
    novel_pose: Vec<(FramePose, TriMesh)>,
}

/// Where a synthetic subject keeps its novel poses.
const NOVEL_POSE: &str = "test/novel_pose";

impl Evaluation {
    /// The ground truth of `category` in the dataset at `root`; none where a frame lacks it.
    pub fn new(root: &Path, dataset: &Dataset, category: &str) -> Result<Self, NgdError> {
        let novel = root.join(NOVEL_POSE);
        let novel_pose = if novel.join(layout::MESHES).is_dir() {
            truth(&novel, &Dataset::open(&novel, dataset.downscale)?, "test", category)?
        } else {
            Vec::new()
        };
        Ok(Self {
            train: truth(root, dataset, "train", category)?,
            test: truth(root, dataset, "test", category)?,
            novel_pose,
        })
    }

    /// The fit's current metrics, or None without ground truth.
    pub fn measure(&self, fit: &Reconstruction) -> Result<Option<SplitGeometry>, NgdError> {
        let over = |frames: &[(FramePose, TriMesh)]| -> Result<Option<GeometryMetrics>, NgdError> {
            if frames.is_empty() {
                return Ok(None);
            }
            let mut sum = GeometryMetrics { chamfer_cm: 0.0, p2s_cm: 0.0, normal_consistency: 0.0 };
            for (i, (pose, truth)) in frames.iter().enumerate() {
                let m = geometry_metrics(&fit.posed(pose)?, truth, EVALUATION_SAMPLES, i as u64);
                sum.chamfer_cm += m.chamfer_cm / frames.len() as f64;
                sum.p2s_cm += m.p2s_cm / frames.len() as f64;
                sum.normal_consistency += m.normal_consistency / frames.len() as f64;
            }
            Ok(Some(sum))
        };
        let Some(train) = over(&self.train)? else { return Ok(None) };
        Ok(Some(SplitGeometry {
            train,
            test: over(&self.test)?,
            novel_pose: over(&self.novel_pose)?,
            frames: self.train.len() + self.test.len() + self.novel_pose.len(),
        }))
    }
}

/// The ground truth of `category` on up to [`EVALUATED_FRAMES`] frames evenly spread through the
/// split `name` of the dataset at `root`; none where the split or a frame's mesh is missing.
fn truth(
    root: &Path,
    dataset: &Dataset,
    name: &str,
    category: &str,
) -> Result<Vec<(FramePose, TriMesh)>, NgdError> {
    let Ok(split) = dataset.split(name) else { return Ok(Vec::new()) };
    let stride = split.frames.len().div_ceil(EVALUATED_FRAMES).max(1);
    let mut out = Vec::new();
    for k in (0..split.frames.len()).step_by(stride) {
        let path = layout::garment_mesh(root, category, split.frames[k]);
        if !path.exists() {
            return Ok(Vec::new());
        }
        let mesh = mannequin_mesh::ply::read(&path)
            .map_err(|source| NgdError::ReadMesh { path: path.clone(), source })?;
        out.push((FramePose::of(&split, k), mesh.mesh));
    }
    Ok(out)
}
