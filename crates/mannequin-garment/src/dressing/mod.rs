//! Dressing (`mannequin dress`): garments put on a body of any shape (thesis Eqs. 3.1–3.3) and
//! worn through a motion, the cloth simulator resolving what skinning cannot (gravity on loose
//! parts, the body pushing through after a shape change). Each layer collides with the body and
//! with every layer under it, the layers stepping side by side ([`crate::wear`]). A run saves
//! checkpoints and resumes from them; its outputs are a scene, metrics and a fit report per body
//! region.

mod checkpoint;
mod fit_report;
mod metrics;
mod settings;
mod worn;

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::time::Instant;

use mannequin_body::{Settling, shape_body};
use mannequin_cloth::run_checkpoint::{CHECKPOINT, file_hash};
use mannequin_cloth::sim_limits::check_kept_positions;
use mannequin_cloth::{Performer, Settings};
use mannequin_mesh::MorphSequence;

use crate::dress_error::DressError;
use crate::error::GarmentError;
use crate::garment::Garment;
use crate::garment_cache::load_or_make;
use crate::layered_scene::write_layered_scene;
use crate::transfer::Dressed;
use crate::wear::{WearProgress, WearStep, Wearer, wear};
use checkpoint::{DressRun, read_checkpoint, template_hash, write_checkpoint};
pub use fit_report::RegionFit;
pub use metrics::FrameMetrics;
pub use settings::DressSettings;
pub use worn::Worn;

/// How far (m) each layer stands beyond the one under it at rest: twice the simulator's body
/// margin, so the outer layer starts clear of the inner one's collision shell.
const LAYER_GAP: f32 = 0.01;

/// What a dressing wears and where: garments (inner first: `.garment` files or category names),
/// on the body performing the motion.
pub struct DressJob<'a> {
    pub garments: &'a [String],
    pub performer: Performer<'a>,
}

/// The garments to wear, named, inner first, each standing clear of those under it at rest.
pub struct Wardrobe {
    templates: Vec<(String, Garment)>,
    started: Instant,
}

impl Wardrobe {
    /// Loads or makes `job`'s garments at `settings.size`, refusing a run that would keep more
    /// positions than [`mannequin_cloth::sim_limits::MAX_KEPT_POSITIONS`], and layers them.
    pub fn load(job: &DressJob, settings: &DressSettings) -> Result<Self, DressError> {
        let started = Instant::now();
        let (model, motion) = (job.performer.model, job.performer.motion);
        let loaded: Vec<(String, Garment)> = job
            .garments
            .iter()
            .map(|g| load_or_make(g, model, job.performer.body, &settings.size))
            .collect::<Result<_, _>>()?;
        if settings.self_collision && !settings.no_simulation {
            refuse_tucked_in(&loaded)?;
        }
        let settle = Settling::settle_frames(settings.stepping.settle, motion.fps)?;
        let vertices = model.num_vertices() + loaded.iter().map(|(_, g)| g.vertex_count()).sum::<usize>();
        check_kept_positions(job.performer.motion_path, settle + motion.num_frames(), vertices)?;
        // Each layer stands clear of those under it as they stand (in rest space, so on every
        // body shape).
        let mut templates: Vec<(String, Garment)> = Vec::with_capacity(loaded.len());
        for (name, g) in &loaded {
            let inner: Vec<&Garment> = templates.iter().map(|(_, g)| g).collect();
            let layered =
                g.over(&inner, LAYER_GAP, model).map_err(|e| DressError::from(e).of(name.clone()))?;
            templates.push((name.clone(), layered));
        }
        Ok(Self { templates, started })
    }
}

/// Refuses a lower-body garment over one that is not (a shirt tucked into trousers) with the
/// cloth–cloth contacts on: its waistband, held to the body through the garment under it,
/// meets that garment where it was simulated without the waistband, and the layers, each
/// holding the other off, tear the outer one apart.
fn refuse_tucked_in(loaded: &[(String, Garment)]) -> Result<(), DressError> {
    for (i, (name, g)) in loaded.iter().enumerate() {
        let over = loaded[..i].iter().find(|(_, under)| !under.recipe.category.is_lower_body());
        if let (true, Some((under, _))) = (g.recipe.category.is_lower_body(), over) {
            let reason = format!(
                "{name} over {under}: a waistband held to the body over another garment (tucked in) \
                 is not simulated with cloth–cloth contacts yet; list {under} after {name}, or add \
                 --no-self-collision"
            );
            return Err(GarmentError::invalid("--garments", reason).into());
        }
    }
    Ok(())
}

/// A dressing done: every layer's positions and the body's at every frame of the schedule
/// (settling included), and the seconds each stage took.
pub struct Dressing<'a> {
    pub worn: Vec<Worn<'a>>,
    pub schedule: Settling,
    pub body_faces: Vec<[u32; 3]>,
    pub body_frames: Vec<Vec<[f32; 3]>>,
    /// Per layer, its positions at every frame of the schedule.
    pub layers: Vec<Vec<Vec<[f32; 3]>>>,
    stage_s: serde_json::Map<String, serde_json::Value>,
    /// The checkpoint a simulated run saves, dropped once it has finished.
    checkpoint: Option<PathBuf>,
}

/// Wears `wardrobe` on `job`'s body through its motion: simulated (resuming from the checkpoint
/// in `out` when it holds one of this run, unless `settings.restart`), or skinned only.
pub fn dress<'a>(
    wardrobe: &'a Wardrobe,
    job: &'a DressJob,
    settings: &DressSettings,
    out: &Path,
) -> Result<Dressing<'a>, DressError> {
    let (model, motion) = (job.performer.model, job.performer.motion);
    let templates = &wardrobe.templates;
    let worn: Vec<Worn> = templates
        .iter()
        .enumerate()
        .map(|(i, (name, garment))| {
            let dressed = Dressed::new(garment, model, job.performer.betas)
                .map_err(|e| DressError::from(e).of(format!("dressing {name}")))?;
            let name = if templates[..i].iter().any(|(n, _)| n == name) {
                format!("{name}_{i}")
            } else {
                name.clone()
            };
            let material = garment.recipe.material;
            Ok(Worn { name, garment, material, dressed })
        })
        .collect::<Result<_, DressError>>()?;
    let mut stage_s = serde_json::Map::new();
    stage_s.insert("transfer".into(), wardrobe.started.elapsed().as_secs_f64().into());

    let start = Instant::now();
    let schedule = Settling::new(model, motion, settings.stepping.settle)?;
    let shaped = shape_body(model, job.performer.betas)?;
    let body_frames = schedule.body_frames(model, &shaped)?;
    let body_faces = model.template_mesh().faces;
    stage_s.insert("body".into(), start.elapsed().as_secs_f64().into());

    let mut dressing =
        Dressing { worn, schedule, body_faces, body_frames, layers: Vec::new(), stage_s, checkpoint: None };
    let start = Instant::now();
    if settings.no_simulation {
        dressing.layers = dressing.skinned()?;
    } else {
        let checkpoint = out.join(CHECKPOINT);
        if settings.restart {
            std::fs::remove_file(&checkpoint).ok();
        }
        dressing.layers = dressing.simulated(job, settings, &checkpoint)?;
        dressing.checkpoint = Some(checkpoint);
    }
    dressing.time("simulation", start);
    Ok(dressing)
}

impl<'a> Dressing<'a> {
    /// Each layer skinned (Eqs. 3.2–3.3) at every frame of the schedule.
    fn skinned(&self) -> Result<Vec<Vec<Vec<[f32; 3]>>>, DressError> {
        self.worn
            .iter()
            .map(|w| {
                (0..self.schedule.len())
                    .map(|k| {
                        let (pose, trans) = self.schedule.pose(k);
                        Ok(w.dressed.posed(pose, trans)?)
                    })
                    .collect()
            })
            .collect()
    }

    /// Each layer simulated at every frame of the schedule, saving `checkpoint` every
    /// `settings.checkpoint_every` frames and resuming from it.
    fn simulated(
        &self,
        job: &DressJob,
        settings: &DressSettings,
        checkpoint: &Path,
    ) -> Result<Vec<Vec<Vec<[f32; 3]>>>, DressError> {
        let worn = &self.worn;
        let named: Vec<(&str, &Dressed)> = worn.iter().map(|w| (w.name.as_str(), &w.dressed)).collect();
        let wearer = Wearer {
            faces: &self.body_faces,
            frames: &self.body_frames,
            schedule: &self.schedule,
            fps: job.performer.motion.fps,
        };
        let solver = Settings {
            substeps: settings.stepping.substeps,
            self_collision: settings.self_collision,
            ..Settings::default()
        };
        let run = DressRun {
            garments: worn.iter().map(|w| format!("{} {}", w.name, template_hash(w.garment))).collect(),
            body: job.performer.body.to_string(),
            betas: job.performer.betas.to_vec(),
            motion: file_hash(job.performer.motion_path)?,
            fps: job.performer.motion.fps,
            frames: job.performer.motion.num_frames(),
            substeps: settings.stepping.substeps,
            settle: settings.stepping.settle,
            self_collision: settings.self_collision,
        };
        let resume = if checkpoint.exists() {
            let resume = read_checkpoint(checkpoint, &run, &named, self.schedule.len())?;
            tracing::info!("resuming {}", checkpoint.display());
            resume
        } else {
            WearProgress::default()
        };
        let total = worn.len() * (self.schedule.len() - 1);
        let progress = mannequin_io::progress::bar(total as u64, "simulation");
        let mut on_step = |step: &WearStep| -> Result<(), DressError> {
            let done = step.frames_done();
            progress.set_position(done as u64);
            // A step simulates a frame of each layer under way: save when it passes a multiple.
            let every = settings.checkpoint_every;
            if every > 0 && done / every > (done - step.stepped) / every && done < total {
                write_checkpoint(checkpoint, &run, &step.progress(), worn)?;
            }
            Ok(())
        };
        let simulated = wear(&named, &wearer, solver, resume, &mut on_step)?;
        progress.finish_and_clear();
        Ok(simulated
            .into_iter()
            .zip(worn)
            .map(|(layer, w)| {
                let phases: Vec<String> = layer
                    .phases
                    .named()
                    .iter()
                    .map(|(name, d)| format!("{name} {:.1} s", d.as_secs_f64()))
                    .collect();
                tracing::info!("{}: simulated {} frames; {}", w.name, layer.frames.len(), phases.join(", "));
                layer.frames
            })
            .collect())
    }

    /// The schedule's frames that play the motion (after settling).
    pub fn motion_frames(&self) -> Range<usize> {
        self.schedule.settle..self.schedule.len()
    }

    /// Records the seconds since `start` as stage `name`'s (for metrics.json).
    pub fn time(&mut self, name: &str, start: Instant) {
        self.stage_s.insert(name.to_string(), start.elapsed().as_secs_f64().into());
    }

    /// Per garment, how far it stands off the body and where it is stretched past its
    /// material's limit, per body region, on the body settled in the motion's first pose.
    pub fn fit_report(&self) -> Vec<Vec<RegionFit>> {
        let k = self.schedule.settle - 1;
        self.worn
            .iter()
            .enumerate()
            .map(|(i, w)| {
                let posed = (self.layers[i][k].as_slice(), w.dressed.rest());
                fit_report::fit_report(
                    posed.0,
                    &posed.1,
                    &w.garment.mesh.faces,
                    &w.dressed.weights,
                    w.dressed.model().num_joints(),
                    &self.body_frames[k],
                    &self.body_faces,
                    w.material.strain_limit,
                )
            })
            .collect()
    }

    /// Every garment's metrics at every motion frame (timed as stage "metrics").
    pub fn measure(&mut self) -> Vec<Vec<FrameMetrics>> {
        let start = Instant::now();
        let body = (self.body_frames.as_slice(), self.body_faces.as_slice());
        let metrics = metrics::measure(&self.worn, &self.layers, body, self.motion_frames());
        self.time("metrics", start);
        metrics
    }

    /// dressed.glb (the skinned body playing the motion, each garment as morph targets in sync),
    /// one Blender point cache per garment and metrics.json, into `dir`.
    pub fn write(
        &mut self,
        dir: &Path,
        job: &DressJob,
        metrics: &[Vec<FrameMetrics>],
    ) -> Result<(), DressError> {
        let start = Instant::now();
        let (model, motion) = (job.performer.model, job.performer.motion);
        let frames = self.motion_frames();
        let morphs: Vec<MorphSequence> = self
            .worn
            .iter()
            .zip(&self.layers)
            .map(|(w, layer)| {
                let frames = layer[frames.clone()].to_vec();
                let mut mesh = w.garment.mesh.clone();
                mesh.positions = frames[0].clone();
                mesh.colors = Some(vec![w.garment.recipe.category.colour(); mesh.vertex_count()]);
                MorphSequence { name: w.name.clone(), mesh, frames, fps: motion.fps }
            })
            .collect();
        let f = motion.num_frames();
        let poses = motion.poses_for(model)?;
        let pl = model.pose_len();
        let played = (&poses[..f * pl], &motion.trans[..3 * f], motion.fps);
        write_layered_scene(&dir.join("dressed.glb"), model, job.performer.betas, played, &morphs)?;
        self.time("write", start);
        metrics::write_metrics(dir, &self.worn, metrics, motion.fps, &self.stage_s)
    }

    /// Ends a finished dressing: a simulated one drops its checkpoint.
    pub fn finish(self) {
        if let Some(checkpoint) = &self.checkpoint {
            std::fs::remove_file(checkpoint).ok();
        }
    }
}
