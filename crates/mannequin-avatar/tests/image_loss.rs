//! The fused image loss on wgpu (lavapipe on machines without a GPU) against its composition
//! on Flex (`photometric_weighted` plus the mask's mean L1 over slices of the rendered planes),
//! an independent formulation: the value, the colour MSE and the gradient of the rendered planes,
//! on six and three channels with unequal weights; shapes that do not match are refused.

use burn::tensor::{Device, Tensor, TensorData};
use mannequin_avatar::losses::image_loss::{ImageLossConfig, image_loss};
use mannequin_avatar::losses::photometric_weighted;
use mannequin_io::rng::SplitMix64;

const LAMBDA_MASK: f32 = 0.3;

fn wgpu() -> Device {
    mannequin_splat::gpu_device().unwrap_or_else(|e| panic!("{e}"))
}

fn random(n: usize, seed: u64) -> Vec<f32> {
    let mut rng = SplitMix64::new(seed);
    (0..n).map(|_| rng.range(0.0, 1.0) as f32).collect()
}

fn values<const D: usize>(t: Tensor<D>) -> Vec<f32> {
    t.into_data().iter::<f32>().collect()
}

/// Rendered planes: the compared channels, two planes the loss ignores, alpha, depth.
const PLANES: usize = 8;
const ALPHA: usize = 6;

/// The loss, the colour MSE and the gradient of the rendered planes, for a target of `c`
/// channels.
fn run(
    device: &Device,
    [c, h, w]: [usize; 3],
    loss: impl Fn(Tensor<3>, Tensor<3>, Tensor<2>) -> (Tensor<1>, Tensor<1>),
) -> [Vec<f32>; 3] {
    let image = |k, seed| Tensor::<3>::from_data(TensorData::new(random(k * h * w, seed), [k, h, w]), device);
    let rendered = image(PLANES, 1).require_grad();
    let mask = Tensor::<2>::from_data(TensorData::new(random(h * w, 4), [h, w]), device);
    let (value, mse) = loss(rendered.clone(), image(c, 3), mask);
    let grads = value.clone().backward();
    [values(value), values(mse), values(rendered.grad(&grads).expect("rendered"))]
}

fn config(channels: usize) -> ImageLossConfig {
    ImageLossConfig {
        weights: [0.3, 0.4, 0.2, 0.05, 0.1, 0.15][..channels].to_vec(),
        lambda_ssim: 0.2,
        lambda_mask: LAMBDA_MASK,
        alpha_plane: ALPHA,
    }
}

/// With normals (six channels) and without (three): the loss, the colour MSE, and the gradient
/// of every plane, the unread ones (zero) included.
#[test]
fn the_fused_image_loss_matches_its_composition() {
    for channels in [6, 3] {
        let shape = [channels, 23, 31];
        let c = config(channels);
        let weights: Vec<f64> = c.weights.iter().map(|&x| f64::from(x)).collect();
        let composed = run(&Device::flex().autodiff(), shape, |rendered, target, mask| {
            let [_, h, w] = rendered.dims();
            let pred = rendered.clone().narrow(0, 0, channels);
            let alpha = rendered.clone().narrow(0, ALPHA, 1).reshape([h, w]);
            let mse = (rendered.narrow(0, 0, 3).detach() - target.clone().narrow(0, 0, 3)).square().mean();
            let loss = photometric_weighted(pred, target, f64::from(c.lambda_ssim), &weights).expect("loss")
                + (alpha - mask).abs().mean() * f64::from(LAMBDA_MASK);
            (loss, mse)
        });
        let fused = run(&wgpu().autodiff(), shape, |rendered, target, mask| {
            let out = image_loss(rendered, target, mask, &c).expect("loss");
            (out.loss, out.colour_mse)
        });
        for (name, (want, got)) in
            ["loss", "colour MSE", "d rendered"].iter().zip(composed.iter().zip(&fused))
        {
            let scale = want.iter().fold(0f32, |m, w| m.max(w.abs()));
            let worst = want.iter().zip(got).map(|(w, g)| (w - g).abs()).fold(0f32, f32::max);
            // f32 sums over a few thousand pixels in another order.
            assert!(
                worst <= 1e-4 * scale,
                "{channels} channels, {name}: worst difference {worst} against a scale of {scale}"
            );
        }
    }
}

#[test]
fn images_that_do_not_match_are_refused() {
    let gpu = wgpu();
    let planes = Tensor::<3>::zeros([PLANES, 16, 16], &gpu);
    let refused = |rendered: Tensor<3>, target: Tensor<3>, config: ImageLossConfig| {
        let [_, h, w] = target.dims();
        image_loss(rendered, target, Tensor::zeros([h, w], &gpu), &config).err().expect("refused").to_string()
    };
    let err = refused(planes.clone(), Tensor::zeros([6, 16, 15], &gpu), config(6));
    assert!(err.contains("do not match"), "{err}");
    let alpha_in_the_channels = ImageLossConfig { alpha_plane: 5, ..config(6) };
    let err = refused(planes.clone(), Tensor::zeros([6, 16, 16], &gpu), alpha_in_the_channels);
    assert!(err.contains("do not match"), "{err}");
    let alpha_past_the_planes = ImageLossConfig { alpha_plane: PLANES, ..config(6) };
    let err = refused(planes, Tensor::zeros([6, 16, 16], &gpu), alpha_past_the_planes);
    assert!(err.contains("do not match"), "{err}");
    let err = refused(Tensor::zeros([PLANES, 8, 8], &gpu), Tensor::zeros([6, 8, 8], &gpu), config(6));
    assert!(err.contains("H, W"), "{err}");
}
