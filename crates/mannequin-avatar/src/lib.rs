//! Animatable avatars from monocular video: a canonical body mesh deformed by a hash-grid offset
//! field (Tavatar Eq. 4), posed by LBS, carrying Gaussians derived from the posed mesh and
//! rendered by differentiable splatting.

pub mod hash_grid;
pub mod losses;
