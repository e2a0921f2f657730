//! `mannequin export`: a trained avatar as files other tools open: its personalised mesh
//! (canonical or posed `.obj`/`.ply`), a skinned `.glb` with per-vertex colour baked from the
//! Gaussians, and its Gaussians at any pose as a 3DGS `.ply`.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use burn::tensor::Device;
use mannequin_avatar::Avatar;
use mannequin_avatar::export;
use mannequin_avatar::export_files::{ExportFile, MeshExport, mesh_files};
use mannequin_body::Motion;
use mannequin_io::progress::JobTimer;
use mannequin_mesh::write_mesh;

use crate::shared::PoseChoice;

#[derive(clap::Args)]
#[command(group = clap::ArgGroup::new("outputs").required(true).multiple(true).args(["output", "gaussians", "skinned_gaussians"]))]
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
    /// and weights; canonical pose only). Garment layers are nodes of their own in a `.glb`, and
    /// files of their own beside an `.obj`/`.ply` (`<stem>.<garment>.obj`).
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// The Gaussians at the pose as a 3DGS `.ply` in the INRIA layout, for splat viewers.
    #[arg(long)]
    gaussians: Option<PathBuf>,
    /// With a `.glb` output: this motion (AMASS or PeopleSnapshot `.npz`) as its animation.
    #[arg(long, requires = "output")]
    animation: Option<PathBuf>,
    /// The Gaussians at the canonical pose as a 3DGS `.ply` with their skinning (per-splat
    /// joint_0..3 and weight_0..3; docs/viewer.md), for viewers that animate splats with the
    /// `.glb`'s skeleton, such as `mannequin view`.
    #[arg(long)]
    skinned_gaussians: Option<PathBuf>,
}

/// Whether `-o` names a skinned `.glb` (else `.obj` or `.ply`; anything else is an error).
fn is_glb(path: &Path) -> Result<bool> {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("glb") => Ok(true),
        Some("obj" | "ply") => Ok(false),
        _ => bail!("{}: unknown mesh format; expected a .obj, .ply or .glb extension", path.display()),
    }
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
    if let (Some(path), Some(false)) = (&args.animation, glb) {
        bail!("{}: --animation goes into a .glb output", path.display());
    }
    for path in [&args.gaussians, &args.skinned_gaussians].into_iter().flatten() {
        if !path.extension().is_some_and(|e| e.eq_ignore_ascii_case("ply")) {
            bail!("{}: Gaussians are written as a 3DGS .ply; use a .ply extension", path.display());
        }
    }
    let motion = args.animation.as_deref().map(Motion::read).transpose()?;
    let avatar = Avatar::load(&args.avatar, &Device::flex())?;
    let (pose, transl) = args.pose.resolve(avatar.canonical.num_joints())?;
    let posed = avatar.pose(&pose, transl)?;
    let mut files = Vec::new();
    if let (Some(output), Some(glb)) = (&args.output, glb) {
        let how = if glb {
            MeshExport::Glb { motion: motion.as_ref() }
        } else {
            MeshExport::Posed { canonical: args.pose.is_rest() }
        };
        files = mesh_files(&avatar, &posed, how, output)?;
    }
    let writing = |path: &Path| format!("writing {}", path.display());
    if let Some(path) = &args.gaussians {
        let scene = export::gaussian_scene(&avatar, &posed.gaussians)?;
        files.push((path.clone(), ExportFile::Bytes(scene.ply_bytes(&[]).with_context(|| writing(path))?)));
    }
    if let Some(path) = &args.skinned_gaussians {
        let bytes = export::skinned_gaussians_ply(&avatar, &avatar.canonical_pose()?)
            .with_context(|| writing(path))?;
        files.push((path.clone(), ExportFile::Bytes(bytes)));
    }
    for (path, made) in files {
        match made {
            ExportFile::Mesh(mesh) => write_mesh(&path, &mesh)?,
            ExportFile::Bytes(bytes) => {
                mannequin_io::write_atomic(&path, &bytes).with_context(|| writing(&path))?
            }
        }
        tracing::info!("wrote {}", path.display());
    }
    Ok(())
}
