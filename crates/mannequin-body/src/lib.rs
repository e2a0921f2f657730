//! SMPL-family body models: loading, the embedded default body, forward kinematics and linear
//! blend skinning (fast CPU path and a differentiable Burn path), and motion files.

pub mod default_body;
pub mod error;
pub mod face_model;
pub mod gait_cycle;
pub mod kinematics;
pub mod lbs;
pub mod lbs_tensor;
pub mod load_body;
pub mod model;
pub mod motion;
pub mod motion_clip;
pub mod named_pose;
pub mod rodrigues;
pub mod settling;
pub mod skinned_export;
pub mod smpl_joint;
pub mod smpl_npz;
pub mod weight_transfer;

pub use error::BodyError;
pub use face_model::FaceModel;
pub use lbs::{PosedFrames, ShapedBody, forward, frame_skinning, pose_corrected, pose_frames, shape_body};
pub use lbs_tensor::{BodyTensors, PosedTensors, Rig, forward_tensors, rodrigues_tensor, skin_tensors};
pub use load_body::{LoadBodyError, load_body};
pub use model::{BodyModel, BodyModelParts, ModelFamily};
pub use motion::Motion;
pub use named_pose::{POSE_NAMES, named_pose};
pub use settling::Settling;
pub use skinned_export::{skeletal_animation, skinned_body};
pub use smpl_npz::{load_model, parse_model};
