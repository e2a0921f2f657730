//! The fused MLP op (f32) against the same network composed from Burn's ops in f64 and
//! differentiated by Burn's autodiff: same outputs and same gradients of the inputs, weights and
//! biases, for every width the op is compiled for, with inputs that switch ReLUs off; and its
//! kernels on the GPU against it on Flex.

use burn::tensor::{DType, Device, Tensor, TensorData};
use mannequin_avatar::fused_mlp::{WIDTHS, mlp, supports};
use mannequin_avatar::mlp::mlp_tensors;
use mannequin_io::rng::SplitMix64;

fn host(t: Tensor<2>) -> Vec<f32> {
    t.into_data().convert::<f32>().iter::<f32>().collect()
}

/// Every entry within `tol` of the reference, relative to the entry plus the reference's RMS.
fn assert_close(what: &str, got: &[f32], want: &[f32], tol: f32) {
    assert_eq!(got.len(), want.len(), "{what}: lengths");
    let rms = (want.iter().map(|x| x * x).sum::<f32>() / want.len() as f32).sqrt();
    assert!(rms > 0.0, "{what}: the reference is not all zero");
    for (i, (a, b)) in got.iter().zip(want).enumerate() {
        let e = (a - b).abs() / (b.abs() + rms);
        assert!(e <= tol, "{what}: entry {i}: {a} vs {b} (relative {e:e}, rms {rms})");
    }
}

/// Random inputs `x` `[n, i]`, weights and biases for widths `[i, h, o]`, with their shapes.
fn network(n: usize, [i, h, o]: [usize; 3], rng: &mut SplitMix64) -> Vec<(Vec<f32>, [usize; 2])> {
    [[n, i], [i, h], [1, h], [h, h], [1, h], [h, o], [1, o]]
        .into_iter()
        .map(|[r, c]| {
            let bound = (3.0 / r as f64).sqrt();
            ((0..r * c).map(|_| rng.range(-bound, bound) as f32).collect(), [r, c])
        })
        .collect()
}

/// The outputs, then the gradients of `(x, w0, b0, w1, b1, w2, b2)` under a random upstream
/// gradient, of the fused op or (`fused` false) the composition, on `device` in `dtype`.
fn outputs_and_gradients(
    net: &[(Vec<f32>, [usize; 2])],
    device: &Device,
    dtype: DType,
    fused: bool,
) -> Vec<Vec<f32>> {
    let t: Vec<Tensor<2>> = net
        .iter()
        .map(|(v, s)| Tensor::<2>::from_data(TensorData::new(v.clone(), *s), (device, dtype)).require_grad())
        .collect();
    let out = if fused {
        mlp(
            t[0].clone(),
            [t[1].clone(), t[3].clone(), t[5].clone()],
            [t[2].clone(), t[4].clone(), t[6].clone()],
        )
    } else {
        mlp_tensors(t[0].clone(), [1, 3, 5].into_iter().map(|l| (t[l].clone(), t[l + 1].clone())))
    };
    let [n, o] = out.dims();
    let mut w = SplitMix64::new(2);
    let weights: Vec<f32> = (0..n * o).map(|_| w.range(-1.0, 1.0) as f32).collect();
    let weights = Tensor::<2>::from_data(TensorData::new(weights, [n, o]), (device, dtype));
    let grads = (out.clone() * weights).sum().backward();
    let mut all = vec![host(out)];
    all.extend(t.iter().map(|t| host(t.grad(&grads).expect("every input gets a gradient"))));
    all
}

const NAMES: [&str; 8] = ["outputs", "dx", "dw0", "db0", "dw1", "db1", "dw2", "db2"];

#[test]
fn fused_mlp_matches_the_composition_and_its_autodiff() {
    assert!(supports(&[32, 64, 64, 3]) && !supports(&[32, 64, 32, 3]) && !supports(&[32, 64, 3]));
    let device = Device::flex().autodiff();
    let mut rng = SplitMix64::new(9);
    for widths in WIDTHS {
        // Not a multiple of the op's row chunks or blocks.
        let net = network(1237, widths, &mut rng);
        let got = outputs_and_gradients(&net, &device, DType::F32, true);
        let want = outputs_and_gradients(&net, &device, DType::F64, false);
        for ((name, a), b) in NAMES.iter().zip(&got).zip(&want) {
            assert_close(&format!("{widths:?} {name}"), a, b, 1e-5);
        }
    }
}

/// The op's kernels against its Flex twin: the same outputs and gradients on the GPU (lavapipe on
/// machines without one), with as many rows as the avatar's heads see. The GPU sums the weight
/// gradients over the rows in another order than Flex's row chunks, hence 1e-4.
#[test]
fn wgpu_matches_flex() {
    let gpu = mannequin_splat::gpu_device().unwrap_or_else(|e| panic!("{e}")).autodiff();
    let flex = Device::flex().autodiff();
    let mut rng = SplitMix64::new(5);
    for widths in WIDTHS {
        // Not a multiple of the kernels' cubes.
        let net = network(7001, widths, &mut rng);
        let got = outputs_and_gradients(&net, &gpu, DType::F32, true);
        let want = outputs_and_gradients(&net, &flex, DType::F32, true);
        for ((name, a), b) in NAMES.iter().zip(&got).zip(&want) {
            assert_close(&format!("{widths:?} {name}"), a, b, 1e-4);
        }
    }
}
