//! Posing a 1,000-frame clip: the batched fast path against (a) a per-frame single-threaded
//! baseline measured in the same run and (b) the `smplx` Python package on CPU, when the oracle
//! environment is installed ($ORACLE_VENV, default ~/.cache/mannequin-oracles).
//!
//! Run: cargo bench -p mannequin-body --bench pose

#[path = "../tests/common/random_model.rs"]
mod random_model;

use std::process::Command;
use std::time::Instant;

use mannequin_body::{BodyModel, forward, parse_model, pose_frames, shape_body};
use mannequin_io::Npz;

const FRAMES: usize = 1000;

fn best_of<T>(runs: usize, mut f: impl FnMut() -> T) -> f64 {
    (0..runs)
        .map(|_| {
            let start = Instant::now();
            std::hint::black_box(f());
            start.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn clip(model: &BodyModel) -> (Vec<f32>, Vec<f32>) {
    let poses = (0..FRAMES * model.pose_len()).map(|i| 0.6 * ((i as f32) * 0.618).sin()).collect();
    (poses, vec![0.0; FRAMES * 3])
}

fn smplx_seconds() -> Option<f64> {
    let venv = std::env::var("ORACLE_VENV").unwrap_or_else(|_| {
        format!("{}/.cache/mannequin-oracles", std::env::var("HOME").unwrap_or_default())
    });
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tools/oracles/bench_smplx.py");
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get());
    let out = Command::new(format!("{venv}/bin/python"))
        .args([script, &FRAMES.to_string(), &threads.to_string()])
        .output()
        .ok()?;
    let text = String::from_utf8_lossy(&out.stdout);
    text.lines().find_map(|l| l.strip_prefix("smplx_seconds ")?.trim().parse().ok())
}

fn bench(name: &str, model: &BodyModel) -> f64 {
    let (poses, transl) = clip(model);
    let shape = vec![0.5; model.num_betas().min(10)];
    let fast = best_of(5, || forward(model, &shape, &poses, &transl).unwrap());
    // Baseline: the same code one frame at a time on one thread.
    let shaped = shape_body(model, &shape).unwrap();
    let pl = model.pose_len();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let single = pool.install(|| {
        best_of(1, || {
            (0..FRAMES)
                .map(|f| {
                    pose_frames(model, &shaped, &poses[f * pl..(f + 1) * pl], &transl[3 * f..3 * f + 3])
                        .unwrap()
                        .vertices
                        .len()
                })
                .sum::<usize>()
        })
    });
    println!(
        "{name:<28} {:>6} verts  batched {:>8.1} ms  per-frame 1-thread {:>8.1} ms  speed-up {:>5.1}x",
        model.num_vertices(),
        fast * 1e3,
        single * 1e3,
        single / fast
    );
    fast
}

fn main() {
    println!("posing {FRAMES} frames on {} threads", rayon::current_num_threads());
    let bytes = random_model::random_model_npz(24, 10, 65, 106);
    let smpl = parse_model(&Npz::from_bytes("random-smpl.npz".into(), &bytes).unwrap(), None).unwrap();
    let ours = bench("SMPL-format (random)", &smpl);
    bench("default body", &BodyModel::default_body());
    bench("default body (lod1)", &BodyModel::default_body_lod1());
    match smplx_seconds() {
        Some(s) => println!(
            "smplx (PyTorch CPU) SMPL-format: {:.1} ms  -> mannequin is {:.1}x faster (target >= 5x)",
            s * 1e3,
            s / ours
        ),
        None => println!("smplx not installed (run tools/oracles env); no comparison this run"),
    }
}
