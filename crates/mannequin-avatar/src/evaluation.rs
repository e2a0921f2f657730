//! Scoring a trained avatar: render it on a dataset's test sets (novel views and novel poses
//! where the dataset has them, else its own held-out test frames), score the renders against
//! the ground truth, and gather the scores in the one layout `mannequin eval --json` writes.

use std::path::{Path, PathBuf};

use burn::tensor::Device;
use mannequin_data::evaluation::{EvalOptions, evaluate};
use mannequin_data::{Dataset, Scores, TestPoses, TestSet};
use mannequin_io::staging::StagedDir;

use crate::avatar::Avatar;
use crate::error::AvatarError;
use crate::predict::predict_split;
use crate::test_pose_fit::{TestPoseMode, fit_test_poses};

/// The test sets of a dataset folder: `test/novel_view` and `test/novel_pose` as written by
/// `mannequin synth`, or else the folder's own test split (same camera, held-out frames).
fn test_sets(data: &Path) -> Vec<(TestSet, PathBuf)> {
    let nested: Vec<(TestSet, PathBuf)> = [TestSet::NovelView, TestSet::NovelPose]
        .into_iter()
        .map(|set| (set, data.join("test").join(set.name())))
        .filter(|(_, dir)| dir.is_dir())
        .collect();
    if nested.is_empty() { vec![(TestSet::Test, data.to_path_buf())] } else { nested }
}

/// Renders and scores every test set, at poses `test_poses` chooses per set, against the set's
/// own frames or the same frames of `truth` (see `mannequin eval --truth`). Predictions are written under temporary names in `MODEL`
/// and replace an earlier run's `MODEL/eval/<set>/` only once every set is scored, so a failed
/// evaluation leaves the model folder as it was.
/// `on_set(set, frames, poses)` is called before each set, `on_frame` after each pose fit, each
/// render and each score.
pub fn evaluate_avatar(
    model: &Path,
    data: &Path,
    truth: Option<&Path>,
    options: &EvalOptions,
    test_poses: TestPoseMode,
    on_set: &dyn Fn(TestSet, usize, TestPoses),
    on_frame: &dyn Fn(),
) -> Result<Scores, AvatarError> {
    let avatar = Avatar::load(model, &Device::flex())?;
    // Fitting poses needs gradients, rendering does not: a second copy, loaded when needed.
    let mut fitting: Option<Avatar> = None;
    let mut summaries = Vec::new();
    let mut staged = Vec::new();
    for (set, dir) in test_sets(data) {
        let dataset = Dataset::open(&dir, 1)?;
        let mut split = dataset.split("test")?;
        let frames = split.frames.clone();
        let out = model.join("eval").join(set.name());
        let temp = model.join(format!(".eval-{}.partial-{}", set.name(), std::process::id()));
        let stage = StagedDir::new(temp, out.clone()).map_err(mannequin_data::DataError::from)?;
        let poses = test_poses.resolve(dataset.origin.as_ref());
        on_set(set, frames.len(), poses);
        if let TestPoses::Fit { steps } = poses {
            let fitter = match &mut fitting {
                Some(a) => a,
                None => fitting.insert(Avatar::load(model, &Device::flex().autodiff())?),
            };
            split.poses = fit_test_poses(fitter, &dataset, &split, steps, on_frame)?;
        }
        predict_split(&avatar, &dataset, &split, stage.path(), on_frame)?;
        let mut summary = evaluate(stage.path(), truth.unwrap_or(&dir), &frames, options, &|_| on_frame())?;
        summary.pred = out;
        summary.test_poses = poses;
        summaries.push((set, summary));
        staged.push(stage);
    }
    for stage in staged {
        stage.keep().map_err(mannequin_data::DataError::from)?;
    }
    Ok(Scores::new(summaries))
}
