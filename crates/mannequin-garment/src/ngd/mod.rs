//! Garment reconstruction from a monocular video (NGD, seed 002): a base garment deformed through
//! per-face Jacobians and a Poisson solve, fitted to each frame's garment mask and normals.

mod dynamic_field;
mod loss;
mod pose_code;
mod reconstruction;
mod remesh;
mod scene;
mod static_field;
mod target;

pub use loss::{LossParts, LossWeights, image_loss};
pub use reconstruction::{Breakdown, DynamicSettings, Reconstruction, Settings, StepReport, TrainingFrame};
pub use remesh::RemeshSchedule;
pub use scene::{CHANNELS, FramePose};
pub use target::Target;
