//! `mannequin export`: a trained avatar as files other tools open: its personalised mesh
//! (canonical or posed `.obj`/`.ply`), a skinned `.glb` with per-vertex colour baked from the
//! Gaussians, and its Gaussians at any pose as a 3DGS `.ply`.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow, bail};
use burn::tensor::Device;
use mannequin_avatar::params::host_rows;
use mannequin_avatar::{Avatar, Posed, export};
use mannequin_body::Motion;
use mannequin_io::progress::JobTimer;
use mannequin_mesh::gltf::scene_glb_bytes;
use mannequin_mesh::{TriMesh, write_mesh};

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

/// One file of an export, made whole in memory and checked before any file is written, so an
/// export that fails writes none.
enum Made {
    /// An `.obj` or `.ply` mesh, already validated.
    Mesh(TriMesh),
    Bytes(Vec<u8>),
}

/// The mesh files: a skinned `.glb` at the bind pose, or `.obj`/`.ply` at the pose (V_s exactly
/// when `canonical`) with a file per garment layer beside it; each with vertex colour baked from
/// the Gaussians.
fn mesh_files(
    avatar: &Avatar,
    posed: &Posed,
    canonical: bool,
    glb: Option<Option<&Motion>>,
    output: &Path,
) -> Result<Vec<(PathBuf, Made)>> {
    if let Some(motion) = glb {
        let (body, layers) = export::skinned_layers(avatar, posed)?;
        let animation = motion.map(|m| avatar.animation(m)).transpose()?;
        let bytes = scene_glb_bytes(output, &body, &layers, animation.as_ref(), &[])?;
        return Ok(vec![(output.to_path_buf(), Made::Bytes(bytes))]);
    }
    let vertices = if canonical { &posed.personalised } else { &posed.vertices };
    let mut mesh = TriMesh::new(host_rows(vertices.clone()), avatar.canonical.faces.clone());
    mesh.colors = Some(export::vertex_colours(avatar, posed)?);
    // A layer is part of the mesh: valid if the whole is.
    mesh.validate().map_err(|e| anyhow!("{}: {e}", output.display()))?;
    let layers = avatar.canonical.garment_names().iter().map(|name| {
        let part = avatar.canonical.layer_mesh(name, &mesh).expect("a layer the canonical mesh names");
        (layer_path(output, name), Made::Mesh(part))
    });
    let layers: Vec<_> = layers.collect();
    Ok([(output.to_path_buf(), Made::Mesh(mesh))].into_iter().chain(layers).collect())
}

/// Where a layer of `output` goes: `<stem>.<layer>.<extension>` beside it.
fn layer_path(output: &Path, layer: &str) -> PathBuf {
    let stem = output.file_stem().map_or_else(|| "mesh".into(), |s| s.to_string_lossy().into_owned());
    let extension = output.extension().map_or_else(String::new, |e| format!(".{}", e.to_string_lossy()));
    output.with_file_name(format!("{stem}.{layer}{extension}"))
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
        files = mesh_files(&avatar, &posed, args.pose.is_rest(), glb.then_some(motion.as_ref()), output)?;
    }
    let writing = |path: &Path| format!("writing {}", path.display());
    if let Some(path) = &args.gaussians {
        let scene = export::gaussian_scene(&avatar, &posed.gaussians)?;
        files.push((path.clone(), Made::Bytes(scene.ply_bytes(&[]).with_context(|| writing(path))?)));
    }
    if let Some(path) = &args.skinned_gaussians {
        let bytes = export::skinned_gaussians_ply(&avatar, &avatar.canonical_pose()?)
            .with_context(|| writing(path))?;
        files.push((path.clone(), Made::Bytes(bytes)));
    }
    for (path, made) in files {
        match made {
            Made::Mesh(mesh) => write_mesh(&path, &mesh)?,
            Made::Bytes(bytes) => {
                mannequin_io::write_atomic(&path, &bytes).with_context(|| writing(&path))?
            }
        }
        tracing::info!("wrote {}", path.display());
    }
    Ok(())
}
