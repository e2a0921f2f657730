//! Capture judged on what it was not built from (issue 21's table): synthetic subjects dressed
//! in simulated cloth and rendered by `mannequin-synth`, whose frames go in as plain images (no
//! poses, masks or cameras), and whose true bodies the result is compared with.
//!
//! Per subject: the person models, the mirror resolution and the clip fit run on the turning
//! capture's frames, with the focal length assumed as `capture` assumes it. Then, per frame: the mask's IoU against the true
//! mask; PA-MPJPE over the 24 joints and the per-vertex error of the fitted body against the
//! true body under the clothes (both in camera space, after the similarity that best aligns
//! them, as PA-MPJPE is defined); and the time. One more `fit` of a single frame, models
//! loaded afresh, times the one-image path.
//!
//! `cargo bench -p mannequin-fit --bench capture -- [--seed S] [--subjects N] [--frames F] [--per-frame]`

use std::time::Instant;

use glam::DVec3;
use mannequin_body::BodyModel;
use mannequin_data::{Camera, Dataset, Poses};
use mannequin_fit::body_fit::{Fitter, assumed_focal};
use mannequin_fit::clip_fit::{Tracker, fit_clip, resolve_mirrors};
use mannequin_fit::pose_error::aligned_error;
use mannequin_fit::{PersonModels, fit_body};
use mannequin_synth::{SynthOptions, generate};

#[path = "../../../tools/bench_args.rs"]
mod bench_args;
use bench_args::arg;

/// Joints and vertices of a body in a camera's space.
fn in_camera(
    model: &BodyModel,
    betas: &[f32],
    pose: &[f32],
    transl: &[f32; 3],
    camera: &Camera,
) -> (Vec<DVec3>, Vec<DVec3>) {
    let posed = mannequin_body::forward(model, betas, pose, transl).expect("pose");
    let points = |v: &[f32]| -> Vec<DVec3> {
        v.chunks_exact(3)
            .map(|p| camera.world_to_camera(DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)))
            .collect()
    };
    (points(&posed.joints), points(&posed.vertices))
}

fn all_poses(dataset: &Dataset) -> Poses {
    let mut all = dataset.split("train").expect("train split").poses;
    all.append(&dataset.split("test").expect("test split").poses);
    all
}

fn main() {
    let seed: u64 = arg("--seed", 0);
    let subjects: u64 = arg("--subjects", 1).max(1);
    let frames: usize = arg("--frames", 120);
    let dir = std::env::temp_dir().join(format!("mannequin-capture-bench-{}", std::process::id()));
    let model = BodyModel::default_body();
    let mut rows = Vec::new();
    for subject in seed..seed + subjects {
        let data = dir.join(format!("seed-{subject}"));
        let summary =
            generate(&model, &data, &SynthOptions { seed: subject, ..SynthOptions::default() }, &|_| {})
                .expect("synth");
        let dataset = Dataset::open(&data, 1).expect("dataset");
        let truth = all_poses(&dataset);
        let n = frames.min(truth.len());
        let frames: Vec<_> = (0..n).map(|i| dataset.frame(i).expect("frame")).collect();
        let (width, height) = (frames[0].image.width, frames[0].image.height);

        let start = Instant::now();
        let models = PersonModels::load().expect("models");
        let one = models.people(&frames[0].image, None).expect("people");
        fit_body(&model, &one[0].landmarks, width, height, assumed_focal(width, height)).expect("fit");
        let one_image = start.elapsed().as_secs_f64();

        let start = Instant::now();
        let mut tracker = Tracker::new(&models);
        let mut people: Vec<_> =
            frames.iter().map(|f| tracker.next(&f.image).expect("landmarks").expect("the person")).collect();
        let fitter = Fitter::new(&model, width, height, assumed_focal(width, height)).expect("fitter");
        let mirrored = resolve_mirrors(&fitter, &mut people).len();
        let fits = fit_clip(&fitter, &people, &mut || {}).expect("clip");
        let clip = start.elapsed().as_secs_f64();

        let (mut iou, mut mpjpe, mut pve) = (0.0, 0.0, 0.0);
        let mut per_frame = Vec::with_capacity(n);
        for (i, (frame, fit)) in frames.iter().zip(&fits).enumerate() {
            iou += people[i].person_mask(width, height).iou(&frame.mask);
            let (tj, tv) =
                in_camera(&model, &truth.betas, &truth.pose72(i), &truth.transl[i], dataset.camera(i));
            let (fj, fv) = in_camera(&model, &fit.betas, &fit.pose, &fit.transl, &fit.camera);
            let aligned = |a: &[DVec3], b: &[DVec3]| aligned_error(a, b).expect("a body fixes a rotation");
            let (e_j, e_v) = (aligned(&fj, &tj), aligned(&fv, &tv));
            if std::env::args().any(|a| a == "--per-frame") {
                println!("  frame {i:3}: PA-MPJPE {:.1} mm, per-vertex {:.1} mm", 1000.0 * e_j, 1000.0 * e_v);
            }
            mpjpe += e_j;
            per_frame.push(e_j);
            pve += e_v;
        }
        let k = n as f64;
        per_frame.sort_by(f64::total_cmp);
        println!(
            "seed {subject} ({:?}, {n} frames at {width}×{height}, {mirrored} read mirrored): mask IoU {:.3}, PA-MPJPE {:.1} mm (median frame {:.1}), per-vertex {:.1} mm, one image {one_image:.2} s, clip {clip:.1} s",
            summary.subject.outfit,
            iou / k,
            1000.0 * mpjpe / k,
            1000.0 * per_frame[n / 2],
            1000.0 * pve / k
        );
        rows.push((iou / k, 1000.0 * mpjpe / k, 1000.0 * pve / k, one_image, clip * 120.0 / k));
    }
    let _ = std::fs::remove_dir_all(&dir);
    let m = |f: fn(&(f64, f64, f64, f64, f64)) -> f64| rows.iter().map(f).sum::<f64>() / rows.len() as f64;
    println!("\n| measure (mean of {} subjects) | measured | target | met |", rows.len());
    println!("| --- | --- | --- | --- |");
    let line = |name: &str, v: f64, target: &str, met: bool| {
        println!("| {name} | {v:.3} | {target} | {} |", if met { "yes" } else { "no" })
    };
    let iou = m(|r| r.0);
    line("mask IoU against the true masks", iou, "≥ 0.95", iou >= 0.95);
    let mpjpe = m(|r| r.1);
    line("PA-MPJPE, 24 joints (mm)", mpjpe, "≤ 50", mpjpe <= 50.0);
    let pve = m(|r| r.2);
    line("per-vertex error under the clothes, aligned (mm)", pve, "≤ 25", pve <= 25.0);
    let one = m(|r| r.3);
    line("fit on one image, models loaded (s)", one, "≤ 2", one <= 2.0);
    let clip = m(|r| r.4);
    line("capture of 120 frames (s, landmarks + fit)", clip, "≤ 120", clip <= 120.0);
}
