//! `mannequin demo`: the README's main job on the embedded default body. It poses the body in
//! the named poses, writes a procedural walk as AMASS `.npz`, and exports that walk as a skinned,
//! animated `.glb`, all under one folder, with one progress display.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args as ClapArgs;
use mannequin_body::{BodyModel, Motion, POSE_NAMES, forward, named_pose, skeletal_animation, skinned_body};

use crate::body::write_mesh;
use crate::progress::{JobTimer, bar};

#[derive(ClapArgs)]
pub struct Args {
    /// Output folder.
    #[arg(long, default_value = "out/demo")]
    out: PathBuf,
    /// Shape coefficients of the default body, comma-separated.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true, default_value = "0")]
    betas: Vec<f32>,
}

pub fn run(args: Args) -> Result<()> {
    let _timer = JobTimer::start("demo");
    let model = BodyModel::default_body();
    let progress = bar(POSE_NAMES.len() as u64 + 2, "demo");
    for name in POSE_NAMES {
        let posed = forward(&model, &args.betas, &named_pose(name)?, &[0.0; 3])?;
        let mut mesh = model.template_mesh();
        mesh.positions = posed.frame_vertices(0).chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
        write_mesh(&args.out.join("poses").join(format!("{name}.obj")), &mesh)?;
        progress.inc(1);
    }
    let walk = Motion::walk_cycle(4.0, 30.0);
    let walk_path = args.out.join("walk.npz");
    walk.write_amass(&walk_path)?;
    progress.inc(1);
    let glb = args.out.join("walk.glb");
    let animation = skeletal_animation(&model, &walk.poses_for(&model)?, &walk.trans, walk.fps)?;
    mannequin_mesh::gltf::write_glb(&glb, &skinned_body(&model, &args.betas)?, Some(&animation))?;
    progress.finish_and_clear();
    tracing::info!(
        "wrote {}/poses/*.obj ({} poses), {} and {}",
        args.out.display(),
        POSE_NAMES.len(),
        walk_path.display(),
        glb.display()
    );
    Ok(())
}
