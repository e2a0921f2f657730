//! `mannequin cloth simulate`: drape a garment on a body and play a motion with the XPBD
//! simulator (the run is [`mannequin_cloth::simulate`]); the outputs are moved into place
//! together once written.

use std::path::PathBuf;

use anyhow::Result;
use clap::{Args, Subcommand};
use mannequin_body::load_body;
use mannequin_cloth::{SimulateJob, SimulateSettings, simulate};
use mannequin_io::progress::JobTimer;
use mannequin_io::staging::Staging;

use crate::shared::{BodyArgs, Clip};

#[derive(Subcommand)]
pub enum ClothCommand {
    /// Simulate a garment (.obj) on a body playing a motion; writes garment.pc2, garment.npz,
    /// scene.glb and metrics.json.
    Simulate(SimulateArgs),
}

#[derive(Args)]
pub struct SimulateArgs {
    /// Garment mesh (.obj, metres), modelled around the body at rest.
    #[arg(long)]
    garment: PathBuf,
    /// JSON naming garment vertices that are fixed in place ("fixed") or bound to the body
    /// surface nearest them at rest ("attached"), e.g. {"attached": [0, 1, 2]}.
    #[arg(long)]
    pin: Option<PathBuf>,
    #[command(flatten)]
    body: BodyArgs,
    #[command(flatten)]
    clip: Clip,
    #[command(flatten)]
    settings: SimulateSettings,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
}

pub fn run(cmd: ClothCommand) -> Result<()> {
    match cmd {
        ClothCommand::Simulate(args) => simulate_garment(args),
    }
}

fn simulate_garment(args: SimulateArgs) -> Result<()> {
    let _timer = JobTimer::start("cloth simulate");
    let model = load_body(&args.body.body)?;
    let motion = args.clip.load()?;
    let job = SimulateJob {
        garment: &args.garment,
        pins: args.pin.as_deref(),
        performer: args.body.performer(&model, &args.clip, &motion),
    };
    let simulation = simulate(&job, &args.settings, &args.out)?;
    let staging = Staging::new(&args.out)?;
    simulation.write(staging.dir(), &args.out, &job)?;
    staging.commit()?;
    Ok(simulation.finish(&args.out)?)
}
