//! `mannequin demo`: the README's main job on the embedded default body, on the user's path. It
//! makes a synthetic clothed subject and hands its frames to `capture` as plain images (no
//! poses, masks or camera), trains a Tavatar avatar on what `capture` recovers (refining the
//! poses), scores the held-out frames against the subject's truth, animates the avatar with a
//! walk, and exports it (skinned .glb, 3DGS .ply, posed .obj), all under one folder. Each stage runs the same code as its own verb (through the command line the binary
//! hands in); one progress bar at a time shows the stage it belongs to.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args as ClapArgs;
use mannequin_avatar::TrainSettings;
use mannequin_synth::SynthOptions;

use mannequin_io::progress::{JobTimer, set_stage};

#[derive(ClapArgs)]
pub struct Args {
    /// Output folder.
    #[arg(long, default_value = "out/demo")]
    out: PathBuf,
    /// Seed of the synthetic subject and of training.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Training iterations.
    #[arg(long, default_value_t = TrainSettings::default().iterations)]
    iters: usize,
    /// Image size of the synthetic subject.
    #[arg(long, default_value_t = SynthOptions::default().size)]
    size: usize,
    /// Frames of the synthetic subject's turning capture that go to `capture` (the last tenth are
    /// held out and scored).
    #[arg(long, default_value_t = SynthOptions::default().capture_frames as u64, value_parser = clap::value_parser!(u64).range(10..))]
    frames: u64,
    /// Frames of the walk animation.
    #[arg(long, default_value_t = 60)]
    walk_frames: usize,
    /// Simulate the subject's garments without cloth–cloth contacts (faster; folds and layers
    /// may pass through each other).
    #[arg(long)]
    no_self_collision: bool,
}

/// Runs the stages, each through `run_verb` (a verb's command line, without the binary's name).
pub fn run(args: Args, run_verb: impl Fn(&[&str]) -> Result<()>) -> Result<()> {
    let _timer = JobTimer::start("demo");
    let path = |p: &str| args.out.join(p).to_string_lossy().into_owned();
    let (seed, iters, size, frames) =
        (args.seed.to_string(), args.iters.to_string(), args.size.to_string(), args.walk_frames.to_string());
    // Synth's own split is not used (capture makes one); it needs one training frame fewer.
    let (capture_frames, synth_train) = (args.frames.to_string(), (args.frames - 1).to_string());
    let (subject, captured, avatar, walk) =
        (path("subject"), path("captured"), path("avatar"), path("walk.npz"));
    let images = path("subject/images");
    let (eval_json, walk_dir) = (path("eval.json"), path("walk"));
    let (glb, splats, squat) = (path("avatar.glb"), path("avatar_gaussians.ply"), path("avatar_squat.obj"));
    let mut synth = vec![
        "synth",
        "--seed",
        &seed,
        "--size",
        &size,
        "--frames",
        &capture_frames,
        "--train",
        &synth_train,
        "--out",
        &subject,
    ];
    if args.no_self_collision {
        synth.push("--no-self-collision");
    }
    let stages: Vec<(&str, Vec<&str>)> = vec![
        ("subject", synth),
        ("capture", vec!["capture", "--frames", &images, "--out", &captured, "--restart"]),
        (
            "train",
            vec![
                "train",
                "--data",
                &captured,
                "--out",
                &avatar,
                "--iters",
                &iters,
                "--seed",
                &seed,
                "--restart",
            ],
        ),
        (
            "evaluate",
            vec!["eval", "--avatar", &avatar, "--data", &captured, "--truth", &subject, "--json", &eval_json],
        ),
        ("motion", vec!["motion", "walk", "-o", &walk]),
        (
            "animate",
            vec!["animate", "--avatar", &avatar, "--motion", &walk, "--max-frames", &frames, "-o", &walk_dir],
        ),
        ("export", vec!["export", "--avatar", &avatar, "-o", &glb, "--gaussians", &splats]),
        ("export", vec!["export", "--avatar", &avatar, "--named-pose", "squat", "-o", &squat]),
    ];
    let count = stages.len();
    for (i, (name, argv)) in stages.into_iter().enumerate() {
        set_stage(&format!("{}/{count} {name}", i + 1));
        run_verb(&argv).with_context(|| format!("demo stage {name}"))?;
    }
    set_stage("");
    tracing::info!(
        "demo done: {}/avatar (model), eval.json, walk/ (frames), avatar.glb, avatar_gaussians.ply, avatar_squat.obj",
        args.out.display()
    );
    Ok(())
}
