//! Held-out frames fitted before they are scored (issue 36): where a dataset's poses were
//! estimated, each test frame's pose and translation are fitted to its image with the avatar
//! frozen, as InstantAvatar, GART, 3DGS-Avatar and Anim-NeRF do before scoring, so the score
//! measures the avatar and not the pose estimate. The objective is training's, on that frame.

use burn::tensor::Tensor;
use mannequin_data::{Dataset, Origin, PoseOrigin, Poses, Split, TestPoses};

use crate::avatar::{Avatar, Posed};
use crate::error::AvatarError;
use crate::options::TrainOptions;
use crate::pose_refinement::PoseRefinement;
use crate::view_loss::view_loss;
use crate::views::{View, load_views};

/// Steps of the fit per test frame: fitting an image of the avatar itself from a shoulder 0.3 rad
/// and 3.6 cm off takes 150 to bring the shoulder within 0.1 rad (50 steps leave 0.19 rad, 100
/// leave 0.12; tests/pose_refinement.rs).
pub const TEST_POSE_STEPS: usize = 150;
/// The fit's learning rates, as multiples of training's refinement rates: a frozen avatar gives
/// a clean gradient, and the fit has few steps.
const LR_SCALE: f64 = 2.5;
/// Where the rates end, as a fraction of their start.
const FINAL_LR_FACTOR: f64 = 0.1;

/// Which poses a test set is rendered at.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum TestPoseMode {
    /// Fitted where the dataset says its poses were estimated, else as they are.
    Auto,
    /// The dataset's poses as they are.
    AsIs,
    /// Each fitted to its image first.
    Fit,
}

impl TestPoseMode {
    pub fn resolve(self, origin: Option<&Origin>) -> TestPoses {
        let fit = match self {
            Self::AsIs => false,
            Self::Fit => true,
            Self::Auto => origin.is_some_and(|o| o.poses == PoseOrigin::Estimated),
        };
        if fit { TestPoses::Fit { steps: TEST_POSE_STEPS } } else { TestPoses::AsIs }
    }
}

/// `view`'s pose and translation fitted to its targets from where the view has them, `avatar`
/// (with its `personalised` mesh) frozen, in `steps` steps of training's objective on that view.
pub fn fit_view_pose(
    avatar: &Avatar,
    personalised: Tensor<2>,
    view: &View,
    steps: usize,
    options: &TrainOptions,
) -> Result<PoseRefinement, AvatarError> {
    let mut pose = PoseRefinement::new(std::slice::from_ref(view), avatar.device());
    for step in 0..steps {
        let (theta, transl) = pose.pose(0, true);
        let vertices = avatar.skin_tensor(personalised.clone(), theta, transl);
        let gaussians = avatar.bind(&vertices);
        let posed = Posed { personalised: personalised.clone(), vertices, gaussians };
        let rendered = avatar.render(&posed, &view.crop_camera())?;
        let (loss, _) = view_loss(&rendered, view, options)?;
        let grads = (loss + pose.prior(0)).backward();
        let factor = LR_SCALE * FINAL_LR_FACTOR.powf(step as f64 / steps.max(1) as f64);
        pose.update(&grads, factor, 0).map_err(|e| match e {
            AvatarError::NonFinitePose { frame, .. } => {
                AvatarError::Invalid(format!("the pose fitted to test frame {frame} stopped being finite"))
            }
            e => e,
        })?;
    }
    Ok(pose)
}

/// `split`'s poses fitted to its frames of `dataset`, `avatar` frozen (it must live on an
/// autodiff device), in `steps` steps each; `on_frame` is called after each frame.
pub fn fit_test_poses(
    avatar: &Avatar,
    dataset: &Dataset,
    split: &Split,
    steps: usize,
    on_frame: &dyn Fn(),
) -> Result<Poses, AvatarError> {
    let views = load_views(dataset, split, |_, _| {})?;
    let options = TrainOptions::new(avatar.config.method, steps, 0);
    // The avatar is frozen: its personalised mesh is the same for every frame.
    let personalised = avatar.personalised(avatar.offsets()?).detach();
    let mut fitted = split.poses.select(&[]);
    for view in &views {
        fitted.append(
            &fit_view_pose(avatar, personalised.clone(), view, steps, &options)?.poses(&split.poses.betas),
        );
        on_frame();
    }
    Ok(fitted)
}
