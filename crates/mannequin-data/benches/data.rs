//! `cargo bench -p mannequin-data --bench data`: metric throughput at 540×540 (frames/s) and
//! ground-truth rendering speed, each against a baseline measured in the same run, so the
//! printed ratios do not depend on the machine.
//!
//! - SSIM: the separable, parallel implementation against the direct 11×11 window, one thread.
//! - PSNR and LPIPS-free evaluation throughput: PSNR + SSIM per frame.
//! - Rasterizer: a ~13k-vertex mesh at 540², all cores against one thread.

use std::time::Instant;

use mannequin_data::mesh_raster::{RasterMesh, Shading, rasterize};
use mannequin_data::metrics::{
    psnr::psnr,
    ssim::{ssim, ssim_direct},
};
use mannequin_data::rng::SplitMix64;
use mannequin_data::{Camera, Image};

const SIZE: usize = 540;

fn noisy_pair(seed: u64) -> (Image, Image) {
    let mut r = SplitMix64::new(seed);
    let a: Vec<[f32; 3]> = (0..SIZE * SIZE)
        .map(|p| {
            let (x, y) = ((p % SIZE) as f32 / SIZE as f32, (p / SIZE) as f32 / SIZE as f32);
            [(x * 7.0).sin() * 0.4 + 0.5, (y * 5.0).cos() * 0.4 + 0.5, r.uniform() as f32]
        })
        .collect();
    let b = a.iter().map(|p| p.map(|v| (v + 0.1 * (r.uniform() as f32 - 0.5)).clamp(0.0, 1.0))).collect();
    (Image { width: SIZE, height: SIZE, pixels: a }, Image { width: SIZE, height: SIZE, pixels: b })
}

/// Seconds per call of `f`, over `n` calls after one warm-up.
fn time<T>(n: usize, mut f: impl FnMut() -> T) -> f64 {
    std::hint::black_box(f());
    let t = Instant::now();
    for _ in 0..n {
        std::hint::black_box(f());
    }
    t.elapsed().as_secs_f64() / n as f64
}

fn sphere(rings: usize, segments: usize) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let mut pos = Vec::new();
    for i in 0..=rings {
        let th = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..segments {
            let ph = std::f32::consts::TAU * j as f32 / segments as f32;
            pos.push([0.3 * th.sin() * ph.cos(), 0.9 * th.cos(), 0.2 * th.sin() * ph.sin()]);
        }
    }
    let idx = |i: usize, j: usize| (i * segments + j % segments) as u32;
    let faces = (0..rings)
        .flat_map(|i| {
            (0..segments).flat_map(move |j| {
                [[idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)], [idx(i, j), idx(i + 1, j + 1), idx(i, j + 1)]]
            })
        })
        .collect();
    (pos, faces)
}

fn main() {
    let threads = rayon::current_num_threads();
    let single = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("thread pool");
    println!("mannequin-data benchmarks at {SIZE}×{SIZE}, {threads} threads");

    let (a, b) = noisy_pair(1);
    let direct = single.install(|| time(1, || ssim_direct(&a, &b)));
    let fast_one = single.install(|| time(5, || ssim(&a, &b)));
    let fast = time(10, || ssim(&a, &b));
    println!("SSIM direct 11×11, 1 thread : {:8.1} frames/s", 1.0 / direct);
    println!(
        "SSIM separable, 1 thread    : {:8.1} frames/s  ({:.1}× direct)",
        1.0 / fast_one,
        direct / fast_one
    );
    println!(
        "SSIM separable, {threads} threads   : {:8.1} frames/s  ({:.1}× direct)",
        1.0 / fast,
        direct / fast
    );
    let both = time(10, || psnr(&a, &b) + ssim(&a, &b));
    println!("PSNR + SSIM per frame       : {:8.1} frames/s", 1.0 / both);

    let (pos, faces) = sphere(90, 144);
    let normals = mannequin_mesh::normals::vertex_normals(&pos, &faces);
    let mesh =
        RasterMesh { positions: &pos, faces: &faces, normals: &normals, shading: Shading::Flat([0.8; 3]) };
    let cam = Camera::look_at([0.0, 0.0, 2.5], [0.0; 3], [0.0, 1.0, 0.0], 0.8, SIZE, SIZE);
    let r1 = single.install(|| time(5, || rasterize(&mesh, &cam, [1.0; 3])));
    let rn = time(20, || rasterize(&mesh, &cam, [1.0; 3]));
    println!(
        "rasterize {}k vertices, 1 thread: {:7.1} frames/s; {threads} threads: {:7.1} frames/s ({:.1}×)",
        pos.len() / 1000,
        1.0 / r1,
        1.0 / rn,
        r1 / rn
    );
}
