//! A training run from its settings to a saved avatar, as `mannequin train` runs it: the stages
//! before the first iteration ([`preparation`]), then the loop, which reads the one iteration
//! count (the run's [`crate::TrainOptions::iterations`]) for its bound, progress bar and last
//! checkpoint, saves a checkpoint every `checkpoint_every` iterations, and saves the avatar.

mod preparation;

use std::path::PathBuf;

use mannequin_io::progress::bar;

pub use preparation::{LoadedSubject, Subject, WornGarments};

use crate::checkpoint::checkpoint_path;
use crate::error::AvatarError;
use crate::run::TrainingRun;
use crate::trainer::Trainer;

/// A trainer ready for its first (or next) iteration, with the record its checkpoints keep and
/// the model folder they and the avatar go to.
pub struct Training {
    pub trainer: Trainer,
    pub record: TrainingRun,
    pub checkpoint_every: usize,
    pub out: PathBuf,
    /// The dataset's body shape, written with the refined poses.
    pub betas: Vec<f32>,
}

/// The refined training poses in the model folder, in the dataset's pose format (which
/// `animate --motion` reads).
pub const REFINED_POSES: &str = "refined_poses.npz";

impl Training {
    /// Trains to the run's last iteration with a progress bar (a log line per checkpoint where
    /// no terminal shows it), then saves the avatar and its refined poses. A non-finite loss or
    /// refined pose stops the run naming the last checkpoint written.
    pub fn run(mut self) -> Result<(), AvatarError> {
        let (t, iterations) = (&mut self.trainer, self.record.options.iterations);
        let checkpoint = checkpoint_path(&self.out);
        let progress = bar(iterations as u64, "training");
        progress.set_position(t.iteration as u64);
        let mut running_psnr: Option<f64> = None;
        while t.iteration < iterations {
            let stats = t.step().inspect_err(|_| progress.abandon()).map_err(|e| {
                e.with_checkpoint(if checkpoint.exists() {
                    checkpoint.display().to_string()
                } else {
                    "none".into()
                })
            })?;
            let p = running_psnr.map_or(stats.psnr, |r| 0.9 * r + 0.1 * stats.psnr);
            running_psnr = Some(p);
            progress.set_position(stats.iteration as u64);
            progress.set_message(format!("loss {:.4} psnr {p:.1}", stats.loss));
            if stats.iteration % self.checkpoint_every == 0 || stats.iteration == iterations {
                t.save_checkpoint(&checkpoint, &self.record)?;
                if progress.is_hidden() {
                    // No terminal: keep a log line per checkpoint instead of the bar.
                    tracing::info!(
                        "iteration {}/{iterations}: loss {:.6}, running PSNR {p:.2} dB",
                        stats.iteration,
                        stats.loss
                    );
                }
            }
        }
        progress.finish_and_clear();
        t.avatar.save(&self.out)?;
        if let Some(poses) = t.refined_poses(&self.betas) {
            poses.write(&self.out.join(REFINED_POSES))?;
        }
        let out = self.out.display();
        match running_psnr {
            Some(p) => tracing::info!("wrote {out} (running PSNR {p:.2} dB on training crops)"),
            None => tracing::info!("wrote {out} (the checkpoint had finished all {iterations} iterations)"),
        }
        Ok(())
    }
}
