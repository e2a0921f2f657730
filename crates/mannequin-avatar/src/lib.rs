//! Animatable avatars from monocular video: a canonical body mesh deformed by a hash-grid offset
//! field (Tavatar Eq. 4), posed by LBS, carrying Gaussians derived from the posed mesh and
//! rendered by differentiable splatting.

pub mod adam;
pub mod antialias;
pub mod avatar;
pub mod camera_rotation;
pub mod canonical;
pub mod checkpoint;
pub mod colour_init;
pub mod compute;
pub mod config;
pub mod error;
pub mod evaluation;
pub mod export;
pub mod export_files;
pub mod field;
pub mod fused_binding;
pub mod fused_mlp;
pub mod garment_layer;
pub mod gltf_animation;
pub mod hash_grid;
pub mod host_ops;
pub mod ihuman;
pub mod losses;
pub mod mesh_gaussians;
pub mod mlp;
pub mod one_ring_mesh;
pub mod options;
pub mod params;
pub mod pose_refinement;
pub mod predict;
pub mod render_map;
pub mod run;
pub mod settings;
pub mod sh_colour;
pub mod skirt_layer;
pub mod subject_mesh;
pub mod trainer;
pub mod training;
pub mod view_loss;
pub mod views;

pub use avatar::{Avatar, Posed, Rendered};
pub use canonical::Canonical;
pub use checkpoint::{Checkpoint, checkpoint_path};
pub use compute::Compute;
pub use config::{AVATAR_DILATION, AvatarConfig, Method};
pub use error::AvatarError;
pub use options::{HALF_RESOLUTION_SHARE, TrainOptions};
pub use predict::{Prediction, predict, predict_split};
pub use render_map::RenderMap;
pub use run::{GarmentRecord, TrainingRun};
pub use settings::TrainSettings;
pub use skirt_layer::SkirtMode;
pub use trainer::{StepStats, Timings, Trainer};
pub use training::Training;
pub use views::{View, frame_camera, load_views};
