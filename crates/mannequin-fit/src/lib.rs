//! A person's own photo or video in: pretrained person models (detection, landmarks, masks) run
//! with tract, and the body fitted to what they find (thesis §2.2.2); the face model fitted to a
//! portrait or followed through a video (thesis §2.3); a video captured to a dataset. Each
//! pipeline behind one settings struct the command line embeds.

pub mod blazepose;
pub mod body_fit;
pub mod body_photo;
pub mod capture;
mod capture_checkpoint;
mod capture_dataset;
pub mod clip_fit;
pub mod crop;
pub mod distance_transform;
pub mod error;
pub mod face_fit;
pub mod face_landmark_table;
pub mod face_landmarker;
pub mod face_models;
pub mod face_photo;
pub mod face_render;
pub mod face_texture;
pub mod face_track;
mod face_track_checkpoint;
pub mod fit_check;
pub mod fit_settings;
pub mod frame_source;
pub mod head_mesh;
pub mod interpenetration;
pub mod landmark_body;
pub mod levenberg_marquardt;
pub mod network;
pub mod output;
pub mod overlay;
pub mod person_models;
pub mod person_search;
pub mod pose_error;
pub mod pose_landmarker;
pub mod pose_prior;
pub mod rigid_alignment;
pub mod robust;
pub mod ssd_detector;

pub use body_fit::{BodyFit, fit_body};
pub use capture::{CaptureSettings, capture};
pub use error::FitError;
pub use face_models::{Face, FaceModels};
pub use face_track::{FaceTrackSettings, track_face};
pub use fit_settings::FitSettings;
pub use person_models::{Person, PersonModels, pick_person};
