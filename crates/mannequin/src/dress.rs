//! `mannequin dress`: put garments on a body of any shape (thesis Eqs. 3.1–3.3) and play a
//! motion, the cloth simulator resolving what skinning cannot (gravity on loose parts, the body
//! pushing through after a shape change). Layers are simulated inner first; each one collides
//! with the body and with every layer under it.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Args as ClapArgs;
use mannequin_body::{BodyModel, Settling, shape_body};
use mannequin_cloth::{Material, Settings, quality};
use mannequin_garment::{
    Dressed, Garment, LayerProgress, SIZE_NAMES, WearProgress, WearStep, Wearer, load_or_make, wear,
    write_layered_scene,
};
use mannequin_io::{Npz, NpzWriter};
use mannequin_mesh::MorphSequence;
use rayon::prelude::*;
use serde::Serialize;

use crate::shared::BodyArgs;
use mannequin_body::load_body;
use crate::checkpoint::{
    CHECKPOINT, add_run, add_state, check_run, file_hash, frames_array, read_frames, read_state,
};
use crate::shared::Clip;
use crate::sim_limits::{MAX_SUBSTEPS, check_kept_positions, parse_settle};
use mannequin_splat::read_camera;
use crate::staging::Staging;
use mannequin_io::progress::{JobTimer, bar};

mod fit_report;
mod frames;

#[derive(ClapArgs)]
#[command(after_help = "Writes OUT/dressed.glb (the skinned body and every garment as morph targets), \
OUT/<garment>.pc2, OUT/frames/frame_0000.png, ... (and OUT/frames.mp4 with ffmpeg) and OUT/metrics.json.")]
pub struct Args {
    #[command(flatten)]
    body: BodyArgs,
    /// Garments, inner layer first: .garment files (`mannequin garment make`), or category names
    /// (pants, short-pants, shirt, tshirt, long-coat, skirt, dress), made at --size on this body and cached.
    #[arg(long, value_delimiter = ',', required = true)]
    garments: Vec<String>,
    /// The size of garments given by category name.
    #[arg(long, default_value = "M", value_parser = clap::builder::PossibleValuesParser::new(SIZE_NAMES))]
    size: String,
    #[command(flatten)]
    clip: Clip,
    /// Camera JSON (K, extrinsic, width, height) for the frames; default: a front view framing the clip.
    #[arg(long)]
    camera: Option<PathBuf>,
    /// Simulation substeps per frame, at most 100.
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
    /// Skin the garments only (Eqs. 3.2–3.3), without the cloth simulator.
    #[arg(long)]
    no_simulation: bool,
    /// Cloth–cloth contacts within each garment (vertex–triangle and edge–edge); slow, see
    /// `cloth simulate --self-collision`.
    #[arg(long)]
    self_collision: bool,
    /// Skip the rendered frames.
    #[arg(long)]
    no_frames: bool,
    /// Print, per garment and body region, how far it stands off the body and where it is
    /// stretched past its material's limit, on the body settled in the motion's first pose.
    #[arg(long)]
    fit_report: bool,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
    /// Save a checkpoint every this many simulated frames (0: never); a re-run of the same
    /// command goes on from it.
    #[arg(long, default_value_t = 60)]
    checkpoint_every: usize,
    /// Start over even if the folder holds a checkpoint.
    #[arg(long)]
    restart: bool,
}

/// How far (m) each layer stands beyond the one under it at rest: twice the simulator's body
/// margin, so the outer layer starts clear of the inner one's collision shell.
const LAYER_GAP: f32 = 0.01;

/// One garment being worn: its name in the outputs, template and transfer to this body.
struct Worn<'a> {
    name: String,
    garment: &'a Garment,
    dressed: Dressed<'a>,
}

/// Per garment and motion frame, what went wrong where.
#[derive(Debug, Clone, Serialize)]
struct FrameMetrics {
    frame: usize,
    vertices_inside_body: usize,
    /// Triangle pairs crossing the layers under this one.
    crossings_with_inner_layers: usize,
    max_edge_strain: f32,
    mean_edge_strain: f32,
    /// The 99th percentile of the edges' stretch (compression left out).
    p99_edge_stretch: f32,
}

pub fn run(args: Args) -> Result<()> {
    let _timer = JobTimer::start("dress");
    let mut stage_s = serde_json::Map::new();
    let mut stage = |name: &str, start: Instant| {
        stage_s.insert(name.to_string(), start.elapsed().as_secs_f64().into());
    };
    let start = Instant::now();
    let model = load_body(&args.body.body)?;
    let motion = args.clip.load()?;
    let camera = args.camera.as_deref().map(read_camera).transpose()?.map(|(camera, _)| camera);
    let betas = &args.body.betas;
    let loaded: Vec<(String, Garment)> = args
        .garments
        .iter()
        .map(|g| Ok(load_or_make(g, &model, &args.body.body, &args.size)?))
        .collect::<Result<_>>()?;
    let settle = Settling::settle_frames(args.settle, motion.fps)?;
    let vertices = model.num_vertices() + loaded.iter().map(|(_, g)| g.vertex_count()).sum::<usize>();
    check_kept_positions(&args.clip.motion, settle + motion.num_frames(), vertices)?;
    // Each layer stands clear of those under it (in rest space, so on every body shape).
    let body_faces = model.template_mesh().faces;
    let templates: Vec<(String, Garment)> = loaded
        .iter()
        .enumerate()
        .map(|(i, (name, g))| {
            let inner: Vec<&Garment> = loaded[..i].iter().map(|(_, g)| g).collect();
            Ok((name.clone(), g.over(&inner, LAYER_GAP, &model).with_context(|| name.clone())?))
        })
        .collect::<Result<_>>()?;
    let worn: Vec<Worn> = templates
        .iter()
        .enumerate()
        .map(|(i, (name, garment))| {
            let dressed = Dressed::new(garment, &model, betas).with_context(|| format!("dressing {name}"))?;
            let name = if templates[..i].iter().any(|(n, _)| n == name) {
                format!("{name}_{i}")
            } else {
                name.clone()
            };
            Ok(Worn { name, garment, dressed })
        })
        .collect::<Result<_>>()?;
    stage("transfer", start);

    let start = Instant::now();
    let schedule = Settling::new(&model, &motion, args.settle)?;
    let shaped = shape_body(&model, betas)?;
    let body_frames = schedule.body_frames(&model, &shaped)?;
    stage("body", start);

    let checkpoint = args.out.join(CHECKPOINT);
    if args.restart {
        std::fs::remove_file(&checkpoint).ok();
    }
    let start = Instant::now();
    let layers: Vec<Vec<Vec<[f32; 3]>>> = if args.no_simulation {
        worn.iter()
            .map(|w| {
                (0..schedule.len())
                    .map(|k| {
                        let (pose, trans) = schedule.pose(k);
                        Ok(w.dressed.posed(pose, trans)?)
                    })
                    .collect::<Result<_>>()
            })
            .collect::<Result<_>>()?
    } else {
        let named: Vec<(&str, &Dressed)> = worn.iter().map(|w| (w.name.as_str(), &w.dressed)).collect();
        let wearer =
            Wearer { faces: &body_faces, frames: &body_frames, schedule: &schedule, fps: motion.fps };
        let settings =
            Settings { substeps: args.substeps, self_collision: args.self_collision, ..Settings::default() };
        let run = DressRun {
            garments: worn.iter().map(|w| format!("{} {}", w.name, template_hash(w.garment))).collect(),
            body: args.body.body.clone(),
            betas: betas.clone(),
            motion: file_hash(&args.clip.motion)?,
            fps: motion.fps,
            frames: motion.num_frames(),
            substeps: args.substeps,
            settle: args.settle,
            self_collision: args.self_collision,
        };
        let resume = if checkpoint.exists() {
            let resume = read_checkpoint(&checkpoint, &run, &named, schedule.len())?;
            tracing::info!("resuming {}", checkpoint.display());
            resume
        } else {
            WearProgress::default()
        };
        let total = worn.len() * (schedule.len() - 1);
        let progress = bar(total as u64, "simulation");
        let mut on_frame = |step: &WearStep| -> Result<()> {
            let done = step.frames_done();
            progress.set_position(done as u64);
            if args.checkpoint_every > 0 && done.is_multiple_of(args.checkpoint_every) && done < total {
                write_checkpoint(&checkpoint, &run, &step.progress(), &worn)?;
            }
            Ok(())
        };
        let simulated = wear(&named, &wearer, settings, resume, &mut on_frame)?;
        progress.finish_and_clear();
        simulated
            .into_iter()
            .zip(&worn)
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
            .collect()
    };
    stage("simulation", start);

    if args.fit_report {
        let k = schedule.settle - 1;
        for (i, w) in worn.iter().enumerate() {
            let limit = Material::named(&w.garment.recipe.material)?.strain_limit;
            let report = fit_report::fit_report(
                &layers[i][k],
                &w.dressed.rest(),
                &w.garment.mesh.faces,
                &w.dressed.weights,
                model.num_joints(),
                &body_frames[k],
                &body_faces,
                limit,
            );
            println!("{} ({}):", w.name, w.garment.recipe.material);
            println!(
                "  {:<16} {:>8} {:>10} {:>11} {:>15}  verdict",
                "region", "vertices", "min ease", "mean ease", "over the limit"
            );
            for r in report {
                println!(
                    "  {:<16} {:>8} {:>7.1} cm {:>8.1} cm {:>13.0} %  {}",
                    r.region,
                    r.vertices,
                    r.min_ease_cm,
                    r.mean_ease_cm,
                    100.0 * r.share_over_limit,
                    r.verdict
                );
            }
        }
    }

    // From here on, only the motion's frames.
    let motion_frames = schedule.settle..schedule.len();
    let start = Instant::now();
    let metrics: Vec<Vec<FrameMetrics>> = worn
        .iter()
        .enumerate()
        .map(|(i, w)| {
            let rest = w.dressed.rest();
            // Frames are independent: measure them in parallel.
            motion_frames
                .clone()
                .into_par_iter()
                .map(|k| {
                    let positions = &layers[i][k];
                    let (max_edge_strain, mean_edge_strain) =
                        quality::edge_strain(&rest, positions, &w.garment.mesh.faces);
                    let crossings_with_inner_layers = (0..i)
                        .map(|j| {
                            quality::crossing_pairs(
                                positions,
                                &w.garment.mesh.faces,
                                &layers[j][k],
                                &worn[j].garment.mesh.faces,
                            )
                        })
                        .sum();
                    FrameMetrics {
                        frame: k - schedule.settle,
                        vertices_inside_body: quality::vertices_inside_body(
                            positions,
                            &body_frames[k],
                            &body_faces,
                        ),
                        crossings_with_inner_layers,
                        max_edge_strain,
                        mean_edge_strain,
                        p99_edge_stretch: quality::stretch_quantile(
                            &rest,
                            positions,
                            &w.garment.mesh.faces,
                            0.99,
                        ),
                    }
                })
                .collect()
        })
        .collect();
    stage("metrics", start);

    let start = Instant::now();
    let staging = Staging::new(&args.out)?;
    if !args.no_frames {
        let meshes: Vec<(&[[u32; 3]], [f32; 3])> = worn
            .iter()
            .map(|w| (w.garment.mesh.faces.as_slice(), w.garment.recipe.category.colour()))
            .collect();
        let scene = frames::Scene { body_faces: &body_faces, garments: &meshes };
        let garment_frames: Vec<Vec<&[[f32; 3]]>> =
            motion_frames.clone().map(|k| layers.iter().map(|l| l[k].as_slice()).collect()).collect();
        let body_motion: Vec<&[[f32; 3]]> =
            motion_frames.clone().map(|k| body_frames[k].as_slice()).collect();
        frames::render(&scene, &body_motion, &garment_frames, camera.as_ref(), staging.dir(), motion.fps)?;
    }
    stage("render", start);

    let start = Instant::now();
    let motion_layers: Vec<Vec<Vec<[f32; 3]>>> =
        layers.iter().map(|l| l[motion_frames.clone()].to_vec()).collect();
    write_scene(staging.dir(), &model, betas, &motion, &worn, &motion_layers)?;
    stage("write", start);
    write_metrics(staging.dir(), &worn, &metrics, motion.fps, stage_s)?;
    staging.commit()?;
    if !args.no_simulation {
        std::fs::remove_file(&checkpoint).ok();
    }
    Ok(())
}

/// Everything that changes the simulation; a checkpoint of another run is refused.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
struct DressRun {
    /// Each layer's name and template hash, inner first.
    garments: Vec<String>,
    body: String,
    betas: Vec<f32>,
    motion: String,
    fps: f32,
    frames: usize,
    substeps: u32,
    settle: f32,
    self_collision: bool,
}

/// The hash of what a template brings to a run: recipe, mesh and binding to the body.
fn template_hash(g: &Garment) -> String {
    let mut bytes = serde_json::to_vec(&g.recipe).unwrap_or_default();
    let floats =
        g.mesh.positions.iter().chain(&g.offsets).flatten().chain(g.binding.iter().flat_map(|b| &b.bary));
    bytes.extend(floats.flat_map(|x| x.to_le_bytes()));
    let indices = g.mesh.faces.iter().flatten().chain(g.binding.iter().map(|b| &b.face));
    bytes.extend(indices.flat_map(|i| i.to_le_bytes()));
    mannequin_io::fingerprint::hash_bytes(&bytes)
}

/// Finished layers as `finished_<i>`, the one under way as `current` with the cloth's state.
fn write_checkpoint(path: &Path, run: &DressRun, progress: &WearProgress, worn: &[Worn]) -> Result<()> {
    let mut w = NpzWriter::uncompressed();
    add_run(&mut w, run)?;
    for (i, (frames, layer)) in progress.finished.iter().zip(worn).enumerate() {
        w.add(&format!("finished_{i}"), frames_array(frames, layer.garment.vertex_count()));
    }
    if let (Some(current), Some(layer)) = (&progress.current, worn.get(progress.finished.len())) {
        w.add("current", frames_array(&current.frames, layer.garment.vertex_count()));
        add_state(&mut w, &current.state);
    }
    w.write(path)?;
    Ok(())
}

/// The progress a checkpoint of `run` holds for `layers` on a schedule of `schedule` frames; an
/// error naming what differs for another run's, or the field that is not what this run saves.
fn read_checkpoint(
    path: &Path,
    run: &DressRun,
    layers: &[(&str, &Dressed)],
    schedule: usize,
) -> Result<WearProgress> {
    let npz = Npz::read(path)?;
    check_run(&npz, path, run)?;
    let mut progress = WearProgress::default();
    for (i, (_, layer)) in layers.iter().enumerate() {
        let vertices = layer.garment().vertex_count();
        let key = format!("finished_{i}");
        if npz.contains(&key) {
            progress.finished.push(read_frames(&npz, &key, vertices)?);
        } else {
            if npz.contains("current") {
                let frames = read_frames(&npz, "current", vertices)?;
                progress.current = Some(LayerProgress { frames, state: read_state(&npz, vertices)? });
            }
            break;
        }
    }
    progress.check(layers, schedule).with_context(|| path.display().to_string())?;
    Ok(progress)
}

/// dressed.glb (the skinned body playing the motion, each garment as morph targets in sync)
/// and one Blender point cache per garment.
fn write_scene(
    dir: &Path,
    model: &BodyModel,
    betas: &[f32],
    motion: &mannequin_body::Motion,
    worn: &[Worn],
    layers: &[Vec<Vec<[f32; 3]>>],
) -> Result<()> {
    let f = motion.num_frames();
    let morphs: Vec<MorphSequence> = worn
        .iter()
        .zip(layers)
        .map(|(w, frames)| {
            let mut mesh = w.garment.mesh.clone();
            mesh.positions = frames[0].clone();
            mesh.colors = Some(vec![w.garment.recipe.category.colour(); mesh.vertex_count()]);
            MorphSequence { name: w.name.clone(), mesh, frames: frames.clone(), fps: motion.fps }
        })
        .collect();
    let poses = motion.poses_for(model)?;
    let pl = model.pose_len();
    let motion = (&poses[..f * pl], &motion.trans[..3 * f], motion.fps);
    Ok(write_layered_scene(&dir.join("dressed.glb"), model, betas, motion, &morphs)?)
}

fn write_metrics(
    dir: &Path,
    worn: &[Worn],
    metrics: &[Vec<FrameMetrics>],
    fps: f32,
    stage_s: serde_json::Map<String, serde_json::Value>,
) -> Result<()> {
    let garments: Vec<serde_json::Value> = worn
        .iter()
        .zip(metrics)
        .map(|(w, m)| {
            serde_json::json!({
                "name": w.name,
                "category": w.garment.recipe.category.name(),
                "material": w.garment.recipe.material,
                "strain_limit": Material::named(&w.garment.recipe.material).map_or(f32::NAN, |m| m.strain_limit),
                "vertices": w.garment.vertex_count(),
                "max_vertices_inside_body": m.iter().map(|x| x.vertices_inside_body).max(),
                "max_crossings_with_inner_layers": m.iter().map(|x| x.crossings_with_inner_layers).max(),
                "max_edge_strain": m.iter().map(|x| x.max_edge_strain).fold(0.0f32, f32::max),
                "mean_edge_strain": m.iter().map(|x| x.mean_edge_strain).sum::<f32>() / m.len().max(1) as f32,
                "max_p99_edge_stretch": m.iter().map(|x| x.p99_edge_stretch).fold(0.0f32, f32::max),
                "per_frame": m,
            })
        })
        .collect();
    let summary = serde_json::json!({
        "frames": metrics.first().map_or(0, Vec::len),
        "fps": fps,
        "stage_s": stage_s,
        "garments": garments,
    });
    let path = dir.join("metrics.json");
    mannequin_io::write_atomic(&path, serde_json::to_string_pretty(&summary)?.as_bytes())
        .with_context(|| format!("writing {}", path.display()))?;
    for g in summary["garments"].as_array().into_iter().flatten() {
        tracing::info!(
            "{}: at most {} vertices inside the body, {} crossings with inner layers; strain mean {:.3}, \
             max {:.3}; 99 % of edges stretched under {:.3} (the material's limit: {})",
            g["name"],
            g["max_vertices_inside_body"],
            g["max_crossings_with_inner_layers"],
            g["mean_edge_strain"].as_f64().unwrap_or(0.0),
            g["max_edge_strain"].as_f64().unwrap_or(0.0),
            g["max_p99_edge_stretch"].as_f64().unwrap_or(0.0),
            g["strain_limit"]
        );
    }
    tracing::info!("stages (s): {}", summary["stage_s"]);
    Ok(())
}
