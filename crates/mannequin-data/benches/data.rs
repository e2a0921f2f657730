//! `cargo bench -p mannequin-data --bench data`: metric throughput at 540×540 (frames/s), each
//! against a baseline measured in the same run, so the printed ratios do not depend on the
//! machine. (Ground-truth rendering is timed by `mannequin-raster`'s bench, synthetic-subject
//! generation by `mannequin-synth`'s.)
//!
//! - SSIM: the separable, parallel implementation against the direct 11×11 window, one thread.
//! - PSNR + SSIM per frame; LPIPS (AlexNet, random weights) and the geometry metrics
//!   (100k samples per mesh) on all threads against one.

use std::time::Instant;

use mannequin_data::Image;
use mannequin_data::metrics::geometry::geometry_metrics;
use mannequin_data::metrics::lpips::{Lpips, weight_shapes};
use mannequin_data::metrics::{
    psnr::psnr,
    ssim::{ssim, ssim_direct},
};
use mannequin_io::rng::SplitMix64;
use mannequin_io::{NpyArray, NpzWriter};
use mannequin_mesh::{TriMesh, uv_ellipsoid};

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

/// LPIPS with random weights (uniform in ±sqrt(6 / fan-in)), through a weights file.
fn random_lpips() -> Lpips {
    let mut r = SplitMix64::new(9);
    let mut w = NpzWriter::new();
    for (key, shape) in weight_shapes() {
        let fan_in: usize = shape[1..].iter().product();
        let bound = (6.0 / fan_in as f64).sqrt();
        let n: usize = shape.iter().product();
        w.add(&key, NpyArray::f32(shape, (0..n).map(|_| r.range(-bound, bound) as f32).collect()));
    }
    let path = std::env::temp_dir().join(format!("mq-bench-lpips-{}.npz", std::process::id()));
    w.write(&path).expect("temporary weights file");
    let model = Lpips::load(&path).expect("weights just written");
    let _ = std::fs::remove_file(path);
    model
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
    let both = time(10, || (psnr(&a, &b), ssim(&a, &b)));
    println!("PSNR + SSIM per frame       : {:8.1} frames/s", 1.0 / both);

    let lpips = random_lpips();
    let l1 = single.install(|| time(1, || lpips.distance(&a, &b)));
    let ln = time(3, || lpips.distance(&a, &b));
    println!(
        "LPIPS 1 thread: {:6.2} frames/s; {threads} threads: {:6.2} frames/s ({:.1}×)",
        1.0 / l1,
        1.0 / ln,
        l1 / ln
    );

    let (pos, faces) = uv_ellipsoid([0.0; 3], [0.3, 0.9, 0.2], 90, 144);
    let gt = TriMesh::new(pos.clone(), faces.clone());
    let pred = TriMesh::new(pos.iter().map(|p| [p[0] * 1.01, p[1], p[2] + 0.003]).collect(), faces.clone());
    let g1 = single.install(|| time(1, || geometry_metrics(&pred, &gt, 100_000, 0)));
    let gn = time(3, || geometry_metrics(&pred, &gt, 100_000, 0));
    println!(
        "Chamfer+P2S+NC, 100k samples: 1 thread {:.2} s; {threads} threads {:.2} s ({:.1}×)",
        g1,
        gn,
        g1 / gn
    );
}
