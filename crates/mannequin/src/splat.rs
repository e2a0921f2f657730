//! `mannequin splat render` and `mannequin splat info`: render any 3D Gaussian splatting `.ply`
//! (INRIA layout) through a camera, or summarise one.
//!
//! The camera is a JSON file in the OpenCV convention (x right, y down, z forward, pixel centres
//! at +0.5):
//!
//! ```json
//! {
//!   "width": 540, "height": 540,
//!   "K": [[500, 0, 270], [0, 500, 270], [0, 0, 1]],
//!   "extrinsic": [[1, 0, 0, 0], [0, -1, 0, 1], [0, 0, -1, 2.5], [0, 0, 0, 1]],
//!   "near": 0.01, "far": 100,
//!   "background": [1, 1, 1]
//! }
//! ```
//!
//! `K` is the 3×3 intrinsic matrix in pixels and `extrinsic` the 4×4 world→camera transform,
//! both row-major. `near` (default 0.01), `far` (default 1e10) and `background` (RGB in
//! `[0, 1]`, default black) are optional.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use mannequin_splat::{Camera, RenderOptions, SplatScene, render};
use serde_json::{Value, json};

use crate::progress::JobTimer;

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

/// A camera JSON file, with its background colour.
pub fn read_camera(path: &Path) -> anyhow::Result<(Camera, Vec<f64>)> {
    let text = std::fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
    let v: Value =
        serde_json::from_str(&text).with_context(|| format!("{}: not valid JSON", path.display()))?;
    let field = |k: &str| v.get(k).with_context(|| format!("{}: missing field '{k}'", path.display()));
    let number = |k: &str, x: &Value| {
        x.as_f64().with_context(|| format!("{}: field '{k}' must hold numbers, found {x}", path.display()))
    };
    let size = |k: &str| -> anyhow::Result<usize> {
        let x = field(k)?;
        x.as_u64()
            .map(|n| n as usize)
            .with_context(|| format!("{}: '{k}' must be a whole number, found {x}", path.display()))
    };
    let matrix = |k: &str, rows: usize, cols: usize| -> anyhow::Result<Vec<f64>> {
        let m = field(k)?;
        let bad = || format!("{}: '{k}' must be a {rows}×{cols} array of rows", path.display());
        let rs = m.as_array().with_context(bad)?;
        if rs.len() != rows {
            bail!(bad());
        }
        let mut out = Vec::with_capacity(rows * cols);
        for r in rs {
            let r = r.as_array().with_context(bad)?;
            if r.len() != cols {
                bail!(bad());
            }
            for x in r {
                out.push(number(k, x)?);
            }
        }
        Ok(out)
    };
    let optional = |k: &str, default: f64| v.get(k).map_or(Ok(default), |x| number(k, x));
    let (k, e) = (matrix("K", 3, 3)?, matrix("extrinsic", 4, 4)?);
    let camera = Camera {
        width: size("width")?,
        height: size("height")?,
        intrinsic: std::array::from_fn(|i| std::array::from_fn(|j| k[3 * i + j])),
        extrinsic: std::array::from_fn(|i| std::array::from_fn(|j| e[4 * i + j])),
        near: optional("near", 0.01)?,
        far: optional("far", 1e10)?,
    };
    let background = match v.get("background") {
        None => vec![0.0; 3],
        Some(b) => {
            let b = b
                .as_array()
                .with_context(|| format!("{}: 'background' must be [r, g, b]", path.display()))?;
            if b.len() != 3 {
                bail!("{}: 'background' must have 3 values, found {}", path.display(), b.len());
            }
            b.iter().map(|x| number("background", x)).collect::<anyhow::Result<_>>()?
        }
    };
    camera.validate().with_context(|| format!("{}", path.display()))?;
    Ok((camera, background))
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
    fn camera_json_is_read_and_bad_fields_are_named() {
        let dir = temp_dir("cam");
        let good = dir.join("good.json");
        std::fs::write(&good, CAMERA).unwrap();
        let (cam, bg) = read_camera(&good).unwrap();
        assert_eq!((cam.width, cam.height, cam.near, cam.far), (32, 24, 0.01, 1e10));
        assert_eq!(cam.extrinsic[2][3], 2.0);
        assert_eq!(bg, vec![0.0, 0.0, 1.0]);
        let bad = dir.join("bad.json");
        std::fs::write(
            &bad,
            CAMERA.replace("[[30, 0, 16], [0, 30, 12], [0, 0, 1]]", "[[30, 0, 16], [0, 30, 12]]"),
        )
        .unwrap();
        let e = format!("{:#}", read_camera(&bad).unwrap_err());
        assert!(e.contains("bad.json") && e.contains("'K' must be a 3×3"), "{e}");
        std::fs::write(&bad, CAMERA.replace("\"width\": 32", "\"width\": 0")).unwrap();
        let e = format!("{:#}", read_camera(&bad).unwrap_err());
        assert!(e.contains("empty"), "{e}");
        std::fs::remove_dir_all(dir).unwrap();
    }

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
