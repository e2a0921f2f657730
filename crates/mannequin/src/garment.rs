//! `mannequin garment make`: a garment template cut from a body's surface, remeshed and eased
//! (thesis §3.2), written as a `.garment` file; `garment fit` reconstructs one from a dataset's
//! label maps (NGD, `mannequin_garment::ngd`); `garment info` summarises one.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};
use clap::{Args, Subcommand};
use mannequin_cloth::Material;
use mannequin_garment::file::{read_garment, write_garment};
use mannequin_garment::ngd::{NgdSettings, reconstruct};
use mannequin_garment::{CATEGORY_NAMES, Category, Ease, Garment, SIZE_NAMES, make_garment};
use mannequin_io::progress::JobTimer;
use mannequin_mesh::write_obj;

use crate::shared::BodyArgs;
use mannequin_body::load_body;

#[derive(Subcommand)]
pub enum GarmentCommand {
    /// Make a garment template on a body (default: the embedded body at rest) and write it as
    /// a .garment file.
    Make(MakeArgs),
    /// Reconstruct one garment from a dataset's label maps (NGD: a Jacobian field on the
    /// category's template, fitted through the Poisson solve and the differentiable rasteriser):
    /// garment.obj and fit.json.
    Fit(FitArgs),
    /// Summarise a .garment file.
    Info {
        /// The .garment file.
        file: PathBuf,
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
}

#[derive(Args)]
pub struct MakeArgs {
    #[arg(long, value_parser = clap::builder::PossibleValuesParser::new(CATEGORY_NAMES))]
    category: String,
    /// Size: the ease at chest, waist and hips (M: 1.5 / 1.2 / 1.2 cm; each size up adds about 1 cm).
    #[arg(long, default_value = "M", value_parser = clap::builder::PossibleValuesParser::new(SIZE_NAMES))]
    size: String,
    /// Ease at the chest in metres, overriding the size's.
    #[arg(long)]
    ease_chest: Option<f32>,
    /// Ease at the waist in metres, overriding the size's.
    #[arg(long)]
    ease_waist: Option<f32>,
    /// Ease at the hips in metres, overriding the size's.
    #[arg(long)]
    ease_hips: Option<f32>,
    /// Hem height above the soles in metres (the garment's length); the category's by default.
    #[arg(long)]
    length: Option<f32>,
    /// Sleeve length from shoulder (0) to wrist (1); the category's by default.
    #[arg(long)]
    sleeve: Option<f32>,
    /// Target edge length of the triangles, metres (0.005 to 0.1).
    #[arg(long, default_value_t = 0.015)]
    edge_length: f32,
    /// Cloth material; the category's by default.
    #[arg(long, value_enum)]
    material: Option<Material>,
    #[command(flatten)]
    body: BodyArgs,
    /// The .garment file to write.
    #[arg(long)]
    out: PathBuf,
    /// Also write the template as an .obj (with UVs), to look at.
    #[arg(long)]
    obj: Option<PathBuf>,
}

#[derive(Args)]
pub struct FitArgs {
    /// The dataset: images' label maps (`labels/`) with their legend (`subject.json`), cameras and
    /// poses; normal maps (`normals/`) are used when present.
    #[arg(long)]
    data: PathBuf,
    /// The garment to reconstruct, by its category (pants, short-pants, shirt, tshirt,
    /// long-coat, skirt, dress): the base template and the label it is compared with.
    #[arg(long)]
    category: String,
    /// The label of the legend (`subject.json`'s `labels`) that marks this garment in the label
    /// maps, when it is not named after the category (a segmenter's "upper", say).
    #[arg(long)]
    label: Option<String>,
    /// The body model the dataset's poses are for.
    #[arg(long, default_value = "default")]
    body: String,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    ngd: NgdSettings,
}

pub fn run(cmd: GarmentCommand) -> Result<()> {
    match cmd {
        GarmentCommand::Make(args) => make(args),
        GarmentCommand::Fit(args) => fit(args),
        GarmentCommand::Info { file, json } => info(&file, json),
    }
}

fn make(args: MakeArgs) -> Result<()> {
    let category = Category::named(&args.category)?;
    let mut fit = Ease::size(&args.size)?;
    fit.ease_chest = args.ease_chest.unwrap_or(fit.ease_chest);
    fit.ease_waist = args.ease_waist.unwrap_or(fit.ease_waist);
    fit.ease_hips = args.ease_hips.unwrap_or(fit.ease_hips);
    fit.hem_height = args.length;
    fit.sleeve = args.sleeve;
    let material = args.material.unwrap_or_else(|| category.default_material());
    let model = load_body(&args.body.body)?;
    let start = Instant::now();
    let garment =
        make_garment(category, fit, args.edge_length, material, &model, &args.body.body, &args.body.betas)
            .with_context(|| format!("making a {}", category.name()))?;
    write_garment(&args.out, &garment).with_context(|| format!("writing {}", args.out.display()))?;
    if let Some(obj) = &args.obj {
        write_obj(obj, &garment.mesh).with_context(|| format!("writing {}", obj.display()))?;
    }
    tracing::info!("made in {:.1} s", start.elapsed().as_secs_f64());
    println!("{}", serde_json::to_string_pretty(&summary(&args.out, &garment))?);
    Ok(())
}

fn fit(args: FitArgs) -> Result<()> {
    let _timer = JobTimer::start("garment fit");
    let label = args.label.as_deref().unwrap_or(&args.category);
    reconstruct(&args.data, &args.category, label, &args.body, &args.ngd, &args.out)?;
    Ok(())
}

fn info(path: &Path, json: bool) -> Result<()> {
    let garment = read_garment(path)?;
    let s = summary(path, &garment);
    if json {
        println!("{}", serde_json::to_string_pretty(&s)?);
    } else {
        for (k, v) in s.as_object().into_iter().flatten() {
            println!("{k:<22} {v}");
        }
    }
    Ok(())
}

/// The facts a user checks about a template: size, triangle quality, boundaries.
fn summary(path: &Path, g: &Garment) -> serde_json::Value {
    let edges = mannequin_mesh::adjacency::edges(&g.mesh.faces);
    let lengths: Vec<f64> = edges
        .iter()
        .map(|&[a, b]| {
            let (p, q) = (g.mesh.positions[a as usize], g.mesh.positions[b as usize]);
            (0..3).map(|k| ((p[k] - q[k]) as f64).powi(2)).sum::<f64>().sqrt()
        })
        .collect();
    let mean = lengths.iter().sum::<f64>() / lengths.len().max(1) as f64;
    let sd = (lengths.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / lengths.len().max(1) as f64).sqrt();
    serde_json::json!({
        "file": path.display().to_string(),
        "category": g.recipe.category.name(),
        "material": g.recipe.material,
        "body": g.recipe.body,
        "vertices": g.vertex_count(),
        "faces": g.mesh.faces.len(),
        "mean_edge_m": mean,
        "edge_cv": sd / mean.max(1e-12),
        "boundary_loops": mannequin_mesh::adjacency::boundary_loops(&g.mesh.faces).len(),
        "fit": g.recipe.fit,
        "edge_length_m": g.recipe.edge_length,
    })
}
