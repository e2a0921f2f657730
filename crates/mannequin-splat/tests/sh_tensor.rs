//! The tensor SH basis against the slice basis (itself checked against gsplat), and its
//! gradient against finite differences.

use burn::tensor::{DType, Device, Tensor, TensorData};
use mannequin_splat::sh::{basis, basis_len, basis_tensor};

fn directions() -> Vec<[f64; 3]> {
    (0..7)
        .map(|i| {
            let t = i as f64 * 0.9 + 0.3;
            let v = [t.cos() * (1.3 * t).sin(), (0.7 * t).cos(), t.sin() - 0.2];
            let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            v.map(|x| x / n)
        })
        .collect()
}

fn tensor(dirs: &[[f64; 3]], device: &Device) -> Tensor<2> {
    let flat: Vec<f64> = dirs.iter().flatten().copied().collect();
    Tensor::from_data(TensorData::new(flat, [dirs.len(), 3]), (device, DType::F64))
}

#[test]
fn tensor_basis_matches_slice_basis() {
    let device = Device::flex();
    let dirs = directions();
    for degree in 0..=2 {
        let got: Vec<f64> =
            basis_tensor(degree, tensor(&dirs, &device)).unwrap().into_data().iter::<f64>().collect();
        let k = basis_len(degree);
        for (i, d) in dirs.iter().enumerate() {
            let mut want = vec![0.0f64; k];
            basis(degree, *d, &mut want);
            for j in 0..k {
                assert!((got[i * k + j] - want[j]).abs() < 1e-12, "degree {degree} dir {i} basis {j}");
            }
        }
    }
    assert!(basis_tensor(3, tensor(&dirs, &device)).is_err());
}

#[test]
fn tensor_basis_gradient_matches_finite_differences() {
    let device = Device::flex().autodiff();
    let dirs = directions();
    let weights: Vec<f64> = (0..dirs.len() * 9).map(|i| ((i * 37 % 11) as f64 - 5.0) / 5.0).collect();
    let w = Tensor::<2>::from_data(TensorData::new(weights.clone(), [dirs.len(), 9]), (&device, DType::F64));
    let x = tensor(&dirs, &device).require_grad();
    let grads = (basis_tensor(2, x.clone()).unwrap() * w).sum().backward();
    let g: Vec<f64> = x.grad(&grads).unwrap().into_data().iter::<f64>().collect();
    let value = |d: [f64; 3], i: usize| {
        let mut b = [0.0; 9];
        basis(2, d, &mut b);
        b.iter().zip(&weights[i * 9..]).map(|(a, w)| a * w).sum::<f64>()
    };
    let h = 1e-6;
    for (i, d) in dirs.iter().enumerate() {
        for c in 0..3 {
            let (mut p, mut m) = (*d, *d);
            p[c] += h;
            m[c] -= h;
            let fd = (value(p, i) - value(m, i)) / (2.0 * h);
            assert!((g[i * 3 + c] - fd).abs() < 1e-7, "dir {i} axis {c}: {} vs {fd}", g[i * 3 + c]);
        }
    }
}
