//! Training losses of Tavatar §4.3 as differentiable tensor functions: the photometric loss
//! (Eqs. 12–13, built on [`ssim`]), and the mesh regularisers on a fixed topology: Laplacian
//! smoothness and normal consistency (Eq. 15) and the equilateral term (Eq. 14).

pub mod blur;
mod equilateral;
pub mod image_loss;
mod laplacian;
pub mod mesh_loss;
mod normal_consistency;
mod photometric;
mod regularisers;
mod rows;
mod ssim;

pub use blur::{BlurBackend, gaussian_blur_valid, gaussian_window};
pub use photometric::{LAMBDA_SSIM, photometric, photometric_weighted};
pub use regularisers::MeshRegularisers;
pub use ssim::{SsimBackend, ssim, ssim_map, ssim_with_blur};
