//! The loss weights and schedule of a training run: what `mannequin train` records of them in
//! a checkpoint, and the seeds' defaults for each binding.

use crate::config::Method;

/// Where Tavatar's learning rates end, as a fraction of their start. Constant rates leave the
/// last iterations as noisy as the first: on synthetic subject 0 (2,000 iterations) decaying to
/// 0.1 raised novel-view PSNR from 29.9 to 32.3 dB and lowered the normal error from 8.1° to
/// 6.4° (3DGS decays its position rate likewise, to 0.01).
pub const FINAL_LR_FACTOR: f64 = 0.1;

/// Share of the iterations, from the start, trained on views at half resolution: their render
/// and image losses cost a quarter as much (the per-Gaussian render work, offset field,
/// optimiser and mesh terms do not shrink, so an iteration costs about three quarters of a
/// full-resolution one on the synthetic dress), and the first iterations fit shape and mean
/// colour, which half the pixels show as well.
pub const HALF_RESOLUTION_SHARE: f64 = 0.5;

/// Loss weights and switches.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct TrainOptions {
    /// Named in a run's record as `train --iters` names it.
    #[serde(rename = "iters")]
    pub iterations: usize,
    pub seed: u64,
    /// λ_SSIM of Eqs. 12–13.
    pub lambda_ssim: f64,
    /// λ_n (Tavatar 0.05; iHuman 1).
    pub lambda_normal: f64,
    /// λ_m for Laplacian + normal consistency (0.01).
    pub lambda_mesh: f64,
    /// λ_t of the equilateral regulariser, Eq. 14 (0.01; 0 for the "w/o ER" ablation).
    pub lambda_equilateral: f64,
    /// Weight of the L1 between rendered alpha and the mask.
    pub lambda_mask: f64,
    /// Tavatar's learning rates decay exponentially to this fraction of their start by the last
    /// iteration (1 keeps them constant).
    pub final_lr_factor: f64,
    /// Share of the iterations, from the start, on views at half resolution (0: none).
    pub half_resolution_share: f64,
    /// Whether each training frame's pose is refined with the avatar (`train --refine-poses`,
    /// resolved against the dataset's origin). Recorded only when on, so checkpoints from before
    /// refinement still resume.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub refine_poses: bool,
}

impl TrainOptions {
    /// The seeds' weights for `method`.
    pub fn new(method: Method, iterations: usize, seed: u64) -> Self {
        let ihuman = method == Method::Ihuman;
        Self {
            iterations,
            seed,
            lambda_ssim: 0.2,
            lambda_normal: if ihuman { 1.0 } else { 0.05 },
            lambda_mesh: 0.01,
            lambda_equilateral: if ihuman { 0.0 } else { 0.01 },
            lambda_mask: 0.1,
            final_lr_factor: FINAL_LR_FACTOR,
            half_resolution_share: HALF_RESOLUTION_SHARE,
            refine_poses: false,
        }
    }
}
