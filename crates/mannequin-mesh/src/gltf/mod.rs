//! glTF 2.0 binary (`.glb`) export of a skinned mesh and its animation, written with our own code
//! so that the exact layout (bind pose, inverse bind matrices, sampler times) is under test.

mod buffer;
mod document;
mod glb;
mod influences;
mod model;
mod split;

pub use document::write_glb;
pub use model::{SkeletalAnimation, Skeleton, SkinnedMesh};
