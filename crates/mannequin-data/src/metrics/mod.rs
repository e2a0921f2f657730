//! The metrics the papers report, computed as the reference implementations compute them.

pub mod geometry;
pub mod lpips;
pub mod normal_error;
pub mod point_triangle;
pub mod psnr;
pub mod ssim;
pub mod surface_distance;
pub mod surface_sampling;
