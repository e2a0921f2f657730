//! A person's own photo or video in: pretrained person models (detection, landmarks, masks) run
//! with tract, and the body fitted to what they find (thesis §2.2.2).

pub mod blazepose;
pub mod body_fit;
pub mod capture;
pub mod crop;
pub mod distance_transform;
pub mod error;
pub mod face_fit;
pub mod face_landmark_table;
pub mod face_landmarker;
pub mod face_models;
pub mod face_render;
pub mod face_texture;
pub mod interpenetration;
pub mod landmark_body;
pub mod levenberg_marquardt;
pub mod network;
pub mod overlay;
pub mod person_models;
pub mod pose_landmarker;
pub mod pose_prior;
pub mod rigid_alignment;
pub mod robust;
pub mod ssd_detector;

pub use body_fit::{BodyFit, fit_body};
pub use error::FitError;
pub use face_models::{Face, FaceModels};
pub use person_models::{Person, PersonModels, pick_person};
