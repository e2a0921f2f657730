//! `mannequin train`: reconstruct an animatable avatar from a dataset (Tavatar by default, or
//! iHuman), with checkpoints that a re-run of the same command resumes from.

use std::path::PathBuf;

use anyhow::{Context, Result, anyhow, bail};
use clap::Args as ClapArgs;
use mannequin_avatar::canonical::MAX_SUBDIVISIONS;
use mannequin_avatar::checkpoint_path;
use mannequin_avatar::{
    Avatar, AvatarConfig, AvatarError, Canonical, Checkpoint, GarmentRecord, Method, SkirtMode, TrainOptions,
    Trainer, TrainingRun, load_views,
};
use mannequin_body::BodyModel;
use mannequin_data::Dataset;

use crate::compute::Compute;
use crate::garment_layers;
use mannequin_io::progress::{JobTimer, bar};

#[derive(ClapArgs, Clone)]
pub struct Args {
    /// Dataset folder (PeopleSnapshot layout, or `mannequin synth` output).
    #[arg(long)]
    pub data: PathBuf,
    /// Avatar folder to write (avatar.json, avatar.npz, checkpoint.npz).
    #[arg(long)]
    pub out: PathBuf,
    /// Gaussian binding.
    #[arg(long, value_enum, default_value_t = Method::Tavatar)]
    pub method: Method,
    #[arg(long, default_value_t = 2000)]
    pub iters: usize,
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Body model the dataset's poses drive: default, default-lod1, or an SMPL-family .npz.
    #[arg(long, default_value = "default")]
    pub body: String,
    /// Midpoint subdivisions of the body template (each quadruples the faces), at most 3.
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u64).range(0..=MAX_SUBDIVISIONS as u64))]
    pub subdivide: u64,
    /// Divide the images' resolution by this factor.
    #[arg(long, default_value_t = 1)]
    pub downscale: usize,
    /// Save a checkpoint every this many iterations.
    #[arg(long, default_value_t = 200)]
    pub checkpoint_every: usize,
    /// Ablation: no face Gaussians (vertex scales become learnable).
    #[arg(long)]
    pub no_face_gaussians: bool,
    /// Ablation: no vertex Gaussians.
    #[arg(long)]
    pub no_vertex_gaussians: bool,
    /// Ablation: no equilateral regulariser.
    #[arg(long)]
    pub no_equilateral: bool,
    /// gsplat's antialiased mode: opacities scaled by the screen filter's compensation, so
    /// silhouettes do not overshoot the mesh (costs novel-view PSNR and normal accuracy).
    #[arg(long)]
    pub antialiased: bool,
    /// Screen-filter variance in px² added to every Gaussian's footprint (3DGS uses 0.3; larger
    /// values widen silhouettes and shrink the fitted mesh).
    #[arg(long, default_value_t = mannequin_avatar::AVATAR_DILATION, value_parser = parse_dilation)]
    pub dilation: f64,
    /// Skirt layer over the body: auto (where the masks fill the gap between the legs below
    /// mid-thigh) or off.
    #[arg(long, value_enum, default_value_t = SkirtMode::Auto)]
    pub skirt: SkirtMode,
    /// Garments worn as layers of their own, each reconstructed from the label maps (as
    /// `garment fit` does) before the avatar trains over it: `auto` (every garment in the label
    /// maps' legend) or categories, e.g. `upper:tshirt,lower:pants`. A skirt or dress replaces
    /// the skirt layer. Fits are written to OUT/garments/<category>/.
    #[arg(long)]
    pub garments: Option<String>,
    /// Steps of each garment's reconstruction (`garment fit --iters`).
    #[arg(long, default_value_t = 400, requires = "garments")]
    pub garment_iters: usize,
    /// Where training runs: cpu (Flex) or gpu (wgpu on Vulkan).
    #[arg(long, value_enum, default_value_t = Compute::Cpu)]
    pub device: Compute,
    /// Start over even if the model folder holds a checkpoint.
    #[arg(long)]
    pub restart: bool,
}

/// A screen-filter variance: a finite number of px², at least 0.
fn parse_dilation(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(d) if d.is_finite() && d >= 0.0 => Ok(d),
        _ => Err(format!("'{text}': expected a finite variance >= 0 (px²)")),
    }
}

fn avatar_config(args: &Args) -> AvatarConfig {
    let mut config = AvatarConfig::new(args.method, args.seed);
    config.subdivisions = args.subdivide as usize;
    config.antialiased = args.antialiased;
    config.dilation = args.dilation;
    if args.method == Method::Tavatar {
        config.face_gaussians = !args.no_face_gaussians;
        config.vertex_gaussians = !args.no_vertex_gaussians;
    }
    config
}

fn train_options(args: &Args) -> TrainOptions {
    let mut options = TrainOptions::new(args.method, args.iters, args.seed);
    if args.no_equilateral {
        options.lambda_equilateral = 0.0;
    }
    options
}

/// A checkpoint that cannot be resumed, with the way out.
fn start_over(e: AvatarError) -> anyhow::Error {
    anyhow!("{e}; use --restart to start over, or another --out")
}

/// Runs the whole job: checks the dataset, builds or resumes the avatar, trains, saves.
pub fn run(args: Args) -> Result<()> {
    let _timer = JobTimer::start("train");
    let (trainer, record) = prepare(&args)?;
    train(trainer, &record, &args)
}

/// Everything before the first iteration: every input is checked here, and a checkpoint of
/// another run is refused before the views load.
pub fn prepare(args: &Args) -> Result<(Trainer, TrainingRun)> {
    if args.iters == 0 || args.checkpoint_every == 0 {
        bail!("--iters and --checkpoint-every must be at least 1");
    }
    let dataset = Dataset::open(&args.data, args.downscale)?;
    let split = dataset.split("train")?;
    let model = BodyModel::from_spec(&args.body, None)?;
    if model.num_joints() != 24 {
        bail!(
            "{}: the dataset's poses are SMPL's 24 joints, but this body model has {}",
            args.body,
            model.num_joints()
        );
    }
    let garments = match &args.garments {
        Some(spec) => garment_layers::resolve(spec, &args.data)?,
        None => Vec::new(),
    };
    // A skirt or dress garment is the skirt layer's better replacement.
    let skirt = if garments.iter().any(|c| c.flare().is_some()) { SkirtMode::Off } else { args.skirt };
    let mut record = TrainingRun {
        body: args.body.clone(),
        downscale: args.downscale,
        skirt,
        garments: (!garments.is_empty()).then(|| GarmentRecord {
            categories: garments.iter().map(|c| c.name().to_string()).collect(),
            steps: args.garment_iters,
        }),
        data: dataset.fingerprint(&split)?,
        avatar: avatar_config(args),
        options: train_options(args),
    };
    let checkpoint = checkpoint_path(&args.out);
    let resume = if !args.restart && checkpoint.exists() {
        // Whether a skirt layer is added is decided from the views, not loaded yet; it follows
        // from the data, body, subdivisions and skirt mode compared here.
        Some(Checkpoint::open(&checkpoint, &record, &["avatar.skirt_layer"]).map_err(start_over)?)
    } else {
        None
    };
    if args.restart && checkpoint.exists() {
        // Gone before anything new is written, so a restart stopped before its first
        // checkpoint starts over again instead of resuming the old run.
        std::fs::remove_file(&checkpoint).with_context(|| format!("removing {}", checkpoint.display()))?;
    }
    let views = {
        let progress = bar(split.frames.len() as u64, "loading");
        let views = load_views(&dataset, &split, |done, _| progress.set_position(done as u64))?;
        progress.finish_and_clear();
        views
    };
    if views.iter().any(|v| !v.has_normals()) {
        tracing::warn!("{} has no normal maps: the normal loss is off", args.data.display());
    }
    let layers = garment_layers::reconstruct_all(
        &garments,
        (&args.data, &record.data),
        &args.body,
        (args.seed, args.garment_iters),
        &args.out,
    )?;
    let (canonical, skirt_layer) =
        Canonical::for_subject(&model, &split.poses.betas, args.subdivide as usize, &views, skirt, &layers)?;
    if let Some(layer) = &skirt_layer {
        tracing::info!("the masks show a skirt: adding {layer} (--skirt off trains without)");
    }
    record.avatar.skirt_layer = skirt_layer.is_some();
    let device = args.device.device()?.autodiff();
    let avatar = Avatar::new(record.avatar.clone(), canonical, &device)?;
    let mut trainer = Trainer::new(avatar, views, record.options.clone())?;
    // Nothing is written before the first checkpoint: a run that fails leaves no untrained model.
    if let Some(saved) = &resume {
        trainer.resume(saved, &record).map_err(start_over)?;
        tracing::info!("resuming from {} at iteration {}", checkpoint.display(), trainer.iteration);
    }
    tracing::info!(
        "{} Gaussians on {} vertices, {} views, {} iterations",
        trainer.avatar.num_gaussians(),
        trainer.avatar.canonical.num_vertices(),
        trainer.num_views(),
        args.iters
    );
    Ok((trainer, record))
}

/// The training loop with its progress bar, checkpoints and final save.
pub fn train(mut trainer: Trainer, record: &TrainingRun, args: &Args) -> Result<()> {
    let checkpoint = checkpoint_path(&args.out);
    let progress = bar(args.iters as u64, "training");
    progress.set_position(trainer.iteration as u64);
    let mut running_psnr: Option<f64> = None;
    while trainer.iteration < args.iters {
        let stats = match trainer.step() {
            Ok(s) => s,
            Err(AvatarError::NonFiniteLoss { iteration, value, .. }) => {
                progress.abandon();
                let last = if checkpoint.exists() { checkpoint.display().to_string() } else { "none".into() };
                return Err(AvatarError::NonFiniteLoss { iteration, value, checkpoint: last }.into());
            }
            Err(e) => return Err(e.into()),
        };
        let p = running_psnr.map_or(stats.psnr, |r| 0.9 * r + 0.1 * stats.psnr);
        running_psnr = Some(p);
        progress.set_position(stats.iteration as u64);
        progress.set_message(format!("loss {:.4} psnr {p:.1}", stats.loss));
        if stats.iteration % args.checkpoint_every == 0 || stats.iteration == args.iters {
            trainer.save_checkpoint(&checkpoint, record)?;
            if progress.is_hidden() {
                // No terminal: keep a log line per checkpoint instead of the bar.
                tracing::info!(
                    "iteration {}/{}: loss {:.6}, running PSNR {p:.2} dB",
                    stats.iteration,
                    args.iters,
                    stats.loss
                );
            }
        }
    }
    progress.finish_and_clear();
    trainer.avatar.save(&args.out)?;
    match running_psnr {
        Some(p) => tracing::info!("wrote {} (running PSNR {p:.2} dB on training crops)", args.out.display()),
        None => tracing::info!(
            "wrote {} (the checkpoint had finished all {} iterations)",
            args.out.display(),
            args.iters
        ),
    }
    Ok(())
}
