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
use crate::row_totals::row_totals;

type B = CubeBackend;

fn weights(config: &ImageLossConfig, like: &CubeTensor) -> CubeTensor {
    let n = config.weights.len();
    B::float_from_data(TensorData::new(config.weights.clone(), [n]), &like.device)
}

fn dims(t: &CubeTensor) -> [usize; 3] {
    t.shape().to_vec().try_into().expect("image loss images are [C, H, W]")
}

impl ImageLossBackend for CubeBackend {
    fn image_loss_forward(
        rendered: FloatTensor<Self>,
        target: FloatTensor<Self>,
        mask: FloatTensor<Self>,
        config: ImageLossConfig,
    ) -> (FloatTensor<Self>, FloatTensor<Self>, FloatTensor<Self>) {
        let [c, h, w] = dims(&target);
        let (rendered, back) = as_f32(rendered);
        let [target, mask] = [target, mask].map(|t| as_f32(t).0);
        // The SSIM compares the target's C channels with the first C planes.
        let (map, moments) = <B as SsimBackend>::ssim_forward(rendered.clone(), target.clone());
        let share = empty_f32(vec![2, h * w], &rendered);
        let (count, dim) = per_element(&rendered, h * w);
        loss_shares::launch(
            &rendered.client,
            count,
            dim,
            rendered.clone().into_buffer_arg(),
            target.into_buffer_arg(),
            mask.into_buffer_arg(),
            as_f32(map).0.into_buffer_arg(),
            weights(&config, &rendered).into_buffer_arg(),
            share.clone().into_buffer_arg(),
            u32_of(c),
            u32_of(h),
            u32_of(w),
            u32_of(config.alpha_plane),
            config.lambda_ssim,
            config.lambda_mask,
        );
        let [loss, mse] = <[CubeTensor; 2]>::try_from(row_totals(&share, h * w, 2))
            .unwrap_or_else(|_| unreachable!("two rows give two totals"));
        (back(loss), back(mse), moments)
    }

    fn image_loss_backward(
        rendered: FloatTensor<Self>,
        target: FloatTensor<Self>,
        mask: FloatTensor<Self>,
        moments: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        config: ImageLossConfig,
    ) -> FloatTensor<Self> {
        let [c, h, w] = dims(&target);
        let k = dims(&rendered)[0];
        let (rendered, back) = as_f32(rendered);
        let [target, mask, grad] = [target, mask, grad].map(|t| as_f32(t).0);
        let weights = weights(&config, &rendered);
        let (mh, mw) = (h + 1 - TAPS, w + 1 - TAPS);
        let d_map = empty_f32(vec![c, mh, mw], &rendered);
        let (count, dim) = per_element(&rendered, c * mh * mw);
        map_gradient::launch(
            &rendered.client,
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
            <B as SsimBackend>::ssim_backward(rendered.clone(), target.clone(), moments, d_map, true, false);
        let d_rendered = empty_f32(vec![k, h, w], &rendered);
        let (count, dim) = per_element(&rendered, h * w);
        let client = rendered.client.clone();
        pixel_gradients::launch(
            &client,
            count,
            dim,
            rendered.into_buffer_arg(),
            target.into_buffer_arg(),
            mask.into_buffer_arg(),
            as_f32(d_ssim).0.into_buffer_arg(),
            grad.into_buffer_arg(),
            weights.into_buffer_arg(),
            d_rendered.clone().into_buffer_arg(),
            u32_of(c),
            u32_of(k),
            u32_of(h),
            u32_of(w),
            u32_of(config.alpha_plane),
            config.lambda_ssim,
            config.lambda_mask,
        );
        back(d_rendered)
    }
}
