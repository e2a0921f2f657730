//! The Burn op, on Flex and on wgpu (lavapipe on machines without a GPU), against the CPU
//! renderer: the same images and the same gradients, with the tensors flowing through autodiff.

mod common;

use burn::tensor::{Device, Tensor, TensorData};
use common::{ColorForm, RotForm, Scene, camera};
use mannequin_splat::{
    Camera, ColorTensor, OutputGrads, RenderOptions, RotationTensor, SplatError, backward, gpu_device,
    render, splat_render,
};

fn devices() -> Vec<(&'static str, Device)> {
    let gpu = gpu_device().unwrap_or_else(|e| panic!("{e}"));
    vec![("flex", Device::flex()), ("wgpu", gpu)]
}

fn tensor<const D: usize>(v: &[f32], shape: [usize; D], device: &Device) -> Tensor<D> {
    Tensor::from_data(TensorData::new(v.to_vec(), shape), device)
}

fn values<const D: usize>(t: Tensor<D>) -> Vec<f32> {
    t.into_data().try_to_vec::<f32>().expect("f32 tensor")
}

fn close(what: &str, got: &[f32], want: &[f32], tol: f32) {
    assert_eq!(got.len(), want.len(), "{what}: length");
    let scale = want.iter().fold(1e-6f32, |m, v| m.max(v.abs()));
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        assert!((g - w).abs() <= tol * scale, "{what}[{i}]: {g} vs {w} (scale {scale})");
    }
}

/// A leaf tensor of either rank, to read its gradient back.
enum Leaf {
    Two(Tensor<2>),
    Three(Tensor<3>),
}

/// Renders through the op with a random linear loss on all three outputs, and compares images and
/// gradients with the CPU renderer on the same inputs.
fn check(rot: RotForm, col: ColorForm, seed: u64) {
    let scene = Scene::random(40, seed, if let ColorForm::Sh(d) = col { d } else { 0 }, 4);
    check_scene(&scene, rot, col, seed, camera(32, 24));
}

fn check_scene(scene: &Scene, rot: RotForm, col: ColorForm, seed: u64, cam: Camera) {
    let opts = RenderOptions {
        background: vec![0.3; if let ColorForm::Features(c) = col { c } else { 3 }],
        ..Default::default()
    };
    let s = scene.cast::<f32>();
    let g = s.gaussians(rot, col);
    let want = render(&g, &cam, &opts).unwrap();
    let mut rng = common::Rng::new(seed + 1);
    let wi: Vec<f32> = want.image.iter().map(|_| rng.uniform(-1.0, 1.0) as f32).collect();
    let wa: Vec<f32> = want.alpha.iter().map(|_| rng.uniform(-1.0, 1.0) as f32).collect();
    let wd: Vec<f32> =
        want.alpha.iter().map(|&a| if a > 0.05 { rng.uniform(-1.0, 1.0) as f32 } else { 0.0 }).collect();
    let d_want = backward(
        &g,
        &cam,
        &opts,
        &want,
        &OutputGrads { image: Some(&wi), alpha: Some(&wa), depth: Some(&wd) },
    )
    .unwrap();
    let n = scene.len();
    for (name, device) in devices() {
        let device = device.autodiff();
        let means = tensor(&s.means, [n, 3], &device).require_grad();
        let (rotations, rot_leaf) = match rot {
            RotForm::Quaternion => {
                let q = tensor(&s.quats, [n, 4], &device).require_grad();
                (RotationTensor::Quaternions(q.clone()), Leaf::Two(q))
            }
            RotForm::Matrix => {
                let m = tensor(&s.matrices, [n, 3, 3], &device).require_grad();
                (RotationTensor::Matrices(m.clone()), Leaf::Three(m))
            }
        };
        let scales = tensor(&s.scales, [n, 3], &device).require_grad();
        let opacities = tensor(&s.opacities, [n], &device).require_grad();
        let (colors, col_leaf) = match col {
            ColorForm::Sh(d) => {
                let k = (d + 1) * (d + 1);
                let c = tensor(&s.sh, [n, k, 3], &device).require_grad();
                (ColorTensor::Sh { degree: d, coeffs: c.clone() }, Leaf::Three(c))
            }
            ColorForm::Features(ch) => {
                let f = tensor(&s.features[..n * ch], [n, ch], &device).require_grad();
                (ColorTensor::Features(f.clone()), Leaf::Two(f))
            }
        };
        let out =
            splat_render(means.clone(), rotations, scales.clone(), opacities.clone(), colors, &cam, &opts)
                .unwrap();
        let tag = |what: &str| format!("{name} {rot:?} {col:?} {what}");
        close(&tag("image"), &values(out.image()), &want.image, 1e-5);
        close(&tag("alpha"), &values(out.alpha()), &want.alpha, 1e-5);
        // Expected depth is a ratio that amplifies rounding where alpha is tiny: compare the
        // accumulated depth (depth × alpha) instead.
        let got_alpha = values(out.alpha());
        let acc = |d: &[f32], a: &[f32]| d.iter().zip(a).map(|(d, a)| d * a).collect::<Vec<f32>>();
        close(
            &tag("depth × alpha"),
            &acc(&values(out.depth()), &got_alpha),
            &acc(&want.depth, &want.alpha),
            1e-5,
        );
        let [c, h, w] = out.image().dims();
        let loss = (out.image() * tensor(&wi, [c, h, w], &device)).sum()
            + (out.alpha() * tensor(&wa, [h, w], &device)).sum()
            + (out.depth() * tensor(&wd, [h, w], &device)).sum();
        let grads = loss.backward();
        let grad = |t: &Tensor<2>| values(t.grad(&grads).expect("gradient"));
        close(&tag("d means"), &grad(&means), &d_want.means, 1e-4);
        close(&tag("d scales"), &grad(&scales), &d_want.scales, 1e-4);
        close(&tag("d opacities"), &values(opacities.grad(&grads).unwrap()), &d_want.opacities, 1e-4);
        let leaf_grad = |l: &Leaf| match l {
            Leaf::Two(t) => values(t.grad(&grads).expect("gradient")),
            Leaf::Three(t) => values(t.grad(&grads).expect("gradient")),
        };
        close(&tag("d rotations"), &leaf_grad(&rot_leaf), &d_want.rotations, 1e-4);
        close(&tag("d colours"), &leaf_grad(&col_leaf), &d_want.colors, 1e-4);
    }
}

#[test]
fn quaternions_and_sh_match_the_cpu_renderer_on_every_backend() {
    check(RotForm::Quaternion, ColorForm::Sh(2), 31);
}

#[test]
fn matrices_and_sh_degree_3_match_the_cpu_renderer_on_every_backend() {
    check(RotForm::Matrix, ColorForm::Sh(3), 34);
}

#[test]
fn matrices_and_features_match_the_cpu_renderer_on_every_backend() {
    check(RotForm::Matrix, ColorForm::Features(4), 32);
}

/// A dense stack of nearly opaque Gaussians: pixels saturate (alpha capped) and stop early
/// (transmittance floor), and the device kernels must replay exactly where the CPU did.
#[test]
fn saturated_pixels_match_the_cpu_renderer_on_every_backend() {
    let mut scene = Scene::random(120, 33, 1, 3);
    for i in 0..60 {
        scene.opacities[i] = 0.97;
        for k in 0..3 {
            scene.means[3 * i + k] *= 0.3;
        }
    }
    let s = scene.cast::<f32>();
    let cpu = render(
        &s.gaussians(RotForm::Quaternion, ColorForm::Sh(1)),
        &camera(32, 24),
        &RenderOptions::default(),
    );
    let opaque = cpu.unwrap().alpha.iter().filter(|&&a| a > 0.999).count();
    assert!(opaque > 20, "only {opaque} pixels reach the transmittance floor");
    check_scene(&scene, RotForm::Quaternion, ColorForm::Sh(1), 33, camera(32, 24));
}

/// Many tiles, with splats that span several of them and lists of a few hundred Gaussians:
/// the device binning feeds the compositor the lists the CPU renderer uses.
#[test]
fn a_many_tile_image_matches_the_cpu_renderer_on_every_backend() {
    let mut scene = Scene::random(400, 36, 1, 3);
    for v in scene.scales.iter_mut().step_by(7) {
        *v *= 4.0;
    }
    check_scene(&scene, RotForm::Quaternion, ColorForm::Sh(1), 36, camera(112, 80));
}

/// Gradients reach tensors computed by Burn's own ops upstream, and a few steps of gradient
/// descent on the means pull a render towards a target.
#[test]
fn the_op_chains_with_burn_ops_and_descends() {
    let target_scene = Scene::random(12, 40, 0, 3);
    let cam = camera(24, 20);
    let opts = RenderOptions::default();
    for (name, device) in devices() {
        let device = device.autodiff();
        let s = target_scene.cast::<f32>();
        let n = target_scene.len();
        let render_with = |means: Tensor<2>| {
            splat_render(
                means,
                RotationTensor::Quaternions(tensor(&s.quats, [n, 4], &device)),
                tensor(&s.scales, [n, 3], &device),
                tensor(&s.opacities, [n], &device),
                ColorTensor::Sh { degree: 0, coeffs: tensor(&s.sh, [n, 1, 3], &device) },
                &cam,
                &opts,
            )
            .unwrap()
            .image()
        };
        let target = render_with(tensor(&s.means, [n, 3], &device)).detach();
        let offset: Vec<f32> = (0..3 * n).map(|i| if i % 3 == 0 { 0.04 } else { -0.03 }).collect();
        let mut shift = tensor(&offset, [n, 3], &device).require_grad();
        let mut losses = Vec::new();
        for _ in 0..30 {
            let means = tensor(&s.means, [n, 3], &device) + shift.clone();
            let loss = (render_with(means) - target.clone()).powf_scalar(2.0).sum();
            losses.push(values(loss.clone())[0]);
            let grads = loss.backward();
            let g = values(shift.grad(&grads).expect("gradient through the addition"));
            let next: Vec<f32> = values(shift.clone()).iter().zip(&g).map(|(v, d)| v - 5e-4 * d).collect();
            shift = tensor(&next, [n, 3], &device).require_grad();
        }
        assert!(losses[29] < 0.5 * losses[0], "{name}: loss {:?}", losses);
    }
}

#[test]
fn without_autodiff_the_op_just_renders() {
    let scene = Scene::random(10, 50, 1, 3);
    let s = scene.cast::<f32>();
    let cam = camera(20, 16);
    let want =
        render(&s.gaussians(RotForm::Quaternion, ColorForm::Sh(1)), &cam, &RenderOptions::default()).unwrap();
    for (name, device) in devices() {
        let n = scene.len();
        let out = splat_render(
            tensor(&s.means, [n, 3], &device),
            RotationTensor::Quaternions(tensor(&s.quats, [n, 4], &device)),
            tensor(&s.scales, [n, 3], &device),
            tensor(&s.opacities, [n], &device),
            ColorTensor::Sh { degree: 1, coeffs: tensor(&s.sh, [n, 4, 3], &device) },
            &cam,
            &RenderOptions::default(),
        )
        .unwrap();
        close(&format!("{name} image"), &values(out.image()), &want.image, 1e-5);
    }
}

#[test]
fn mismatched_tensor_shapes_are_errors() {
    let device = Device::flex();
    let z = |shape: [usize; 2]| Tensor::<2>::zeros(shape, &device);
    let err = splat_render(
        z([5, 3]),
        RotationTensor::Quaternions(z([4, 4])),
        z([5, 3]),
        Tensor::zeros([5], &device),
        ColorTensor::Features(z([5, 2])),
        &camera(8, 8),
        &RenderOptions::default(),
    )
    .err()
    .expect("an error");
    assert!(matches!(err, SplatError::Shape { field: "rotations (quaternions)", .. }), "{err}");
}

/// No Gaussians at all: the background, and zero-length gradients.
#[test]
fn an_empty_scene_renders_the_background_on_every_backend() {
    for (name, device) in devices() {
        let device = device.autodiff();
        let means = Tensor::<2>::zeros([0, 3], &device).require_grad();
        let out = splat_render(
            means.clone(),
            RotationTensor::Quaternions(Tensor::zeros([0, 4], &device)),
            Tensor::zeros([0, 3], &device),
            Tensor::zeros([0], &device),
            ColorTensor::Features(Tensor::zeros([0, 2], &device)),
            &camera(20, 17),
            &RenderOptions { background: vec![0.25, 0.5], ..Default::default() },
        )
        .unwrap();
        let image = values(out.image());
        assert!(image[..340].iter().all(|&v| v == 0.25) && image[340..].iter().all(|&v| v == 0.5), "{name}");
        let grads = (out.image().sum() + out.alpha().sum()).backward();
        assert_eq!(means.grad(&grads).map(|g| g.dims()), Some([0, 3]), "{name}");
    }
}

/// NaN or infinite Gaussians are skipped and counted on every backend: the image is the one
/// without them (rendered by the CPU renderer with their opacity set to 0), and their gradients
/// are zero.
#[test]
fn non_finite_gaussians_are_skipped_and_counted_on_every_backend() {
    let scene = Scene::random(30, 61, 0, 3);
    let bad_ones = [2, 4, 9, 17, 23];
    let mut hidden = scene.clone();
    for &i in &bad_ones {
        hidden.opacities[i] = 0.0;
    }
    let cam = camera(40, 32);
    let opts = RenderOptions::default();
    let h = hidden.cast::<f32>();
    let want = render(&h.gaussians(RotForm::Quaternion, ColorForm::Features(3)), &cam, &opts).unwrap();
    let mut s = scene.cast::<f32>();
    s.means[3 * 2 + 1] = f32::NAN;
    s.scales[3 * 4] = f32::INFINITY;
    s.opacities[9] = f32::NAN;
    s.features[3 * 17 + 2] = f32::NEG_INFINITY;
    s.quats[4 * 23] = f32::INFINITY;
    let n = scene.len();
    for (name, device) in devices() {
        let device = device.autodiff();
        let means = tensor(&s.means, [n, 3], &device).require_grad();
        let render_with = |features: &[f32]| {
            splat_render(
                means.clone(),
                RotationTensor::Quaternions(tensor(&s.quats, [n, 4], &device)),
                tensor(&s.scales, [n, 3], &device),
                tensor(&s.opacities, [n], &device),
                ColorTensor::Features(tensor(&features[..3 * n], [n, 3], &device)),
                &cam,
                &opts,
            )
            .unwrap()
        };
        let out = render_with(&s.features);
        assert_eq!(values(out.skipped()), [5.0], "{name}: skipped");
        close(&format!("{name} image"), &values(out.image()), &want.image, 1e-5);
        let grads = out.image().sum().backward();
        let d = values(means.grad(&grads).expect("gradient"));
        assert!(d.iter().all(|v| v.is_finite()) && d.iter().any(|&v| v != 0.0), "{name}: {d:?}");
        for &i in &bad_ones {
            assert_eq!(d[3 * i..3 * i + 3], [0.0; 3], "{name}: Gaussian {i}");
        }
        let clean = render_with(&h.features);
        assert_eq!(values(clean.skipped()), [4.0], "{name}: skipped with finite features");
    }
}

/// With the Vulkan driver hidden from the loader, a GPU test fails with `GpuUnavailable`'s one line
/// instead of wgpu falling back to OpenGL and panicking on the kernels' WGSL. The test runs in a
/// child process, as wgpu's runtime comes up once per process.
#[cfg(target_os = "linux")]
#[test]
fn without_a_vulkan_driver_gpu_tests_fail_with_one_line() {
    let out = std::process::Command::new(std::env::current_exe().unwrap())
        .args(["--exact", "an_empty_scene_renders_the_background_on_every_backend"])
        // The loader's variable since 1.3.207, and the one before it.
        .env("VK_DRIVER_FILES", "/nonexistent")
        .env("VK_ICD_FILENAMES", "/nonexistent")
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout) + String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{text}");
    assert!(
        text.contains("no GPU for the wgpu kernels (no Vulkan adapter): install a Vulkan driver"),
        "{text}"
    );
    assert!(!text.contains("WGSL") && !text.contains("Shader validation"), "{text}");
}
