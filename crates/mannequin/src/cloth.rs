//! `mannequin cloth simulate`: drape a garment on a body and play a motion with the XPBD
//! simulator. The body starts at rest and blends into the motion's first frame over a settling
//! period, so the garment hangs before the motion starts. Checkpoints let a re-run of the same
//! command resume; a state that goes non-finite stops the run and keeps the frames before it.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand};
use mannequin_body::{
    BodyModel, Motion, Settling, pose_frames, shape_body, skeletal_animation, skinned_body,
};
use mannequin_cloth::{
    Attachment, Body, Cloth, ClothState, MATERIAL_NAMES, Material, Settings, Simulator, quality,
};
use mannequin_io::{NpyArray, Npz, NpzWriter};
use mannequin_mesh::{MorphSequence, PointCache, TriMesh, points, read_obj, write_scene_glb};
use serde::Serialize;

use crate::shared::BodyArgs;
use mannequin_body::load_body;
use crate::checkpoint::{
    CHECKPOINT, add_run, add_state, check_run, file_hash, frames_array, read_frames, read_state,
};
use crate::shared::Clip;
use crate::sim_limits::{MAX_SUBSTEPS, check_kept_positions, parse_settle};
use crate::staging::Staging;
use mannequin_io::progress::{JobTimer, bar};

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
    #[arg(long, default_value = "cotton", value_parser = clap::builder::PossibleValuesParser::new(MATERIAL_NAMES))]
    material: String,
    /// Simulation substeps per output frame (one constraint iteration each), at most 100.
    #[arg(
        long,
        default_value_t = 20,
        allow_hyphen_values = true,
        value_parser = clap::value_parser!(u32).range(1..=MAX_SUBSTEPS as i64)
    )]
    substeps: u32,
    /// Seconds before the motion: half at rest, half blending into its first frame (at most 10).
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true, value_parser = parse_settle)]
    settle: f32,
    /// Cloth–cloth contacts (vertex–triangle, Eq. 3.22). Experimental: cloth piling onto itself
    /// still tangles in places and they cost about 4× the time, so they are off unless asked
    /// for; metrics.json counts the self-intersecting pairs either way.
    #[arg(long)]
    self_collision: bool,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
    /// Save a checkpoint every this many frames.
    #[arg(long, default_value_t = 30)]
    checkpoint_every: usize,
    /// Start over even if the folder holds a checkpoint.
    #[arg(long)]
    restart: bool,
}

pub fn run(cmd: ClothCommand) -> Result<()> {
    match cmd {
        ClothCommand::Simulate(args) => simulate(args),
    }
}

/// The vertices a pins file names.
#[derive(Debug, Default, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Pins {
    #[serde(default)]
    fixed: Vec<u32>,
    #[serde(default)]
    attached: Vec<u32>,
}

fn read_pins(path: &Path, vertices: usize) -> Result<Pins> {
    let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let pins: Pins = serde_json::from_str(&text).with_context(|| {
        format!("{}: expected {{\"fixed\": [vertex, ...], \"attached\": [vertex, ...]}}", path.display())
    })?;
    for (field, list) in [("fixed", &pins.fixed), ("attached", &pins.attached)] {
        if let Some(&v) = list.iter().find(|&&v| v as usize >= vertices) {
            bail!(
                "{}: {field}: vertex {v} is out of range (the garment has {vertices} vertices)",
                path.display()
            );
        }
    }
    if let Some(v) = pins.attached.iter().find(|v| pins.fixed.contains(v)) {
        bail!("{}: attached: vertex {v} is also fixed; expected each vertex in one list", path.display());
    }
    Ok(pins)
}

/// Everything that changes the result; a checkpoint of another run is refused.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
struct ClothRun {
    garment: String,
    pins: String,
    motion: String,
    body: String,
    betas: Vec<f32>,
    fps: f32,
    frames: usize,
    material: String,
    substeps: u32,
    settle: f32,
    self_collision: bool,
}

/// Per-frame quality of the simulated garment.
#[derive(Debug, Clone, Serialize, serde::Deserialize)]
struct FrameMetrics {
    frame: usize,
    vertices_inside_body: usize,
    self_intersecting_pairs: usize,
    max_edge_strain: f32,
    mean_edge_strain: f32,
    simulation_ms: f64,
}

impl FrameMetrics {
    /// Whether these are motion frame `frame`'s, every measure finite and non-negative.
    fn is_frame(&self, frame: usize) -> bool {
        let measures = [self.max_edge_strain, self.mean_edge_strain].map(f64::from);
        self.frame == frame
            && measures.into_iter().chain([self.simulation_ms]).all(|x| x.is_finite() && x >= 0.0)
    }
}

/// Where a run stands: the next schedule frame to reach, and what it has recorded.
struct Progress {
    next: usize,
    frames: Vec<Vec<[f32; 3]>>,
    metrics: Vec<FrameMetrics>,
}

fn write_checkpoint(path: &Path, run: &ClothRun, state: &ClothState, progress: &Progress) -> Result<()> {
    let mut w = NpzWriter::new();
    add_run(&mut w, run)?;
    w.add("next", NpyArray::i64(vec![1], vec![progress.next as i64]));
    add_state(&mut w, state);
    w.add("frames", frames_array(&progress.frames, state.positions.len()));
    w.add("metrics", NpyArray::text(&serde_json::to_string(&progress.metrics)?));
    w.write(path)?;
    Ok(())
}

/// The checkpoint's progress and state, if it is one of `run` on `schedule`; an error naming
/// the settings that differ if it is another run's, or the field that is not what this run
/// would have saved.
fn read_checkpoint(
    path: &Path,
    run: &ClothRun,
    vertices: usize,
    schedule: &Settling,
) -> Result<(Progress, ClothState)> {
    let npz = Npz::read(path)?;
    check_run(&npz, path, run)?;
    let last = schedule.len() - 1;
    let raw = npz.require("next")?.to_i64().filter(|n| n.len() == 1).map(|n| n[0]);
    let Some(next) = raw.and_then(|n| usize::try_from(n).ok()).filter(|n| (1..=last).contains(n)) else {
        bail!(
            "{}: next: {}; expected one frame number from 1 to {last} (the run's {} frames, settling included)",
            path.display(),
            raw.map_or("not one whole number".into(), |n| n.to_string()),
            schedule.len()
        );
    };
    let state = read_state(&npz, vertices)?;
    let frames = read_frames(&npz, "frames", vertices)?;
    let recorded = next.saturating_sub(schedule.settle);
    if frames.len() != recorded {
        bail!(
            "{}: frames: {} frames; expected {recorded}, the motion frames before frame {next} of the run",
            path.display(),
            frames.len()
        );
    }
    let metrics: Vec<FrameMetrics> = serde_json::from_str(npz.text("metrics")?)
        .with_context(|| format!("{}: metrics: expected the per-frame metrics as JSON", path.display()))?;
    let wrong = |i: usize| i >= recorded || metrics.get(i).is_none_or(|m| !m.is_frame(i));
    if let Some(i) = (0..metrics.len().max(recorded)).find(|&i| wrong(i)) {
        bail!(
            "{}: metrics: entry {i} is not motion frame {i}'s; expected {recorded} entries of finite, \
             non-negative measures",
            path.display()
        );
    }
    Ok((Progress { next, frames, metrics }, state))
}

/// Refuses a garment that is not around the body: half its vertices farther than this from the
/// nearest body vertex at rest (m) means another unit or another placement.
const FAR_FROM_BODY: f32 = 0.15;

fn check_placement(path: &Path, garment: &TriMesh, body: &[[f32; 3]]) -> Result<()> {
    let mut distances: Vec<f32> = garment
        .positions
        .iter()
        .map(|p| {
            body.iter()
                .map(|b| (0..3).map(|d| (p[d] - b[d]).powi(2)).sum::<f32>())
                .fold(f32::INFINITY, f32::min)
        })
        .map(f32::sqrt)
        .collect();
    distances.sort_by(f32::total_cmp);
    let median = distances[distances.len() / 2];
    if median > FAR_FROM_BODY {
        bail!(
            "{}: the garment is far from the body: half its vertices are over {median:.2} m from it at \
             rest (expected within {FAR_FROM_BODY} m: a garment in metres, modelled around the rest pose)",
            path.display()
        );
    }
    Ok(())
}

fn simulate(args: SimulateArgs) -> Result<()> {
    let _timer = JobTimer::start("cloth simulate");
    let garment_path = &args.garment;
    let garment = read_obj(garment_path)?;
    let material = Material::named(&args.material)?;
    let pins = match &args.pin {
        Some(p) => read_pins(p, garment.vertex_count())?,
        None => Pins::default(),
    };
    let cloth =
        Cloth::new(&garment, &material, &pins.fixed).with_context(|| garment_path.display().to_string())?;
    let model = load_body(&args.body.body)?;
    let motion = args.clip.load()?;
    check_kept_positions(&args.clip.motion, motion.num_frames(), garment.vertex_count())?;
    let schedule = Settling::new(&model, &motion, args.settle)?;
    let shaped = shape_body(&model, &args.body.betas)?;
    let faces = model.template_mesh().faces;
    let body_at = |k: usize| -> Result<Vec<[f32; 3]>> {
        let (pose, trans) = schedule.pose(k);
        Ok(points(pose_frames(&model, &shaped, pose, trans)?.frame_vertices(0)))
    };
    let rest = body_at(0)?;
    check_placement(garment_path, &garment, &rest)?;
    let attachments: Vec<Attachment> = pins
        .attached
        .iter()
        .map(|&v| Attachment::bind(&rest, &faces, v, garment.positions[v as usize]))
        .collect();

    let run = ClothRun {
        garment: file_hash(garment_path)?,
        pins: match &args.pin {
            Some(p) => file_hash(p)?,
            None => "none".into(),
        },
        motion: file_hash(&args.clip.motion)?,
        body: args.body.body.clone(),
        betas: args.body.betas.clone(),
        fps: motion.fps,
        frames: motion.num_frames(),
        material: args.material.clone(),
        substeps: args.substeps,
        settle: args.settle,
        self_collision: args.self_collision,
    };
    let settings =
        Settings { substeps: args.substeps, self_collision: run.self_collision, ..Settings::default() };
    let mut sim = Simulator::new(cloth, Some(Body::new(faces.clone())), attachments, settings)?;
    let checkpoint = args.out.join(CHECKPOINT);
    if args.restart {
        std::fs::remove_file(&checkpoint).ok();
    }
    let mut progress = Progress { next: 1, frames: Vec::new(), metrics: Vec::new() };
    if checkpoint.exists() {
        let (resumed, state) = read_checkpoint(&checkpoint, &run, garment.vertex_count(), &schedule)?;
        sim.restore(state)?;
        tracing::info!("resuming {} at frame {} of {}", checkpoint.display(), resumed.next, schedule.len());
        progress = resumed;
    }

    let dt = 1.0 / motion.fps;
    let bar = bar(schedule.len() as u64, "frames");
    bar.set_position(progress.next as u64);
    let mut previous = body_at(progress.next - 1)?;
    let outcome = (progress.next..schedule.len()).try_for_each(|k| -> Result<()> {
        let next = body_at(k)?;
        let start = Instant::now();
        sim.step_frame(&previous, &next, dt).with_context(|| {
            let when = if k < schedule.settle {
                "while settling".to_string()
            } else {
                format!("at motion frame {}", k - schedule.settle)
            };
            format!("{} {when} (simulation frame {k})", garment_path.display())
        })?;
        let ms = start.elapsed().as_secs_f64() * 1e3;
        if k >= schedule.settle {
            record(&mut progress, &sim, &garment, &next, &faces, k - schedule.settle, ms);
        }
        bar.set_message(format!("{ms:.0} ms/frame"));
        bar.inc(1);
        progress.next = k + 1;
        if args.checkpoint_every > 0
            && progress.next.is_multiple_of(args.checkpoint_every)
            && progress.next < schedule.len()
        {
            write_checkpoint(&checkpoint, &run, &sim.state(), &progress)?;
        }
        previous = next;
        Ok(())
    });
    bar.finish_and_clear();
    if progress.frames.is_empty() {
        return outcome;
    }
    write_outputs(&args.out, &garment, &model, &args.body.betas, &motion, &progress, &sim)?;
    match outcome {
        Ok(()) => {
            std::fs::remove_file(&checkpoint).ok();
            Ok(())
        }
        Err(e) => {
            bail!("{e:#}; kept the {} frames before it in {}", progress.frames.len(), args.out.display())
        }
    }
}

/// Adds the simulator's current positions as motion frame `frame`, with its metrics.
fn record(
    progress: &mut Progress,
    sim: &Simulator,
    garment: &TriMesh,
    body: &[[f32; 3]],
    body_faces: &[[u32; 3]],
    frame: usize,
    ms: f64,
) {
    let positions = sim.positions().to_vec();
    let (max_edge_strain, mean_edge_strain) =
        quality::edge_strain(&garment.positions, &positions, &garment.faces);
    progress.metrics.push(FrameMetrics {
        frame,
        vertices_inside_body: quality::vertices_inside_body(&positions, body, body_faces),
        self_intersecting_pairs: quality::self_intersecting_pairs(&positions, &garment.faces),
        max_edge_strain,
        mean_edge_strain,
        simulation_ms: ms,
    });
    progress.frames.push(positions);
}

/// garment.pc2, garment.npz, scene.glb and metrics.json for the frames recorded so far, put in
/// place together once all are written.
fn write_outputs(
    dir: &Path,
    garment: &TriMesh,
    model: &BodyModel,
    betas: &[f32],
    motion: &Motion,
    progress: &Progress,
    sim: &Simulator,
) -> Result<()> {
    let frames = &progress.frames;
    let (f, v) = (frames.len(), garment.vertex_count());
    let staging = Staging::new(dir)?;
    PointCache { start: 0.0, sampling: 1.0, frames: frames.clone() }
        .write(&staging.dir().join("garment.pc2"))?;

    let mut npz = NpzWriter::new();
    npz.add("positions", NpyArray::f32(vec![f, v, 3], frames.iter().flatten().flatten().copied().collect()));
    let faces: Vec<i64> = garment.faces.iter().flatten().map(|&i| i as i64).collect();
    npz.add("faces", NpyArray::i64(vec![garment.face_count(), 3], faces));
    npz.add("fps", NpyArray::f64(vec![1], vec![motion.fps as f64]));
    npz.write(staging.dir().join("garment.npz"))?;

    let skinned = skinned_body(model, betas)?;
    let poses = motion.poses_for(model)?;
    let pl = model.pose_len();
    let animation =
        skeletal_animation(model.num_joints(), &poses[..f * pl], &motion.trans[..3 * f], motion.fps)?;
    let mut mesh = garment.clone();
    mesh.positions = frames[0].clone();
    let cache = MorphSequence { name: "garment".into(), mesh, frames: frames.clone(), fps: motion.fps };
    write_scene_glb(staging.dir().join("scene.glb"), &skinned, Some(&animation), &[cache])?;

    let m = &progress.metrics;
    let phases: serde_json::Map<String, serde_json::Value> = sim
        .phase_times()
        .named()
        .into_iter()
        .map(|(name, d)| (name.to_string(), d.as_secs_f64().into()))
        .collect();
    let total_ms: f64 = m.iter().map(|x| x.simulation_ms).sum();
    let summary = serde_json::json!({
        "frames": f,
        "fps": motion.fps,
        "max_vertices_inside_body": m.iter().map(|x| x.vertices_inside_body).max(),
        "max_self_intersecting_pairs": m.iter().map(|x| x.self_intersecting_pairs).max(),
        "max_edge_strain": m.iter().map(|x| x.max_edge_strain).fold(0.0f32, f32::max),
        "mean_edge_strain": m.iter().map(|x| x.mean_edge_strain).sum::<f32>() / f as f32,
        "simulation_s": total_ms / 1e3,
        "ms_per_frame": total_ms / f as f64,
        "phase_s": phases,
        "per_frame": m,
    });
    let text = serde_json::to_string_pretty(&summary)?;
    let metrics = staging.dir().join("metrics.json");
    mannequin_io::write_atomic(&metrics, text.as_bytes())
        .with_context(|| format!("writing {}", metrics.display()))?;
    staging.commit()?;
    tracing::info!(
        "wrote {}: {f} frames of {v} vertices; {:.1} ms per frame; at most {} vertices inside the body, {} self-intersecting pairs",
        dir.display(),
        total_ms / f as f64,
        summary["max_vertices_inside_body"],
        summary["max_self_intersecting_pairs"],
    );
    Ok(())
}
