//! The fused renderer features on wgpu (lavapipe on machines without a GPU) against their
//! composition on Flex (the fused colour, a product by the rotation's transpose and a
//! concatenation, differentiated by Burn): the features and the gradients of the means, the SH
//! coefficients and the normals, degrees 0–3, the colour's clamp exercised.

use burn::tensor::{DType, Device, Tensor, TensorData};
use mannequin_avatar::render_features::{FeaturesConfig, render_features};
use mannequin_avatar::sh_colour::{ColourConfig, sh_colour};
use mannequin_io::rng::SplitMix64;

fn host(t: Tensor<2>) -> Vec<f32> {
    t.into_data().iter::<f32>().collect()
}

/// Every entry within `tol` of the reference, relative to the entry plus the reference's RMS.
fn assert_close(what: &str, got: &[f32], want: &[f32], tol: f32) {
    assert_eq!(got.len(), want.len(), "{what}: lengths");
    let rms = (want.iter().map(|x| x * x).sum::<f32>() / want.len() as f32).sqrt();
    for (i, (a, b)) in got.iter().zip(want).enumerate() {
        // Degree 0 has no view dependence: both give exact zeros for the means.
        let e = if a == b { 0.0 } else { (a - b).abs() / (b.abs() + rms) };
        assert!(e <= tol, "{what}: entry {i}: {a} vs {b} (relative {e:e}, rms {rms})");
    }
}

/// A rotation about an oblique axis (Rodrigues), row-major.
fn rotation() -> [f32; 9] {
    let (axis, angle) = ([0.48f64, -0.6, 0.64], 0.9f64);
    let n = axis.iter().map(|a| a * a).sum::<f64>().sqrt();
    let [x, y, z] = axis.map(|a| a / n);
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    [
        t * x * x + c,
        t * x * y - s * z,
        t * x * z + s * y,
        t * x * y + s * z,
        t * y * y + c,
        t * y * z - s * x,
        t * x * z - s * y,
        t * y * z + s * x,
        t * z * z + c,
    ]
    .map(|v| v as f32)
}

#[test]
fn fused_features_on_wgpu_match_their_composition_on_flex() {
    let mut rng = SplitMix64::new(5);
    let g = 1500;
    let mut random =
        |n: usize, lo: f64, hi: f64| -> Vec<f32> { (0..n).map(|_| rng.range(lo, hi) as f32).collect() };
    let means = random(3 * g, -0.5, 0.5);
    let normals = random(3 * g, -1.0, 1.0);
    let w = random(6 * g, -1.0, 1.0);
    let r = rotation();
    let gpu = mannequin_splat::gpu_device().unwrap_or_else(|e| panic!("{e}"));
    for degree in 0..=3 {
        let k3 = 3 * (degree + 1) * (degree + 1);
        let coeffs = random(g * k3, -2.5, 2.5);
        let colour = ColourConfig { eye: [0.3, 0.2, 3.0], degree };
        let run = |device: &Device, fused: bool| {
            let device = device.clone().autodiff();
            let t = |v: &Vec<f32>, width| {
                Tensor::<2>::from_data(TensorData::new(v.clone(), [g, width]), (&device, DType::F32))
            };
            let (m, c, n) =
                (t(&means, 3).require_grad(), t(&coeffs, k3).require_grad(), t(&normals, 3).require_grad());
            let features = if fused {
                let config = FeaturesConfig { colour: colour.clone(), rotation: r };
                render_features(m.clone(), c.clone(), n.clone(), &config)
            } else {
                let rt: Vec<f32> = (0..9).map(|k| r[(k % 3) * 3 + k / 3]).collect();
                let rt = Tensor::<2>::from_data(TensorData::new(rt, [3, 3]), (&device, DType::F32));
                Tensor::cat(vec![sh_colour(m.clone(), c.clone(), &colour), n.clone().matmul(rt)], 1)
            };
            let grads = (features.clone() * t(&w, 6)).sum().backward();
            let grad = |x: &Tensor<2>| host(x.grad(&grads).expect("a gradient"));
            [host(features), grad(&m), grad(&c), grad(&n)]
        };
        let want = run(&Device::flex(), false);
        let got = run(&gpu, true);
        let zeros = want[0].chunks(6).flat_map(|f| &f[..3]).filter(|&&x| x == 0.0).count();
        assert!(zeros > g / 20, "degree {degree}: the clamp is exercised");
        for (name, (got, want)) in
            ["features", "d means", "d coefficients", "d normals"].iter().zip(got.iter().zip(&want))
        {
            assert_close(&format!("degree {degree}: {name}"), got, want, 1e-4);
        }
    }
}
