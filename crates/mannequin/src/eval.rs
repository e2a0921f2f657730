//! `mannequin eval`: score a trained avatar on a dataset's test sets, or a folder of
//! predictions against a ground-truth dataset's test frames. Both print one table and write
//! one JSON layout (`novel_view` / `novel_pose` / `test` / `geometry`).

use std::cell::RefCell;
use std::path::PathBuf;

use anyhow::{Context, Result};
use indicatif::ProgressBar;
use mannequin_avatar::evaluation::evaluate_avatar;
use mannequin_avatar::test_pose_fit::TestPoseMode;
use mannequin_data::evaluation::{EvalOptions, MAX_SURFACE_SAMPLES, evaluate, test_frames};
use mannequin_data::metrics::lpips::Lpips;
use mannequin_data::{Scores, TestPoses, TestSet};

use mannequin_io::progress::{JobTimer, bar};

#[derive(clap::Args)]
pub struct Args {
    /// A trained avatar folder (written by `mannequin train`), rendered and scored on --data's
    /// test sets (predictions are kept under AVATAR/eval/<set>/).
    #[arg(long, required_unless_present = "pred", conflicts_with = "pred", requires = "data")]
    avatar: Option<PathBuf>,
    /// Dataset folder whose test sets the avatar is scored on: test/novel_view and
    /// test/novel_pose of `mannequin synth`, or else the folder's own test split (`test`).
    #[arg(long, requires = "avatar")]
    data: Option<PathBuf>,
    /// Folder of predictions (images/image_NNNN.png or .jpg, optionally normals/ and meshes/) for the
    /// test frames of --gt.
    #[arg(long, requires = "gt")]
    pred: Option<PathBuf>,
    /// Ground-truth dataset folder (see docs/dataset-format.md); its test split's frames are scored.
    #[arg(long, requires = "pred")]
    gt: Option<PathBuf>,
    /// What --gt's test frames are, which names them in the scores.
    #[arg(long, value_enum, default_value_t = TestSet::Test, requires = "pred")]
    set: TestSet,
    /// Score --avatar's renders of --data's test frames against this dataset's images, masks and
    /// normal maps of the same frames: the synthetic subject whose frames went to `mannequin
    /// capture` as plain images. Meshes are left out: the avatar lives in --data's world frame.
    #[arg(long, requires = "avatar")]
    truth: Option<PathBuf>,
    /// Poses of --avatar's test frames: auto fits each to its image first (the avatar frozen) where
    /// --data's poses were estimated (`mannequin capture`), and takes them as they are where they
    /// are the truth; as-is and fit choose.
    #[arg(long, value_enum, default_value_t = TestPoseMode::Auto, requires = "avatar")]
    test_poses: TestPoseMode,
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
    #[arg(long, default_value_t = 100_000, value_parser = clap::value_parser!(u64).range(1..=MAX_SURFACE_SAMPLES as u64))]
    samples: u64,
    /// Seed of the surface samples.
    #[arg(long, default_value_t = 0)]
    seed: u64,
}

fn parse_background(s: &str) -> Result<[f32; 3]> {
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

/// Renders and scores the avatar's test sets with one progress bar per set.
fn evaluate_with_progress(
    avatar: &std::path::Path,
    data: &std::path::Path,
    truth: Option<&std::path::Path>,
    options: &EvalOptions,
    test_poses: TestPoseMode,
) -> Result<Scores> {
    let current: RefCell<Option<ProgressBar>> = RefCell::new(None);
    let on_set = |set: TestSet, frames: usize, poses: TestPoses| {
        tracing::info!("{}: {poses}", set.name());
        let stages = if matches!(poses, TestPoses::Fit { .. }) { 3 } else { 2 };
        if let Some(b) = current.replace(Some(bar((stages * frames) as u64, set.name()))) {
            b.finish_and_clear();
        }
    };
    let on_frame = || {
        if let Some(b) = current.borrow().as_ref() {
            b.inc(1);
        }
    };
    let scores = evaluate_avatar(avatar, data, truth, options, test_poses, &on_set, &on_frame)?;
    if let Some(b) = current.take() {
        b.finish_and_clear();
    }
    Ok(scores)
}

fn cell(v: Option<f64>, digits: usize) -> String {
    v.map_or("-".into(), |v| format!("{v:.digits$}"))
}

/// The scores as a table on stdout: a row per test set, then the geometry.
fn print_scores(s: &Scores) {
    println!("{:>11} {:>7} {:>8} {:>7} {:>7}  poses", "test set", "frames", "PSNR", "SSIM", "LPIPS");
    for (set, summary) in s.sets() {
        println!(
            "{:>11} {:>7} {:>8.2} {:>7.4} {:>7}  {}",
            set.name(),
            summary.frames,
            summary.psnr,
            summary.ssim,
            cell(summary.lpips, 4),
            summary.test_poses
        );
    }
    let g = &s.geometry;
    println!(
        "geometry: Chamfer {} cm, P2S {} cm, normal consistency {}, normal angle {}°, normal MSE×1e3 {}",
        cell(g.chamfer_cm, 3),
        cell(g.p2s_cm, 3),
        cell(g.normal_consistency, 3),
        cell(g.normal_angle_deg, 2),
        cell(g.normal_mse_x1e3, 2)
    );
    for (name, m) in &g.garments {
        println!(
            "{name}: Chamfer {:.3} cm, P2S {:.3} cm, normal consistency {:.3}",
            m.chamfer_cm, m.p2s_cm, m.normal_consistency
        );
    }
}

pub fn run(args: Args) -> Result<()> {
    let _timer = JobTimer::start("eval");
    let background = parse_background(&args.background)?;
    let lpips = args.lpips_weights.as_deref().map(Lpips::load).transpose()?;
    let options = EvalOptions {
        background,
        lpips,
        samples: args.samples as usize,
        seed: args.seed,
        compare_meshes: args.truth.is_none(),
    };
    let scores = match (&args.avatar, &args.data, &args.pred, &args.gt) {
        (Some(avatar), Some(data), _, _) => {
            evaluate_with_progress(avatar, data, args.truth.as_deref(), &options, args.test_poses)?
        }
        (_, _, Some(pred), Some(gt)) => {
            let frames = test_frames(gt)?;
            let progress = bar(frames.len() as u64, args.set.name());
            let summary = evaluate(pred, gt, &frames, &options, &|_| progress.inc(1))?;
            progress.finish_and_clear();
            Scores::new(vec![(args.set, summary)])
        }
        _ => anyhow::bail!("give --avatar and --data, or --pred and --gt"),
    };
    print_scores(&scores);
    if let Some(path) = &args.json {
        mannequin_io::write_atomic(path, serde_json::to_string_pretty(&scores)?.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
        tracing::info!("wrote {}", path.display());
    }
    Ok(())
}
