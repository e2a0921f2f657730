//! Issue 21's avatar row: is `capture`'s output as good to train on as the truth? A synthetic
//! subject's turning capture goes to `capture` as plain frames; one avatar trains on what
//! `capture` recovers (its masks, camera and poses), another on the true masks, camera and poses
//! of the same frames. Both are scored on the same held-out frames (the capture's test split),
//! each rendered with its own dataset's camera and poses for them, against the same truth: the
//! true images composited by the true masks. Everything runs through the CLI a user runs.
//!
//! `cargo bench -p mannequin --bench capture_avatar -- [--seed S] [--iters N]`

use std::path::Path;
use std::process::Command;
use std::time::Instant;

use mannequin_data::{Dataset, DatasetWriter, Poses};

#[path = "../../../tools/bench_args.rs"]
mod bench_args;
use bench_args::arg;

/// The bound on how far the captured avatar may fall behind, in dB.
const WITHIN_DB: f64 = 1.5;

fn mannequin(args: &[&str]) -> f64 {
    let start = Instant::now();
    let out = Command::new(env!("CARGO_BIN_EXE_mannequin")).args(args).output().unwrap();
    assert!(out.status.success(), "mannequin {args:?}: {}", String::from_utf8_lossy(&out.stderr));
    start.elapsed().as_secs_f64()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Every frame's poses of the synthetic capture: its training frames, then its test frames.
fn all_poses(dataset: &Dataset) -> Poses {
    let mut all = dataset.split("train").unwrap().poses;
    all.append(&dataset.split("test").unwrap().poses);
    all
}

/// The synthetic subject's frames with their true masks, camera and poses, split as `like` is.
fn truth_view(synth: &Path, like: &Dataset, out: &Path) {
    for sub in ["images", "masks", "poses"] {
        std::fs::create_dir_all(out.join(sub)).unwrap();
    }
    for i in 0..like.frame_count {
        for file in [mannequin_data::layout::image, mannequin_data::layout::mask] {
            std::fs::copy(file(synth, i), file(out, i)).unwrap();
        }
    }
    std::fs::copy(synth.join("cameras.npz"), out.join("cameras.npz")).unwrap();
    let truth = all_poses(&Dataset::open(synth, 1).unwrap());
    let writer = DatasetWriter::new(out);
    for (name, range) in &like.splits {
        writer.write_poses(name, &truth.select(&range.frames())).unwrap();
    }
    writer.write_splits(&like.splits).unwrap();
}

/// Trains on `data`, renders its test split, and scores that against `truth`'s: PSNR, SSIM.
fn train_and_score(data: &Path, truth: &Path, avatar: &Path, iters: &str) -> (f64, f64, f64) {
    let seconds = mannequin(&["train", "--data", s(data), "--out", s(avatar), "--iters", iters]);
    mannequin(&["eval", "--avatar", s(avatar), "--data", s(data)]);
    let json = avatar.join("truth_scores.json");
    mannequin(&[
        "eval",
        "--pred",
        s(&avatar.join("eval/test")),
        "--gt",
        s(truth),
        "--set",
        "test",
        "--json",
        s(&json),
    ]);
    let scores: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    (scores["test"]["psnr"].as_f64().unwrap(), scores["test"]["ssim"].as_f64().unwrap(), seconds)
}

fn main() {
    let seed: u64 = arg("--seed", 0);
    let iters: u64 = arg("--iters", 2000);
    let iters = iters.to_string();
    let dir = std::env::temp_dir().join(format!("mq-bench-capture-avatar-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (synth, captured, truth) = (dir.join("synth"), dir.join("captured"), dir.join("truth"));
    mannequin(&["synth", "--seed", &seed.to_string(), "--out", s(&synth)]);
    let capture_s = mannequin(&["capture", "--frames", s(&synth.join("images")), "--out", s(&captured)]);
    let like = Dataset::open(&captured, 1).unwrap();
    assert_eq!(like.frame_count, Dataset::open(&synth, 1).unwrap().frame_count, "capture left frames out");
    truth_view(&synth, &like, &truth);

    println!("seed {seed}: {} frames, test split {:?}", like.frame_count, like.splits["test"].frames());
    println!("  capture: {capture_s:.1} s");
    let (psnr_t, ssim_t, train_t) = train_and_score(&truth, &truth, &dir.join("avatar-truth"), &iters);
    println!(
        "  trained on the true poses (baseline): PSNR {psnr_t:.2} dB, SSIM {ssim_t:.3} ({train_t:.0} s)"
    );
    let (psnr_c, ssim_c, train_c) = train_and_score(&captured, &truth, &dir.join("avatar-captured"), &iters);
    println!(
        "  trained on capture's output:          PSNR {psnr_c:.2} dB, SSIM {ssim_c:.3} ({train_c:.0} s)"
    );
    let gap = psnr_t - psnr_c;
    println!(
        "  capture's avatar is {gap:.2} dB behind; target within {WITHIN_DB} dB: {}",
        if gap <= WITHIN_DB { "met" } else { "NOT met" }
    );
    std::fs::remove_dir_all(&dir).ok();
}
