//! `mannequin dress`: put garments on a body of any shape and play a motion (the run is
//! [`mannequin_garment::dress`]); prints the fit report, renders the frames and moves the
//! outputs into place together.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Result;
use clap::Args as ClapArgs;
use mannequin_body::load_body;
use mannequin_garment::dressing::RegionFit;
use mannequin_garment::{DressJob, DressSettings, Dressing, Wardrobe, dress};
use mannequin_io::progress::JobTimer;
use mannequin_io::staging::Staging;
use mannequin_splat::read_camera;

use crate::shared::{BodyArgs, Clip};

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
    #[command(flatten)]
    clip: Clip,
    /// Camera JSON (K, extrinsic, width, height) for the frames; default: a front view framing the clip.
    #[arg(long)]
    camera: Option<PathBuf>,
    #[command(flatten)]
    settings: DressSettings,
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
}

pub fn run(args: Args) -> Result<()> {
    let _timer = JobTimer::start("dress");
    let model = load_body(&args.body.body)?;
    let motion = args.clip.load()?;
    let camera = args.camera.as_deref().map(read_camera).transpose()?.map(|(camera, _)| camera);
    let job =
        DressJob { garments: &args.garments, performer: args.body.performer(&model, &args.clip, &motion) };
    let wardrobe = Wardrobe::load(&job, &args.settings)?;
    let mut dressing = dress(&wardrobe, &job, &args.settings, &args.out)?;
    if args.fit_report {
        print_fit_report(&dressing, &dressing.fit_report());
    }
    let metrics = dressing.measure();

    let start = Instant::now();
    let staging = Staging::new(&args.out)?;
    if !args.no_frames {
        render_frames(&dressing, camera.as_ref(), staging.dir(), motion.fps)?;
    }
    dressing.time("render", start);
    dressing.write(staging.dir(), &job, &metrics)?;
    staging.commit()?;
    dressing.finish();
    Ok(())
}

/// Each garment's regions, one row each, with its verdict.
fn print_fit_report(dressing: &Dressing, report: &[Vec<RegionFit>]) {
    for (w, regions) in dressing.worn.iter().zip(report) {
        println!("{} ({}):", w.name, w.material);
        println!(
            "  {:<16} {:>8} {:>10} {:>11} {:>15}  verdict",
            "region", "vertices", "min ease", "mean ease", "over the limit"
        );
        for r in regions {
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

/// The motion's frames rendered into `dir` ([`frames::render`]).
fn render_frames(
    dressing: &Dressing,
    camera: Option<&mannequin_splat::Camera>,
    dir: &std::path::Path,
    fps: f32,
) -> Result<()> {
    let meshes: Vec<(&[[u32; 3]], [f32; 3])> = dressing
        .worn
        .iter()
        .map(|w| (w.garment.mesh.faces.as_slice(), w.garment.recipe.category.colour()))
        .collect();
    let scene = frames::Scene { body_faces: &dressing.body_faces, garments: &meshes };
    let garment_frames: Vec<Vec<&[[f32; 3]]>> =
        dressing.motion_frames().map(|k| dressing.layers.iter().map(|l| l[k].as_slice()).collect()).collect();
    let body_motion: Vec<&[[f32; 3]]> =
        dressing.motion_frames().map(|k| dressing.body_frames[k].as_slice()).collect();
    frames::render(&scene, &body_motion, &garment_frames, camera, dir, fps)
}
