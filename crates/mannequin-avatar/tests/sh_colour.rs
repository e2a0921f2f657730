//! The fused colour op (f32) against the tensor composition in f64, differentiated by Burn's
//! autodiff: same colours and same gradients of the means and the coefficients, for degrees 0–2,
//! with coefficients that push some channels below zero so the clamp is exercised; and the CubeCL
//! kernels (wgpu) against Flex, degrees 0–3.

use burn::tensor::{DType, Device, Tensor, TensorData};
use mannequin_avatar::sh_colour::{ColourConfig, sh_colour, sh_colour_tensors};
use mannequin_io::rng::SplitMix64;

fn host(t: Tensor<2>) -> Vec<f32> {
    t.into_data().convert::<f32>().iter::<f32>().collect()
}

/// Every entry within `tol` of the reference, relative to the entry plus the reference's RMS.
fn assert_close(what: &str, got: &[f32], want: &[f32], tol: f32) {
    assert_eq!(got.len(), want.len(), "{what}: lengths");
    let rms = (want.iter().map(|x| x * x).sum::<f32>() / want.len() as f32).sqrt();
    for (i, (a, b)) in got.iter().zip(want).enumerate() {
        let e = (a - b).abs() / (b.abs() + rms);
        assert!(e <= tol, "{what}: entry {i}: {a} vs {b} (relative {e:e}, rms {rms})");
    }
}

#[test]
fn fused_colour_matches_the_tensor_composition_and_its_autodiff() {
    let device = Device::flex().autodiff();
    let mut rng = SplitMix64::new(3);
    let g = 3000;
    // A body-sized cloud, seen from 3 m.
    let means: Vec<f32> = (0..g)
        .flat_map(|_| [rng.range(-0.4, 0.4), rng.range(-0.9, 0.9), rng.range(-0.2, 0.2)])
        .map(|x| x as f32)
        .collect();
    let config = |degree| ColourConfig { eye: [0.3, 0.2, 3.0], degree };
    for degree in 0..=2 {
        let k3 = 3 * (degree + 1) * (degree + 1);
        let coeffs: Vec<f32> = (0..g * k3).map(|_| rng.range(-2.5, 2.5) as f32).collect();
        let inputs = |dtype: DType| {
            let t = |v: &Vec<f32>, w| {
                Tensor::<2>::from_data(TensorData::new(v.clone(), [g, w]), (&device, dtype))
            };
            (t(&means, 3).require_grad(), t(&coeffs, k3).require_grad())
        };
        let colour = |fused: bool, m: Tensor<2>, c: Tensor<2>| {
            if fused {
                sh_colour(m, c, &config(degree))
            } else {
                sh_colour_tensors(m, c, &config(degree)).unwrap()
            }
        };
        let (m32, c32) = inputs(DType::F32);
        let (m64, c64) = inputs(DType::F64);
        let (got, want) = (host(colour(true, m32, c32)), host(colour(false, m64, c64)));
        assert!(
            want.iter().filter(|&&x| x == 0.0).count() > g / 20,
            "degree {degree}: the clamp is exercised"
        );
        assert_close(&format!("degree {degree}: colours"), &got, &want, 1e-5);

        let w: Vec<f32> = (0..g * 3).map(|_| rng.range(-1.0, 1.0) as f32).collect();
        let gradients = |fused: bool| {
            let (m, c) = inputs(if fused { DType::F32 } else { DType::F64 });
            let w = Tensor::<2>::from_data(TensorData::new(w.clone(), [g, 3]), (&device, m.dtype()));
            let grads = (colour(fused, m.clone(), c.clone()) * w).sum().backward();
            (m.grad(&grads).map(host), host(c.grad(&grads).unwrap()))
        };
        let ((dm, dc), (dm_ref, dc_ref)) = (gradients(true), gradients(false));
        let dm = dm.expect("the op always returns a mean gradient");
        match dm_ref {
            Some(dm_ref) => assert_close(&format!("degree {degree}: mean gradients"), &dm, &dm_ref, 1e-4),
            // Degree 0 does not depend on the view: the composition has no path to the means.
            None => assert!(degree == 0 && dm.iter().all(|&x| x == 0.0), "degree {degree}: mean gradients"),
        }
        assert_close(&format!("degree {degree}: coefficient gradients"), &dc, &dc_ref, 1e-5);
    }
}

/// The CubeCL kernels (wgpu; lavapipe where there is no GPU) against the Flex op, through
/// Autodiff: same colours and same gradients of the means and coefficients, degrees 0–3, the
/// clamp exercised. Both run the same f32 formulas, so they agree to rounding (1e-4 relative).
#[test]
fn fused_colour_on_wgpu_matches_flex() {
    let mut rng = SplitMix64::new(11);
    let g = 2000;
    let means: Vec<f32> = (0..g)
        .flat_map(|_| [rng.range(-0.4, 0.4), rng.range(-0.9, 0.9), rng.range(-0.2, 0.2)])
        .map(|x| x as f32)
        .collect();
    let gpu = mannequin_splat::gpu_device().unwrap_or_else(|e| panic!("{e}"));
    for degree in 0..=3 {
        let config = ColourConfig { eye: [0.3, 0.2, 3.0], degree };
        let k3 = 3 * (degree + 1) * (degree + 1);
        let coeffs: Vec<f32> = (0..g * k3).map(|_| rng.range(-2.5, 2.5) as f32).collect();
        let w: Vec<f32> = (0..g * 3).map(|_| rng.range(-1.0, 1.0) as f32).collect();
        let run = |device: &Device| {
            let device = device.clone().autodiff();
            let t = |v: &Vec<f32>, width| {
                Tensor::<2>::from_data(TensorData::new(v.clone(), [g, width]), (&device, DType::F32))
            };
            let (m, c) = (t(&means, 3).require_grad(), t(&coeffs, k3).require_grad());
            let colour = sh_colour(m.clone(), c.clone(), &config);
            let grads = (colour.clone() * t(&w, 3)).sum().backward();
            (host(colour), host(m.grad(&grads).unwrap()), host(c.grad(&grads).unwrap()))
        };
        let (want, dm_want, dc_want) = run(&Device::flex());
        let (got, dm, dc) = run(&gpu);
        assert!(
            want.iter().filter(|&&x| x == 0.0).count() > g / 20,
            "degree {degree}: the clamp is exercised"
        );
        assert_close(&format!("degree {degree}: wgpu colours"), &got, &want, 1e-4);
        if degree > 0 {
            assert_close(&format!("degree {degree}: wgpu mean gradients"), &dm, &dm_want, 1e-4);
        } else {
            assert!(dm.iter().chain(&dm_want).all(|&x| x == 0.0), "degree 0: mean gradients are zero");
        }
        assert_close(&format!("degree {degree}: wgpu coefficient gradients"), &dc, &dc_want, 1e-4);
    }
}
