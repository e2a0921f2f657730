//! The op on the CubeCL backends, in f32, on top of the fused SSIM's own kernels.

use burn::backend::TensorMetadata;
use burn::backend::ops::FloatTensorOps;
use burn::backend::tensor::FloatTensor;
use burn::backend::wgpu::{CubeBackend, CubeTensor};
use burn::tensor::TensorData;

use super::kernels::{loss_shares, map_gradient, pixel_gradients};
use super::{ImageLossBackend, ImageLossConfig};
use crate::cube_launch::{empty_f32, per_element, u32_of};
use crate::losses::SsimBackend;
use crate::losses::blur::{TAPS, as_f32};

type B = CubeBackend;

fn weights(config: &ImageLossConfig, like: &CubeTensor) -> CubeTensor {
    let n = config.weights.len();
    B::float_from_data(TensorData::new(config.weights.clone(), [n]), &like.device)
}

fn dims(pred: &CubeTensor) -> [usize; 3] {
    pred.shape().to_vec().try_into().expect("image loss inputs are [C, H, W]")
}

impl ImageLossBackend for CubeBackend {
    fn image_loss_forward(
        pred: FloatTensor<Self>,
        alpha: FloatTensor<Self>,
        target: FloatTensor<Self>,
        mask: FloatTensor<Self>,
        config: ImageLossConfig,
    ) -> (FloatTensor<Self>, FloatTensor<Self>) {
        let [c, h, w] = dims(&pred);
        let (pred, back) = as_f32(pred);
        let [alpha, target, mask] = [alpha, target, mask].map(|t| as_f32(t).0);
        let (map, moments) = <B as SsimBackend>::ssim_forward(pred.clone(), target.clone());
        let share = empty_f32(vec![h * w], &pred);
        let (count, dim) = per_element(&pred, h * w);
        loss_shares::launch(
            &pred.client,
            count,
            dim,
            pred.clone().into_buffer_arg(),
            target.into_buffer_arg(),
            alpha.into_buffer_arg(),
            mask.into_buffer_arg(),
            as_f32(map).0.into_buffer_arg(),
            weights(&config, &pred).into_buffer_arg(),
            share.clone().into_buffer_arg(),
            u32_of(c),
            u32_of(h),
            u32_of(w),
            config.lambda_ssim,
            config.lambda_mask,
        );
        (back(B::float_sum(share)), moments)
    }

    fn image_loss_backward(
        pred: FloatTensor<Self>,
        alpha: FloatTensor<Self>,
        target: FloatTensor<Self>,
        mask: FloatTensor<Self>,
        moments: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        config: ImageLossConfig,
    ) -> (FloatTensor<Self>, FloatTensor<Self>) {
        let [c, h, w] = dims(&pred);
        let (pred, back) = as_f32(pred);
        let [alpha, target, mask, grad] = [alpha, target, mask, grad].map(|t| as_f32(t).0);
        let weights = weights(&config, &pred);
        let (mh, mw) = (h + 1 - TAPS, w + 1 - TAPS);
        let d_map = empty_f32(vec![c, mh, mw], &pred);
        let (count, dim) = per_element(&pred, c * mh * mw);
        map_gradient::launch(
            &pred.client,
            count,
            dim,
            grad.clone().into_buffer_arg(),
            weights.clone().into_buffer_arg(),
            d_map.clone().into_buffer_arg(),
            u32_of(c),
            u32_of(h),
            u32_of(w),
            config.lambda_ssim,
        );
        let (d_ssim, _) =
            <B as SsimBackend>::ssim_backward(pred.clone(), target.clone(), moments, d_map, true, false);
        let (d_pred, d_alpha) = (empty_f32(vec![c, h, w], &pred), empty_f32(vec![h, w], &pred));
        let (count, dim) = per_element(&pred, h * w);
        let client = pred.client.clone();
        pixel_gradients::launch(
            &client,
            count,
            dim,
            pred.into_buffer_arg(),
            target.into_buffer_arg(),
            alpha.into_buffer_arg(),
            mask.into_buffer_arg(),
            as_f32(d_ssim).0.into_buffer_arg(),
            grad.into_buffer_arg(),
            weights.into_buffer_arg(),
            d_pred.clone().into_buffer_arg(),
            d_alpha.clone().into_buffer_arg(),
            u32_of(c),
            u32_of(h),
            u32_of(w),
            config.lambda_ssim,
            config.lambda_mask,
        );
        (back(d_pred), back(d_alpha))
    }
}
