//! Garment reconstruction from a monocular video (NGD, seed 002): a base garment deformed through
//! per-face Jacobians and a Poisson solve, fitted to each frame's garment mask and normals; the
//! pipeline from a dataset to the fitted garment (`garment fit`), and the garments a clothed
//! avatar wears as layers (`train --garments`).

mod dynamic_field;
mod error;
mod evaluation;
mod kept;
pub mod layers;
mod legend;
mod loss;
mod pipeline;
mod pose_code;
mod reconstruction;
mod remesh;
mod scene;
mod settings;
mod static_field;
mod target;

pub use error::NgdError;
pub use loss::{LossParts, LossWeights, image_loss};
pub use pipeline::{FittedGarment, reconstruct};
pub use reconstruction::{Breakdown, DynamicSettings, Reconstruction, Settings, StepReport, TrainingFrame};
pub use remesh::RemeshSchedule;
pub use scene::{CHANNELS, FramePose};
pub use settings::NgdSettings;
pub use target::Target;
