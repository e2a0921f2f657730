//! `cloth simulate`'s run: drape a garment on a body and play a motion with the XPBD simulator.
//! The body starts at rest and blends into the motion's first frame over a settling period, so
//! the garment hangs before the motion starts. Checkpoints let a re-run of the same run resume;
//! a state that goes non-finite stops the run and keeps the frames before it.

mod metrics;
mod outputs;
mod performer;
mod pins;
mod placement;
mod progress;
mod settings;
mod stepping;

use std::path::{Path, PathBuf};
use std::time::Instant;

use mannequin_body::{Settling, pose_frames, shape_body};
use mannequin_mesh::{TriMesh, points, read_obj};

use crate::attachment::Attachment;
use crate::body::Body;
use crate::cloth::Cloth;
use crate::material::Material;
use crate::phase_times::PhaseTimes;
use crate::run_checkpoint::{CHECKPOINT, file_hash};
use crate::settings::Settings;
use crate::sim_limits::check_kept_positions;
use crate::simulate_error::SimulateError;
use crate::simulator::Simulator;
use metrics::FrameMetrics;
pub use performer::Performer;
pub use pins::Pins;
use pins::read_pins;
use placement::check_placement;
use progress::{ClothRun, Progress, read_checkpoint, write_checkpoint};
pub use settings::SimulateSettings;
pub use stepping::{SETTLE_SECONDS, Stepping};

/// What a run simulates: the garment (its file, `.obj` or `.garment`, named in messages and
/// hashed into the run, with its pins file) ready to simulate, on the body performing the motion.
pub struct SimulateJob<'a> {
    pub garment_path: &'a Path,
    pub pins_path: Option<&'a Path>,
    pub garment: GarmentInput,
    pub performer: Performer<'a>,
}

/// A garment ready to simulate: its mesh around the body at rest (metres), the vertices held,
/// and its fabric when its file names one.
pub struct GarmentInput {
    pub mesh: TriMesh,
    pub pins: Pins,
    pub material: Option<Material>,
}

impl GarmentInput {
    /// A bare mesh (`.obj`) and its pins file. A mesh with nothing attached hangs on the body
    /// by friction alone, so that is said.
    pub fn read_obj(path: &Path, pins: Option<&Path>) -> Result<Self, SimulateError> {
        let mesh = read_obj(path)?;
        let pins = match pins {
            Some(p) => read_pins(p, mesh.vertex_count())?,
            None => Pins::default(),
        };
        if pins.attached.is_empty() && pins.fixed.is_empty() {
            tracing::warn!(
                "{}: a bare mesh with no --pin: nothing holds it on the body (a skirt or trousers \
                 slides down); a library garment's .garment file carries its waistband",
                path.display()
            );
        }
        Ok(Self { mesh, pins, material: None })
    }
}

/// A run simulated as far as it went: the motion frames recorded and their metrics, and the
/// error that stopped it, if one did.
pub struct Simulation {
    garment: TriMesh,
    progress: Progress,
    phases: PhaseTimes,
    /// The material's strain limit, which the stretch is measured against.
    strain_limit: f32,
    stopped: Option<SimulateError>,
    checkpoint: PathBuf,
}

/// Simulates `job` with `settings`, resuming from the checkpoint in `out` when it holds one of
/// this run (and `settings.restart` is not set). An error before any motion frame is recorded is
/// returned as is; one after is kept in the [`Simulation`] with the frames before it.
pub fn simulate(
    job: &SimulateJob,
    settings: &SimulateSettings,
    out: &Path,
) -> Result<Simulation, SimulateError> {
    let garment_path = job.garment_path;
    let (garment, pins) = (&job.garment.mesh, &job.garment.pins);
    let material = settings.material.or(job.garment.material).unwrap_or_default();
    let cloth = Cloth::new(garment, &material, &pins.fixed)
        .map_err(|e| SimulateError::from(e).of(garment_path.display().to_string()))?;
    let (model, motion) = (job.performer.model, job.performer.motion);
    check_kept_positions(job.performer.motion_path, motion.num_frames(), garment.vertex_count())?;
    let schedule = Settling::new(model, motion, settings.stepping.settle)?;
    let shaped = shape_body(model, job.performer.betas)?;
    let faces = model.template_mesh().faces;
    let body_at = |k: usize| -> Result<Vec<[f32; 3]>, SimulateError> {
        let (pose, trans) = schedule.pose(k);
        Ok(points(pose_frames(model, &shaped, pose, trans)?.frame_vertices(0)))
    };
    let rest = body_at(0)?;
    check_placement(garment_path, garment, &rest)?;
    let attachments: Vec<Attachment> = pins
        .attached
        .iter()
        .map(|&v| Attachment::bind(&rest, &faces, v, garment.positions[v as usize]))
        .collect();

    let run = ClothRun {
        garment: file_hash(garment_path)?,
        pins: match job.pins_path {
            Some(p) => file_hash(p)?,
            None => "none".into(),
        },
        motion: file_hash(job.performer.motion_path)?,
        body: job.performer.body.to_string(),
        betas: job.performer.betas.to_vec(),
        fps: motion.fps,
        frames: motion.num_frames(),
        material,
        substeps: settings.stepping.substeps,
        settle: settings.stepping.settle,
        self_collision: settings.self_collision,
    };
    let solver = Settings {
        substeps: settings.stepping.substeps,
        self_collision: run.self_collision,
        ..Settings::default()
    };
    let mut sim = Simulator::new(cloth, Some(Body::new(faces.clone())), attachments, solver)?;
    let checkpoint = out.join(CHECKPOINT);
    if settings.restart {
        std::fs::remove_file(&checkpoint).ok();
    }
    let mut progress = Progress::start();
    if checkpoint.exists() {
        let (resumed, state) = read_checkpoint(&checkpoint, &run, garment.vertex_count(), &schedule)?;
        sim.restore(state)?;
        tracing::info!("resuming {} at frame {} of {}", checkpoint.display(), resumed.next, schedule.len());
        progress = resumed;
    }

    let dt = 1.0 / motion.fps;
    let bar = mannequin_io::progress::bar(schedule.len() as u64, "frames");
    bar.set_position(progress.next as u64);
    let mut previous = body_at(progress.next - 1)?;
    let outcome = (progress.next..schedule.len()).try_for_each(|k| -> Result<(), SimulateError> {
        let next = body_at(k)?;
        let start = Instant::now();
        sim.step_frame(&previous, &next, dt).map_err(|e| {
            let when = if k < schedule.settle {
                "while settling".to_string()
            } else {
                format!("at motion frame {}", k - schedule.settle)
            };
            SimulateError::from(e).of(format!("{} {when} (simulation frame {k})", garment_path.display()))
        })?;
        let ms = start.elapsed().as_secs_f64() * 1e3;
        if k >= schedule.settle {
            let positions = sim.positions().to_vec();
            let cloth = (garment.positions.as_slice(), garment.faces.as_slice());
            let body = (next.as_slice(), faces.as_slice());
            progress.metrics.push(FrameMetrics::measure(k - schedule.settle, &positions, cloth, body, ms));
            progress.frames.push(positions);
        }
        bar.set_message(format!("{ms:.0} ms/frame"));
        bar.inc(1);
        progress.next = k + 1;
        if settings.checkpoint_every > 0
            && progress.next.is_multiple_of(settings.checkpoint_every)
            && progress.next < schedule.len()
        {
            write_checkpoint(&checkpoint, &run, &sim.state(), &progress)?;
        }
        previous = next;
        Ok(())
    });
    bar.finish_and_clear();
    let stopped = match outcome {
        Err(e) if progress.frames.is_empty() => return Err(e),
        outcome => outcome.err(),
    };
    let strain_limit = sim.cloth().material.strain_limit;
    Ok(Simulation {
        garment: garment.clone(),
        progress,
        phases: sim.phase_times(),
        strain_limit,
        stopped,
        checkpoint,
    })
}

impl Simulation {
    /// garment.pc2, garment.npz, scene.glb and metrics.json for the frames recorded, into `dir`
    /// (a staging folder the caller moves into `out`).
    pub fn write(&self, dir: &Path, out: &Path, job: &SimulateJob) -> Result<(), SimulateError> {
        let body = (job.performer.model, job.performer.betas, job.performer.motion);
        let frames = &self.progress.frames;
        let metrics = (self.progress.metrics.as_slice(), self.strain_limit);
        let summary = outputs::write_outputs(dir, &self.garment, body, frames, metrics, &self.phases)?;
        let f = frames.len();
        tracing::info!(
            "wrote {}: {f} frames of {} vertices; {:.1} ms per frame; at most {} vertices inside the body, {} self-intersecting pairs, p99 stretch {:.1} % (limit {:.1} %)",
            out.display(),
            self.garment.vertex_count(),
            summary["ms_per_frame"].as_f64().unwrap_or(0.0),
            summary["max_vertices_inside_body"],
            summary["max_self_intersecting_pairs"],
            100.0 * summary["max_p99_edge_stretch"].as_f64().unwrap_or(0.0),
            100.0 * self.strain_limit,
        );
        Ok(())
    }

    /// Ends the run whose outputs are in `out`: a finished one drops its checkpoint; a stopped
    /// one is its error, saying how many frames were kept.
    pub fn finish(self, out: &Path) -> Result<(), SimulateError> {
        match self.stopped {
            None => {
                std::fs::remove_file(&self.checkpoint).ok();
                Ok(())
            }
            Some(error) => Err(SimulateError::Kept {
                error: Box::new(error),
                frames: self.progress.frames.len(),
                out: out.display().to_string(),
            }),
        }
    }
}
