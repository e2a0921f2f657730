//! `mannequin <verb>`: the one binary. Each verb lives in its own module with its clap
//! arguments and a `run` function; this file only dispatches and reports errors.

mod animate;
mod batch;
mod body;
mod capture;
mod cloth;
mod demo;
mod dress;
mod eval;
mod export;
mod face;
mod fit;
mod garment;
mod logging;
mod motion;
mod render;
mod segment;
mod shared;
mod splat;
mod synth;
mod train;
mod view;

use clap::{CommandFactory, Parser, Subcommand};

#[derive(Parser)]
#[command(name = "mannequin", version, about = "Animatable, clothed 3D digital humans")]
struct Cli {
    /// Log more (-v: debug, -vv: trace). RUST_LOG overrides this.
    #[arg(short, long, action = clap::ArgAction::Count, global = true)]
    verbose: u8,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Inspect, pose or animate a body model (SMPL, SMPL-H, SMPL-X or the embedded default).
    #[command(subcommand)]
    Body(body::BodyCommand),
    /// Simulate a garment on a moving body (XPBD cloth).
    #[command(subcommand)]
    Cloth(cloth::ClothCommand),
    /// Make garment templates (.garment) cut from a body's surface, or summarise one.
    #[command(subcommand)]
    Garment(garment::GarmentCommand),
    /// Dress a body of any shape in garments and play a motion: skinned transfer (MGN) and cloth
    /// simulation, as a glTF scene, point caches, rendered frames and metrics.
    Dress(dress::Args),
    /// A person's own video (or frames) to a dataset `train` reads: landmarks and masks by the
    /// shipped person models, one body shape, a pose per frame, one static camera, and garment
    /// labels (`segment`).
    Capture(capture::Args),
    /// Garment labels from a dataset's images, person masks and poses alone (`auto` decides the
    /// garments): labels/, hands/ and the legend, as `garment fit` and `train --garments` read them.
    Segment(segment::Args),
    /// Fit the body to a person in a photo: detection, landmarks and mask by the shipped person
    /// models, then shape, pose and camera (body.npz, .obj, .glb, overlay.png, fit.json).
    Fit(fit::Args),
    /// Fit the default body's face to a portrait: face detection and 468 face-mesh landmarks by
    /// the shipped face models, then shape, expression and head pose (face.obj, overlay.png,
    /// fit.json).
    #[command(subcommand)]
    Face(face::FaceCommand),
    /// Write motion files (a procedural walk as AMASS .npz).
    #[command(subcommand)]
    Motion(motion::MotionCommand),
    /// Render a trained avatar playing an AMASS or PeopleSnapshot motion, as PNG frames (and .mp4).
    Animate(animate::Args),
    /// The main job on the embedded default body: synthetic subject, training, evaluation,
    /// animation and export, under one folder.
    Demo(demo::Args),
    /// Score an avatar, or a folder of predictions, on a dataset's test sets: PSNR, SSIM, LPIPS,
    /// normal and geometry errors.
    Eval(eval::Args),
    /// Generate a synthetic clothed subject with full ground truth, in the dataset layout.
    Synth(synth::Args),
    /// Render a 3D Gaussian splatting .ply through a camera, or summarise one.
    Splat(splat::Args),
    /// Render a trained avatar at a dataset frame or a motion frame: colour, normals, alpha or depth.
    Render(render::Args),
    /// Reconstruct an animatable avatar from a dataset (Tavatar or iHuman binding).
    Train(train::Args),
    /// Export a trained avatar: its mesh (.obj/.ply, canonical or posed), a skinned coloured .glb,
    /// or its Gaussians at a pose as a 3DGS .ply.
    Export(export::Args),
    /// Many people as an array of tasks: a manifest planned for Slurm, Kubernetes or this
    /// machine, each person's steps resumable, and a report of them all.
    #[command(subcommand)]
    Batch(batch::BatchCommand),
    /// Look at an avatar (its Gaussians animated), a dressed body, a cloth simulation, a .glb or a
    /// 3DGS .ply in the browser: a local server on 127.0.0.1 with an embedded page.
    View(view::Args),
}

/// Runs one verb.
fn dispatch(command: Command) -> anyhow::Result<()> {
    match command {
        Command::Body(cmd) => body::run(cmd),
        Command::Cloth(cmd) => cloth::run(cmd),
        Command::Garment(cmd) => garment::run(cmd),
        Command::Dress(args) => dress::run(args),
        Command::Capture(args) => capture::run(args),
        Command::Fit(args) => fit::run(args),
        Command::Segment(args) => segment::run(args),
        Command::View(args) => view::run(args),
        Command::Face(cmd) => face::run(cmd),
        Command::Motion(cmd) => motion::run(cmd),
        Command::Animate(args) => animate::run(args),
        Command::Demo(args) => demo::run(args, run_verb),
        Command::Batch(cmd) => batch::run(cmd, &run_verb, Cli::command()),
        Command::Eval(args) => eval::run(args),
        Command::Synth(args) => synth::run(args),
        Command::Splat(args) => splat::run(args),
        Command::Train(args) => train::run(args),
        Command::Render(args) => render::run(args),
        Command::Export(args) => export::run(args),
    }
}

/// Parses and runs one verb's command line (without the binary's name): the demo chains several
/// through here.
fn run_verb(argv: &[&str]) -> anyhow::Result<()> {
    let cli = Cli::try_parse_from(std::iter::once("mannequin").chain(argv.iter().copied()))?;
    dispatch(cli.command)
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    logging::init_logging(cli.verbose);
    match dispatch(cli.command) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            // One readable line: the chain of causes, outermost first.
            eprintln!("error: {}", e.chain().map(|c| c.to_string()).collect::<Vec<_>>().join(": "));
            std::process::ExitCode::FAILURE
        }
    }
}
