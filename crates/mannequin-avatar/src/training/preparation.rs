//! Everything a training run does before its first iteration, in the order a user meets its
//! refusals: the counts, the dataset and the body model ([`Subject::open`]); the run's record
//! against a checkpoint of the model folder, before the views load ([`Subject::load`]); then the
//! subject's mesh, the device and the trainer, resumed where the checkpoint left off
//! ([`LoadedSubject::start`]). The garment layers are found between the first two stages and
//! reconstructed between the last two, by the garment crate.

use std::path::{Path, PathBuf};

use mannequin_body::BodyModel;
use mannequin_data::{Dataset, Split};
use mannequin_io::progress::bar;

use super::Training;
use crate::avatar::Avatar;
use crate::canonical::Canonical;
use crate::checkpoint::{Checkpoint, checkpoint_path};
use crate::error::AvatarError;
use crate::garment_layer::GarmentLayer;
use crate::options::TrainOptions;
use crate::run::{GarmentRecord, TrainingRun};
use crate::settings::TrainSettings;
use crate::skirt_layer::SkirtMode;
use crate::trainer::Trainer;
use crate::views::{View, load_views};

/// The dataset's training split and the body model its poses drive, checked.
pub struct Subject {
    settings: TrainSettings,
    data: PathBuf,
    dataset: Dataset,
    split: Split,
    model: BodyModel,
}

/// The garments a run wears as layers of their own, as its record names them before they are
/// reconstructed.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct WornGarments {
    /// Their categories' names, in order.
    pub names: Vec<String>,
    /// Whether one of them (a skirt or dress) replaces the skirt layer.
    pub replace_skirt: bool,
    /// Steps of each one's reconstruction.
    pub steps: usize,
}

/// A subject with its run's record checked against the model folder, and its views loaded.
pub struct LoadedSubject {
    subject: Subject,
    record: TrainingRun,
    resume: Option<Checkpoint>,
    views: Vec<View>,
    out: PathBuf,
}

impl Subject {
    /// Opens the dataset at `data` and the body model `settings` name, refusing zero counts and a
    /// body model that is not driven by SMPL's 24 joints.
    pub fn open(data: &Path, settings: &TrainSettings) -> Result<Self, AvatarError> {
        if settings.iterations == 0 || settings.checkpoint_every == 0 {
            return Err(AvatarError::Invalid("--iters and --checkpoint-every must be at least 1".into()));
        }
        let dataset = Dataset::open(data, settings.downscale)?;
        let split = dataset.split("train")?;
        let model = BodyModel::from_spec(&settings.body, None)?;
        if model.num_joints() != 24 {
            return Err(AvatarError::Invalid(format!(
                "{}: the dataset's poses are SMPL's 24 joints, but this body model has {}",
                settings.body,
                model.num_joints()
            )));
        }
        Ok(Self { settings: settings.clone(), data: data.to_path_buf(), dataset, split, model })
    }

    /// The run's record with `garments`, then its checkpoint in `out`: one of another run is
    /// refused before the views load, and `--restart` drops it before anything new is written.
    /// Then the views, with a progress bar.
    pub fn load(self, out: &Path, garments: WornGarments) -> Result<LoadedSubject, AvatarError> {
        let s = &self.settings;
        let skirt = if garments.replace_skirt { SkirtMode::Off } else { s.skirt };
        let record = TrainingRun {
            body: s.body.clone(),
            downscale: s.downscale,
            skirt,
            garments: (!garments.names.is_empty())
                .then_some(GarmentRecord { categories: garments.names, steps: garments.steps }),
            data: self.dataset.fingerprint(&self.split)?,
            avatar: s.avatar_config(),
            options: TrainOptions {
                refine_poses: s.refine_poses.resolve(self.dataset.origin.as_ref()),
                ..s.options()
            },
        };
        let checkpoint = checkpoint_path(out);
        let resume = if !s.restart && checkpoint.exists() {
            // Whether a skirt layer is added is decided from the views, not loaded yet; it
            // follows from the data, body, subdivisions and skirt mode compared here.
            let saved = Checkpoint::open(&checkpoint, &record, &["avatar.skirt_layer"]);
            Some(saved.map_err(AvatarError::cannot_resume)?)
        } else {
            None
        };
        if s.restart && checkpoint.exists() {
            // Gone before anything new is written, so a restart stopped before its first
            // checkpoint starts over again instead of resuming the old run.
            std::fs::remove_file(&checkpoint)
                .map_err(|e| AvatarError::Invalid(format!("removing {}: {e}", checkpoint.display())))?;
        }
        let progress = bar(self.split.frames.len() as u64, "loading");
        let views = load_views(&self.dataset, &self.split, |done, _| progress.set_position(done as u64))?;
        progress.finish_and_clear();
        if record.options.refine_poses {
            tracing::info!(
                "refining the {} training poses with the avatar (--refine-poses off to keep them)",
                views.len()
            );
        }
        if views.iter().any(|v| !v.has_normals()) {
            tracing::warn!("{} has no normal maps: the normal loss is off", self.data.display());
        }
        Ok(LoadedSubject { subject: self, record, resume, views, out: out.to_path_buf() })
    }
}

impl LoadedSubject {
    /// The run's record: the garment reconstruction reads the dataset's fingerprint here.
    pub fn record(&self) -> &TrainingRun {
        &self.record
    }

    /// The avatar over `garments` (the reconstructed layers) on the settings' device, and its
    /// trainer, resumed from the model folder's checkpoint if it holds one of this run. Nothing
    /// is written before the first checkpoint: a run that fails leaves no untrained model.
    pub fn start(self, garments: &[GarmentLayer]) -> Result<Training, AvatarError> {
        let Self { subject, mut record, resume, views, out } = self;
        let s = &subject.settings;
        let betas = &subject.split.poses.betas;
        let subdivisions = s.subdivisions as usize;
        let (canonical, skirt_layer) =
            Canonical::for_subject(&subject.model, betas, subdivisions, &views, record.skirt, garments)?;
        if let Some(layer) = &skirt_layer {
            tracing::info!("the masks show a skirt: adding {layer} (--skirt off trains without)");
        }
        record.avatar.skirt_layer = skirt_layer.is_some();
        let device = s.device.device()?.autodiff();
        let avatar = Avatar::new(record.avatar.clone(), canonical, &device)?;
        let mut trainer = Trainer::new(avatar, views, record.options.clone())?;
        if let Some(saved) = &resume {
            trainer.resume(saved, &record).map_err(AvatarError::cannot_resume)?;
            tracing::info!(
                "resuming from {} at iteration {}",
                checkpoint_path(&out).display(),
                trainer.iteration
            );
        }
        tracing::info!(
            "{} Gaussians on {} vertices, {} views, {} iterations",
            trainer.avatar.num_gaussians(),
            trainer.avatar.canonical.num_vertices(),
            trainer.num_views(),
            trainer.options.iterations
        );
        let betas = betas.clone();
        Ok(Training { trainer, record, checkpoint_every: s.checkpoint_every, out, betas })
    }
}
