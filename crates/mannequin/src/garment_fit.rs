//! `mannequin garment fit --data DIR --category C --out G`: one garment reconstructed from a
//! dataset's label maps (NGD, issue 20; its first slice). The category's template, carried to the
//! dataset's body shape with its skinning weights (GRBF), is the base; a static per-face Jacobian
//! field deforms it through the Poisson solve; each step poses the garment in one training frame,
//! renders its mask (the body drawn too, so it hides what it hides) with the differentiable
//! rasteriser, and compares it with the frame's label map of that garment, hands left out
//! (NGD's Eq. 13). Writes the fitted garment at rest and `fit.json` (mask IoU per training frame,
//! before and after).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use mannequin_body::forward;
use mannequin_data::diff_raster::render;
use mannequin_data::labels::LabelMap;
use mannequin_data::maps::read_mask_npy;
use mannequin_data::rng::SplitMix64;
use mannequin_data::{Dataset, layout};
use mannequin_garment::Dressed;
use mannequin_garment::jacobian_fit::JacobianFieldFit;
use mannequin_mesh::TriMesh;

use crate::body::load_body;
use crate::dress::load_or_make;
use crate::progress::{JobTimer, bar};

/// How far inside its skin the body is drawn as an occluder, in metres.
const INSET: f32 = 0.015;

#[derive(clap::Args)]
pub struct FitArgs {
    /// The dataset: images' label maps (`labels/`) with their legend (`subject.json`), cameras and
    /// poses.
    #[arg(long)]
    data: PathBuf,
    /// The garment to reconstruct, by its category (pants, short-pants, shirt, tshirt,
    /// long-coat, skirt, dress): the base template and the label it is compared with.
    #[arg(long)]
    category: String,
    /// The base template's size.
    #[arg(long, default_value = "M")]
    size: String,
    /// Optimisation steps (one training frame each).
    #[arg(long, default_value_t = 300)]
    iters: usize,
    /// Adam's step size on the Jacobians.
    #[arg(long, default_value_t = 0.003)]
    rate: f64,
    /// The Jacobian regulariser's weight (toward the base shape).
    #[arg(long, default_value_t = 1e-4)]
    regulariser: f64,
    /// NGD's vertex noise (Eqs. 11–12): each step's posed vertices move by γ N(0, 1) (1 − e/T)
    /// at step e of T, so early steps see the garment's overall shape; γ in metres (0: none).
    #[arg(long, default_value_t = 0.0)]
    noise: f64,
    /// Images are read at 1/N of their size.
    #[arg(long, default_value_t = 2)]
    downscale: usize,
    /// Seeds the order the frames are visited in.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// The body model the dataset's poses are for.
    #[arg(long, default_value = "default")]
    body: String,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
}

/// One training frame's target: per pixel the garment's label (1 or 0), and whether it counts
/// (hands are left out).
struct Target {
    frame: usize,
    mask: Vec<f64>,
    counts: Vec<bool>,
}

pub fn fit(args: FitArgs) -> Result<()> {
    let _timer = JobTimer::start("garment fit");
    let start = Instant::now();
    let dataset = Dataset::open(&args.data, args.downscale)?;
    let label = garment_label(&args.data, &args.category)?;
    let model = load_body(&args.body)?;
    let train = dataset.split("train")?;
    if train.frames.is_empty() {
        bail!("{}: the train split has no frames", args.data.display());
    }
    let betas = train.poses.betas.clone();
    let (_, garment) = load_or_make(&args.category, &model, &args.body, &args.size)?;
    let dressed = Dressed::new(&garment, &model, &betas)?;
    let base = dressed.rest();
    let faces = garment.mesh.faces.clone();
    let mut field = JacobianFieldFit::new(&base, &faces)?;
    let targets =
        train.frames.iter().map(|&f| target(&args.data, &dataset, f, label)).collect::<Result<Vec<_>>>()?;
    let frame_of = |k: usize| (train.poses.pose72(k), train.poses.transl[k]);
    let body_faces = model.template_mesh().faces;
    let iou_of = |rest: &[[f32; 3]]| -> Result<Vec<f64>> {
        (0..targets.len())
            .map(|k| {
                let (pose, transl) = frame_of(k);
                let scene = Scene::new(&dressed, &model, &betas, &body_faces, rest, &pose, &transl)?;
                let image = scene.render(&dataset, targets[k].frame).image;
                Ok(iou(&image, &targets[k]))
            })
            .collect()
    };
    let before = iou_of(&base)?;
    let mut rng = SplitMix64::new(args.seed);
    let progress = bar(args.iters as u64, "garment fit");
    let mut losses = Vec::with_capacity(args.iters);
    for step in 0..args.iters {
        let k = rng.below(targets.len());
        let (pose, transl) = frame_of(k);
        let rest: Vec<[f32; 3]> = field.positions().iter().map(|p| p.map(|x| x as f32)).collect();
        let mut scene = Scene::new(&dressed, &model, &betas, &body_faces, &rest, &pose, &transl)?;
        let scale = args.noise * (1.0 - step as f64 / args.iters as f64);
        if scale > 0.0 {
            for p in scene.positions.iter_mut().take(scene.blends.len()) {
                p.iter_mut().for_each(|c| *c += (scale * rng.normal()) as f32);
            }
        }
        let rendered = scene.render(&dataset, targets[k].frame);
        let t = &targets[k];
        let n = t.counts.iter().filter(|c| **c).count().max(1) as f64;
        let mut loss = 0.0;
        let grad: Vec<[f64; 1]> = rendered
            .image
            .iter()
            .zip(&t.mask)
            .zip(&t.counts)
            .map(|((r, m), &c)| {
                if !c {
                    return [0.0];
                }
                loss += (r[0] - m).powi(2) / n;
                [2.0 * (r[0] - m) / n]
            })
            .collect();
        losses.push(loss);
        let d = rendered.backward(&grad, &scene.faces, &scene.attributes, dataset.camera(t.frame)).positions;
        // Back through the skinning to the rest positions: d rest = Mᵀ d posed (garment only).
        let d_rest: Vec<[f64; 3]> = scene
            .blends
            .iter()
            .zip(&d)
            .map(|(m, g)| {
                let g = glam::Vec3A::new(g[0] as f32, g[1] as f32, g[2] as f32);
                (m.transpose() * g).to_array().map(f64::from)
            })
            .collect();
        field.step(&d_rest, args.rate, args.regulariser);
        progress.inc(1);
    }
    progress.finish();
    let fitted: Vec<[f32; 3]> = field.positions().iter().map(|p| p.map(|x| x as f32)).collect();
    let after = iou_of(&fitted)?;
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    let mesh = TriMesh { positions: fitted, faces: faces.clone(), uv: garment.mesh.uv.clone(), colors: None };
    crate::body::write_mesh(&args.out.join("garment.obj"), &mesh)?;
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    let report = serde_json::json!({
        "category": args.category,
        "label": label,
        "frames": train.frames,
        "mask_iou_before": before,
        "mask_iou_after": after,
        "mean_mask_iou": { "before": mean(&before), "after": mean(&after) },
        "losses": losses,
        "regulariser": field.regulariser(args.regulariser),
        "seconds": start.elapsed().as_secs_f64(),
    });
    let path = args.out.join("fit.json");
    mannequin_io::write_atomic(&path, serde_json::to_string_pretty(&report)?.as_bytes())
        .with_context(|| format!("writing {}", path.display()))?;
    tracing::info!(
        "fitted the {} to {} frames' label maps: mask IoU {:.3} → {:.3}; wrote {}",
        args.category,
        targets.len(),
        mean(&before),
        mean(&after),
        args.out.display()
    );
    Ok(())
}

/// The label index of `category` in the dataset's legend (`subject.json`'s `labels`).
fn garment_label(root: &Path, category: &str) -> Result<u8> {
    let path = root.join("subject.json");
    let text = std::fs::read_to_string(&path).with_context(|| {
        format!("{}: the dataset has no label legend (subject.json with \"labels\"); garment fit needs label maps", path.display())
    })?;
    let json: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("{}: not JSON", path.display()))?;
    let names: Vec<&str> =
        json["labels"].as_array().into_iter().flatten().filter_map(|v| v.as_str()).collect();
    match names.iter().position(|n| *n == category) {
        Some(i) => Ok(i as u8),
        None => bail!("{}: labels: no '{category}' among {names:?}", path.display()),
    }
}

/// Frame `frame`'s label map as the garment's mask, with its hands left out.
fn target(root: &Path, dataset: &Dataset, frame: usize, label: u8) -> Result<Target> {
    let labels = LabelMap::read_png(&layout::label(root, frame))?;
    let camera = dataset.camera(frame);
    let factor = labels.width / camera.width;
    if factor == 0 || labels.width != factor * camera.width || labels.height != factor * camera.height {
        bail!(
            "{}: {}×{}, not a multiple of the cameras' {}×{}",
            layout::label(root, frame).display(),
            labels.width,
            labels.height,
            camera.width,
            camera.height
        );
    }
    let hands = read_mask_npy(&layout::hand_mask(root, frame)).ok();
    let (w, h) = (camera.width, camera.height);
    let mut mask = vec![0.0; w * h];
    let mut counts = vec![true; w * h];
    for y in 0..h {
        for x in 0..w {
            let mut share = 0.0;
            let mut hand = false;
            for dy in 0..factor {
                for dx in 0..factor {
                    let i = (y * factor + dy) * labels.width + x * factor + dx;
                    share += f64::from(u8::from(labels.labels[i] == label));
                    hand |= hands.as_ref().is_some_and(|m| m.values.get(i).copied().unwrap_or(false));
                }
            }
            mask[y * w + x] = share / (factor * factor) as f64;
            counts[y * w + x] = !hand;
        }
    }
    Ok(Target { frame, mask, counts })
}

/// The posed garment (attribute 1) and body (attribute 0) as one mesh, and the garment
/// vertices' blended skinning matrices.
struct Scene {
    positions: Vec<[f32; 3]>,
    faces: Vec<[u32; 3]>,
    attributes: Vec<[f64; 1]>,
    blends: Vec<glam::Mat3A>,
}

impl Scene {
    #[allow(clippy::too_many_arguments)]
    fn new(
        dressed: &Dressed,
        model: &mannequin_body::BodyModel,
        betas: &[f32],
        body_faces: &[[u32; 3]],
        rest: &[[f32; 3]],
        pose: &[f32],
        transl: &[f32; 3],
    ) -> Result<Self> {
        let skinned = dressed.skin(rest, pose, transl)?;
        let body = occluder(model, betas, body_faces, pose, transl)?;
        let g = skinned.len() as u32;
        let mut positions: Vec<[f32; 3]> = skinned.iter().map(|(p, _)| *p).collect();
        positions.extend(&body);
        let mut faces = dressed.garment().mesh.faces.clone();
        faces.extend(body_faces.iter().map(|f| f.map(|v| v + g)));
        let mut attributes = vec![[1.0]; g as usize];
        attributes.extend(std::iter::repeat_n([0.0], body.len()));
        Ok(Self { positions, faces, attributes, blends: skinned.iter().map(|(_, m)| *m).collect() })
    }

    fn render(&self, dataset: &Dataset, frame: usize) -> mannequin_data::diff_raster::Rendered<1> {
        render(&self.positions, &self.faces, &self.attributes, dataset.camera(frame), [0.0])
    }
}

/// The posed body as the garment's occluder, drawn `INSET` inside its skin: it hides the garment
/// where a limb passes in front, not where the garment, lying close, dips under the skin.
fn occluder(
    model: &mannequin_body::BodyModel,
    betas: &[f32],
    faces: &[[u32; 3]],
    pose: &[f32],
    transl: &[f32; 3],
) -> Result<Vec<[f32; 3]>> {
    let posed = forward(model, betas, pose, transl)?;
    let body: Vec<[f32; 3]> = posed.frame_vertices(0).chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    let normals = mannequin_mesh::normals::vertex_normals(&body, faces);
    Ok(body.iter().zip(&normals).map(|(p, n)| std::array::from_fn(|c| p[c] - INSET * n[c])).collect())
}

fn iou(image: &[[f64; 1]], target: &Target) -> f64 {
    let (mut inter, mut union) = (0.0, 0.0);
    for ((r, m), &c) in image.iter().zip(&target.mask).zip(&target.counts) {
        if !c {
            continue;
        }
        let (a, b) = (r[0] > 0.5, *m > 0.5);
        inter += f64::from(u8::from(a && b));
        union += f64::from(u8::from(a || b));
    }
    if union == 0.0 { 1.0 } else { inter / union }
}
