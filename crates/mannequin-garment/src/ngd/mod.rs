//! Garment reconstruction from a monocular video (NGD, seed 002): a base garment deformed through
//! per-face Jacobians and a Poisson solve, fitted to each frame's garment mask and normals.

mod loss;
mod reconstruction;
mod scene;
mod target;

pub use loss::{LossParts, image_loss};
pub use reconstruction::{Breakdown, Reconstruction, Settings, StepReport, TrainingFrame};
pub use scene::{CHANNELS, FramePose};
pub use target::Target;
