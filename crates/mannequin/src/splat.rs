//! `mannequin splat render` and `mannequin splat info`: render any 3D Gaussian splatting `.ply`
//! (INRIA layout) through a camera, or summarise one.
//!
//! The camera is a JSON file in the OpenCV convention; [`mannequin_splat::camera_json`] gives
//! its fields.

use std::path::{Path, PathBuf};

use anyhow::Context;
use mannequin_splat::{RenderOptions, SplatScene, read_camera, render};
use serde_json::{Value, json};

use mannequin_io::progress::JobTimer;

#[derive(clap::Args)]
pub struct Args {
    #[command(subcommand)]
    verb: Verb,
}

#[derive(clap::Subcommand)]
enum Verb {
    /// Render a 3DGS `.ply` through a camera to an 8-bit sRGB PNG.
    Render {
        /// Splat file in the INRIA layout (binary or ASCII).
        #[arg(long)]
        ply: PathBuf,
        /// Camera JSON (see `mannequin splat --help`).
        #[arg(long)]
        camera: PathBuf,
        /// Output PNG.
        #[arg(short, long)]
        output: PathBuf,
        /// Screen-filter variance in px² (3DGS viewers use 0.3; Mannequin avatars train with 0.1).
        #[arg(long, default_value_t = mannequin_splat::DILATION)]
        dilation: f64,
    },
    /// Print what a 3DGS `.ply` holds: count, SH degree, bounds, opacities and scales.
    Info {
        /// Splat file in the INRIA layout.
        file: PathBuf,
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
}

pub fn run(args: Args) -> anyhow::Result<()> {
    match args.verb {
        Verb::Render { ply, camera, output, dilation } => render_to_png(&ply, &camera, &output, dilation),
        Verb::Info { file, json } => info(&file, json),
    }
}

fn render_to_png(ply: &Path, camera: &Path, output: &Path, dilation: f64) -> anyhow::Result<()> {
    let _timer = JobTimer::start("splat render");
    let scene = SplatScene::read_ply(ply)?;
    let (camera, background) = read_camera(camera)?;
    let opts = RenderOptions { background, dilation, ..RenderOptions::default() };
    let out =
        render(&scene.gaussians(), &camera, &opts).with_context(|| format!("rendering {}", ply.display()))?;
    if out.skipped > 0 {
        tracing::warn!(
            "{}: skipped {} Gaussians with NaN or infinite parameters",
            ply.display(),
            out.skipped
        );
    }
    let npx = out.width * out.height;
    let image = mannequin_data::Image {
        width: out.width,
        height: out.height,
        pixels: (0..npx).map(|i| [out.image[i], out.image[npx + i], out.image[2 * npx + i]]).collect(),
    };
    image.write_png(output)?;
    tracing::info!(
        "{}: {} Gaussians → {}×{} {}",
        ply.display(),
        scene.len(),
        out.width,
        out.height,
        output.display()
    );
    Ok(())
}

/// Minimum, mean and maximum of the finite values (`null` when none is finite).
fn stats(values: impl Iterator<Item = f64>) -> Value {
    let (mut lo, mut hi, mut sum, mut n) = (f64::INFINITY, f64::NEG_INFINITY, 0.0, 0usize);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
        sum += v;
        n += 1;
    }
    if n == 0 { Value::Null } else { json!({"min": lo, "mean": sum / n as f64, "max": hi}) }
}

/// A `stats` value as a table cell.
fn stats_cell(v: &Value) -> String {
    match (v["min"].as_f64(), v["mean"].as_f64(), v["max"].as_f64()) {
        (Some(lo), Some(mean), Some(hi)) => format!("min {lo:.4}  mean {mean:.4}  max {hi:.4}"),
        _ => "none finite".into(),
    }
}

fn info(path: &Path, as_json: bool) -> anyhow::Result<()> {
    let s = SplatScene::read_ply(path)?;
    let n = s.len();
    let g = s.gaussians();
    let non_finite = (0..n)
        .filter(|&i| {
            let k = s.sh.len() / n.max(1);
            s.means[3 * i..3 * i + 3]
                .iter()
                .chain(&s.scales[3 * i..3 * i + 3])
                .chain(&s.quaternions[4 * i..4 * i + 4])
                .chain(&s.sh[k * i..k * (i + 1)])
                .chain(std::iter::once(&s.opacities[i]))
                .any(|v| !v.is_finite())
        })
        .count();
    let axis = |k: usize| stats(s.means.iter().skip(k).step_by(3).map(|&v| v as f64));
    let norms = s.quaternions.chunks_exact(4).map(|q| q.iter().map(|v| (v * v) as f64).sum::<f64>().sqrt());
    let facts = json!({
        "file": path.display().to_string(),
        "gaussians": n,
        "sh_degree": s.sh_degree,
        "channels": g.channels(),
        "non_finite": non_finite,
        "mean_x": axis(0),
        "mean_y": axis(1),
        "mean_z": axis(2),
        "opacity": stats(s.opacities.iter().map(|&v| v as f64)),
        "scale": stats(s.scales.iter().map(|&v| v as f64)),
        "quaternion_norm": stats(norms),
    });
    if as_json {
        println!("{}", serde_json::to_string_pretty(&facts)?);
        return Ok(());
    }
    println!("{}", path.display());
    println!("  Gaussians       {n}");
    println!("  SH degree       {} ({} channels)", s.sh_degree, g.channels());
    println!("  non-finite      {non_finite}");
    for name in ["x", "y", "z"] {
        println!("  mean {name}          {}", stats_cell(&facts[format!("mean_{name}")]));
    }
    println!("  opacity         {}", stats_cell(&facts["opacity"]));
    println!("  scale (σ, m)    {}", stats_cell(&facts["scale"]));
    println!("  |quaternion|    {}", stats_cell(&facts["quaternion_norm"]));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp_dir(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("mq-cli-splat-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    const CAMERA: &str = r#"{"width": 32, "height": 24, "K": [[30, 0, 16], [0, 30, 12], [0, 0, 1]],
        "extrinsic": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 2], [0, 0, 0, 1]], "background": [0, 0, 1]}"#;

    #[test]
    fn render_writes_a_png_with_the_background_where_nothing_is_drawn() {
        let dir = temp_dir("render");
        let scene = SplatScene {
            means: vec![0.0, 0.0, 0.0],
            quaternions: vec![1.0, 0.0, 0.0, 0.0],
            scales: vec![0.1, 0.1, 0.1],
            opacities: vec![0.95],
            sh_degree: 0,
            // DC coefficient giving red: 0.5 + 0.2821·c.
            sh: vec![1.7, -1.8, -1.8],
        };
        let (ply, cam, png) = (dir.join("s.ply"), dir.join("c.json"), dir.join("o.png"));
        scene.write_ply(&ply).unwrap();
        std::fs::write(&cam, CAMERA).unwrap();
        run(Args { verb: Verb::Render { ply, camera: cam, output: png.clone(), dilation: 0.3 } }).unwrap();
        let img = mannequin_data::Image::read_png(&png).unwrap();
        assert_eq!((img.width, img.height), (32, 24));
        assert_eq!(img.at(0, 0), [0.0, 0.0, 1.0]);
        let centre = img.at(16, 12);
        // Alpha about 0.86 half a pixel from the mean: mostly red over the blue background.
        assert!(centre[0] > 0.8 && centre[1] < 0.05 && centre[2] < 0.2, "{centre:?}");
        std::fs::remove_dir_all(dir).unwrap();
    }
}
