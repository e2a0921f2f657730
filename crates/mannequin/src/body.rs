//! `mannequin body info|pose|animate`: inspect a body model, write a posed body as `.obj` or
//! `.ply`, or a skinned, animated `.glb` of it playing a motion.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand};
use mannequin_body::{BodyModel, FaceModel, forward, load_body, skeletal_animation, skinned_body};
use mannequin_mesh::write_mesh;
use serde_json::json;

use crate::shared::{BodyArgs, Clip, PoseChoice};

#[derive(Subcommand)]
pub enum BodyCommand {
    /// Print a model's family, sizes, joints and shape space (to stdout).
    Info(InfoArgs),
    /// Pose a body and write it as `.obj` or `.ply` (chosen by the output extension).
    Pose(PoseArgs),
    /// Drive a body with a motion and write a skinned, animated glTF binary (`.glb`).
    Animate(AnimateArgs),
}

#[derive(Args)]
pub struct InfoArgs {
    /// Body model: `default`, `default-lod1`, or a SMPL / SMPL-H / SMPL-X `.npz` or released `.pkl`.
    #[arg(long, default_value = "default")]
    body: String,
    /// Also list every joint with its parent and rest position.
    #[arg(long)]
    joints: bool,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

#[derive(Args)]
pub struct PoseArgs {
    #[command(flatten)]
    body: BodyArgs,
    #[command(flatten)]
    pose: PoseChoice,
    /// Output mesh, `.obj` or `.ply`.
    #[arg(short, long)]
    output: PathBuf,
}

#[derive(Args)]
pub struct AnimateArgs {
    #[command(flatten)]
    body: BodyArgs,
    #[command(flatten)]
    clip: Clip,
    /// Output `.glb`.
    #[arg(short, long)]
    output: PathBuf,
}

pub fn run(cmd: BodyCommand) -> Result<()> {
    match cmd {
        BodyCommand::Info(args) => info(&args),
        BodyCommand::Pose(args) => pose(args),
        BodyCommand::Animate(args) => animate(args),
    }
}

/// The facts `body info` reports, as JSON (the table prints the same values).
fn facts(m: &BodyModel, list_joints: bool) -> Result<serde_json::Value> {
    let (lo, hi) = m.v_template.iter().fold((f32::MAX, f32::MIN), |(lo, hi), p| (lo.min(p[1]), hi.max(p[1])));
    let mut v = json!({
        "model": m.name,
        "family": m.family.name(),
        "gender": m.gender,
        "vertices": m.num_vertices(),
        "faces": m.faces.len(),
        "joints": m.num_joints(),
        "betas": m.num_betas(),
        "expressions": m.num_expression(),
        "pose_features": m.num_pose_features(),
        "uv_coordinates": m.uv.as_ref().map(|uv| uv.coords.len()),
        "height_m": hi - lo,
        "extras": m.extras.keys().collect::<Vec<_>>(),
    });
    if list_joints {
        let rest = mannequin_body::shape_body(m, &[])?.joints;
        v["joint_list"] = m
            .joint_names
            .iter()
            .enumerate()
            .map(|(k, name)| {
                json!({"name": name, "parent": m.parents()[k].map(|p| &m.joint_names[p]), "rest": rest[k].to_array()})
            })
            .collect();
    }
    Ok(v)
}

fn info(args: &InfoArgs) -> Result<()> {
    let m = load_body(&args.body)?;
    let mut f = facts(&m, args.joints)?;
    // The face model lives on the full default body's head.
    let face = (args.body == "default").then(FaceModel::default_face);
    if let Some(face) = &face {
        f["face"] = serde_json::json!({
            "shape_components": face.num_shape(),
            "shape_variance": face.shape_variance,
            "expression_units": face.expression_names,
            "head_vertices": face.vertices.len(),
        });
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&f)?);
        return Ok(());
    }
    for key in ["model", "family", "gender", "vertices", "faces", "joints", "betas"] {
        println!("{key:<12} {}", f[key].as_str().map_or(f[key].to_string(), str::to_string));
    }
    if m.num_expression() > 0 {
        println!("{:<12} {}", "expressions", m.num_expression());
    }
    println!("{:<12} {}", "pose feats", m.num_pose_features());
    println!(
        "{:<12} {}",
        "uv",
        f["uv_coordinates"].as_u64().map_or("none".into(), |n| format!("{n} coordinates"))
    );
    println!("{:<12} {:.3} m (template, Y extent)", "height", f["height_m"].as_f64().unwrap_or(f64::NAN));
    if let Some(face) = &face {
        let shares: Vec<String> = face.shape_variance.iter().map(|v| format!("{:.1}", 100.0 * v)).collect();
        println!(
            "{:<12} {} shape components keeping {:.1} % of the sampled faces' variance (each, %: {}); {} expression units; {} head vertices",
            "face",
            face.num_shape(),
            100.0 * face.shape_variance.iter().sum::<f32>(),
            shares.join(" "),
            face.num_expressions(),
            face.vertices.len()
        );
    }
    if !m.extras.is_empty() {
        println!("{:<12} {}", "extras", m.extras.keys().cloned().collect::<Vec<_>>().join(", "));
    }
    for (k, j) in f["joint_list"].as_array().into_iter().flatten().enumerate() {
        let r: Vec<f64> = j["rest"].as_array().into_iter().flatten().filter_map(|x| x.as_f64()).collect();
        println!(
            "  {k:>2} {:<16} parent {:<16} rest ({:+.3}, {:+.3}, {:+.3})",
            j["name"].as_str().unwrap_or(""),
            j["parent"].as_str().unwrap_or("-"),
            r[0],
            r[1],
            r[2]
        );
    }
    Ok(())
}

fn pose(args: PoseArgs) -> Result<()> {
    let model = load_body(&args.body.body)?;
    let (pose, transl) = args.pose.resolve(model.num_joints())?;
    let posed = forward(&model, &args.body.betas, &pose, &transl)?;
    let mut mesh = model.template_mesh();
    mesh.positions = posed.frame_vertices(0).chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    write_mesh(&args.output, &mesh)?;
    tracing::info!("wrote {} ({} vertices)", args.output.display(), mesh.vertex_count());
    Ok(())
}

fn animate(args: AnimateArgs) -> Result<()> {
    if !args.output.extension().is_some_and(|e| e.eq_ignore_ascii_case("glb")) {
        bail!("{}: body animate writes a glTF binary; use a .glb extension", args.output.display());
    }
    let motion = args.clip.load()?;
    let model = load_body(&args.body.body)?;
    let poses = motion.poses_for(&model)?;
    let skinned = skinned_body(&model, &args.body.betas)?;
    let animation = skeletal_animation(model.num_joints(), &poses, &motion.trans, motion.fps)?;
    mannequin_mesh::gltf::write_glb(&args.output, &skinned, Some(&animation))
        .with_context(|| format!("writing {}", args.output.display()))?;
    tracing::info!(
        "wrote {}: {} frames at {} fps ({:.1} s), {} vertices, {} joints",
        args.output.display(),
        motion.num_frames(),
        motion.fps,
        motion.num_frames().saturating_sub(1) as f32 / motion.fps,
        model.num_vertices(),
        model.num_joints()
    );
    Ok(())
}
