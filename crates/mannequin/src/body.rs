//! `mannequin body info|pose`: inspect a body model and write a posed body as `.obj` or `.ply`.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand};
use mannequin_body::{BodyModel, Motion, forward, named_pose};
use mannequin_mesh::TriMesh;

#[derive(Subcommand)]
pub enum BodyCommand {
    /// Print a model's family, sizes, joints and shape space.
    ///
    /// MODEL is `default`, `default-lod1`, or a SMPL/SMPL-H/SMPL-X `.npz` or released `.pkl`.
    Info {
        /// `default`, `default-lod1` or a model `.npz` or `.pkl`.
        model: String,
        /// Also list every joint with its parent and rest position.
        #[arg(long)]
        joints: bool,
    },
    /// Pose a body and write it as `.obj` or `.ply` (chosen by the output extension).
    Pose(PoseArgs),
}

/// Shape, pose and model options shared by the body verbs.
#[derive(Args)]
pub struct BodyArgs {
    /// `default`, `default-lod1` or a SMPL-family `.npz` or `.pkl`.
    #[arg(long, default_value = "default")]
    pub model: String,
    /// Shape coefficients, comma-separated (missing ones are 0).
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub betas: Vec<f32>,
}

#[derive(Args)]
pub struct PoseArgs {
    #[command(flatten)]
    body: BodyArgs,
    /// A motion file (AMASS or PeopleSnapshot `.npz`); `--frame` picks the frame.
    #[arg(long, conflicts_with = "named")]
    pose: Option<PathBuf>,
    /// Frame of `--pose` to use.
    #[arg(long, default_value_t = 0)]
    frame: usize,
    /// A built-in pose: t-pose, a-pose, arms-raised, squat, walk, arms-crossed.
    #[arg(long)]
    named: Option<String>,
    /// Output mesh, `.obj` or `.ply`.
    #[arg(short, long)]
    output: PathBuf,
}

pub fn run(cmd: BodyCommand) -> Result<()> {
    match cmd {
        BodyCommand::Info { model, joints } => info(&model, joints),
        BodyCommand::Pose(args) => pose(args),
    }
}

pub fn load_model(spec: &str) -> Result<BodyModel> {
    BodyModel::from_spec(spec, None).with_context(|| format!("loading body model '{spec}'"))
}

fn info(spec: &str, list_joints: bool) -> Result<()> {
    let m = load_model(spec)?;
    let (lo, hi) = m.v_template.iter().fold((f32::MAX, f32::MIN), |(lo, hi), p| (lo.min(p[1]), hi.max(p[1])));
    println!("model        {}", m.name);
    println!("family       {}", m.family.name());
    println!("gender       {}", m.gender);
    println!("vertices     {}", m.num_vertices());
    println!("faces        {}", m.faces.len());
    println!("joints       {}", m.num_joints());
    println!("betas        {}", m.num_betas());
    if m.num_expression() > 0 {
        println!("expressions  {}", m.num_expression());
    }
    println!("pose feats   {}", m.num_pose_features());
    println!(
        "uv           {}",
        m.uv.as_ref().map_or("none".to_string(), |uv| format!("{} coordinates", uv.coords.len()))
    );
    println!("height       {:.3} m (template, Y extent)", hi - lo);
    if !m.extras.is_empty() {
        println!("extras       {}", m.extras.keys().cloned().collect::<Vec<_>>().join(", "));
    }
    if list_joints {
        let rest = mannequin_body::shape_body(&m, &[])?.joints;
        for (k, name) in m.joint_names.iter().enumerate() {
            let parent = m.parents()[k].map_or("-".to_string(), |p| m.joint_names[p].clone());
            let j = rest[k];
            println!("  {k:>2} {name:<16} parent {parent:<16} rest ({:+.3}, {:+.3}, {:+.3})", j.x, j.y, j.z);
        }
    }
    Ok(())
}

/// The single pose (3J values) and translation a `body pose` call asks for.
fn chosen_pose(args: &PoseArgs, model: &BodyModel) -> Result<(Vec<f32>, [f32; 3])> {
    if let Some(path) = &args.pose {
        let motion = Motion::read(path)?;
        if args.frame >= motion.num_frames() {
            bail!(
                "{}: frame {} requested, the motion has {}",
                path.display(),
                args.frame,
                motion.num_frames()
            );
        }
        let poses = motion.poses_for(model)?;
        let pl = model.pose_len();
        let t = &motion.trans[3 * args.frame..3 * args.frame + 3];
        return Ok((poses[args.frame * pl..(args.frame + 1) * pl].to_vec(), [t[0], t[1], t[2]]));
    }
    let name = args.named.as_deref().unwrap_or("t-pose");
    if model.num_joints() != 24 {
        bail!("named poses are SMPL (24-joint) poses; this model has {} joints", model.num_joints());
    }
    Ok((named_pose(name)?.to_vec(), [0.0; 3]))
}

fn pose(args: PoseArgs) -> Result<()> {
    let model = load_model(&args.body.model)?;
    let (pose, transl) = chosen_pose(&args, &model)?;
    let posed = forward(&model, &args.body.betas, &pose, &transl)?;
    let mut mesh = model.template_mesh();
    mesh.positions = posed.frame_vertices(0).chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    write_mesh(&args.output, &mesh)?;
    tracing::info!("wrote {} ({} vertices)", args.output.display(), mesh.vertex_count());
    Ok(())
}

/// Writes `.obj` or `.ply` by extension, atomically.
pub fn write_mesh(path: &Path, mesh: &TriMesh) -> Result<()> {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("obj") => mannequin_mesh::obj::write_obj(path, mesh)?,
        Some("ply") => mannequin_mesh::ply::write(path, mesh, None)?,
        _ => bail!("{}: unknown mesh format; expected a .obj or .ply extension", path.display()),
    }
    Ok(())
}
