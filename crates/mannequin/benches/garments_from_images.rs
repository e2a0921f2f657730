//! Garments from the images alone (issue 37), on synthetic subjects of every outfit the generator
//! makes (540², 120 frames, 96 to train on). For each subject:
//!
//! - **labels, images only**: `capture` on the subject's frames (its poses, camera and masks
//!   estimated, then `segment`), each garment's label IoU against the true label maps over every
//!   frame; and the outfit `--garments auto` decided against the true one;
//! - **labels, true poses and masks** (an upper bound on the labels: the user has no true
//!   poses): `segment` on a copy holding the images, true masks, cameras and poses;
//! - **geometry**: `garment fit` on that copy with the estimated labels, no normal maps, and a base
//!   template one size off the true garment's; Chamfer and normal consistency against the true
//!   garment meshes on training frames, held-out frames (the capture's last quarter turn, which
//!   repeats its first) and novel poses (`test/novel_pose`: walking, arms raised and crossed,
//!   squatting). The poses and camera are the true ones, so that the fit is compared in the
//!   truth's frame: an upper bound as to the poses;
//! - **time**: `segment` on the 120 captured frames, against the 30 s.
//!
//! The seeds are not those the segmentation was tuned on (1, 2, 3 at 270²).
//!
//! `cargo bench -p mannequin --bench garments_from_images -- [--seeds 11,12,13,14] [--iters 400]`

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use mannequin_data::labels::LabelMap;

#[path = "../../../tools/bench_args.rs"]
mod bench_args;
#[path = "../../../tools/bench_cli.rs"]
mod bench_cli;
#[path = "../../../tools/copy_dir.rs"]
mod copy_dir;
use bench_cli::{mannequin, subject};
use copy_dir::copy_dir;

/// The time target for segmenting 120 frames, seconds.
const SEGMENT_TARGET_S: f64 = 30.0;
/// The targets for the label IoU, Chamfer (cm) and normal consistency.
const IOU_TARGET: f64 = 0.85;
const CHAMFER_TARGET: f64 = 0.8;
const NC_TARGET: f64 = 0.88;

/// A label's role: garments compared by where they are worn, whatever category they were named.
fn role(name: &str) -> &str {
    match name {
        "tshirt" | "shirt" | "long-coat" => "upper",
        "pants" | "short-pants" | "skirt" => "lower",
        other => other,
    }
}

fn legend(data: &Path) -> Vec<String> {
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(data.join("subject.json")).unwrap()).unwrap();
    json["labels"].as_array().unwrap().iter().map(|v| v.as_str().unwrap().to_string()).collect()
}

/// Per role (skin, hair, shoes, upper, lower, dress): intersection over union of the estimated
/// label maps in `estimate` and the true ones in `truth`, summed over all frames the estimate has.
fn label_iou(truth: &Path, estimate: &Path) -> BTreeMap<String, f64> {
    let (lt, le) = (legend(truth), legend(estimate));
    let mut counts: BTreeMap<String, (f64, f64)> = BTreeMap::new();
    let mut frames: Vec<PathBuf> = std::fs::read_dir(estimate.join("labels"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "png"))
        .collect();
    frames.sort();
    for path in frames {
        let e = LabelMap::read_png(&path).unwrap();
        let t = LabelMap::read_png(&truth.join("labels").join(path.file_name().unwrap())).unwrap();
        for r in ["skin", "hair", "shoes", "upper", "lower", "dress"] {
            let (mut inter, mut union) = (0.0, 0.0);
            for (&a, &b) in t.labels.iter().zip(&e.labels) {
                let (a, b) = (role(&lt[a as usize]) == r, role(&le[b as usize]) == r);
                inter += f64::from(u8::from(a && b));
                union += f64::from(u8::from(a || b));
            }
            let c = counts.entry(r.to_string()).or_default();
            c.0 += inter;
            c.1 += union;
        }
    }
    counts.into_iter().filter(|(_, (_, u))| *u > 0.0).map(|(r, (i, u))| (r, i / u)).collect()
}

/// The true garments of a subject with their sizes, from the generator's outfit name.
fn true_garments(data: &Path) -> Vec<(&'static str, &'static str)> {
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(data.join("subject.json")).unwrap()).unwrap();
    match json["subject"]["outfit"].as_str().unwrap() {
        "tight-shirt-trousers" => vec![("pants", "S"), ("shirt", "S")],
        "loose-shirt-trousers" => vec![("pants", "L"), ("tshirt", "M")],
        "shirt-skirt" => vec![("skirt", "M"), ("tshirt", "M")],
        "dress" => vec![("dress", "M")],
        other => panic!("unknown outfit {other}"),
    }
}

/// A size one step off `size`, for a base template that is not the truth's.
fn other_size(size: &str) -> &'static str {
    match size {
        "S" => "M",
        "M" => "L",
        _ => "M",
    }
}

/// What a user with the true poses, camera and masks would have (plus the true garment meshes,
/// which only score the fit).
fn with_true_poses(data: &Path, out: &Path) {
    let _ = std::fs::remove_dir_all(out);
    for name in ["images", "masks", "poses", "meshes", "test/novel_pose"] {
        copy_dir(&data.join(name), &out.join(name));
    }
    for name in ["cameras.npz", "splits.json", "origin.json"] {
        std::fs::copy(data.join(name), out.join(name)).unwrap();
    }
}

fn segmentation_seconds(data: &Path) -> f64 {
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(data.join("labels/segmentation.json")).unwrap()).unwrap();
    json["result"]["seconds"].as_f64().unwrap()
}

fn s(v: &impl ToString) -> String {
    v.to_string()
}

fn main() {
    let seeds: Vec<u64> = bench_args::arg("--seeds", "11,12,13,14".to_string())
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    let iters: usize = bench_args::arg("--iters", 400);
    let root = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("garments-from-images-bench");
    let cache = root.join("cache");
    std::fs::create_dir_all(&cache).unwrap();
    let mut worst_iou: f64 = 1.0;
    let (mut chamfers, mut ncs, mut novel) = (Vec::new(), Vec::new(), Vec::new());
    for &seed in &seeds {
        let data = subject(seed, &root, &cache);
        let truth = true_garments(&data);
        // Images only: capture (which segments) on the frames.
        let captured = root.join(format!("captured-{seed}"));
        if !captured.join("labels/segmentation.json").exists() {
            let _ = std::fs::remove_dir_all(&captured);
            mannequin(
                &[
                    "capture",
                    "--frames",
                    &s(&data.join("images").display()),
                    "--out",
                    &s(&captured.display()),
                ],
                &cache,
            );
        }
        let seconds = mannequin(&["segment", "--data", &s(&captured.display()), "--replace"], &cache);
        let in_process = segmentation_seconds(&captured);
        let decided: Vec<String> = legend(&captured)[4..].to_vec();
        let iou_images = label_iou(&data, &captured);
        // True poses, camera and masks.
        let posed = root.join(format!("true-poses-{seed}"));
        with_true_poses(&data, &posed);
        mannequin(&["segment", "--data", &s(&posed.display())], &cache);
        let iou_posed = label_iou(&data, &posed);
        println!(
            "seed {seed}: true {:?}, decided from the images {decided:?}",
            truth.iter().map(|(c, _)| *c).collect::<Vec<_>>()
        );
        println!("  label IoU          images only   true poses+masks");
        for (r, v) in &iou_images {
            println!("  {r:<18} {v:>11.3} {:>18.3}", iou_posed.get(r).copied().unwrap_or(f64::NAN));
            if ["upper", "lower", "dress"].contains(&r.as_str()) {
                worst_iou = worst_iou.min(*v);
            }
        }
        println!(
            "  segment, 120 frames: {seconds:.1} s wall ({in_process:.1} s in the labelling) against {SEGMENT_TARGET_S:.0} s: ratio {:.3}",
            seconds / SEGMENT_TARGET_S
        );
        let estimated = legend(&posed);
        println!("  garment fit ({iters} steps, estimated labels, no normal maps, template one size off):");
        println!(
            "  garment   size  template   Chamfer (train, test, novel poses)        NC (train, test, novel poses)   mask IoU"
        );
        for (category, size) in truth {
            let label = estimated[4..].iter().find(|n| role(n) == role(category)).cloned();
            let Some(label) = label else {
                println!("  {category}: no label of its role among {estimated:?}");
                continue;
            };
            let out = root.join(format!("fit-{seed}-{category}"));
            let template = other_size(size);
            mannequin(
                &[
                    "garment",
                    "fit",
                    "--data",
                    &s(&posed.display()),
                    "--category",
                    category,
                    "--label",
                    &label,
                    "--size",
                    template,
                    "--iters",
                    &s(&iters),
                    "--out",
                    &s(&out.display()),
                ],
                &cache,
            );
            let report: serde_json::Value =
                serde_json::from_slice(&std::fs::read(out.join("fit.json")).unwrap()).unwrap();
            let g = |when: &str, split: &str, key: &str| {
                report["geometry"][when][split][key].as_f64().unwrap_or(f64::NAN)
            };
            println!(
                "  {category:<9} {size:>4} {template:>9}   {:.3} → {:.3}, {:.3} → {:.3}, {:.3} → {:.3}   {:.3}, {:.3}, {:.3}     {:.3}",
                g("before", "train", "chamfer_cm"),
                g("after", "train", "chamfer_cm"),
                g("before", "test", "chamfer_cm"),
                g("after", "test", "chamfer_cm"),
                g("before", "novel_pose", "chamfer_cm"),
                g("after", "novel_pose", "chamfer_cm"),
                g("after", "train", "normal_consistency"),
                g("after", "test", "normal_consistency"),
                g("after", "novel_pose", "normal_consistency"),
                report["mean_mask_iou"]["after"].as_f64().unwrap_or(f64::NAN),
            );
            chamfers.push(g("after", "train", "chamfer_cm"));
            ncs.push(g("after", "train", "normal_consistency"));
            novel.push(g("after", "novel_pose", "chamfer_cm"));
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    println!(
        "worst garment label IoU, images only: {worst_iou:.3} (target ≥ {IOU_TARGET}); mean Chamfer {:.3} cm (target ≤ {CHAMFER_TARGET}), {:.3} cm on novel poses; mean NC {:.3} (target ≥ {NC_TARGET}) over {} garments",
        mean(&chamfers),
        mean(&novel),
        mean(&ncs),
        chamfers.len()
    );
}
