//! NGD's garment reconstruction (`mannequin garment fit`, issue 20) on synthetic subjects with
//! garment layers, 540² read at 270², on this machine's CPU. For every garment of every subject:
//! Chamfer (cm) and normal consistency against its ground-truth meshes (simulated cloth) on
//! training frames and on the held-out test frames, mask IoU, and the time against the issue's
//! 10 minutes for 100 frames; the template it starts from is the baseline in the same run. Then
//! the ablations beside the full method, averaged over all garments: with vertex noise and with
//! the Jacobian regulariser (both off in the full method, which they made worse: docs/ngd.md),
//! without remeshing, the static field only, and masks only (no normal loss). Last, the full
//! method's per-step time in each phase.
//!
//! `cargo bench -p mannequin --bench garment_fit -- [--seeds 0,1,3] [--iters 400] [--ablations 1]`

use std::path::{Path, PathBuf};

#[path = "../../../tools/bench_args.rs"]
mod bench_args;
#[path = "../../../tools/bench_cli.rs"]
mod bench_cli;
use bench_cli::{mannequin, subject};

/// The training-time target for 100 frames, seconds.
const TARGET_S: f64 = 600.0;

/// The garment categories the subject's label legend holds.
fn garments(data: &Path) -> Vec<String> {
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(data.join("subject.json")).unwrap()).unwrap();
    let categories = ["pants", "short-pants", "shirt", "tshirt", "long-coat", "skirt", "dress"];
    json["labels"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|v| v.as_str())
        .filter(|l| categories.contains(l))
        .map(String::from)
        .collect()
}

#[derive(Default, Clone, Copy)]
struct Row {
    train_chamfer: f64,
    test_chamfer: f64,
    normal_consistency: f64,
    iou: f64,
    seconds: f64,
}

impl Row {
    fn add(&mut self, other: &Row, share: f64) {
        self.train_chamfer += other.train_chamfer * share;
        self.test_chamfer += other.test_chamfer * share;
        self.normal_consistency += other.normal_consistency * share;
        self.iou += other.iou * share;
        self.seconds += other.seconds * share;
    }

    fn print(&self, name: &str) {
        println!(
            "  {name:<28} {:>8.3} {:>8.3} {:>8.3} {:>8.3} {:>8.1}",
            self.train_chamfer, self.test_chamfer, self.normal_consistency, self.iou, self.seconds
        );
    }
}

/// The fit's report: the template's row, the fit's row and the per-step breakdown.
fn fit(
    data: &Path,
    category: &str,
    out: &Path,
    extra: &[&str],
    cache: &Path,
) -> (Row, Row, serde_json::Value) {
    let mut args: Vec<String> = [
        "garment",
        "fit",
        "--data",
        &data.display().to_string(),
        "--category",
        category,
        "--out",
        &out.display().to_string(),
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    args.extend(extra.iter().map(|s| s.to_string()));
    mannequin(&args, cache);
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("fit.json")).unwrap()).unwrap();
    let row = |when: &str| Row {
        train_chamfer: report["geometry"][when]["train"]["chamfer_cm"].as_f64().unwrap(),
        test_chamfer: report["geometry"][when]["test"]["chamfer_cm"].as_f64().unwrap_or(f64::NAN),
        normal_consistency: report["geometry"][when]["train"]["normal_consistency"].as_f64().unwrap(),
        iou: report["mean_mask_iou"][when].as_f64().unwrap(),
        seconds: if when == "after" { report["seconds"].as_f64().unwrap() } else { 0.0 },
    };
    (row("before"), row("after"), report["ms_per_step"].clone())
}

fn main() {
    let seeds: Vec<u64> = bench_args::arg("--seeds", "0,1,3".to_string())
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    let iters: usize = bench_args::arg("--iters", 400);
    let ablations = bench_args::arg("--ablations", 1) != 0;
    let root = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("garment-fit-bench");
    let cache = root.join("cache");
    std::fs::create_dir_all(&cache).unwrap();
    let iters_arg = iters.to_string();
    let variants: Vec<(&str, Vec<&str>)> = {
        let mut v = vec![("full method", vec![])];
        if ablations {
            v.extend([
                ("+ vertex noise (γ = 1 cm)", vec!["--noise", "0.01"]),
                ("+ Jacobian regulariser 1e-4", vec!["--regulariser", "1e-4"]),
                ("− remeshing", vec!["--remesh-every", "0"]),
                ("static field only", vec!["--pose-components", "0"]),
                ("masks only (no normal loss)", vec!["--normal-weight", "0"]),
            ]);
        }
        v
    };
    let mut mean = vec![Row::default(); variants.len()];
    let mut template_mean = Row::default();
    let mut count = 0;
    let mut breakdowns = Vec::new();
    let header = "  variant                      Chamfer   (test)       NC      IoU        s";
    let jobs: Vec<(u64, PathBuf, String)> = seeds
        .iter()
        .flat_map(|&seed| {
            let data = subject(seed, &root, &cache);
            garments(&data).into_iter().map(move |g| (seed, data.clone(), g))
        })
        .collect();
    for (seed, data, garment) in &jobs {
        println!("seed {seed}, {garment} ({iters} steps):");
        println!("{header}");
        for (k, (name, extra)) in variants.iter().enumerate() {
            let mut args = vec!["--iters", iters_arg.as_str()];
            args.extend(extra);
            let out = root.join(format!("fit-{seed}-{garment}-{k}"));
            let (template, row, breakdown) = fit(data, garment, &out, &args, &cache);
            if k == 0 {
                template.print("template (baseline)");
                template_mean.add(&template, 1.0);
                breakdowns.push(breakdown);
            }
            row.print(name);
            mean[k].add(&row, 1.0);
        }
        count += 1;
    }
    let share = 1.0 / count.max(1) as f64;
    println!("mean over {count} garments (seeds {seeds:?}):");
    println!("{header}");
    let mut t = Row::default();
    t.add(&template_mean, share);
    t.print("template (baseline)");
    for (k, (name, _)) in variants.iter().enumerate() {
        let mut r = Row::default();
        r.add(&mean[k], share);
        r.print(name);
    }
    let full_seconds = mean[0].seconds * share;
    println!(
        "training time (96 training frames, {iters} steps): {full_seconds:.1} s against {TARGET_S:.0} s: ratio {:.3}",
        full_seconds / TARGET_S
    );
    println!("per step, ms (full method, mean over garments):");
    if let Some(first) = breakdowns.first().and_then(|b| b.as_object()) {
        for key in first.keys() {
            let ms: f64 = breakdowns.iter().map(|b| b[key].as_f64().unwrap_or(0.0)).sum::<f64>()
                / breakdowns.len() as f64;
            println!("  {key:<14} {ms:>8.1}");
        }
    }
}
