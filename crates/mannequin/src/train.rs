//! `mannequin train`: reconstruct an animatable avatar from a dataset (Tavatar by default, or
//! iHuman), with checkpoints that a re-run of the same command resumes from. The run and its
//! settings live in `mannequin_avatar::training`; the garments it wears as layers are found and
//! reconstructed between its stages.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args as ClapArgs;
use mannequin_avatar::TrainSettings;
use mannequin_avatar::garment_layer::GarmentLayer;
use mannequin_avatar::training::{Subject, WornGarments};
use mannequin_garment::ngd::NgdSettings;
use mannequin_garment::ngd::layers as garment_layers;

use mannequin_io::progress::JobTimer;

#[derive(ClapArgs, Clone)]
pub struct Args {
    /// Dataset folder (PeopleSnapshot layout, or `mannequin synth` output).
    #[arg(long)]
    pub data: PathBuf,
    /// Avatar folder to write (avatar.json, avatar.npz, checkpoint.npz).
    #[arg(long)]
    pub out: PathBuf,
    #[command(flatten)]
    pub settings: TrainSettings,
    /// Garments worn as layers of their own, each reconstructed from the label maps (as
    /// `garment fit` does) before the avatar trains over it: `auto` (every garment in the label
    /// maps' legend) or categories, e.g. `upper:tshirt,lower:pants`. A skirt or dress replaces
    /// the skirt layer. Fits are written to OUT/garments/<category>/.
    #[arg(long)]
    pub garments: Option<String>,
    /// Steps of each garment's reconstruction (`garment fit --iters`).
    #[arg(long, default_value_t = NgdSettings::default().steps, requires = "garments")]
    pub garment_iters: usize,
}

/// Runs the whole job: checks the dataset, builds or resumes the avatar, trains, saves.
pub fn run(args: Args) -> Result<()> {
    let _timer = JobTimer::start("train");
    let Args { data, out, settings, garments, garment_iters } = &args;
    let subject = Subject::open(data, settings)?;
    let garments = match garments {
        Some(spec) => garment_layers::resolve(spec, data)?,
        None => Vec::new(),
    };
    let worn = WornGarments {
        names: garments.iter().map(|c| c.name().to_string()).collect(),
        replace_skirt: garments.iter().any(|c| c.flare().is_some()),
        steps: *garment_iters,
    };
    let loaded = subject.load(out, worn)?;
    let layers: Vec<GarmentLayer> = garment_layers::reconstruct_all(
        &garments,
        (data, &loaded.record().data),
        &settings.body,
        (settings.seed, *garment_iters),
        out,
    )?
    .into_iter()
    .map(|g| GarmentLayer { name: g.category, positions: g.positions, faces: g.faces, weights: g.weights })
    .collect();
    loaded.start(&layers)?.run()?;
    Ok(())
}
