//! Differentiable 3D Gaussian splatting (Kerbl et al. 2023), forward and backward.
//!
//! The renderer follows the 3DGS rules with gsplat 1.5's conventions: EWA projection with a
//! 0.3 px low-pass, 16×16 tiles with a per-tile depth order, front-to-back compositing with alpha
//! capped at 0.99, contributions under 1/255 skipped, and a stop once transmittance would fall to
//! 1e-4. Colours are spherical harmonics up to degree 3 (3DGS's `+0.5` offset and clamp at 0) or
//! arbitrary per-Gaussian features.
//!
//! Three ways in:
//! - [`render`] and [`backward`]: the CPU renderer on slices, generic over `f32`/`f64` (rayon,
//!   16-lane rows, no per-pixel allocation);
//! - [`splat_render`]: the same as a differentiable Burn op on tensors, on Flex (the CPU code in
//!   place) and on the CubeCL backends (device kernels throughout: projection, binning by a
//!   stable radix sort, compositing, and both backward passes);
//! - [`SplatScene`]: 3DGS `.ply` files in the INRIA layout.
//!
//! ```
//! use mannequin_splat::{Camera, Colors, Gaussians, RenderOptions, Rotations, render};
//! let camera = Camera::look_at([0.0, 1.0, 2.5], [0.0, 1.0, 0.0], [0.0, 1.0, 0.0], 0.8, 64, 48);
//! let g = Gaussians {
//!     means: &[0.0f32, 1.0, 0.0],
//!     rotations: Rotations::Quaternions(&[1.0, 0.0, 0.0, 0.0]),
//!     scales: &[0.1, 0.1, 0.1],
//!     opacities: &[0.8],
//!     colors: Colors::Features { channels: 3, values: &[1.0, 0.5, 0.2] },
//! };
//! let out = render(&g, &camera, &RenderOptions::default()).unwrap();
//! assert_eq!(out.image.len(), 3 * 64 * 48);
//! ```

mod camera;
pub mod camera_file;
pub mod camera_json;
mod composite;
mod composite_vjp;
mod error;
pub mod framing;
mod gaussians;
mod gpu;
mod op;
mod planes;
pub mod ply;
mod project;
mod real;
mod render;
pub mod sh;
mod tiles;

pub use camera::Camera;
pub use camera_file::read_camera;
pub use camera_json::parse_camera_json;
pub use error::SplatError;
pub use framing::{box_centre, clip_camera, front_camera};
pub use gaussians::{Colors, GaussianGrads, Gaussians, Rotations};
pub use gpu::{GpuUnavailable, gpu_device};
pub use op::{ColorTensor, RotationTensor, SplatBackend, SplatConfig, SplatImages, splat_render};
pub use ply::SplatScene;
pub use project::{DILATION, EXTENT_SIGMA, Projection};
pub use real::Real;
pub use render::{OutputGrads, RenderOptions, RenderOutput, backward, project_gaussians, render};

/// Side of a square screen tile, in pixels.
pub const TILE: usize = 16;
