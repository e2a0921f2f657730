//! Forward and forward+backward time of the CPU renderer at 540×540, against a straightforward
//! rayon tile rasterizer kept here as the baseline and timed in the same run.
//!
//! `cargo bench -p mannequin-splat --bench splat` (add `-- --quick` for fewer repetitions,
//! `-- --ours-only` to skip the baseline when profiling).
//!
//! `-- --device gpu` times the Burn op (`splat_render`, forward and forward+backward through
//! autodiff) on the wgpu device against the same op on Flex, and with `--save-scenes DIR` writes
//! each scene, camera and image gradient as `DIR/scene_N.npz` for `tools/bench/gsplat_speed.py`,
//! which times gsplat's CUDA rasterizer on them in the same job.
//! Scenes: a human-sized shell (1.7 m tall, 2.5 m from the camera) with 40k and 200k Gaussians.

use std::time::Instant;

use mannequin_splat::{
    Camera, Colors, Gaussians, OutputGrads, Projection, RenderOptions, Rotations, TILE, backward,
    project_gaussians, render,
};
use rayon::prelude::*;

/// SplitMix64, so the scene is the same on every run.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
}

struct Scene {
    means: Vec<f32>,
    quats: Vec<f32>,
    scales: Vec<f32>,
    opacities: Vec<f32>,
    sh: Vec<f32>,
}

const SH_DEGREE: usize = 3;

/// `n` flat Gaussians tangent to an ellipsoid-ish body shell (semi-axes 0.25 × 0.85 × 0.15 m,
/// standing on the ground), with in-plane σ of 0.3–0.5 × the spacing (about a triangle's
/// inradius, as Tavatar's face Gaussians) and 1 mm across.
fn human_shell(n: usize, seed: u64) -> Scene {
    let mut rng = Rng(seed);
    let k = (SH_DEGREE + 1) * (SH_DEGREE + 1);
    let mut s = Scene { means: vec![], quats: vec![], scales: vec![], opacities: vec![], sh: vec![] };
    // Area of the shell ≈ 2.2 m²; spacing between neighbours ≈ sqrt(area / n).
    let spacing = (2.2 / n as f64).sqrt();
    for _ in 0..n {
        let u = rng.range(0.0, std::f64::consts::TAU);
        let v = rng.range(-1.0, 1.0f64).acos();
        let bulge = 1.0 + 0.3 * (3.0 * v).cos();
        let (a, b, c) = (0.25 * bulge, 0.85, 0.15);
        let p = [a * v.sin() * u.cos(), b * v.cos() + 0.85, c * v.sin() * u.sin()];
        // Outward normal of the ellipsoid; the Gaussian's thin axis points along it.
        let nrm = [p[0] / (a * a), (p[1] - 0.85) / (b * b), p[2] / (c * c)];
        let len = (nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]).sqrt();
        let nz = [nrm[0] / len, nrm[1] / len, nrm[2] / len];
        // Quaternion rotating +z onto the normal.
        let (w, x, y, z) = (1.0 + nz[2], -nz[1], nz[0], 0.0);
        let ql = (w * w + x * x + y * y + z * z).sqrt().max(1e-9);
        s.means.extend(p.map(|v| v as f32));
        s.quats.extend([w / ql, x / ql, y / ql, z / ql].map(|v| v as f32));
        s.scales
            .extend([spacing * rng.range(0.3, 0.5), spacing * rng.range(0.3, 0.5), 0.001].map(|v| v as f32));
        s.opacities.push(rng.range(0.5, 1.0) as f32);
        for b in 0..k {
            for _ in 0..3 {
                s.sh.push(if b == 0 { rng.range(-0.5, 1.0) } else { rng.range(-0.1, 0.1) } as f32);
            }
        }
    }
    s
}

impl Scene {
    fn gaussians(&self) -> Gaussians<'_, f32> {
        Gaussians {
            means: &self.means,
            rotations: Rotations::Quaternions(&self.quats),
            scales: &self.scales,
            opacities: &self.opacities,
            colors: Colors::Sh { degree: SH_DEGREE, coeffs: &self.sh },
        }
    }
}

/// The baseline: 3.33σ boxes binned to tiles, a sort per tile, every Gaussian evaluated at every
/// pixel of its tiles with `f32::exp`, and a backward that walks back to front recovering
/// transmittance by division, reducing per-Gaussian gradients on one thread. Screen-space only:
/// the projection and its backward are left out, which flatters the baseline.
// The baseline is deliberately the straightforward code, indexed loops included.
#[allow(clippy::needless_range_loop)]
mod naive {
    use super::*;

    /// One pixel's forward result: index, colour, final transmittance, list entries consumed.
    type PixelOut = (usize, [f32; 3], f32, u32);

    pub struct Binned {
        pub lists: Vec<Vec<u32>>,
    }

    pub fn bin(p: &Projection<f32>, w: usize, h: usize) -> Binned {
        let (tx, ty) = (w.div_ceil(TILE), h.div_ceil(TILE));
        let mut lists = vec![Vec::new(); tx * ty];
        for i in 0..p.depths.len() {
            let (rx, ry) = (p.radii[2 * i] as f32, p.radii[2 * i + 1] as f32);
            if rx == 0.0 {
                continue;
            }
            let (mx, my) = (p.means2d[2 * i], p.means2d[2 * i + 1]);
            let t = TILE as f32;
            let x0 = ((mx - rx) / t).floor().clamp(0.0, tx as f32) as usize;
            let x1 = ((mx + rx) / t).ceil().clamp(0.0, tx as f32) as usize;
            let y0 = ((my - ry) / t).floor().clamp(0.0, ty as f32) as usize;
            let y1 = ((my + ry) / t).ceil().clamp(0.0, ty as f32) as usize;
            for y in y0..y1 {
                for x in x0..x1 {
                    lists[y * tx + x].push(i as u32);
                }
            }
        }
        lists
            .par_iter_mut()
            .for_each(|l| l.sort_by(|&a, &b| p.depths[a as usize].total_cmp(&p.depths[b as usize])));
        Binned { lists }
    }

    pub struct Forward {
        pub color: Vec<f32>,
        pub t_final: Vec<f32>,
        pub last: Vec<u32>,
    }

    fn alpha(p: &Projection<f32>, o: &[f32], i: usize, x: usize, y: usize) -> (f32, f32, f32, f32) {
        let (dx, dy) = (x as f32 + 0.5 - p.means2d[2 * i], y as f32 + 0.5 - p.means2d[2 * i + 1]);
        let (a, b, c) = (p.conics[3 * i], p.conics[3 * i + 1], p.conics[3 * i + 2]);
        let s = 0.5 * (a * dx * dx + c * dy * dy) + b * dx * dy;
        ((o[i] * (-s).exp()).min(0.99), s, dx, dy)
    }

    pub fn forward(p: &Projection<f32>, o: &[f32], bins: &Binned, w: usize, h: usize) -> Forward {
        let tx = w.div_ceil(TILE);
        let per_tile: Vec<Vec<PixelOut>> = bins
            .lists
            .par_iter()
            .enumerate()
            .map(|(tile, list)| {
                let mut px = Vec::new();
                for y in (tile / tx) * TILE..((tile / tx) * TILE + TILE).min(h) {
                    for x in (tile % tx) * TILE..((tile % tx) * TILE + TILE).min(w) {
                        let (mut t, mut col, mut last) = (1.0f32, [0.0f32; 3], 0u32);
                        for (k, &g) in list.iter().enumerate() {
                            let g = g as usize;
                            let (al, s, _, _) = alpha(p, o, g, x, y);
                            if s < 0.0 || al < 1.0 / 255.0 {
                                continue;
                            }
                            let next = t * (1.0 - al);
                            if next <= 1e-4 {
                                break;
                            }
                            for c in 0..3 {
                                col[c] += p.colors[3 * g + c] * al * t;
                            }
                            t = next;
                            last = k as u32 + 1;
                        }
                        px.push((y * w + x, col, t, last));
                    }
                }
                px
            })
            .collect();
        let mut f = Forward { color: vec![0.0; 3 * w * h], t_final: vec![1.0; w * h], last: vec![0; w * h] };
        for (i, col, t, last) in per_tile.into_iter().flatten() {
            for c in 0..3 {
                f.color[c * w * h + i] = col[c];
            }
            f.t_final[i] = t;
            f.last[i] = last;
        }
        f
    }

    /// Screen-space gradients (mean 2, conic 3, opacity 1, colour 3) per Gaussian.
    pub fn backward(
        p: &Projection<f32>,
        o: &[f32],
        bins: &Binned,
        fwd: &Forward,
        d_color: &[f32],
        w: usize,
        h: usize,
    ) -> Vec<[f32; 9]> {
        let tx = w.div_ceil(TILE);
        let npx = w * h;
        let per_tile: Vec<Vec<(u32, [f32; 9])>> = bins
            .lists
            .par_iter()
            .enumerate()
            .map(|(tile, list)| {
                let mut out = Vec::new();
                for y in (tile / tx) * TILE..((tile / tx) * TILE + TILE).min(h) {
                    for x in (tile % tx) * TILE..((tile % tx) * TILE + TILE).min(w) {
                        let i = y * w + x;
                        let mut t = fwd.t_final[i];
                        let mut behind = [0.0f32; 3];
                        for k in (0..fwd.last[i] as usize).rev() {
                            let g = list[k] as usize;
                            let (al, s, dx, dy) = alpha(p, o, g, x, y);
                            if s < 0.0 || al < 1.0 / 255.0 {
                                continue;
                            }
                            t /= 1.0 - al;
                            let mut gr = [0.0f32; 9];
                            let mut d_al = 0.0;
                            for c in 0..3 {
                                let col = p.colors[3 * g + c];
                                gr[6 + c] = al * t * d_color[c * npx + i];
                                d_al += (col * t - behind[c] / (1.0 - al)) * d_color[c * npx + i];
                                behind[c] += col * al * t;
                            }
                            let e = (-s).exp();
                            let ds = -d_al * al;
                            let (a, b, cc) = (p.conics[3 * g], p.conics[3 * g + 1], p.conics[3 * g + 2]);
                            gr[0] = -ds * (a * dx + b * dy);
                            gr[1] = -ds * (b * dx + cc * dy);
                            gr[2] = ds * 0.5 * dx * dx;
                            gr[3] = ds * dx * dy;
                            gr[4] = ds * 0.5 * dy * dy;
                            gr[5] = d_al * e;
                            out.push((g as u32, gr));
                        }
                    }
                }
                out
            })
            .collect();
        let mut grads = vec![[0.0f32; 9]; p.depths.len()];
        for (g, gr) in per_tile.into_iter().flatten() {
            for k in 0..9 {
                grads[g as usize][k] += gr[k];
            }
        }
        grads
    }
}

/// Best of `reps` timed runs after a warm-up, in ms: on a shared machine the minimum is the
/// least disturbed measurement, for both implementations alike.
fn best_ms(reps: usize, mut f: impl FnMut()) -> f64 {
    f();
    (0..reps)
        .map(|_| {
            let s = Instant::now();
            f();
            s.elapsed().as_secs_f64() * 1e3
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    if std::env::args().any(|a| a == "--device") {
        return gpu::main();
    }
    let quick = std::env::args().any(|a| a == "--quick");
    // For profiling: time only this crate's renderer.
    let ours_only = std::env::args().any(|a| a == "--ours-only");
    let reps = if quick { 3 } else { 11 };
    let (w, h) = (540, 540);
    let camera = Camera::look_at([0.0, 0.9, 2.5], [0.0, 0.85, 0.0], [0.0, 1.0, 0.0], 0.72, w, h);
    let opts = RenderOptions {
        background: vec![1.0, 1.0, 1.0],
        count_contributors: true,
        ..RenderOptions::default()
    };
    println!(
        "mannequin-splat CPU renderer, {w}×{h}, SH degree {SH_DEGREE}, {} rayon threads",
        rayon::current_num_threads()
    );
    println!(
        "{:>8} {:>10} {:>12} {:>12} {:>12} {:>14} {:>14}",
        "N", "impl", "forward ms", "fwd+bwd ms", "backward ms", "contrib/s (M)", "speed-up"
    );
    for n in [40_000, 200_000] {
        let scene = human_shell(n, 7);
        let g = scene.gaussians();
        let out = render(&g, &camera, &opts).expect("render");
        let contributions: u64 = out.count.as_ref().expect("counted").iter().map(|&c| c as u64).sum();
        let d_image: Vec<f32> = (0..out.image.len()).map(|i| ((i % 7) as f32 - 3.0) * 0.01).collect();
        let grads = OutputGrads { image: Some(&d_image), alpha: None, depth: None };

        let fwd_opts = RenderOptions { count_contributors: false, ..opts.clone() };
        let ours_fwd = best_ms(reps, || {
            std::hint::black_box(render(&g, &camera, &fwd_opts).expect("render"));
        });
        let ours_both = best_ms(reps, || {
            let o = render(&g, &camera, &fwd_opts).expect("render");
            std::hint::black_box(backward(&g, &camera, &fwd_opts, &o, &grads).expect("backward"));
        });

        if ours_only {
            println!(
                "{n:>8} {:>10} {ours_fwd:>12.1} {ours_both:>12.1} {:>12.1}",
                "ours",
                ours_both - ours_fwd
            );
            continue;
        }
        let base_fwd = best_ms(reps, || {
            let p = project_gaussians(&g, &camera, &fwd_opts).expect("project");
            let b = naive::bin(&p, w, h);
            std::hint::black_box(naive::forward(&p, &scene.opacities, &b, w, h));
        });
        let base_both = best_ms(reps, || {
            let p = project_gaussians(&g, &camera, &fwd_opts).expect("project");
            let b = naive::bin(&p, w, h);
            let f = naive::forward(&p, &scene.opacities, &b, w, h);
            std::hint::black_box(naive::backward(&p, &scene.opacities, &b, &f, &d_image, w, h));
        });
        let rate = |ms: f64| contributions as f64 / (ms * 1e-3) / 1e6;
        println!(
            "{n:>8} {:>10} {base_fwd:>12.1} {base_both:>12.1} {:>12.1} {:>14.0} {:>14}",
            "baseline",
            base_both - base_fwd,
            rate(base_both),
            "1.00×"
        );
        println!(
            "{n:>8} {:>10} {ours_fwd:>12.1} {ours_both:>12.1} {:>12.1} {:>14.0} {:>13.2}×",
            "ours",
            ours_both - ours_fwd,
            rate(ours_both),
            base_both / ours_both
        );
        if n == 40_000 {
            let verdict = if ours_both <= 40.0 { "met" } else { "NOT met" };
            println!("         target forward+backward ≤ 40 ms for 40k: {verdict} ({ours_both:.1} ms)");
        }
        println!(
            "         {contributions} Gaussian-pixel contributions per frame, alpha coverage {:.1}%",
            100.0 * out.alpha.iter().filter(|&&a| a > 0.5).count() as f64 / (w * h) as f64
        );
    }
}

/// The Burn op on the wgpu device against the same op on Flex.
mod gpu {
    use super::*;
    use burn::tensor::{Device, Tensor, TensorData};
    use mannequin_io::{NpyArray, NpzWriter};
    use mannequin_splat::{ColorTensor, RotationTensor, splat_render};

    /// The scene's tensors on one device, made once so uploads stay out of the timings.
    struct Inputs {
        means: Tensor<2>,
        quats: Tensor<2>,
        scales: Tensor<2>,
        opacities: Tensor<1>,
        sh: Tensor<3>,
        d_image: Tensor<3>,
    }

    impl Inputs {
        fn new(scene: &Scene, d_image: &[f32], w: usize, h: usize, device: &Device) -> Self {
            let n = scene.opacities.len();
            let k = (SH_DEGREE + 1) * (SH_DEGREE + 1);
            let t2 =
                |v: &[f32], c: usize| Tensor::<2>::from_data(TensorData::new(v.to_vec(), [n, c]), device);
            Inputs {
                means: t2(&scene.means, 3),
                quats: t2(&scene.quats, 4),
                scales: t2(&scene.scales, 3),
                opacities: Tensor::from_data(TensorData::new(scene.opacities.clone(), [n]), device),
                sh: Tensor::from_data(TensorData::new(scene.sh.clone(), [n, k, 3]), device),
                d_image: Tensor::from_data(TensorData::new(d_image.to_vec(), [3, h, w]), device),
            }
        }

        /// One render; with `backward`, also the gradients of every input of L = ⟨image, dL/dimage⟩.
        fn run(&self, camera: &Camera, opts: &RenderOptions, backward: bool, device: &Device) {
            let leaf = |t: &Tensor<2>| if backward { t.clone().require_grad() } else { t.clone() };
            let means = leaf(&self.means);
            let out = splat_render(
                means.clone(),
                RotationTensor::Quaternions(leaf(&self.quats)),
                leaf(&self.scales),
                self.opacities.clone(),
                ColorTensor::Sh { degree: SH_DEGREE, coeffs: self.sh.clone() },
                camera,
                opts,
            )
            .expect("render");
            if backward {
                let grads = (out.image() * self.d_image.clone()).sum().backward();
                std::hint::black_box(means.grad(&grads));
            } else {
                std::hint::black_box(out.planes);
            }
            device.sync().expect("sync");
        }
    }

    fn save(dir: &std::path::Path, n: usize, scene: &Scene, camera: &Camera, d_image: &[f32]) {
        let (w, h) = (camera.width, camera.height);
        let k = (SH_DEGREE + 1) * (SH_DEGREE + 1);
        let flat = |m: &[[f64; 4]; 4]| m.iter().flatten().map(|&v| v as f32).collect();
        let mut npz = NpzWriter::new();
        npz.add("means", NpyArray::f32(vec![n, 3], scene.means.clone()))
            .add("quats", NpyArray::f32(vec![n, 4], scene.quats.clone()))
            .add("scales", NpyArray::f32(vec![n, 3], scene.scales.clone()))
            .add("opacities", NpyArray::f32(vec![n], scene.opacities.clone()))
            .add("sh", NpyArray::f32(vec![n, k, 3], scene.sh.clone()))
            .add("viewmat", NpyArray::f32(vec![4, 4], flat(&camera.extrinsic)))
            .add(
                "K",
                NpyArray::f32(vec![3, 3], camera.intrinsic.iter().flatten().map(|&v| v as f32).collect()),
            )
            .add("d_image", NpyArray::f32(vec![3, h, w], d_image.to_vec()));
        std::fs::create_dir_all(dir).expect("scene folder");
        npz.write(dir.join(format!("scene_{n}.npz"))).expect("write scene");
    }

    pub fn main() {
        let args: Vec<String> = std::env::args().collect();
        let value = |name: &str| args.iter().position(|a| a == name).and_then(|i| args.get(i + 1)).cloned();
        assert_eq!(
            value("--device").as_deref(),
            Some("gpu"),
            "--device takes gpu here (the CPU bench is the default)"
        );
        let save_dir = value("--save-scenes").map(std::path::PathBuf::from);
        let reps = if args.iter().any(|a| a == "--quick") { 5 } else { 21 };
        let gpu = mannequin_splat::gpu_device().unwrap_or_else(|e| panic!("{e}")).autodiff();
        let flex = Device::flex().autodiff();
        let (w, h) = (540, 540);
        let camera = Camera::look_at([0.0, 0.9, 2.5], [0.0, 0.85, 0.0], [0.0, 1.0, 0.0], 0.72, w, h);
        let opts = RenderOptions { background: vec![1.0, 1.0, 1.0], ..RenderOptions::default() };
        println!(
            "splat_render through Burn autodiff, {w}×{h}, SH degree {SH_DEGREE}; best of {reps} after a warm-up"
        );
        println!("{:>8} {:>12} {:>12} {:>12} {:>10}", "N", "device", "forward ms", "fwd+bwd ms", "speed-up");
        for n in [40_000, 200_000] {
            let scene = human_shell(n, 7);
            let d_image: Vec<f32> = (0..3 * w * h).map(|i| ((i % 7) as f32 - 3.0) * 0.01).collect();
            if let Some(dir) = &save_dir {
                save(dir, n, &scene, &camera, &d_image);
            }
            let mut base = None;
            for (name, device) in [("flex (CPU)", &flex), ("wgpu", &gpu)] {
                let inputs = Inputs::new(&scene, &d_image, w, h, device);
                let fwd = best_ms(reps, || inputs.run(&camera, &opts, false, device));
                let both = best_ms(reps, || inputs.run(&camera, &opts, true, device));
                let speedup = base.get_or_insert(both).to_owned() / both;
                println!("{n:>8} {name:>12} {fwd:>12.2} {both:>12.2} {speedup:>9.1}×");
            }
        }
    }
}
