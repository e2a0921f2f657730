//! `mannequin eval`: compare a folder of predictions with a ground-truth dataset folder, frame by
//! frame, or a trained avatar with a dataset's test sets; print a table and optionally write the
//! scores as JSON.

use std::path::PathBuf;

use anyhow::Context;
use mannequin_data::evaluation::{EvalOptions, EvalSummary, FrameScores, evaluate, matching_frames};
use mannequin_data::metrics::lpips::Lpips;

use crate::eval_avatar::{evaluate_with_progress, print_scores};
use crate::progress::{JobTimer, bar};

#[derive(clap::Args)]
pub struct Args {
    /// Folder of predictions: images/image_NNNN.png (or .jpg), optionally normals/ and meshes/.
    #[arg(long, required_unless_present = "model", conflicts_with = "model", requires = "gt")]
    pred: Option<PathBuf>,
    /// Ground-truth dataset folder (PeopleSnapshot layout, see docs/dataset-format.md).
    #[arg(long, requires = "pred")]
    gt: Option<PathBuf>,
    /// A trained avatar (model folder of `mannequin train`), scored on --data's test sets.
    #[arg(long, requires = "data")]
    model: Option<PathBuf>,
    /// Dataset folder whose test sets the avatar is scored on (test/novel_view and
    /// test/novel_pose of `mannequin synth`, or the folder's own test split).
    #[arg(long, requires = "model")]
    data: Option<PathBuf>,
    /// Write the scores (means and per frame) to this JSON file.
    #[arg(long)]
    json: Option<PathBuf>,
    /// LPIPS AlexNet weights (.npz of the lpips.LPIPS(net='alex') state dict); LPIPS is null without.
    #[arg(long)]
    lpips_weights: Option<PathBuf>,
    /// Background the ground truth is composited on: white, black, or R,G,B in [0,1].
    #[arg(long, default_value = "white")]
    background: String,
    /// Surface samples per mesh for Chamfer, P2S and normal consistency.
    #[arg(long, default_value_t = 100_000)]
    samples: usize,
    /// Seed of the surface samples.
    #[arg(long, default_value_t = 0)]
    seed: u64,
}

fn parse_background(s: &str) -> anyhow::Result<[f32; 3]> {
    match s {
        "white" => Ok([1.0; 3]),
        "black" => Ok([0.0; 3]),
        _ => {
            let v: Vec<f32> = s
                .split(',')
                .map(|c| c.trim().parse::<f32>())
                .collect::<Result<_, _>>()
                .with_context(|| format!("--background '{s}': expected white, black or R,G,B"))?;
            match v[..] {
                [r, g, b] if v.iter().all(|c| (0.0..=1.0).contains(c)) => Ok([r, g, b]),
                _ => anyhow::bail!("--background '{s}': expected three values in [0, 1]"),
            }
        }
    }
}

fn cell(v: Option<f64>, digits: usize) -> String {
    v.map_or("-".into(), |v| format!("{v:.digits$}"))
}

fn row(label: &str, s: &FrameScores) -> String {
    format!(
        "{label:>8} {:>8.3} {:>7.4} {:>7} {:>9} {:>8} {:>8} {:>7} {:>6}",
        s.psnr,
        s.ssim,
        cell(s.lpips, 4),
        cell(s.normal_mse_x1e3, 2),
        cell(s.normal_angle_deg, 2),
        cell(s.chamfer_cm, 3),
        cell(s.p2s_cm, 3),
        cell(s.normal_consistency, 3)
    )
}

fn print_table(summary: &EvalSummary) {
    println!(
        "{:>8} {:>8} {:>7} {:>7} {:>9} {:>8} {:>8} {:>7} {:>6}",
        "frame", "PSNR", "SSIM", "LPIPS", "N-MSE×1e3", "N-angle°", "CD cm", "P2S cm", "NC"
    );
    for s in &summary.per_frame {
        println!("{}", row(&format!("{:04}", s.frame), s));
    }
    let mean = FrameScores {
        frame: 0,
        psnr: summary.psnr,
        ssim: summary.ssim,
        lpips: summary.lpips,
        normal_mse_x1e3: summary.normal_mse_x1e3,
        normal_angle_deg: summary.normal_angle_deg,
        chamfer_cm: summary.chamfer_cm,
        p2s_cm: summary.p2s_cm,
        normal_consistency: summary.normal_consistency,
    };
    println!("{}", row("mean", &mean));
    println!(
        "{} frames; ground truth composited on {:?}{}",
        summary.frames,
        summary.background,
        if summary.gt_downscale > 1 {
            format!(", downscaled ×{}", summary.gt_downscale)
        } else {
            String::new()
        }
    );
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let _timer = JobTimer::start("eval");
    let background = parse_background(&args.background)?;
    let lpips = args.lpips_weights.as_deref().map(Lpips::load).transpose()?;
    let options = EvalOptions { background, lpips, samples: args.samples, seed: args.seed };
    let text = match (&args.model, &args.data, &args.pred, &args.gt) {
        (Some(model), Some(data), _, _) => {
            let scores = evaluate_with_progress(model, data, &options)?;
            print_scores(&scores);
            serde_json::to_string_pretty(&scores)?
        }
        (_, _, Some(pred), Some(gt)) => {
            let frames = matching_frames(pred, gt)?;
            let progress = bar(frames.len() as u64, "eval");
            let summary = evaluate(pred, gt, &options, &|_| progress.inc(1))?;
            progress.finish_and_clear();
            print_table(&summary);
            serde_json::to_string_pretty(&summary)?
        }
        _ => anyhow::bail!("give --model and --data, or --pred and --gt"),
    };
    if let Some(path) = &args.json {
        mannequin_io::write_atomic(path, text.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
        println!("wrote {}", path.display());
    }
    Ok(())
}
