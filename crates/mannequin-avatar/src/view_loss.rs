//! The image terms of the training loss on one view (Eq. 12 on colour, Eq. 13 on normals where
//! the view has them, and an L1 between rendered alpha and the mask), shared by training and by
//! fitting a test frame's pose with the avatar frozen, so both chase the same objective. On a
//! GPU the image terms are one fused op ([`crate::losses::image_loss`]).

use burn::tensor::{Tensor, TensorData};

use crate::avatar::{ALPHA_PLANE, Rendered};
use crate::error::AvatarError;
use crate::host_ops;
use crate::losses::image_loss::{ImageLossConfig, image_loss};
use crate::losses::photometric_weighted;
use crate::options::TrainOptions;
use crate::views::View;

/// The loss of `r` against `view`'s targets, and the colour MSE (detached, for PSNR).
pub fn view_loss(r: &Rendered, view: &View, o: &TrainOptions) -> Result<(Tensor<1>, Tensor<1>), AvatarError> {
    let crop = &view.crop;
    let device = r.planes.device();
    let (channels, h, w) = (view.target_channels(), crop.height, crop.width);
    let target: Tensor<3> =
        Tensor::from_data(TensorData::new(view.targets.clone(), [channels, h, w]), &device);
    // Eq. 12 on colour and Eq. 13 on normals in one pass over the stacked image.
    let weights: Vec<f64> = if view.has_normals() {
        [1.0 / 3.0; 3].into_iter().chain([o.lambda_normal / 3.0; 3]).collect()
    } else {
        vec![1.0 / 3.0; 3]
    };
    let mask: Tensor<2> = Tensor::from_data(TensorData::new(view.mask.clone(), [h, w]), &device);
    if host_ops::on_cube(&device) {
        let config = ImageLossConfig {
            weights: weights.iter().map(|&x| x as f32).collect(),
            lambda_ssim: o.lambda_ssim as f32,
            lambda_mask: o.lambda_mask as f32,
            alpha_plane: ALPHA_PLANE,
        };
        let out = image_loss(r.planes.clone(), target, mask, &config)?;
        return Ok((out.loss, out.colour_mse));
    }
    let mse = (r.rgb().detach() - target.clone().narrow(0, 0, 3)).square().mean();
    let pred = if view.has_normals() { r.image() } else { r.rgb() };
    let loss = photometric_weighted(pred, target, o.lambda_ssim, &weights)?;
    Ok((loss + (r.alpha() - mask).abs().mean() * o.lambda_mask, mse))
}
