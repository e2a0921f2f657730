//! glTF 2.0 binary (`.glb`) export of a skinned mesh and its animation, with vertex caches beside
//! it, written with our own code so that the exact layout (bind pose, inverse bind matrices,
//! sampler times, morph keys) is under test.

mod blend_shapes;
mod buffer;
mod document;
mod glb;
mod glb_check;
pub mod influences;
mod model;
mod morph;
mod split;

pub use blend_shapes::{BlendShapeAnimation, BlendShapeMesh, write_blend_shape_glb};
pub use document::{scene_glb_bytes, write_glb, write_layered_glb, write_scene_glb};
pub use glb_check::check_glb;
pub use model::{SkeletalAnimation, Skeleton, SkinnedLayer, SkinnedMesh};
pub use morph::{MAX_MORPH_FRAMES, MorphSequence};
