//! Forward + backward time of the training losses on Flex (f32, autodiff), as the trainer runs
//! them every iteration:
//! - the SSIM loss of an RGB and a normal map (two 3-channel calls) at 540×540 and on a 250×150
//!   crop: the fused op against SSIM written with Burn's ops around three blurs: Burn's
//!   `conv2d` with the direct 11×11 window (the baseline), `conv2d` as a 1×11 and an 11×1 pass,
//!   and the separable blur op;
//! - the blur alone on 540×540×6, the op against `conv2d` as a 1×11 and an 11×1 pass;
//! - the mesh regularisers on the default body (13,380 vertices, 26,756 faces): the fused host
//!   op against the tensor composition it replaces on Flex, and against the trainer's
//!   per-iteration budget of 150 ms.
//!
//! `cargo bench -p mannequin-avatar --bench losses` (add `-- --quick` for fewer repetitions).
//! Times are medians, with the fastest run in brackets (the CPU may be shared).

mod timing;

use timing::median_and_min_ms;

use burn::tensor::module::conv2d;
use burn::tensor::ops::ConvOptions;
use burn::tensor::{Device, Tensor, TensorData};
use mannequin_avatar::losses::{
    MeshRegularisers, gaussian_blur_valid, gaussian_window, ssim, ssim_with_blur,
};
use mannequin_body::BodyModel;
use mannequin_io::rng::SplitMix64;

/// The trainer's whole per-iteration budget on the 2-core CPU.
const BUDGET_MS: f64 = 150.0;

fn window(shape: [usize; 4], values: Vec<f32>, device: &Device) -> Tensor<4> {
    Tensor::from_data(TensorData::new(values, shape), device)
}

/// 'Valid' blur as one `conv2d` with the 11×11 outer-product window: the baseline.
fn conv_blur_direct(x: Tensor<3>) -> Tensor<3> {
    let [n, h, w] = x.dims();
    let g = gaussian_window();
    let k = g.iter().flat_map(|a| g.iter().map(move |b| (a * b) as f32)).collect();
    let weight = window([1, 1, 11, 11], k, &x.device());
    let y = conv2d(x.reshape([n, 1, h, w]), weight, None, ConvOptions::new([1, 1], [0, 0], [1, 1], 1));
    y.reshape([n, h - 10, w - 10])
}

/// 'Valid' blur as a 1×11 then an 11×1 `conv2d`.
fn conv_blur_separable(x: Tensor<3>) -> Tensor<3> {
    let [n, h, w] = x.dims();
    let g: Vec<f32> = gaussian_window().iter().map(|&v| v as f32).collect();
    let options = || ConvOptions::new([1, 1], [0, 0], [1, 1], 1);
    let rows = window([1, 1, 1, 11], g.clone(), &x.device());
    let cols = window([1, 1, 11, 1], g, &x.device());
    let y = conv2d(x.reshape([n, 1, h, w]), rows, None, options());
    conv2d(y, cols, None, options()).reshape([n, h - 10, w - 10])
}

/// A smooth `[c, H, W]` image and a noisy copy.
fn pair(c: usize, h: usize, w: usize, seed: u64, device: &Device) -> (Tensor<3>, Tensor<3>) {
    let mut rng = SplitMix64::new(seed);
    let mut clean = Vec::with_capacity(c * h * w);
    for ch in 0..c {
        for y in 0..h {
            for x in 0..w {
                let (u, v) = (x as f32 / w as f32, y as f32 / h as f32);
                clean.push(0.5 + 0.3 * (6.0 * u + ch as f32).sin() * (4.0 * v).cos());
            }
        }
    }
    let noisy: Vec<f32> = clean.iter().map(|&s| (s + 0.05 * rng.normal() as f32).clamp(0.0, 1.0)).collect();
    let t = |v: Vec<f32>| Tensor::from_data(TensorData::new(v, [c, h, w]), device);
    (t(clean), t(noisy))
}

/// Forward + backward of `loss(leaves)`, reading the gradients back so that all work is done.
fn forward_backward<const D: usize, const N: usize>(
    leaves: &[Tensor<D>; N],
    loss: impl Fn([Tensor<D>; N]) -> Tensor<1>,
) {
    let leaves = leaves.clone().map(|x| x.require_grad());
    let grads = loss(leaves.clone()).backward();
    for x in leaves {
        std::hint::black_box(x.grad(&grads).expect("a gradient").into_data());
    }
}

fn print(name: &str, (median, min): (f64, f64), baseline: Option<f64>) {
    let ratio = baseline.map(|b| format!("{:6.1}× faster", b / median)).unwrap_or_default();
    println!("    {name:<36}{median:8.1} ms ({min:6.1})   {ratio}");
}

fn ssim_section(reps: usize, device: &Device) {
    println!(
        "SSIM loss, forward + backward, f32 Flex autodiff ({} rayon threads)",
        rayon::current_num_threads()
    );
    for (h, w) in [(540, 540), (150, 250)] {
        // RGB and normals: predictions require gradients, targets do not.
        let (rgb, rgb_target) = pair(3, h, w, 7, device);
        let (normals, normals_target) = pair(3, h, w, 8, device);
        let preds = [rgb, normals];
        let run_with = |f: &dyn Fn(Tensor<3>, Tensor<3>) -> Tensor<1>| {
            median_and_min_ms(reps, || {
                forward_backward(&preds, |[a, b]| f(a, rgb_target.clone()) + f(b, normals_target.clone()))
            })
        };
        let composite =
            |blur: fn(Tensor<3>) -> Tensor<3>| run_with(&|x, y| ssim_with_blur(x, y, blur).unwrap());
        let direct = composite(conv_blur_direct);
        println!("  {w}×{h}, RGB + normals (2 × 3 channels):");
        print("baseline: Burn ops, 11×11 conv2d", direct, None);
        print("Burn ops, conv2d 1×11 then 11×1", composite(conv_blur_separable), Some(direct.0));
        print("Burn ops, separable blur op", composite(|t| gaussian_blur_valid(t).unwrap()), Some(direct.0));
        print("fused SSIM op (ours)", run_with(&|x, y| ssim(x, y).unwrap()), Some(direct.0));
    }
    let (planes, _) = pair(6, 540, 540, 9, device);
    let planes = [planes];
    println!("  blur alone, 540×540×6, forward + backward:");
    let conv = median_and_min_ms(reps, || forward_backward(&planes, |[x]| conv_blur_separable(x).sum()));
    print("conv2d 1×11 then 11×1", conv, None);
    print(
        "separable blur op",
        median_and_min_ms(reps, || forward_backward(&planes, |[x]| gaussian_blur_valid(x).unwrap().sum())),
        Some(conv.0),
    );
}

fn mesh_section(reps: usize, device: &Device) {
    let body = BodyModel::default_body();
    let topology =
        MeshRegularisers::new(body.num_vertices(), &body.faces, device).expect("the default body's faces");
    let mut rng = SplitMix64::new(3);
    let v: Vec<f32> = body.v_template.iter().flatten().map(|&c| c + 0.002 * rng.normal() as f32).collect();
    let vertices = [Tensor::<2>::from_data(TensorData::new(v, [body.num_vertices(), 3]), device)];
    println!(
        "Mesh regularisers on the default body (V = {}, F = {}), forward + backward, f32 Flex autodiff:",
        topology.num_vertices(),
        topology.num_faces()
    );
    type Loss<'a> = &'a dyn Fn(Tensor<2>) -> Tensor<1>;
    let report = |name: &str, fused: Loss, tensors: Loss| {
        let (median, min) = median_and_min_ms(reps, || forward_backward(&vertices, |[v]| fused(v)));
        let (base, _) = median_and_min_ms(reps, || forward_backward(&vertices, |[v]| tensors(v)));
        println!(
            "    {name:<20} fused {median:6.2} ms ({min:6.2}), tensor ops {base:6.2} ms: {:4.1}× faster; {:4.1}% of the {BUDGET_MS} ms budget",
            base / median,
            100.0 * median / BUDGET_MS
        );
    };
    let t = &topology;
    report("Laplacian", &|v| t.laplacian(v).unwrap(), &|v| t.laplacian_tensors(v).unwrap());
    report("normal consistency", &|v| t.normal_consistency(v).unwrap(), &|v| {
        t.normal_consistency_tensors(v).unwrap()
    });
    report("equilateral", &|v| t.equilateral(v).unwrap(), &|v| t.equilateral_tensors(v).unwrap());
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let reps = if quick { 3 } else { 15 };
    let device = Device::flex().autodiff();
    ssim_section(reps, &device);
    mesh_section(reps, &device);
}
