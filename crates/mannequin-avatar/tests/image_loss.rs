//! The fused image loss on wgpu (lavapipe on machines without a GPU) against its composition
//! on Flex (`photometric_weighted` plus the mask's mean L1), an independent formulation: the
//! value and the gradients of the prediction and of alpha, on six channels with unequal weights,
//! and shapes that do not match are refused.

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

/// The loss and the gradients of the prediction and alpha.
fn run(
    device: &Device,
    [c, h, w]: [usize; 3],
    loss: impl Fn(Tensor<3>, Tensor<2>, Tensor<3>, Tensor<2>) -> Tensor<1>,
) -> [Vec<f32>; 3] {
    let image = |seed| Tensor::<3>::from_data(TensorData::new(random(c * h * w, seed), [c, h, w]), device);
    let plane = |seed| Tensor::<2>::from_data(TensorData::new(random(h * w, seed), [h, w]), device);
    let (pred, alpha) = (image(1).require_grad(), plane(2).require_grad());
    let value = loss(pred.clone(), alpha.clone(), image(3), plane(4));
    let grads = value.clone().backward();
    [values(value), values(pred.grad(&grads).expect("pred")), values(alpha.grad(&grads).expect("alpha"))]
}

fn config() -> ImageLossConfig {
    ImageLossConfig {
        weights: vec![0.3, 0.4, 0.2, 0.05, 0.1, 0.15],
        lambda_ssim: 0.2,
        lambda_mask: LAMBDA_MASK,
    }
}

#[test]
fn the_fused_image_loss_matches_its_composition() {
    let shape = [6, 23, 31];
    let c = config();
    let weights: Vec<f64> = c.weights.iter().map(|&x| f64::from(x)).collect();
    let composed = run(&Device::flex().autodiff(), shape, |pred, alpha, target, mask| {
        photometric_weighted(pred, target, f64::from(c.lambda_ssim), &weights).expect("loss")
            + (alpha - mask).abs().mean() * f64::from(LAMBDA_MASK)
    });
    let fused = run(&wgpu().autodiff(), shape, |pred, alpha, target, mask| {
        image_loss(pred, alpha, target, mask, &c).expect("loss")
    });
    for (name, (want, got)) in ["loss", "d pred", "d alpha"].iter().zip(composed.iter().zip(&fused)) {
        let scale = want.iter().fold(0f32, |m, w| m.max(w.abs()));
        let worst = want.iter().zip(got).map(|(w, g)| (w - g).abs()).fold(0f32, f32::max);
        // f32 sums over a few thousand pixels in another order.
        assert!(worst <= 1e-4 * scale, "{name}: worst difference {worst} against a scale of {scale}");
    }
}

#[test]
fn images_that_do_not_match_are_refused() {
    let gpu = wgpu();
    let pred = Tensor::<3>::zeros([6, 16, 16], &gpu);
    let err = image_loss(
        pred.clone(),
        Tensor::zeros([16, 16], &gpu),
        Tensor::zeros([6, 16, 15], &gpu),
        Tensor::zeros([16, 16], &gpu),
        &config(),
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("do not match"), "{err}");
    let small = Tensor::<3>::zeros([6, 8, 8], &gpu);
    let err =
        image_loss(small.clone(), Tensor::zeros([8, 8], &gpu), small, Tensor::zeros([8, 8], &gpu), &config())
            .unwrap_err()
            .to_string();
    assert!(err.contains("H, W ≥ 11"), "{err}");
}
