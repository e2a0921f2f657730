//! The one mesh rasteriser. [`hard`] gives each pixel its nearest triangle, depth and
//! perspective-correct barycentrics, and shades it (ground truth, overlays); [`differentiable`]
//! builds on it, interpolating per-vertex attributes and antialiasing silhouettes so that an
//! image loss reaches the vertices (garment fit, silhouettes).
//!
//! It sits above `mannequin-data` only for the image types it fills ([`mannequin_data::Image`],
//! masks, normal and depth maps).

pub mod differentiable;
pub mod hard;

pub use hard::{NEAR, NO_FACE, Raster, RasterMesh, Shading, rasterize, sample_bilinear};
