//! `mannequin garment fit --data DIR --category C --out G`: one garment reconstructed from a
//! dataset's label maps and normal maps (NGD, issue 20; `mannequin_garment::ngd`). The category's
//! template, carried to the dataset's body shape with its skinning weights (GRBF), is the base.
//! Writes the fitted garment at rest, and `fit.json`: the mask IoU of every training frame before
//! and after, the losses, where the time went, and, where the dataset has the garment's
//! ground-truth meshes, Chamfer distance and normal consistency before and after on training
//! frames and on the held-out test frames.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use mannequin_data::metrics::geometry::{GeometryMetrics, geometry_metrics};
use mannequin_data::{Dataset, Split, layout};
use mannequin_garment::ngd::{
    DynamicSettings, FramePose, Reconstruction, RemeshSchedule, Settings, Target, TrainingFrame,
};
use mannequin_garment::{Category, Dressed};
use mannequin_mesh::{MorphSequence, TriMesh};

use mannequin_body::load_body;
use mannequin_garment::{load_or_make, write_layered_scene};
use mannequin_io::progress::{JobTimer, bar};

/// Below this mean mask IoU over the first pass through the frames, the category is probably not
/// the garment in the label maps (the right template starts near 0.7).
const MISMATCH_IOU: f64 = 0.5;
/// The normal loss's weight where the dataset has normal maps.
const DEFAULT_NORMAL_WEIGHT: f64 = 2.0;
/// Frames evaluated against the ground truth, at most, per split.
const EVALUATED_FRAMES: usize = 12;
/// Surface samples per mesh for Chamfer and normal consistency.
const EVALUATION_SAMPLES: usize = 20_000;

#[derive(clap::Args)]
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
    ngd: NgdArgs,
}

/// How a garment is reconstructed; `mannequin train --garments` fits with the defaults.
#[derive(clap::Args, Clone)]
pub struct NgdArgs {
    /// The base template's size.
    #[arg(long, default_value = "M")]
    size: String,
    /// Optimisation steps (one training frame each).
    #[arg(long, default_value_t = 400)]
    pub iters: usize,
    /// Adam's step size on the static Jacobian field.
    #[arg(long, default_value_t = 0.01)]
    rate: f64,
    /// The Jacobian regulariser's weight λ in λ Σ ‖M_t − I‖² (toward the base shape); 0 by
    /// default, since 1e-4 made every garment but the pants worse (docs/ngd.md).
    #[arg(long, default_value_t = 0.0)]
    regulariser: f64,
    /// NGD's vertex noise (Eqs. 11–12): each step's posed vertices move by γ N(0, 1) (1 − e/T)
    /// at step e of T, so early steps see the garment's overall shape; γ in metres (0: none).
    #[arg(long, default_value_t = 0.0)]
    noise: f64,
    /// The weight of the normal-map loss (Huber, on the garment's pixels) against the mask loss;
    /// 0 fits the masks alone. Without it: 2 where the dataset has normal maps, else 0.
    #[arg(long)]
    normal_weight: Option<f64>,
    /// The weight of 1 − SSIM between the rendered and the dataset's normal maps on the
    /// garment's pixels (with the normal loss); 0 by default, since it made the fit worse
    /// (docs/ngd.md).
    #[arg(long, default_value_t = 0.0)]
    ssim_weight: f64,
    /// NGD's dynamic field (§3.1): an MLP on the pose's first principal components adds a
    /// pose-dependent part to the Jacobians; 0 components: the static field alone.
    #[arg(long, default_value_t = 4)]
    pose_components: usize,
    /// Adam's step size on the dynamic field's network.
    #[arg(long, default_value_t = 1e-3)]
    network_rate: f64,
    /// Steps between NGD's adaptive remeshings (§3.2: the faces with the largest gradients are
    /// split, finer as the fit goes); 0: none.
    #[arg(long, default_value_t = 100)]
    remesh_every: usize,
    /// Images are read at 1/N of their size.
    #[arg(long, default_value_t = 2)]
    downscale: usize,
    /// Seeds the order the frames are visited in.
    #[arg(long, default_value_t = 0)]
    seed: u64,
}

impl NgdArgs {
    /// The defaults, as `garment fit` has them, with `seed`.
    pub fn defaults(seed: u64) -> Self {
        use clap::{Args, FromArgMatches};
        let matches = Self::augment_args(clap::Command::new("ngd")).get_matches_from(["ngd"]);
        let mut args = Self::from_arg_matches(&matches).expect("the defaults parse");
        args.seed = seed;
        args
    }
}

/// A reconstructed garment at rest on the dataset's body, with its skinning weights (V × J).
pub struct FittedGarment {
    pub category: String,
    pub positions: Vec<[f32; 3]>,
    pub faces: Vec<[u32; 3]>,
    pub weights: Vec<f32>,
}

pub fn fit(args: FitArgs) -> Result<()> {
    let _timer = JobTimer::start("garment fit");
    let label = args.label.as_deref().unwrap_or(&args.category);
    reconstruct(&args.data, &args.category, label, &args.body, &args.ngd, &args.out)?;
    Ok(())
}

/// Reconstructs the garment of `category` that `label` marks in the dataset at `data`, writing
/// `garment.obj`, `fit.json`, `fitted.glb` and the point cache into `out`.
pub fn reconstruct(
    data: &Path,
    category: &str,
    label_name: &str,
    body: &str,
    ngd: &NgdArgs,
    out: &Path,
) -> Result<FittedGarment> {
    let start = Instant::now();
    let dataset = Dataset::open(data, ngd.downscale)?;
    let legend = label_legend(data)?;
    let label = label_index(data, &legend, label_name)?;
    let outer = outer_labels(&legend, category)?;
    let model = load_body(body)?;
    let train = dataset.split("train")?;
    if train.frames.is_empty() {
        bail!("{}: the train split has no frames", data.display());
    }
    // The targets first: a broken label map is refused before the template is made (seconds).
    let frames = train
        .frames
        .iter()
        .enumerate()
        .map(|(k, &f)| {
            let camera = dataset.camera(f).clone();
            let target = Target::read(data, &camera, f, label, legend.len(), &outer)?;
            Ok(TrainingFrame { target, camera, pose: frame_pose(&train, k) })
        })
        .collect::<Result<Vec<_>>>()?;
    let (_, garment) = load_or_make(category, &model, body, &ngd.size)?;
    let dressed = Dressed::new(&garment, &model, &train.poses.betas)?;
    let has_normals = frames.iter().all(|f| f.target.normals.is_some());
    let normal_weight = match ngd.normal_weight {
        Some(w) if w > 0.0 && !has_normals => bail!(
            "{}: --normal-weight {w} needs normal maps ({}/normal_%04d.png) for every training frame",
            data.display(),
            layout::NORMALS
        ),
        Some(w) => w,
        None if has_normals => DEFAULT_NORMAL_WEIGHT,
        None => {
            tracing::info!(
                "{}: no normal maps for every training frame ({}/normal_%04d.png): fitting the label maps alone",
                data.display(),
                layout::NORMALS
            );
            0.0
        }
    };
    let settings = Settings {
        steps: ngd.iters,
        rate: ngd.rate,
        regulariser: ngd.regulariser,
        noise: ngd.noise,
        normal_weight,
        ssim_weight: if normal_weight > 0.0 { ngd.ssim_weight } else { 0.0 },
        dynamic: (ngd.pose_components > 0)
            .then_some(DynamicSettings { components: ngd.pose_components, rate: ngd.network_rate }),
        remesh: (ngd.remesh_every > 0)
            .then(|| RemeshSchedule { every: ngd.remesh_every, ..Default::default() }),
        seed: ngd.seed,
    };
    let poses: Vec<Vec<f32>> = frames.iter().map(|f| f.pose.pose.clone()).collect();
    let mut fit = Reconstruction::new(&dressed, settings, &poses)?;
    let evaluation = Evaluation::new(data, &dataset, category)?;
    let before = fit.mask_iou(&frames)?;
    let geometry_before = evaluation.measure(&fit)?;
    let progress = bar(ngd.iters as u64, "garment fit");
    let mut losses = Vec::with_capacity(ngd.iters);
    let mut first_pass = Vec::new();
    for _ in 0..ngd.iters {
        let report = fit.step(&frames)?;
        losses.push(report.losses);
        if first_pass.len() < frames.len() {
            first_pass.push(report.mask_iou);
            if first_pass.len() == frames.len() && mean(&first_pass) < MISMATCH_IOU {
                progress.suspend(|| {
                    tracing::warn!(
                        "the {} overlaps its label maps by a mean mask IoU of {:.2} over the first pass through the \
                         frames (below {MISMATCH_IOU}): the label '{label_name}' may not mark a garment of category {}",
                        category,
                        mean(&first_pass),
                        category
                    )
                });
            }
        }
        progress.inc(1);
    }
    progress.finish();
    let after = fit.mask_iou(&frames)?;
    let geometry_after = evaluation.measure(&fit)?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    // The template's UVs hold while the topology is the template's.
    let uv = garment.mesh.uv.clone().filter(|_| fit.faces().len() == garment.mesh.faces.len());
    let mesh = TriMesh { positions: fit.rest(), faces: fit.faces().to_vec(), uv, colors: None };
    mannequin_mesh::write_mesh(&out.join("garment.obj"), &mesh)?;
    let report = serde_json::json!({
        "category": category,
        "label": label_name,
        "settings": fit.settings(),
        "frames": train.frames,
        "faces": { "base": garment.mesh.faces.len(), "fitted": fit.faces().len() },
        "mask_iou_before": before,
        "mask_iou_after": after,
        "mean_mask_iou": { "before": mean(&before), "after": mean(&after) },
        "geometry": { "before": geometry_before, "after": geometry_after },
        "losses": losses,
        "regulariser": fit.regulariser(),
        "ms_per_step": fit.breakdown.per_step_ms(fit.steps_taken()),
        "seconds": start.elapsed().as_secs_f64(),
    });
    let path = out.join("fit.json");
    mannequin_io::write_atomic(&path, serde_json::to_string_pretty(&report)?.as_bytes())
        .with_context(|| format!("writing {}", path.display()))?;
    write_scene(out, &model, &train, &frames, &fit, category)?;
    let geometry = match (&geometry_before, &geometry_after) {
        (Some(b), Some(a)) => format!(
            "; against the ground truth on training frames, Chamfer {:.2} → {:.2} cm, normal consistency {:.3} → {:.3}",
            b.train.chamfer_cm, a.train.chamfer_cm, b.train.normal_consistency, a.train.normal_consistency
        ),
        _ => String::new(),
    };
    tracing::info!(
        "fitted the {} to {} frames: mask IoU {:.3} → {:.3}{geometry}; wrote {}",
        category,
        frames.len(),
        mean(&before),
        mean(&after),
        out.display()
    );
    Ok(FittedGarment {
        category: category.to_string(),
        positions: fit.rest(),
        faces: fit.faces().to_vec(),
        weights: fit.weights().to_vec(),
    })
}

/// The capture's frame rate as the scene plays it (the datasets do not record one).
const SCENE_FPS: f32 = 30.0;

/// `fitted.glb`: the skinned body playing the training frames' poses, with the fitted garment in
/// each (its dynamic field's shape for that pose, skinned) as morph targets in sync; and
/// `<category>.pc2`, the same frames as a Blender point cache. `mannequin view OUT` plays both.
fn write_scene(
    dir: &Path,
    model: &mannequin_body::BodyModel,
    train: &Split,
    frames: &[TrainingFrame],
    fit: &Reconstruction,
    category: &str,
) -> Result<()> {
    let posed: Vec<Vec<[f32; 3]>> =
        frames.iter().map(|f| Ok(fit.posed(&f.pose)?.positions)).collect::<Result<_>>()?;
    let mut mesh = TriMesh::new(posed[0].clone(), fit.faces().to_vec());
    mesh.colors = Some(vec![Category::named(category)?.colour(); mesh.vertex_count()]);
    let layer = MorphSequence { name: category.to_string(), mesh, frames: posed, fps: SCENE_FPS };
    let poses: Vec<f32> = frames.iter().flat_map(|f| f.pose.pose.clone()).collect();
    let trans: Vec<f32> = frames.iter().flat_map(|f| f.pose.transl).collect();
    Ok(write_layered_scene(
        &dir.join("fitted.glb"),
        model,
        &train.poses.betas,
        (&poses, &trans, SCENE_FPS),
        &[layer],
    )?)
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

fn frame_pose(split: &Split, k: usize) -> FramePose {
    FramePose { pose: split.poses.pose72(k), transl: split.poses.transl[k] }
}

/// The dataset's label names (`subject.json`'s `labels`), by index.
pub fn label_legend(root: &Path) -> Result<Vec<String>> {
    let path = root.join("subject.json");
    let text = std::fs::read_to_string(&path).with_context(|| {
        format!("{}: the dataset has no label legend (subject.json with \"labels\"); garment fit needs label maps", path.display())
    })?;
    let json: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("{}: not JSON", path.display()))?;
    Ok(json["labels"].as_array().into_iter().flatten().filter_map(|v| v.as_str().map(String::from)).collect())
}

fn label_index(root: &Path, legend: &[String], name: &str) -> Result<u8> {
    match legend.iter().position(|n| n == name) {
        Some(i) => Ok(i as u8),
        None => bail!("{}: labels: no '{name}' among {legend:?}", root.join("subject.json").display()),
    }
}

/// The labels of garments worn over one of `category`: upper-body garments over a lower-body one.
/// Where they show, the garment may be behind them, so those pixels say nothing about it.
fn outer_labels(legend: &[String], category: &str) -> Result<Vec<u8>> {
    if !Category::named(category)?.is_lower_body() {
        return Ok(Vec::new());
    }
    Ok(legend
        .iter()
        .enumerate()
        .filter(|(_, name)| Category::named(name).is_ok_and(|c| !c.is_lower_body()))
        .map(|(i, _)| i as u8)
        .collect())
}

/// The mean geometry metrics over evaluated frames of the training and test splits.
#[derive(serde::Serialize)]
struct SplitGeometry {
    train: GeometryMetrics,
    test: Option<GeometryMetrics>,
    frames: usize,
}

/// The frames whose ground-truth garment mesh the fit is compared with: up to
/// [`EVALUATED_FRAMES`] evenly spread through each split.
struct Evaluation {
    train: Vec<(FramePose, TriMesh)>,
    test: Vec<(FramePose, TriMesh)>,
}

impl Evaluation {
    fn new(root: &Path, dataset: &Dataset, category: &str) -> Result<Self> {
        let read = |name: &str| -> Result<Vec<(FramePose, TriMesh)>> {
            let Ok(split) = dataset.split(name) else { return Ok(Vec::new()) };
            let stride = split.frames.len().div_ceil(EVALUATED_FRAMES).max(1);
            let mut out = Vec::new();
            for k in (0..split.frames.len()).step_by(stride) {
                let path = layout::garment_mesh(root, category, split.frames[k]);
                if !path.exists() {
                    return Ok(Vec::new());
                }
                let mesh = mannequin_mesh::ply::read(&path)
                    .with_context(|| format!("reading {}", path.display()))?;
                out.push((frame_pose(&split, k), mesh.mesh));
            }
            Ok(out)
        };
        Ok(Self { train: read("train")?, test: read("test")? })
    }

    /// The fit's current metrics, or None without ground truth.
    fn measure(&self, fit: &Reconstruction) -> Result<Option<SplitGeometry>> {
        let over = |frames: &[(FramePose, TriMesh)]| -> Result<Option<GeometryMetrics>> {
            if frames.is_empty() {
                return Ok(None);
            }
            let mut sum = GeometryMetrics { chamfer_cm: 0.0, p2s_cm: 0.0, normal_consistency: 0.0 };
            for (i, (pose, truth)) in frames.iter().enumerate() {
                let m = geometry_metrics(&fit.posed(pose)?, truth, EVALUATION_SAMPLES, i as u64);
                sum.chamfer_cm += m.chamfer_cm / frames.len() as f64;
                sum.p2s_cm += m.p2s_cm / frames.len() as f64;
                sum.normal_consistency += m.normal_consistency / frames.len() as f64;
            }
            Ok(Some(sum))
        };
        let Some(train) = over(&self.train)? else { return Ok(None) };
        Ok(Some(SplitGeometry { train, test: over(&self.test)?, frames: self.train.len() + self.test.len() }))
    }
}
