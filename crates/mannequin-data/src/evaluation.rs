//! Frame-by-frame comparison of a predicted folder with a ground-truth dataset folder.
//!
//! The frames scored are the ground truth's test frames, named by the caller: a prediction
//! missing for one of them is an error, and other files in the prediction folder (left by an
//! earlier run, say) are never scored. Each folder's images may be PNG or JPEG
//! (`images/image_NNNN.png` or `.jpg`). The ground truth is composited on the stated background
//! with its mask; the prediction is taken as rendered. Where both folders hold normal maps (`normals/`) or meshes (`meshes/`), normal and
//! geometry metrics are added, and
//! per garment where both hold its meshes (`meshes/garment_<name>_%04d.ply`). A ground truth at an integer multiple of the prediction's size
//! is box-downscaled to it first (PeopleSnapshot's 1080² against 540² renders).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use mannequin_mesh::{TriMesh, double_areas};
use serde::Serialize;

use crate::dataset::Dataset;
use crate::error::DataError;
use crate::frame_files::ImageFiles;
use crate::image::Image;
use crate::layout;
use crate::maps::{NormalMap, read_mask_npy};
use crate::metrics::geometry::{GeometryMetrics, geometry_metrics};
use crate::metrics::lpips::Lpips;
use crate::metrics::normal_error::normal_error;
use crate::metrics::{psnr::psnr, ssim::ssim};

pub use mannequin_io::limits::MAX_SURFACE_SAMPLES;

pub struct EvalOptions {
    pub background: [f32; 3],
    pub lpips: Option<Lpips>,
    /// Surface samples per mesh for the geometry metrics.
    pub samples: usize,
    /// Whether meshes both folders hold are compared: not where the prediction lives in another
    /// world frame than the truth (an avatar trained on `capture`'s poses and camera).
    pub compare_meshes: bool,
    pub seed: u64,
}

/// The scores of one frame; `None` where the inputs for a metric are missing.
#[derive(Debug, Clone, Serialize)]
pub struct FrameScores {
    pub frame: usize,
    pub psnr: f64,
    pub ssim: f64,
    pub lpips: Option<f64>,
    pub normal_mse_x1e3: Option<f64>,
    pub normal_angle_deg: Option<f64>,
    pub chamfer_cm: Option<f64>,
    pub p2s_cm: Option<f64>,
    pub normal_consistency: Option<f64>,
    /// Per garment that both folders have meshes of (`meshes/garment_<name>_%04d.ply`).
    pub garments: BTreeMap<String, GeometryMetrics>,
}

/// The poses a test set was rendered at: the dataset's as they are, or each fitted to its test
/// image with the avatar frozen (the peers' protocol for estimated poses), in so many steps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(tag = "mode", rename_all = "kebab-case")]
pub enum TestPoses {
    AsIs,
    Fit { steps: usize },
}

impl std::fmt::Display for TestPoses {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::AsIs => write!(f, "the dataset's poses as they are"),
            Self::Fit { steps } => write!(f, "each pose fitted to its image in {steps} steps"),
        }
    }
}

/// Means over frames (over the frames that have the metric, for the optional ones).
#[derive(Debug, Clone, Serialize)]
pub struct EvalSummary {
    pub pred: PathBuf,
    pub gt: PathBuf,
    pub background: [f32; 3],
    pub gt_downscale: usize,
    pub frames: usize,
    /// Whether the renders' poses were the dataset's or fitted to each test image first.
    pub test_poses: TestPoses,
    pub psnr: f64,
    pub ssim: f64,
    pub lpips: Option<f64>,
    pub normal_mse_x1e3: Option<f64>,
    pub normal_angle_deg: Option<f64>,
    pub chamfer_cm: Option<f64>,
    pub p2s_cm: Option<f64>,
    pub normal_consistency: Option<f64>,
    /// Per garment, over the frames that have it.
    pub garments: BTreeMap<String, GeometryMetrics>,
    pub per_frame: Vec<FrameScores>,
}

/// The mean of each garment's metrics over the frames that have it.
pub(crate) fn garment_means(frames: &[FrameScores]) -> BTreeMap<String, GeometryMetrics> {
    let mut sums: BTreeMap<String, (GeometryMetrics, usize)> = BTreeMap::new();
    for (name, m) in frames.iter().flat_map(|f| &f.garments) {
        let zero = GeometryMetrics { chamfer_cm: 0.0, p2s_cm: 0.0, normal_consistency: 0.0 };
        let (sum, n) = sums.entry(name.clone()).or_insert((zero, 0));
        sum.chamfer_cm += m.chamfer_cm;
        sum.p2s_cm += m.p2s_cm;
        sum.normal_consistency += m.normal_consistency;
        *n += 1;
    }
    sums.into_iter()
        .map(|(name, (s, n))| {
            let n = n as f64;
            let mean = GeometryMetrics {
                chamfer_cm: s.chamfer_cm / n,
                p2s_cm: s.p2s_cm / n,
                normal_consistency: s.normal_consistency / n,
            };
            (name, mean)
        })
        .collect()
}

/// The names of the garments whose meshes `dir` holds (`meshes/garment_<name>_%04d.ply`).
fn garment_names(dir: &Path) -> Result<BTreeSet<String>, DataError> {
    let meshes = dir.join(layout::MESHES);
    if !meshes.is_dir() {
        return Ok(BTreeSet::new());
    }
    let entries = std::fs::read_dir(&meshes).map_err(|e| DataError::os(&meshes, e))?;
    Ok(entries
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter_map(|f| {
            let stem = f.strip_prefix("garment_")?.strip_suffix(".ply")?;
            let (name, frame) = stem.rsplit_once('_')?;
            frame.parse::<usize>().ok().map(|_| name.to_string())
        })
        .collect())
}

/// The frames of `gt`'s test split: what a prediction folder for it is scored on.
pub fn test_frames(gt: &Path) -> Result<Vec<usize>, DataError> {
    let dataset = Dataset::open(gt, 1)?;
    let range = dataset.splits.get("test").ok_or_else(|| {
        DataError::file(gt, "has no 'test' split to score (see docs/dataset-format.md, splits.json)")
    })?;
    Ok(range.frames())
}

/// The integer factor from `pred`'s size to `gt`'s, or an error naming both files.
fn downscale_factor(
    pred: (usize, usize),
    gt: (usize, usize),
    pred_path: &Path,
    gt_path: &Path,
) -> Result<usize, DataError> {
    let f = gt.0 / pred.0.max(1);
    if f >= 1 && gt.0 == f * pred.0 && gt.1 == f * pred.1 {
        return Ok(f);
    }
    Err(DataError::file(
        pred_path,
        format!(
            "is {}×{} but {} is {}×{} (not an integer multiple)",
            pred.0,
            pred.1,
            gt_path.display(),
            gt.0,
            gt.1
        ),
    ))
}

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    s / n as f64
}

/// The mean of a metric over the frames that have it (`None` when none has).
pub(crate) fn mean_of(frames: &[FrameScores], get: impl Fn(&FrameScores) -> Option<f64>) -> Option<f64> {
    let v: Vec<f64> = frames.iter().filter_map(get).collect();
    (!v.is_empty()).then(|| mean(v.into_iter()))
}

/// The mesh at `path`, refused unless it has a surface to sample: the geometry metrics of a
/// mesh without area are undefined (NaN), not zero.
fn surface(path: &Path) -> Result<TriMesh, DataError> {
    let mesh = mannequin_mesh::ply::read(path)?.mesh;
    if double_areas(&mesh.positions, &mesh.faces).iter().sum::<f64>() > 0.0 {
        return Ok(mesh);
    }
    let reason = format!(
        "faces: expected a surface to score (a face of positive area), found {} faces on {} vertices",
        mesh.face_count(),
        mesh.vertex_count()
    );
    Err(DataError::file(path, reason))
}

/// Scores one frame; `images` are the prediction's and the ground truth's image files.
fn score_frame(
    (pred, gt): (&Path, &Path),
    images: &(ImageFiles, ImageFiles),
    garment_names: &BTreeSet<String>,
    frame: usize,
    opt: &EvalOptions,
) -> Result<(FrameScores, usize), DataError> {
    let (pred_path, gt_path) = (images.0.path(pred, frame), images.1.path(gt, frame));
    let p = Image::read(&pred_path)?;
    let g = Image::read(&gt_path)?;
    let factor = downscale_factor((p.width, p.height), (g.width, g.height), &pred_path, &gt_path)?;
    // A metric's complaint (sizes, too small for its window) is about the prediction's file.
    let on_pred = |e: DataError| DataError::file(&pred_path, e.to_string());
    let mask_path = layout::mask(gt, frame);
    let mask = read_mask_npy(&mask_path)?;
    if (mask.width, mask.height) != (g.width, g.height) {
        return Err(DataError::file(
            mask_path,
            format!("mask is {}×{}, image is {}×{}", mask.width, mask.height, g.width, g.height),
        ));
    }
    let mut g = g.composite(&mask, opt.background);
    if factor > 1 {
        g = g.downscale(factor);
    }
    let (psnr, ssim) = (psnr(&p, &g).map_err(on_pred)?, ssim(&p, &g).map_err(on_pred)?);
    let lpips = opt.lpips.as_ref().map(|m| m.distance(&p, &g)).transpose().map_err(on_pred)?;
    let (pn_path, gn_path) = (layout::normal(pred, frame), layout::normal(gt, frame));
    let normals = if pn_path.exists() && gn_path.exists() {
        let pn = NormalMap::read_png(&pn_path)?;
        let mut gn = NormalMap::read_png(&gn_path)?;
        if factor > 1 {
            gn = gn.downscale(factor);
        }
        Some(normal_error(&pn, &gn).map_err(|e| DataError::file(&pn_path, e.to_string()))?)
    } else {
        None
    };
    let mesh_metrics = |pm_path: PathBuf, gm_path: PathBuf| -> Result<Option<GeometryMetrics>, DataError> {
        if !(opt.compare_meshes && pm_path.exists() && gm_path.exists()) {
            return Ok(None);
        }
        let pm = surface(&pm_path)?;
        let gm = surface(&gm_path)?;
        Ok(Some(geometry_metrics(&pm, &gm, opt.samples, opt.seed)))
    };
    let geometry = mesh_metrics(layout::mesh(pred, frame), layout::mesh(gt, frame))?;
    let mut garments = BTreeMap::new();
    for name in garment_names {
        let paths = (layout::garment_mesh(pred, name, frame), layout::garment_mesh(gt, name, frame));
        if let Some(m) = mesh_metrics(paths.0, paths.1)? {
            garments.insert(name.clone(), m);
        }
    }
    Ok((
        FrameScores {
            frame,
            psnr,
            ssim,
            lpips,
            normal_mse_x1e3: normals.map(|n| n.mse_x1e3),
            normal_angle_deg: normals.map(|n| n.angular_deg),
            chamfer_cm: geometry.map(|m| m.chamfer_cm),
            p2s_cm: geometry.map(|m| m.p2s_cm),
            normal_consistency: geometry.map(|m| m.normal_consistency),
            garments,
        },
        factor,
    ))
}

/// Compares the prediction of each of `frames` with the ground truth; `on_frame` is called
/// after each (for progress display).
pub fn evaluate(
    pred: &Path,
    gt: &Path,
    frames: &[usize],
    opt: &EvalOptions,
    on_frame: &dyn Fn(&FrameScores),
) -> Result<EvalSummary, DataError> {
    if frames.is_empty() {
        return Err(DataError::file(gt, "no test frames to score"));
    }
    if !(1..=MAX_SURFACE_SAMPLES).contains(&opt.samples) {
        return Err(DataError::Invalid(format!(
            "surface samples per mesh: expected 1 to {MAX_SURFACE_SAMPLES}, found {}",
            opt.samples
        )));
    }
    let images = (ImageFiles::list(pred)?, ImageFiles::list(gt)?);
    let garments = garment_names(pred)?;
    let mut per_frame = Vec::with_capacity(frames.len());
    let mut gt_downscale = 1;
    for &f in frames {
        let (scores, factor) = score_frame((pred, gt), &images, &garments, f, opt)?;
        gt_downscale = factor;
        on_frame(&scores);
        per_frame.push(scores);
    }
    Ok(EvalSummary {
        pred: pred.to_path_buf(),
        gt: gt.to_path_buf(),
        background: opt.background,
        gt_downscale,
        frames: per_frame.len(),
        test_poses: TestPoses::AsIs,
        psnr: mean(per_frame.iter().map(|s| s.psnr)),
        ssim: mean(per_frame.iter().map(|s| s.ssim)),
        lpips: mean_of(&per_frame, |s| s.lpips),
        normal_mse_x1e3: mean_of(&per_frame, |s| s.normal_mse_x1e3),
        normal_angle_deg: mean_of(&per_frame, |s| s.normal_angle_deg),
        chamfer_cm: mean_of(&per_frame, |s| s.chamfer_cm),
        p2s_cm: mean_of(&per_frame, |s| s.p2s_cm),
        normal_consistency: mean_of(&per_frame, |s| s.normal_consistency),
        garments: garment_means(&per_frame),
        per_frame,
    })
}
