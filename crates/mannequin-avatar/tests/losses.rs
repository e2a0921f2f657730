//! The training losses against independent references: SSIM (the fused op, and the formulation
//! from Burn's ops around the blur op) against the evaluation metric of `mannequin-data`
//! (checked against scikit-image), the blur against a direct 11×11 window,
//! gradients against central differences in f64, the mesh regularisers against values worked
//! out by hand, the GPU (wgpu) forms against Flex, and bad input against clear errors.

use std::collections::HashMap;
use std::sync::Arc;

use burn::tensor::{DType, Device, Tensor, TensorData};
use mannequin_avatar::AvatarError;
use mannequin_avatar::losses::mesh_loss::{HostMesh, HostTerm, MeshLoss, mesh_loss};
use mannequin_avatar::losses::{
    MeshRegularisers, gaussian_blur_valid, gaussian_window, photometric, photometric_weighted, ssim,
    ssim_map, ssim_with_blur,
};
use mannequin_avatar::one_ring_mesh::OneRingMesh;
use mannequin_data::Image;
use mannequin_data::metrics::ssim::ssim as metric_ssim;
use mannequin_io::rng::SplitMix64;

fn tensor<const D: usize>(v: &[f64], shape: [usize; D], device: &Device, dtype: DType) -> Tensor<D> {
    Tensor::from_data(TensorData::new(v.to_vec(), shape), (device, dtype))
}

fn values<const D: usize>(t: Tensor<D>) -> Vec<f64> {
    t.into_data().convert::<f64>().iter::<f64>().collect()
}

fn scalar(t: Tensor<1>) -> f64 {
    values(t)[0]
}

/// A `[3, H, W]` tensor's values as the metric's image (values are f32 either way).
fn image(v: &[f64], h: usize, w: usize) -> Image {
    let pixels = (0..h * w).map(|p| [0, 1, 2].map(|c| v[c * h * w + p] as f32)).collect();
    Image { width: w, height: h, pixels }
}

/// Uniform values in [0, 1], rounded to f32 so both precisions see the same image.
fn random_image(rng: &mut SplitMix64, n: usize) -> Vec<f64> {
    (0..n).map(|_| rng.uniform() as f32 as f64).collect()
}

/// A smooth `[3, H, W]` image and a copy with Gaussian noise, clamped to [0, 1].
fn smooth_and_noisy(h: usize, w: usize, noise: f64, seed: u64) -> (Vec<f64>, Vec<f64>) {
    let mut rng = SplitMix64::new(seed);
    let mut clean = Vec::new();
    for c in 0..3 {
        for y in 0..h {
            for x in 0..w {
                let (u, v) = (x as f64 / w as f64, y as f64 / h as f64);
                let s = 0.5 + 0.3 * (6.0 * u + c as f64).sin() * (4.0 * v).cos() + 0.1 * (15.0 * u * v).sin();
                clean.push(s as f32 as f64);
            }
        }
    }
    let noisy = clean.iter().map(|&s| ((s + noise * rng.normal()).clamp(0.0, 1.0)) as f32 as f64).collect();
    (clean, noisy)
}

/// Mean SSIM as a function of the two images.
type SsimFn = fn(Tensor<3>, Tensor<3>) -> Tensor<1>;

/// The fused op and the composite formulation.
fn both_ssims() -> [(&'static str, SsimFn); 2] {
    [
        ("fused", |x, y| ssim(x, y).unwrap()),
        ("composite", |x, y| ssim_with_blur(x, y, |t| gaussian_blur_valid(t).unwrap()).unwrap()),
    ]
}

fn assert_ssim_matches(a: &[f64], b: &[f64], h: usize, w: usize, what: &str) {
    let want = metric_ssim(&image(a, h, w), &image(b, h, w)).unwrap();
    let device = Device::flex();
    for (name, f) in both_ssims() {
        for (dtype, tol) in [(DType::F64, 1e-12), (DType::F32, 1e-5)] {
            let got = scalar(f(tensor(a, [3, h, w], &device, dtype), tensor(b, [3, h, w], &device, dtype)));
            assert!((got - want).abs() < tol, "{what}, {name} {dtype:?}: {got} vs metric {want}");
        }
    }
}

#[test]
fn ssim_matches_the_metric_on_random_images() {
    let mut rng = SplitMix64::new(11);
    for (h, w) in [(11, 11), (17, 23), (40, 31)] {
        let a = random_image(&mut rng, 3 * h * w);
        let b: Vec<f64> = a.iter().map(|&v| (0.7 * v + 0.3 * rng.uniform()) as f32 as f64).collect();
        assert_ssim_matches(&a, &b, h, w, &format!("random {h}×{w}"));
    }
}

#[test]
fn ssim_matches_the_metric_on_a_smooth_image_and_a_noisy_copy() {
    let (h, w) = (64, 96);
    let (clean, noisy) = smooth_and_noisy(h, w, 0.05, 5);
    let s = metric_ssim(&image(&clean, h, w), &image(&noisy, h, w)).unwrap();
    assert!(s > 0.3 && s < 0.95, "a noisy copy should be similar, not identical: {s}");
    assert_ssim_matches(&clean, &noisy, h, w, "smooth vs noisy");
}

#[test]
fn identical_images_give_ssim_one_and_zero_loss() {
    let (h, w) = (30, 45);
    let (clean, _) = smooth_and_noisy(h, w, 0.0, 1);
    let device = Device::flex();
    for dtype in [DType::F32, DType::F64] {
        let x = tensor(&clean, [3, h, w], &device, dtype);
        for (name, f) in both_ssims() {
            assert_eq!(scalar(f(x.clone(), x.clone())), 1.0, "{name} {dtype:?}");
        }
        assert_eq!(scalar(photometric(x.clone(), x, 0.2).unwrap()), 0.0, "{dtype:?}");
    }
}

#[test]
fn ssim_map_covers_the_valid_window_positions_of_a_crop() {
    let (h, w) = (15, 26);
    let (a, b) = smooth_and_noisy(h, w, 0.1, 3);
    let device = Device::flex();
    let map =
        ssim_map(tensor(&a, [3, h, w], &device, DType::F64), tensor(&b, [3, h, w], &device, DType::F64));
    let map = map.unwrap();
    assert_eq!(map.dims(), [3, h - 10, w - 10]);
    let mean = values(map).iter().sum::<f64>() / (3 * (h - 10) * (w - 10)) as f64;
    assert!((mean - metric_ssim(&image(&a, h, w), &image(&b, h, w)).unwrap()).abs() < 1e-12);
}

#[test]
fn blur_equals_a_direct_two_dimensional_window() {
    let (n, h, w) = (2, 14, 19);
    let x = random_image(&mut SplitMix64::new(2), n * h * w);
    let got = values(gaussian_blur_valid(tensor(&x, [n, h, w], &Device::flex(), DType::F64)).unwrap());
    let g = gaussian_window();
    let (oh, ow) = (h - 10, w - 10);
    assert_eq!(got.len(), n * oh * ow);
    for p in 0..n {
        for y in 0..oh {
            for xo in 0..ow {
                let mut want = 0.0;
                for (i, gi) in g.iter().enumerate() {
                    for (j, gj) in g.iter().enumerate() {
                        want += gi * gj * x[(p * h + y + i) * w + xo + j];
                    }
                }
                let v = got[(p * oh + y) * ow + xo];
                assert!((v - want).abs() < 1e-14, "plane {p} ({y}, {xo}): {v} vs {want}");
            }
        }
    }
}

/// Compares the autodiff gradient of `f` at `x` with central differences, in f64 on Flex.
fn check_gradient<const D: usize>(
    what: &str,
    x: &[f64],
    shape: [usize; D],
    f: impl Fn(Tensor<D>) -> Tensor<1>,
) {
    let device = Device::flex().autodiff();
    let leaf = tensor(x, shape, &device, DType::F64).require_grad();
    let grads = f(leaf.clone()).backward();
    let analytic = values(leaf.grad(&grads).expect("the loss depends on its input"));
    let plain = Device::flex();
    let at = |v: &[f64]| scalar(f(tensor(v, shape, &plain, DType::F64)));
    let h = 1e-6;
    let scale = analytic.iter().fold(1e-3f64, |m, g| m.max(g.abs()));
    for i in 0..x.len() {
        let (mut up, mut down) = (x.to_vec(), x.to_vec());
        up[i] += h;
        down[i] -= h;
        let numeric = (at(&up) - at(&down)) / (2.0 * h);
        assert!(
            (analytic[i] - numeric).abs() < 1e-6 * scale,
            "{what}[{i}]: autodiff {} vs finite differences {numeric}",
            analytic[i]
        );
    }
}

#[test]
fn ssim_gradients_match_finite_differences() {
    let (c, h, w) = (2, 13, 12);
    let mut rng = SplitMix64::new(4);
    let a = random_image(&mut rng, c * h * w);
    let b = random_image(&mut rng, c * h * w);
    for (name, f) in both_ssims() {
        check_gradient(&format!("{name}: d SSIM / d pred"), &a, [c, h, w], |x| {
            let target = tensor(&b, [c, h, w], &x.device(), DType::F64);
            f(x, target)
        });
        // Symmetric in its arguments, but the op computes each gradient separately.
        check_gradient(&format!("{name}: d SSIM / d target"), &b, [c, h, w], |y| {
            f(tensor(&a, [c, h, w], &y.device(), DType::F64), y)
        });
        // Both at once: the same image on both sides, at S = 1, where the gradient vanishes.
        check_gradient(&format!("{name}: d SSIM(x, x) / dx"), &a, [c, h, w], |x| f(x.clone(), x));
    }
}

#[test]
fn photometric_is_the_weighted_sum_and_has_the_right_gradient() {
    let (h, w) = (12, 14);
    let mut rng = SplitMix64::new(8);
    let a = random_image(&mut rng, 3 * h * w);
    let b = random_image(&mut rng, 3 * h * w);
    let l1 = a.iter().zip(&b).map(|(p, q)| (p - q).abs()).sum::<f64>() / a.len() as f64;
    let want = 0.2 * (1.0 - metric_ssim(&image(&a, h, w), &image(&b, h, w)).unwrap()) + 0.8 * l1;
    let device = Device::flex();
    let got = photometric(
        tensor(&a, [3, h, w], &device, DType::F64),
        tensor(&b, [3, h, w], &device, DType::F64),
        0.2,
    );
    assert!((scalar(got.unwrap()) - want).abs() < 1e-12);
    check_gradient("d photometric / d pred", &a, [3, h, w], |x| {
        let target = tensor(&b, [3, h, w], &x.device(), DType::F64);
        photometric(x, target, 0.2).unwrap()
    });
}

#[test]
fn weighted_photometric_of_stacked_maps_is_the_sum_of_their_losses() {
    // Colour and normals stacked as six channels, weighted 1/3 and 0.05/3 per channel: the loss
    // of Eq. 12 plus 0.05 times that of Eq. 13, each from the host SSIM metric and host L1.
    let (h, w) = (13, 12);
    let mut rng = SplitMix64::new(9);
    let a = random_image(&mut rng, 6 * h * w);
    let b = random_image(&mut rng, 6 * h * w);
    let n = 3 * h * w;
    let loss = |p: &[f64], q: &[f64]| {
        let l1 = p.iter().zip(q).map(|(x, y)| (x - y).abs()).sum::<f64>() / p.len() as f64;
        0.2 * (1.0 - metric_ssim(&image(p, h, w), &image(q, h, w)).unwrap()) + 0.8 * l1
    };
    let want = loss(&a[..n], &b[..n]) + 0.05 * loss(&a[n..], &b[n..]);
    let weights = [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0, 0.05 / 3.0, 0.05 / 3.0, 0.05 / 3.0];
    let device = Device::flex();
    let got = photometric_weighted(
        tensor(&a, [6, h, w], &device, DType::F64),
        tensor(&b, [6, h, w], &device, DType::F64),
        0.2,
        &weights,
    );
    assert!((scalar(got.unwrap()) - want).abs() < 1e-12);
    check_gradient("d weighted photometric / d pred", &a, [6, h, w], |x| {
        let target = tensor(&b, [6, h, w], &x.device(), DType::F64);
        photometric_weighted(x, target, 0.2, &weights).unwrap()
    });
    let zeros = Tensor::<3>::zeros([6, h, w], &device);
    let err = photometric_weighted(zeros.clone(), zeros, 0.2, &weights[..3]).expect_err("an error");
    assert!(err.to_string().contains("3 channel weights for images of 6 channels"), "{err}");
}

#[test]
fn ssim_and_photometric_reject_bad_images() {
    let device = Device::flex();
    let zeros = |s: [usize; 3]| Tensor::<3>::zeros(s, &device);
    let message = |r: Result<Tensor<1>, AvatarError>| r.expect_err("an error").to_string();
    assert!(message(ssim(zeros([3, 20, 20]), zeros([3, 20, 21]))).contains("different shapes"));
    assert!(message(ssim(zeros([3, 10, 20]), zeros([3, 10, 20]))).contains("H, W ≥ 11"));
    assert!(message(photometric(zeros([3, 20, 20]), zeros([1, 20, 20]), 0.2)).contains("different shapes"));
    assert!(message(photometric(zeros([3, 20, 20]), zeros([3, 20, 20]), 1.5)).contains("λ_SSIM"));
    let f64_zeros = Tensor::<3>::zeros([3, 20, 20], (&device, DType::F64));
    assert!(message(ssim(zeros([3, 20, 20]), f64_zeros)).contains("different float types"));
    let blur_error = gaussian_blur_valid(zeros([2, 30, 10])).expect_err("an error").to_string();
    assert!(blur_error.contains("H, W ≥ 11"), "{blur_error}");
}

/// The SSIM loss on the GPU backend (lavapipe where there is no GPU) agrees with Flex, value and
/// gradients, for the fused op and the composite.
#[test]
fn ssim_on_wgpu_matches_flex() {
    let (c, h, w) = (2, 24, 17);
    let (a, b) = smooth_and_noisy(h, w, 0.1, 9);
    for (name, f) in both_ssims() {
        let run = |device: Device| {
            let device = device.autodiff();
            let x = tensor(&a[..c * h * w], [c, h, w], &device, DType::F32).require_grad();
            let y = tensor(&b[..c * h * w], [c, h, w], &device, DType::F32).require_grad();
            let loss = f(x.clone(), y.clone());
            let value = scalar(loss.clone());
            let grads = loss.backward();
            (value, [x, y].map(|t| values(t.grad(&grads).unwrap())))
        };
        let (v_flex, g_flex) = run(Device::flex());
        let (v_gpu, g_gpu) = run(mannequin_splat::gpu_device().unwrap_or_else(|e| panic!("{e}")));
        assert!((v_flex - v_gpu).abs() < 1e-5, "{name}: {v_flex} vs {v_gpu}");
        for (input, (gf, gg)) in ["pred", "target"].iter().zip(g_flex.iter().zip(&g_gpu)) {
            let scale = gf.iter().fold(0.0f64, |m, g| m.max(g.abs()));
            for (i, (f, g)) in gf.iter().zip(gg).enumerate() {
                assert!((f - g).abs() < 1e-4 * scale, "{name} d/d{input}[{i}]: flex {f} vs wgpu {g}");
            }
        }
    }
}

// ---- Mesh regularisers ----

fn topology(num_vertices: usize, faces: &[[u32; 3]]) -> MeshRegularisers {
    MeshRegularisers::new(num_vertices, faces, &Device::flex()).unwrap()
}

fn vertices(v: &[[f64; 3]]) -> Tensor<2> {
    let flat: Vec<f64> = v.iter().flatten().copied().collect();
    tensor(&flat, [v.len(), 3], &Device::flex(), DType::F64)
}

/// An `n × n` grid of unit squares in the plane z = 0, each split along its diagonal.
fn flat_grid(n: usize) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let id = |i: usize, j: usize| (i * (n + 1) + j) as u32;
    let v = (0..=n).flat_map(|i| (0..=n).map(move |j| [j as f64, i as f64, 0.0])).collect();
    let mut f = Vec::new();
    for i in 0..n {
        for j in 0..n {
            f.push([id(i, j), id(i, j + 1), id(i + 1, j + 1)]);
            f.push([id(i, j), id(i + 1, j + 1), id(i + 1, j)]);
        }
    }
    (v, f)
}

#[test]
fn equilateral_triangle_costs_the_minimum_three_quarters() {
    // An equilateral triangle of side 2, tilted out of every coordinate plane: no variance, and
    // Σ (1 − cos 60°)² = 3 · ¼.
    let s3 = 3f64.sqrt();
    let tri = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, s3, 0.0]];
    let (c, s) = (0.6f64, 0.8f64);
    let rotated: Vec<[f64; 3]> =
        tri.iter().map(|p| [p[0], c * p[1] - s * p[2], s * p[1] + c * p[2] + 1.0]).collect();
    let topo = topology(3, &[[0, 1, 2]]);
    let loss = scalar(topo.equilateral(vertices(&rotated)).unwrap());
    assert!((loss - 0.75).abs() < 1e-14, "{loss}");
    // It is the minimum: moving any corner in any direction costs more.
    let mut rng = SplitMix64::new(4);
    for _ in 0..20 {
        let mut moved = rotated.clone();
        let (k, d) = (rng.below(3), rng.below(3));
        moved[k][d] += rng.range(-0.05, 0.05);
        assert!(scalar(topo.equilateral(vertices(&moved)).unwrap()) > loss);
    }
}

#[test]
fn right_triangle_three_four_five_costs_what_was_worked_out_by_hand() {
    // Sides 3, 4, 5: mean 4, population variance ((−1)² + 0² + 1²)/3 = 2/3.
    // Angles: 90° (cos 0) and the two acute ones with cos 4/5 and cos 3/5, so
    // Σ (1 − cos φ)² = 1 + (1/5)² + (2/5)² = 1 + 0.04 + 0.16 = 1.2.
    // Total 2/3 + 6/5 = 28/15.
    let tri = [[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 3.0, 0.0]];
    let loss = scalar(topology(3, &[[0, 1, 2]]).equilateral(vertices(&tri)).unwrap());
    assert!((loss - 28.0 / 15.0).abs() < 1e-14, "{loss}");
    // Two faces average, not sum: add an equilateral face (¾) far away.
    let s3 = 3f64.sqrt();
    let both = [tri.as_slice(), &[[10.0, 0.0, 0.0], [12.0, 0.0, 0.0], [11.0, s3, 0.0]]].concat();
    let loss = scalar(topology(6, &[[0, 1, 2], [3, 4, 5]]).equilateral(vertices(&both)).unwrap());
    assert!((loss - (28.0 / 15.0 + 0.75) / 2.0).abs() < 1e-14, "{loss}");
}

#[test]
fn flat_grid_has_zero_normal_consistency_and_zero_interior_laplacian() {
    let n = 4;
    let (v, f) = flat_grid(n);
    let topo = topology(v.len(), &f);
    assert_eq!(topo.num_faces(), 2 * n * n);
    // Interior edges of the grid: horizontal, vertical and diagonal ones not on the boundary.
    assert_eq!(topo.num_hinges(), 2 * n * (n - 1) + n * n);
    let nc = scalar(topo.normal_consistency(vertices(&v)).unwrap());
    assert!(nc.abs() < 1e-14, "{nc}");
    let delta = values(topo.laplacian_vectors(vertices(&v)).unwrap());
    for i in 0..=n {
        for j in 0..=n {
            let d = &delta[3 * (i * (n + 1) + j)..][..3];
            let interior = (1..n).contains(&i) && (1..n).contains(&j);
            let norm = d.iter().map(|x| x * x).sum::<f64>().sqrt();
            // The boundary is pulled inwards, so the test can tell the two apart.
            assert_eq!(norm < 1e-14, interior, "vertex ({i}, {j}): δ = {d:?}");
        }
    }
}

#[test]
fn folded_pair_at_ninety_degrees_costs_one() {
    // Two triangles on the edge 0–1 along x, one in the plane z = 0, one in the plane y = 0.
    let v = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.3, 1.0, 0.0], [0.6, 0.0, 2.0]];
    let topo = topology(4, &[[0, 1, 2], [1, 0, 3]]);
    assert_eq!(topo.num_hinges(), 1);
    let nc = scalar(topo.normal_consistency(vertices(&v)).unwrap());
    assert!((nc - 1.0).abs() < 1e-14, "{nc}");
    // Folded by 120° out of the plane (dihedral normals 120° apart): 1 − cos 120° = 1.5.
    let (c, s) = ((120f64).to_radians().cos(), (120f64).to_radians().sin());
    let v = [v[0], v[1], v[2], [0.6, -c, -s]];
    let nc = scalar(topo.normal_consistency(vertices(&v)).unwrap());
    assert!((nc - 1.5).abs() < 1e-14, "{nc}");
}

#[test]
fn laplacian_of_a_single_triangle_is_worked_out_by_hand() {
    // δ₀ = (0,0,0) − ((1,0,0) + (0,1,0))/2 = (−½, −½, 0): ‖δ₀‖² = ½;
    // δ₁ = (1,0,0) − (0,½,0): 1¼; δ₂ = (0,1,0) − (½,0,0): 1¼. Mean (½ + 1¼ + 1¼)/3 = 1.
    let v = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let loss = scalar(topology(3, &[[0, 1, 2]]).laplacian(vertices(&v)).unwrap());
    assert!((loss - 1.0).abs() < 1e-14, "{loss}");
    // An isolated vertex neither contributes nor counts.
    let v4 = [v.as_slice(), &[[5.0, 5.0, 5.0]]].concat();
    let loss = scalar(topology(4, &[[0, 1, 2]]).laplacian(vertices(&v4)).unwrap());
    assert!((loss - 1.0).abs() < 1e-14, "{loss}");
}

#[test]
fn mesh_regulariser_gradients_match_finite_differences() {
    let (v, f) = flat_grid(3);
    let mut rng = SplitMix64::new(21);
    let x: Vec<f64> = v.iter().flatten().map(|&c| c + 0.3 * rng.normal()).collect();
    let topo = MeshRegularisers::new(v.len(), &f, &Device::flex()).unwrap();
    let shape = [v.len(), 3];
    check_gradient("d laplacian", &x, shape, |v| topo.laplacian(v).unwrap());
    check_gradient("d normal consistency", &x, shape, |v| topo.normal_consistency(v).unwrap());
    check_gradient("d equilateral", &x, shape, |v| topo.equilateral(v).unwrap());
}

#[test]
fn mesh_topology_rejects_bad_faces_and_vertices() {
    let device = Device::flex();
    let message = |r: Result<MeshRegularisers, AvatarError>| r.expect_err("an error").to_string();
    assert!(message(MeshRegularisers::new(3, &[[0, 1, 3]], &device)).contains("names vertex 3"));
    assert!(message(MeshRegularisers::new(3, &[[0, 1, 1]], &device)).contains("repeats a vertex"));
    assert!(message(MeshRegularisers::new(3, &[], &device)).contains("at least one face"));
    let topo = topology(3, &[[0, 1, 2]]);
    let wrong = Tensor::<2>::zeros([4, 3], &device);
    for r in [topo.laplacian(wrong.clone()), topo.normal_consistency(wrong.clone()), topo.equilateral(wrong)]
    {
        assert!(r.expect_err("an error").to_string().contains("expects [3, 3]"));
    }
}

#[test]
fn default_body_topology_is_a_closed_manifold_mesh() {
    let body = mannequin_body::BodyModel::default_body();
    let topo = topology(body.num_vertices(), &body.faces);
    assert_eq!((topo.num_vertices(), topo.num_faces()), (body.v_template.len(), body.faces.len()));
    // Every edge of a closed manifold mesh joins exactly two faces: 3F = 2E, one pair per edge.
    assert_eq!(3 * topo.num_faces(), 2 * topo.num_edges());
    assert_eq!(topo.num_hinges(), topo.num_edges());
}

/// The fused host regularisers (what Flex runs) against their tensor compositions, values and
/// gradients, on the default body's template jittered by up to 3 mm, in f64 and f32.
#[test]
fn fused_mesh_regularisers_match_their_tensor_compositions() {
    let body = mannequin_body::BodyModel::default_body();
    let device = Device::flex().autodiff();
    let topo = MeshRegularisers::new(body.num_vertices(), &body.faces, &device).unwrap();
    let mut rng = SplitMix64::new(8);
    // Rounded to f32, so the f32 and f64 runs see the same mesh.
    let x: Vec<f64> = body
        .v_template
        .iter()
        .flatten()
        .map(|&c| f64::from((f64::from(c) + rng.range(-0.003, 0.003)) as f32))
        .collect();
    type Term<'a> =
        (&'a str, Box<dyn Fn(Tensor<2>) -> Tensor<1> + 'a>, Box<dyn Fn(Tensor<2>) -> Tensor<1> + 'a>);
    let terms: [Term; 3] = [
        (
            "Laplacian",
            Box::new(|v| topo.laplacian(v).unwrap()),
            Box::new(|v| topo.laplacian_tensors(v).unwrap()),
        ),
        (
            "normal consistency",
            Box::new(|v| topo.normal_consistency(v).unwrap()),
            Box::new(|v| topo.normal_consistency_tensors(v).unwrap()),
        ),
        (
            "equilateral",
            Box::new(|v| topo.equilateral(v).unwrap()),
            Box::new(|v| topo.equilateral_tensors(v).unwrap()),
        ),
    ];
    let shape = [x.len() / 3, 3];
    for (name, fused, tensors) in &terms {
        let run = |f: &dyn Fn(Tensor<2>) -> Tensor<1>, dtype: DType| {
            let v = tensor(&x, shape, &device, dtype).require_grad();
            let loss = f(v.clone());
            let grads = loss.clone().backward();
            (scalar(loss), values(v.grad(&grads).unwrap()))
        };
        // The reference is the composition in f64: in f32 its cancellations (Binet–Cauchy on
        // centimetre edges) cost more than the fused op's, which works in f64 throughout. Burn's
        // f64 autodiff of the composition still carries a relative error near 1e-6 (on the
        // Laplacian the fused gradient matches central differences to 1e-9, the composition's
        // to 4e-7), so f64 is held to 1e-5.
        let (want_value, want_grad) = run(tensors.as_ref(), DType::F64);
        let rms = (want_grad.iter().map(|g| g * g).sum::<f64>() / want_grad.len() as f64).sqrt();
        assert!(rms > 0.0, "{name}: the gradient is not trivially zero");
        for (dtype, tol) in [(DType::F64, 1e-5), (DType::F32, 1e-4)] {
            let (value, grad) = run(fused.as_ref(), dtype);
            assert!(
                (value - want_value).abs() <= tol * want_value.abs(),
                "{name} {dtype:?}: {value} vs {want_value}"
            );
            for (i, (a, b)) in grad.iter().zip(&want_grad).enumerate() {
                assert!(
                    (a - b).abs() <= tol * (b.abs() + rms),
                    "{name} {dtype:?}: gradient entry {i}: {a} vs {b}"
                );
            }
        }
    }
}

/// The body's faces as the fused op's mesh, its hinges found here independently of
/// [`MeshRegularisers`] (the Flex values below tie the two together).
fn host_mesh(num_vertices: usize, faces: &[[u32; 3]]) -> Arc<HostMesh> {
    let mut sides: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
    for &[a, b, c] in faces {
        for (p, q, o) in [(a, b, c), (b, c, a), (c, a, b)] {
            sides.entry((p.min(q), p.max(q))).or_default().push(o);
        }
    }
    let mut hinges: Vec<[u32; 4]> = sides
        .iter()
        .flat_map(|(&(a, b), o)| {
            (0..o.len()).flat_map(move |i| (i + 1..o.len()).map(move |j| [a, b, o[i], o[j]]))
        })
        .collect();
    hinges.sort_unstable();
    let mut connected = vec![false; num_vertices];
    faces.iter().flatten().for_each(|&v| connected[v as usize] = true);
    Arc::new(HostMesh {
        rings: Arc::new(OneRingMesh::new(num_vertices, faces)),
        hinges,
        num_connected: connected.iter().filter(|&&c| c).count(),
    })
}

/// The fused regularisers' CubeCL kernels (wgpu; lavapipe where there is no GPU) against the
/// Flex op, through Autodiff, on the default body's template jittered by up to 3 mm: same loss
/// and vertex gradients to 1e-4 (the GPU works in f32, Flex in f64).
#[test]
fn fused_mesh_regularisers_on_wgpu_match_flex() {
    let body = mannequin_body::BodyModel::default_body();
    let mesh = host_mesh(body.num_vertices(), &body.faces);
    let topo = topology(body.num_vertices(), &body.faces);
    let mut rng = SplitMix64::new(9);
    let x: Vec<f64> =
        body.v_template.iter().flatten().map(|&c| f64::from(c) + rng.range(-0.003, 0.003)).collect();
    let shape = [x.len() / 3, 3];
    let gpu = mannequin_splat::gpu_device().unwrap_or_else(|e| panic!("{e}"));
    for (term, name) in [
        (HostTerm::Laplacian, "Laplacian"),
        (HostTerm::NormalConsistency, "normal consistency"),
        (HostTerm::Equilateral, "equilateral"),
    ] {
        let run = |device: &Device| {
            let v = tensor(&x, shape, &device.clone().autodiff(), DType::F32).require_grad();
            let loss = mesh_loss(v.clone(), MeshLoss { term, mesh: mesh.clone() });
            // Scaled, so the upstream gradient is not 1.
            let grads = (loss.clone() * 3.0).backward();
            (scalar(loss), values(v.grad(&grads).unwrap()))
        };
        let (want, want_grad) = run(&Device::flex());
        let same_mesh = match term {
            HostTerm::Laplacian => topo.laplacian(vertices_f32(&x, shape)),
            HostTerm::NormalConsistency => topo.normal_consistency(vertices_f32(&x, shape)),
            HostTerm::Equilateral => topo.equilateral(vertices_f32(&x, shape)),
        };
        assert_eq!(scalar(same_mesh.unwrap()), want, "{name}: the test's mesh is the regularisers'");
        let (got, grad) = run(&gpu);
        assert!((got - want).abs() <= 1e-4 * want.abs(), "{name}: wgpu {got} vs Flex {want}");
        let rms = (want_grad.iter().map(|g| g * g).sum::<f64>() / want_grad.len() as f64).sqrt();
        assert!(rms > 0.0, "{name}: the gradient is not trivially zero");
        for (i, (a, b)) in grad.iter().zip(&want_grad).enumerate() {
            assert!(
                (a - b).abs() <= 1e-4 * (b.abs() + rms),
                "{name}: gradient entry {i}: wgpu {a} vs Flex {b}"
            );
        }
    }
}

fn vertices_f32(x: &[f64], shape: [usize; 2]) -> Tensor<2> {
    tensor(x, shape, &Device::flex(), DType::F32)
}
