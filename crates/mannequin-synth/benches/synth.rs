//! `cargo bench -p mannequin-synth --bench synth`: synthetic-subject generation, a short capture
//! on all threads against one measured in the same run (so the printed ratio does not depend on
//! the machine), and `mannequin synth` with default settings (176 frames at 540²), timed once
//! with the cloth–cloth contacts and once without.

use std::time::Instant;

use mannequin_body::BodyModel;
use mannequin_synth::{SynthOptions, generate};

/// Seconds one call of `f` takes.
fn time_once<T>(f: impl FnOnce() -> T) -> f64 {
    let t = Instant::now();
    std::hint::black_box(f());
    t.elapsed().as_secs_f64()
}

fn main() {
    let threads = rayon::current_num_threads();
    let single = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("thread pool");
    let model = BodyModel::default_body();
    let dir = std::env::temp_dir().join(format!("mq-bench-synth-{}", std::process::id()));
    let short = SynthOptions {
        capture_frames: 12,
        train_frames: 8,
        view_poses: 2,
        motion_frames: 2,
        ..SynthOptions::default()
    };
    let frames = short.total_frames() as f64;
    let s1 =
        single.install(|| time_once(|| generate(&model, &dir, &short, &|_| {}).expect("synthetic subject")));
    let sn = time_once(|| generate(&model, &dir, &short, &|_| {}).expect("synthetic subject"));
    println!(
        "synth, {} frames: 1 thread {:.1} frames/s; {threads} threads {:.1} frames/s ({:.1}×)",
        frames,
        frames / s1,
        frames / sn,
        s1 / sn
    );
    // The default subject with the cloth–cloth contacts (the default) and without: the issue's
    // target is 60 s with them.
    let full = SynthOptions::default();
    let with = time_once(|| generate(&model, &dir, &full, &|_| {}).expect("synthetic subject"));
    let plain = SynthOptions { self_collision: false, ..full.clone() };
    let without = time_once(|| generate(&model, &dir, &plain, &|_| {}).expect("synthetic subject"));
    let size = full.size;
    println!(
        "synth default ({} frames at {size}²): {with:.1} s with cloth–cloth contacts (target 60 s), \
         {without:.1} s without ({:.2}×)",
        full.total_frames(),
        with / without
    );
    let _ = std::fs::remove_dir_all(dir);
}
