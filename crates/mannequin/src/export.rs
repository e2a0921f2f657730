//! `mannequin export`: a trained avatar as files other tools open: its personalised mesh
//! (canonical or posed `.obj`/`.ply`), a skinned `.glb` with per-vertex colour baked from the
//! Gaussians, and its Gaussians at any pose as a 3DGS `.ply`.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use burn::tensor::Device;
use mannequin_avatar::params::host_rows;
use mannequin_avatar::{Avatar, Posed, export};
use mannequin_mesh::TriMesh;

use crate::body::write_mesh;
use crate::pose_choice::PoseChoice;
use crate::progress::JobTimer;

#[derive(clap::Args)]
#[command(group = clap::ArgGroup::new("outputs").required(true).multiple(true).args(["output", "gaussians"]))]
pub struct Args {
    /// Trained avatar folder (written by `mannequin train`).
    #[arg(long)]
    avatar: PathBuf,
    /// The pose: --motion/--frame or --named-pose; neither (or t-pose) is the canonical pose,
    /// where the mesh is the personalised canonical mesh itself.
    #[command(flatten)]
    pose: PoseChoice,
    /// The mesh with vertex colour baked from the Gaussians, by extension: `.obj` or `.ply` at the
    /// pose, or a skinned `.glb` (bind pose: the canonical mesh; COLOR_0; the avatar's skeleton
    /// and weights; canonical pose only).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// The Gaussians at the pose as a 3DGS `.ply` in the INRIA layout, for splat viewers.
    #[arg(long)]
    gaussians: Option<PathBuf>,
}

/// Whether `-o` names a skinned `.glb` (else `.obj` or `.ply`; anything else is an error).
fn is_glb(path: &Path) -> Result<bool> {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("glb") => Ok(true),
        Some("obj" | "ply") => Ok(false),
        _ => bail!("{}: unknown mesh format; expected a .obj, .ply or .glb extension", path.display()),
    }
}

/// Writes the mesh: skinned `.glb` at the bind pose, or `.obj`/`.ply` at the pose (V_s exactly
/// when `canonical`); each with vertex colour baked from the Gaussians.
fn write_output(avatar: &Avatar, posed: &Posed, canonical: bool, glb: bool, output: &Path) -> Result<()> {
    if glb {
        let skinned = export::skinned_mesh(avatar, posed)?;
        return mannequin_mesh::gltf::write_glb(output, &skinned, None)
            .with_context(|| format!("writing {}", output.display()));
    }
    let vertices = if canonical { &posed.personalised } else { &posed.vertices };
    let mut mesh = TriMesh::new(host_rows(vertices.clone()), avatar.canonical.faces.clone());
    mesh.colors = Some(export::vertex_colours(avatar, posed)?);
    write_mesh(output, &mesh)
}

pub fn run(args: Args) -> Result<()> {
    let _timer = JobTimer::start("export");
    // Every argument is checked before the model loads.
    let glb = args.output.as_deref().map(is_glb).transpose()?;
    if let (Some(true), Some(output)) = (glb, &args.output)
        && !args.pose.is_rest()
    {
        bail!(
            "{}: a .glb is written at its bind pose (the canonical mesh); drop --named-pose/--motion, or write .obj/.ply",
            output.display()
        );
    }
    if let Some(path) =
        args.gaussians.as_deref().filter(|p| !p.extension().is_some_and(|e| e.eq_ignore_ascii_case("ply")))
    {
        bail!("{}: Gaussians are written as a 3DGS .ply; use a .ply extension", path.display());
    }
    let avatar = Avatar::load(&args.avatar, &Device::flex())?;
    let (pose, transl) = args.pose.resolve(avatar.canonical.num_joints())?;
    let posed = avatar.pose(&pose, transl)?;
    if let (Some(output), Some(glb)) = (&args.output, glb) {
        write_output(&avatar, &posed, args.pose.is_rest(), glb, output)?;
        tracing::info!("wrote {} ({} vertices)", output.display(), avatar.canonical.num_vertices());
    }
    if let Some(path) = &args.gaussians {
        let scene = export::gaussian_scene(&avatar, &posed.gaussians)?;
        scene.write_ply(path)?;
        tracing::info!("wrote {} ({} Gaussians, SH degree {})", path.display(), scene.len(), scene.sh_degree);
    }
    Ok(())
}
