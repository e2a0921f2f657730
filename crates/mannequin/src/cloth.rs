//! `mannequin cloth simulate`: drape a garment on a body and play a motion with the XPBD
//! simulator (the run is [`mannequin_cloth::simulate`]); the outputs are moved into place
//! together once written.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand};
use mannequin_body::{BodyModel, load_body};
use mannequin_cloth::{GarmentInput, Pins, SimulateJob, SimulateSettings, simulate};
use mannequin_garment::{Dressed, read_for_body};
use mannequin_io::progress::JobTimer;
use mannequin_io::staging::Staging;
use mannequin_mesh::TriMesh;

use crate::shared::{BodyArgs, Clip};

#[derive(Subcommand)]
pub enum ClothCommand {
    /// Simulate a garment (.obj) on a body playing a motion; writes garment.pc2, garment.npz,
    /// scene.glb and metrics.json.
    Simulate(SimulateArgs),
}

#[derive(Args)]
pub struct SimulateArgs {
    /// The garment: a library garment (.garment, from `garment make`), put on this body's shape
    /// and held at the waist as `dress` holds it, or a bare mesh (.obj, metres) modelled around
    /// the body at rest.
    #[arg(long)]
    garment: PathBuf,
    /// For an .obj: JSON naming garment vertices that are fixed in place ("fixed") or bound to
    /// the body surface nearest them at rest ("attached"), e.g. {"attached": [0, 1, 2]}.
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
    let performer = args.body.performer(&model, &args.clip, &motion);
    let garment = match args.garment.extension().is_some_and(|e| e == "garment") {
        true => {
            if let Some(pin) = &args.pin {
                bail!(
                    "--pin {}: {} is a .garment, which carries its own attachments; --pin is for an .obj",
                    pin.display(),
                    args.garment.display()
                );
            }
            worn(&args.garment, &model, performer.betas)?
        }
        false => GarmentInput::read_obj(&args.garment, args.pin.as_deref())?,
    };
    let job = SimulateJob { garment_path: &args.garment, pins_path: args.pin.as_deref(), garment, performer };
    let simulation = simulate(&job, &args.settings, &args.out)?;
    let staging = Staging::new(&args.out)?;
    simulation.write(staging.dir(), &args.out, &job)?;
    staging.commit()?;
    Ok(simulation.finish(&args.out)?)
}

/// The library garment at `path` put on the body of shape `betas` at rest (Eq. 3.2), its
/// waistband attached as `dress` attaches it, in its own fabric.
fn worn(path: &Path, model: &BodyModel, betas: &[f32]) -> Result<GarmentInput> {
    let garment = read_for_body(path, model)?;
    let dressed = Dressed::new(&garment, model, betas).with_context(|| path.display().to_string())?;
    let pins = Pins { fixed: Vec::new(), attached: dressed.held() };
    let mesh = TriMesh::new(dressed.rest(), garment.mesh.faces.clone());
    Ok(GarmentInput { mesh, pins, material: Some(garment.recipe.material) })
}
