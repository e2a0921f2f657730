//! Splatting as a differentiable Burn operation, on the Flex (CPU) and CubeCL (wgpu, CUDA)
//! backends, with the hand-written backward pass.
//!
//! ```
//! use burn::tensor::{Device, Tensor};
//! use mannequin_splat::{Camera, ColorTensor, RenderOptions, RotationTensor, splat_render};
//! let device = Device::flex().autodiff();
//! let camera = Camera::look_at([0.0, 0.0, 3.0], [0.0; 3], [0.0, 1.0, 0.0], 0.8, 64, 48);
//! let means = Tensor::<2>::from_floats([[0.0, 0.0, 0.0]], &device).require_grad();
//! let images = splat_render(
//!     means.clone(),
//!     RotationTensor::Quaternions(Tensor::from_floats([[1.0, 0.0, 0.0, 0.0]], &device)),
//!     Tensor::from_floats([[0.1, 0.1, 0.1]], &device),
//!     Tensor::from_floats([0.8], &device),
//!     ColorTensor::Features(Tensor::from_floats([[1.0, 0.5, 0.2]], &device)),
//!     &camera,
//!     &RenderOptions::default(),
//! )
//! .unwrap();
//! let grads = images.image().sum().backward();
//! assert!(means.grad(&grads).is_some());
//! ```

mod autodiff;
mod binning;
mod config;
mod cube;
mod device_buffers;
mod flex;
mod host;
mod kernels;
mod project_kernels;
mod radix_sort;
mod saved;
mod scan;

pub use config::SplatConfig;
pub use project_kernels::{sh_basis, sh_basis_vjp};

use burn::backend::tensor::FloatTensor;
use burn::backend::{Backend, Dispatch, backend_extension};
use burn::tensor::Tensor;

use crate::{Camera, RenderOptions, SplatError, sh};

/// Orientation of each Gaussian, as a tensor.
pub enum RotationTensor {
    /// `[N, 4]` quaternions `(w, x, y, z)`, normalised inside the op.
    Quaternions(Tensor<2>),
    /// `[N, 3, 3]` matrices whose columns are the Gaussian's axes (a mesh-derived frame).
    Matrices(Tensor<3>),
}

/// Per-Gaussian colour, as a tensor.
pub enum ColorTensor {
    /// `[N, (degree+1)², 3]` SH coefficients, evaluated along the view ray (3DGS convention).
    Sh { degree: usize, coeffs: Tensor<3> },
    /// `[N, C]` features composited as they are (normals, for instance).
    Features(Tensor<2>),
}

/// What [`splat_render`] returns; the images are differentiable.
pub struct SplatImages {
    /// `[C + 2, H, W]`: colour or features over the background (C planes), accumulated opacity
    /// and expected camera-space depth, stacked as the op renders them. A loss that reads them
    /// in place spares the device the slices (copies, where a plane is not aligned).
    pub planes: Tensor<3>,
    /// The op's saved state, where the count of skipped Gaussians is.
    saved: Tensor<1>,
}

impl SplatImages {
    fn plane(&self, k: usize) -> Tensor<2> {
        let [_, h, w] = self.planes.dims();
        self.planes.clone().narrow(0, k, 1).reshape([h, w])
    }

    /// `[C, H, W]` colour or features over the background.
    pub fn image(&self) -> Tensor<3> {
        let c = self.planes.dims()[0] - 2;
        self.planes.clone().narrow(0, 0, c)
    }

    /// `[H, W]` accumulated opacity.
    pub fn alpha(&self) -> Tensor<2> {
        self.plane(self.planes.dims()[0] - 2)
    }

    /// `[H, W]` expected camera-space depth.
    pub fn depth(&self) -> Tensor<2> {
        self.plane(self.planes.dims()[0] - 1)
    }

    /// `[1]`: how many Gaussians were skipped for a NaN or infinite parameter (a whole number,
    /// exact up to 2²⁴). It stays on the device until asked for (a slice of the saved state: a
    /// copy on a GPU).
    pub fn skipped(&self) -> Tensor<1> {
        self.saved.clone().narrow(0, saved::SKIPPED, 1)
    }
}

/// Backends that can splat. Inputs are flat `[N, k]` float tensors (means, rotations, scales,
/// opacities as `[N, 1]`, colours); [`splat_render`] is the friendly entry point.
#[backend_extension(Flex, Cube, Autodiff)]
pub trait SplatBackend: Backend {
    /// Returns `[C + 2, H, W]` (colour, alpha, expected depth) and the state the backward pass
    /// needs, as an opaque float tensor.
    fn splat_forward(
        means: FloatTensor<Self>,
        rotations: FloatTensor<Self>,
        scales: FloatTensor<Self>,
        opacities: FloatTensor<Self>,
        colors: FloatTensor<Self>,
        config: SplatConfig,
    ) -> (FloatTensor<Self>, FloatTensor<Self>);

    /// Gradients of the five inputs given the gradient `grad` of the rendered `[C + 2, H, W]`.
    #[allow(clippy::too_many_arguments, clippy::type_complexity)]
    fn splat_backward(
        means: FloatTensor<Self>,
        rotations: FloatTensor<Self>,
        scales: FloatTensor<Self>,
        opacities: FloatTensor<Self>,
        colors: FloatTensor<Self>,
        rendered: FloatTensor<Self>,
        saved: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        config: SplatConfig,
    ) -> (FloatTensor<Self>, FloatTensor<Self>, FloatTensor<Self>, FloatTensor<Self>, FloatTensor<Self>);
}

fn shape_error(field: &'static str, expected: usize, found: usize) -> SplatError {
    SplatError::Shape { field, expected, found }
}

/// Renders Gaussians given as tensors, differentiably on devices with autodiff enabled. Works
/// on Flex and on the CubeCL backends; the device is the one the tensors live on.
///
/// Shapes, camera and options are checked here. Per-Gaussian values are not (that would need a
/// read-back from the device): NaN or infinite Gaussians are skipped and counted
/// ([`SplatImages::skipped`]), and others are rendered as the formulas say, so keep scales
/// positive and opacities in `[0, 1]`.
pub fn splat_render(
    means: Tensor<2>,
    rotations: RotationTensor,
    scales: Tensor<2>,
    opacities: Tensor<1>,
    colors: ColorTensor,
    camera: &Camera,
    options: &RenderOptions,
) -> Result<SplatImages, SplatError> {
    let [n, three] = means.dims();
    if three != 3 {
        return Err(shape_error("means (per Gaussian)", 3, three));
    }
    let check = |field, found: [usize; 2], per: usize| {
        if found == [n, per] { Ok(()) } else { Err(shape_error(field, n * per, found[0] * found[1])) }
    };
    check("scales", scales.dims(), 3)?;
    check("opacities", [opacities.dims()[0], 1], 1)?;
    let (rotations, matrices) = match rotations {
        RotationTensor::Quaternions(q) => {
            check("rotations (quaternions)", q.dims(), 4)?;
            (q, false)
        }
        RotationTensor::Matrices(m) => {
            let [a, b, c] = m.dims();
            check("rotations (matrices)", [a, b * c], 9)?;
            if [b, c] != [3, 3] {
                return Err(shape_error("rotations (matrices) per Gaussian", 9, b * c));
            }
            (m.reshape([n, 9]), true)
        }
    };
    let (colors, sh_degree, color_len) = match colors {
        ColorTensor::Sh { degree, coeffs } => {
            if degree > sh::MAX_DEGREE {
                return Err(SplatError::Options(format!(
                    "SH degree {degree} is not supported (0 to {})",
                    sh::MAX_DEGREE
                )));
            }
            let [a, k, c] = coeffs.dims();
            let per = 3 * sh::basis_len(degree);
            check("SH coefficients", [a, k * c], per)?;
            if c != 3 {
                return Err(shape_error("SH coefficients per basis", 3, c));
            }
            (coeffs.reshape([n, per]), Some(degree), per)
        }
        ColorTensor::Features(f) => {
            let [a, c] = f.dims();
            if c == 0 {
                return Err(SplatError::Options("features need at least one channel".into()));
            }
            check("features", [a, c], c)?;
            (f, None, c)
        }
    };
    let config = SplatConfig {
        camera: camera.clone(),
        options: options.clone(),
        matrices,
        sh_degree,
        color_len,
        header: Default::default(),
    };
    camera.validate()?;
    config.options_checked()?;
    let (rendered, saved) = <Dispatch as SplatBackend>::splat_forward(
        means.into_dispatch(),
        rotations.into_dispatch(),
        scales.into_dispatch(),
        opacities.reshape([n, 1]).into_dispatch(),
        colors.into_dispatch(),
        config,
    );
    Ok(SplatImages { planes: Tensor::<3>::from_dispatch(rendered), saved: Tensor::<1>::from_dispatch(saved) })
}
