//! `cargo bench -p mannequin-raster --bench raster`: ground-truth rendering of a ~13k-vertex mesh
//! at 540×540 (frames/s), all threads against one measured in the same run, so the printed ratio
//! does not depend on the machine.

use std::time::Instant;

use mannequin_data::Camera;
use mannequin_mesh::uv_ellipsoid;
use mannequin_raster::{RasterMesh, Shading, rasterize};

const SIZE: usize = 540;

/// Seconds per call of `f`, over `n` calls after one warm-up.
fn time<T>(n: usize, mut f: impl FnMut() -> T) -> f64 {
    std::hint::black_box(f());
    let t = Instant::now();
    for _ in 0..n {
        std::hint::black_box(f());
    }
    t.elapsed().as_secs_f64() / n as f64
}

fn main() {
    let threads = rayon::current_num_threads();
    let single = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("thread pool");
    println!("mannequin-raster benchmarks at {SIZE}×{SIZE}, {threads} threads");
    let (pos, faces) = uv_ellipsoid([0.0; 3], [0.3, 0.9, 0.2], 90, 144);
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
