//! Pose refinement (issue 36): each training frame's body pose (every joint, the global
//! orientation with them) and root translation become parameters, initialised from the
//! dataset's and optimised with the avatar, as InstantAvatar, GART and 3DGS-Avatar refine their
//! estimated SMPL poses. Estimated poses are off by centimetres; an avatar trained on them as
//! they are blurs and misplaces limbs. A prior keeps each pose near its estimate and near its
//! neighbouring frames'.

use burn::tensor::{Device, Gradients, Tensor};
use mannequin_data::{Origin, PoseOrigin, Poses};
use mannequin_io::{Npz, NpzWriter};

use crate::adam::Adam;
use crate::error::AvatarError;
use crate::params::{Param, host, tensor_from};
use crate::views::View;

/// Learning rate of the axis-angle pose (radians per step at most, Adam's scale).
pub const POSE_LR: f64 = 1.5e-2;
/// Learning rate of the root translation (metres per step at most).
pub const TRANSL_LR: f64 = 3e-3;
/// Share of the iterations, from the start, before the poses move: the avatar must first look
/// like the person, or the photometric gradient pulls the poses towards a blur.
pub const START_SHARE: f64 = 0.1;
/// Weight of Σ‖θ − θ₀‖² (radians²): a weak pull towards the estimate for joints the images
/// barely constrain (wrists, feet).
pub const LAMBDA_POSE_PRIOR: f64 = 1e-3;
/// Weight of ‖t − t₀‖² (m²).
pub const LAMBDA_TRANSL_PRIOR: f64 = 1e-1;
/// Weight of the squared difference to each neighbouring frame's pose and translation: a
/// video's consecutive frames move little.
pub const LAMBDA_SMOOTH: f64 = 1e-2;

/// Checkpoint member prefixes of the refined poses and their optimiser.
const PARAM_PREFIX: &str = "refine/";
const ADAM_PREFIX: &str = "refine_";

/// Whether `train` refines the poses: `auto` does where the dataset says they were estimated
/// (`capture` writes so), not where they are the truth or the dataset does not say.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum RefinePoses {
    Auto,
    On,
    Off,
}

impl RefinePoses {
    pub fn resolve(self, origin: Option<&Origin>) -> bool {
        match self {
            Self::On => true,
            Self::Off => false,
            Self::Auto => origin.is_some_and(|o| o.poses == PoseOrigin::Estimated),
        }
    }
}

/// The training views' poses as parameters, their estimates, and their optimiser.
pub struct PoseRefinement {
    frames: Vec<usize>,
    /// Per view, `pose/<frame>` [1, 72] then `transl/<frame>` [1, 3].
    params: Vec<Param>,
    /// The estimates the prior pulls towards, in the same order.
    initial: Vec<Tensor<2>>,
    adam: Adam,
}

impl PoseRefinement {
    pub fn new(views: &[View], device: &Device) -> Self {
        let mut params = Vec::with_capacity(2 * views.len());
        for v in views {
            let pose = tensor_from(v.pose.clone(), 1, v.pose.len(), device);
            params.push(Param::new(&format!("pose/{:05}", v.frame), pose, POSE_LR));
            params.push(Param::new(
                &format!("transl/{:05}", v.frame),
                tensor_from(v.transl.to_vec(), 1, 3, device),
                TRANSL_LR,
            ));
        }
        let initial = params.iter().map(|p| p.value.clone().detach()).collect();
        let adam = Adam::new(&params);
        Self { frames: views.iter().map(|v| v.frame).collect(), params, initial, adam }
    }

    /// View `k`'s pose [1, 72] and translation [1, 3]; detached while `learning` is false.
    pub fn pose(&self, k: usize, learning: bool) -> (Tensor<2>, Tensor<2>) {
        let (p, t) = (self.params[2 * k].value.clone(), self.params[2 * k + 1].value.clone());
        if learning { (p, t) } else { (p.detach(), t.detach()) }
    }

    /// The prior on view `k`: its distance to its estimate and to its neighbouring frames'
    /// current poses (held fixed, so only view `k` moves).
    pub fn prior(&self, k: usize) -> Tensor<1> {
        let (pose, transl) = self.pose(k, true);
        let sq = |a: Tensor<2>, b: Tensor<2>| (a - b).square().sum();
        let mut loss = sq(pose.clone(), self.initial[2 * k].clone()) * LAMBDA_POSE_PRIOR
            + sq(transl.clone(), self.initial[2 * k + 1].clone()) * LAMBDA_TRANSL_PRIOR;
        let neighbours = [k.checked_sub(1), Some(k + 1)];
        for n in neighbours.into_iter().flatten().filter(|&n| n < self.frames.len()) {
            if self.frames[n].abs_diff(self.frames[k]) == 1 {
                let (np, nt) = self.pose(n, false);
                loss = loss + (sq(pose.clone(), np) + sq(transl.clone(), nt)) * LAMBDA_SMOOTH;
            }
        }
        loss
    }

    /// One Adam step of every pose that received a gradient, at `lr_factor` times the base
    /// rates; then refuses view `k`'s pose if it stopped being finite.
    pub fn update(&mut self, grads: &Gradients, lr_factor: f64, k: usize) -> Result<(), AvatarError> {
        for (i, p) in self.params.iter_mut().enumerate() {
            p.lr = lr_factor * if i % 2 == 0 { POSE_LR } else { TRANSL_LR };
        }
        self.adam.update(&mut self.params, grads);
        let values = host(self.params[2 * k].value.clone())
            .into_iter()
            .chain(host(self.params[2 * k + 1].value.clone()));
        if values.into_iter().any(|x| !x.is_finite()) {
            return Err(AvatarError::NonFinitePose { frame: self.frames[k], checkpoint: String::new() });
        }
        Ok(())
    }

    /// The refined poses in the dataset's pose format, with the dataset's `betas`.
    pub fn poses(&self, betas: &[f32]) -> Poses {
        let mut out = Poses {
            betas: betas.to_vec(),
            global_orient: Vec::new(),
            body_pose: Vec::new(),
            transl: Vec::new(),
        };
        for pair in self.params.chunks_exact(2) {
            let pose = host(pair[0].value.clone());
            let t = host(pair[1].value.clone());
            out.global_orient.push([pose[0], pose[1], pose[2]]);
            out.body_pose.extend_from_slice(&pose[3..]);
            out.transl.push([t[0], t[1], t[2]]);
        }
        out
    }

    pub fn save(&self, w: &mut NpzWriter) {
        for p in &self.params {
            p.save(w, PARAM_PREFIX);
        }
        self.adam.save(&self.params, w, ADAM_PREFIX);
    }

    /// Restores poses and optimiser saved by [`PoseRefinement::save`], `step` steps in.
    pub fn load(&mut self, npz: &Npz, step: usize) -> Result<(), AvatarError> {
        for p in &mut self.params {
            p.load(npz, PARAM_PREFIX, mannequin_io::limits::FLOAT32)?;
        }
        self.adam = Adam::load(&self.params, npz, step, ADAM_PREFIX)?;
        Ok(())
    }
}
