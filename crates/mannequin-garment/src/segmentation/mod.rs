//! Garment labels from a dataset's images, person masks and body poses alone (issue 37;
//! `mannequin segment`, and `capture`, which runs it): no network, no truth. The fitted body,
//! drawn into each frame, says which part of the body each pixel of the person shows, and each
//! part allows a few classes (a hand is skin, a shin skin or the lower garment). Colour models
//! seeded from the parts every person shows the same way (face and hands skin, the crown hair,
//! chest the top, thighs the bottom, feet shoes) score the rest; a mean-field pass makes labels
//! follow the image's edges. The clip then votes on the body's surface, so each spot of the body
//! gets one answer over all the frames that see it, and a second labelling pass reads that vote.
//! The votes also decide the outfit (`--garments auto`).

mod body_parts;
mod class;
mod colour_model;
mod frame_view;
mod labelling;
mod outfit;
mod settings;

use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

use mannequin_body::smpl_joint::{L_HIP, L_KNEE};
use mannequin_body::{load_body, shape_body};
use mannequin_data::image::Mask;
use mannequin_data::labels::LabelMap;
use mannequin_data::maps::write_mask_npy;
use mannequin_data::{Dataset, layout};
use mannequin_io::progress::bar;
use mannequin_io::staging::StagedDir;
use mannequin_raster::hard::NO_FACE;
use rayon::prelude::*;
use serde::Serialize;

pub use body_parts::Part;
pub use class::{CLASSES, Class, Scores};
pub use outfit::{BODY_LABELS, Evidence, Outfit};
pub use settings::SegmentSettings;

use body_parts::vertex_parts;
use colour_model::ColourModel;
use frame_view::{FramePose, FrameView};
use labelling::{argmax, label};

use crate::ngd::NgdError;

/// How strongly the clip's vote on a spot of the body weighs in the second pass (log units per
/// unit of log share).
const VOTE_WEIGHT: f32 = 1.5;
/// Added to each class's share of a vertex's votes before the log: a class the clip never saw
/// there stays possible.
const VOTE_FLOOR: f32 = 0.05;
/// Pixels within this many of a seed pixel must seed the same class (the seed keeps off the
/// part's borders, where the fitted body may be off by a few pixels).
const SEED_MARGIN: usize = 3;
/// Second-pass colours are learnt from pixels whose posterior is at least this sure.
const SURE: f32 = 0.9;

/// What a segmentation decided and how it went.
#[derive(Debug, Clone, Serialize)]
pub struct Segmented {
    pub legend: Vec<String>,
    /// Whether the outfit was decided from the images (`auto`) rather than named.
    pub decided: bool,
    pub evidence: Evidence,
    pub frames: usize,
    pub seconds: f64,
}

/// Labels every frame of the dataset at `data` (posed with the body model `body`), writing
/// `labels/label_%04d.png` with `labels/segmentation.json`, `hands/hand_%04d.npy`, and the legend
/// into `subject.json`'s `labels`. Label maps already there are refused unless `replace`.
pub fn segment(
    data: &Path,
    body: &str,
    settings: &SegmentSettings,
    replace: bool,
) -> Result<Segmented, NgdError> {
    let start = Instant::now();
    settings.check()?;
    if !data.join(layout::MASKS).is_dir() {
        return Err(NgdError::file(
            data,
            format!(
                "no person masks ({}/mask_%04d.npy): segmenting needs them, as capture writes them",
                layout::MASKS
            ),
        ));
    }
    let labels_dir = data.join(layout::LABELS);
    if labels_dir.exists() && !replace {
        return Err(NgdError::file(
            &labels_dir,
            "the dataset has label maps already; pass --replace to overwrite them with the segmentation's",
        ));
    }
    let dataset = Dataset::open(data, 1)?;
    let (poses, betas) = frame_poses(&dataset)?;
    let model = load_body(body)?;
    let shaped = shape_body(&model, &betas)?;
    let rest: Vec<[f32; 3]> = shaped.vertices.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    let joints: Vec<[f32; 3]> = shaped.joints.iter().map(|j| j.to_array()).collect();
    let parts = vertex_parts(&model, &rest, &joints);
    let faces = &model.faces;
    let body = BodyParts {
        faces,
        part: faces.iter().map(|t| parts[t[0] as usize]).collect(),
        upper_thigh: faces
            .iter()
            .map(|t| {
                let p = rest[t[0] as usize];
                let mid_thigh = 0.5 * (joints[L_HIP][1] + joints[L_KNEE][1]);
                let thigh = matches!(parts[t[0] as usize], Part::Hip | Part::Thigh);
                (thigh && p[1] > mid_thigh).then_some(p[0] >= 0.0)
            })
            .collect(),
    };
    let face_part = |f: u32| body.part[f as usize];

    let progress = bar(3 * poses.len() as u64, "segment");
    // Each pass reads and draws its frames again (all three take 5–6 s for 120 frames at 540²)
    // rather than hold 120 frames of images, masks, face ids and barycentrics (about 1 GB).
    let view = |p: &PoseOfFrame| {
        let pose = FramePose { pose: &p.pose, transl: p.transl };
        let v = FrameView::new(&dataset, p.frame, &model, &shaped, &pose);
        progress.inc(1);
        v
    };

    // Pass 1: colour models from the parts' cores.
    let seeds = poses
        .par_iter()
        .map(|p| Ok::<_, NgdError>(seed_colours(&view(p)?, &|f| face_part(f).seed())))
        .try_reduce(empty_models, |mut a, b| {
            a.iter_mut().zip(&b).for_each(|(x, y)| x.merge(y));
            Ok(a)
        })?;
    let mut colours = seeds.clone();
    colours.iter_mut().for_each(ColourModel::finish);

    // Pass 2: labels from the parts' priors; the clip's votes on the body, surer colours.
    let part_prior: Vec<Scores> = parts.iter().map(|p| p.prior()).collect();
    let tally = poses
        .par_iter()
        .map(|p| {
            let v = view(p)?;
            Ok::<_, NgdError>(Tally::of(&v, &body, &part_prior, &colours))
        })
        .try_reduce(|| Tally::new(model.num_vertices()), |a, b| Ok(a.merge(b)))?;
    let mut colours: Vec<ColourModel> = tally.colours.clone();
    colours.iter_mut().zip(&seeds).for_each(|(c, s)| {
        c.merge(s);
        c.finish()
    });
    let evidence = tally.evidence(&parts);
    let (outfit, decided) = Outfit::choose(&settings.garments, &evidence)?;
    let shares = smoothed_shares(&tally.votes, faces);
    let vertex_prior: Vec<Scores> = part_prior
        .iter()
        .zip(&shares)
        .map(|(p, s)| std::array::from_fn(|c| p[c] + VOTE_WEIGHT * (s[c] + VOTE_FLOOR).ln()))
        .collect();

    // Pass 3: the labels, written.
    let stage_labels = StagedDir::new(data.join(".labels-staging"), labels_dir.clone())?;
    let stage_hands = StagedDir::new(data.join(".hands-staging"), data.join(layout::HANDS))?;
    for dir in [stage_labels.path(), stage_hands.path()] {
        std::fs::create_dir_all(dir)
            .map_err(|source| NgdError::CreateFolder { path: dir.to_path_buf(), source })?;
    }
    poses.par_iter().try_for_each(|p| {
        let v = view(p)?;
        let posterior = label(&v, faces, &vertex_prior, &colours);
        let n = v.width * v.height;
        let mut labels = vec![0u8; n];
        let mut hands = vec![false; n];
        for (i, q) in posterior.scores.iter().enumerate() {
            if let Some(q) = q {
                let class = Class::ALL[argmax(q)];
                labels[i] = outfit.label(class);
                hands[i] = class == Class::Skin && v.face[i] != NO_FACE && face_part(v.face[i]) == Part::Hand;
            }
        }
        let name = |path: std::path::PathBuf, dir: &Path| dir.join(path.file_name().unwrap_or_default());
        LabelMap { width: v.width, height: v.height, labels }
            .write_png(&name(layout::label(data, p.frame), stage_labels.path()))?;
        write_mask_npy(
            &name(layout::hand_mask(data, p.frame), stage_hands.path()),
            &Mask { width: v.width, height: v.height, values: hands },
        )?;
        Ok::<(), NgdError>(())
    })?;
    progress.finish();
    let done = Segmented {
        legend: outfit.legend(),
        decided,
        evidence,
        frames: poses.len(),
        seconds: start.elapsed().as_secs_f64(),
    };
    let record = serde_json::json!({ "garments": settings.garments, "result": &done });
    let path = stage_labels.path().join("segmentation.json");
    mannequin_io::write_atomic(&path, serde_json::to_string_pretty(&record)?.as_bytes())
        .map_err(|source| NgdError::Write { path, source })?;
    write_legend(data, &done.legend)?;
    stage_labels.keep()?;
    stage_hands.keep()?;
    Ok(done)
}

/// One frame to label and its body pose.
struct PoseOfFrame {
    frame: usize,
    pose: Vec<f32>,
    transl: [f32; 3],
}

/// Every frame of the dataset's splits with its pose, once each, in frame order, and the body's
/// shape (one for the whole capture).
fn frame_poses(dataset: &Dataset) -> Result<(Vec<PoseOfFrame>, Vec<f32>), NgdError> {
    let mut frames: BTreeMap<usize, PoseOfFrame> = BTreeMap::new();
    let mut betas = None;
    for name in dataset.splits.keys() {
        let split = dataset.split(name)?;
        for (k, &frame) in split.frames.iter().enumerate() {
            frames.entry(frame).or_insert_with(|| PoseOfFrame {
                frame,
                pose: split.poses.pose72(k),
                transl: split.poses.transl[k],
            });
        }
        if !split.frames.is_empty() {
            betas.get_or_insert(split.poses.betas);
        }
    }
    match betas {
        Some(betas) => Ok((frames.into_values().collect(), betas)),
        None => Err(NgdError::file(dataset.root.join(layout::SPLITS), "no split has frames to segment")),
    }
}

fn empty_models() -> Vec<ColourModel> {
    vec![ColourModel::default(); CLASSES]
}

/// The colours of the pixels well inside a seeding part.
fn seed_colours(v: &FrameView, seed_of_face: &dyn Fn(u32) -> Option<Class>) -> Vec<ColourModel> {
    let mut models = empty_models();
    let seed_at = |x: usize, y: usize| {
        let f = v.face[y * v.width + x];
        if f == NO_FACE { None } else { seed_of_face(f) }
    };
    let m = SEED_MARGIN;
    for y in m..v.height.saturating_sub(m) {
        for x in m..v.width.saturating_sub(m) {
            let Some(c) = seed_at(x, y) else { continue };
            let core = [(x - m, y), (x + m, y), (x, y - m), (x, y + m)]
                .iter()
                .all(|&(a, b)| seed_at(a, b) == Some(c));
            if core {
                models[c.index()].add(v.image.at(x, y), 1.0);
            }
        }
    }
    models
}

/// What the second pass gathers over the clip.
struct Tally {
    /// Per body vertex, the posterior mass its visible pixels gave each class.
    votes: Vec<[f64; CLASSES]>,
    /// Colours of the pixels the pass was sure of, per class.
    colours: Vec<ColourModel>,
    /// Rows across both thighs (where the body's thighs are apart) that show the lower garment,
    /// and those of them in which it is one unbroken run.
    rows_across_thighs: f64,
    rows_joined: f64,
}

impl Tally {
    fn new(vertices: usize) -> Self {
        Self {
            votes: vec![[0.0; CLASSES]; vertices],
            colours: empty_models(),
            rows_across_thighs: 0.0,
            rows_joined: 0.0,
        }
    }

    fn of(v: &FrameView, body: &BodyParts, prior: &[Scores], colours: &[ColourModel]) -> Self {
        let faces = body.faces;
        let mut t = Self::new(prior.len());
        let posterior = label(v, faces, prior, colours);
        let lower = |i: usize| posterior.scores[i].is_some_and(|q| argmax(&q) == Class::Lower.index());
        for row in rows_across_thighs(v, body) {
            let runs = row.clone().filter(|&i| lower(i) && (i == row.start || !lower(i - 1))).count();
            if runs > 0 {
                t.rows_across_thighs += 1.0;
                t.rows_joined += f64::from(u8::from(runs == 1));
            }
        }
        for (i, q) in posterior.scores.iter().enumerate() {
            let Some(q) = q else { continue };
            let best = argmax(q);
            if q[best] >= SURE {
                t.colours[best].add(v.image.pixels[i], 1.0);
            }
            let f = v.face[i];
            if f == NO_FACE {
                continue;
            }
            let b = v.barycentrics[i];
            for (k, &vertex) in faces[f as usize].iter().enumerate() {
                let votes = &mut t.votes[vertex as usize];
                votes.iter_mut().zip(q).for_each(|(a, &p)| *a += f64::from(b[k] * p));
            }
        }
        t
    }

    fn merge(mut self, other: Self) -> Self {
        self.votes
            .iter_mut()
            .zip(&other.votes)
            .for_each(|(a, b)| a.iter_mut().zip(b).for_each(|(x, y)| *x += y));
        self.colours.iter_mut().zip(&other.colours).for_each(|(a, b)| a.merge(b));
        self.rows_across_thighs += other.rows_across_thighs;
        self.rows_joined += other.rows_joined;
        self
    }

    fn evidence(&self, parts: &[Part]) -> Evidence {
        let share = |part: Part, of: Class, against: Class| {
            let (mut a, mut b) = (0.0, 0.0);
            for (votes, _) in self.votes.iter().zip(parts).filter(|(_, p)| **p == part) {
                a += votes[of.index()];
                b += votes[against.index()];
            }
            if a + b > 0.0 { a / (a + b) } else { 0.0 }
        };
        Evidence {
            colour_overlap: self.colours[Class::Upper.index()].overlap(&self.colours[Class::Lower.index()]),
            forearms_covered: share(Part::Forearm, Class::Upper, Class::Skin),
            shins_covered: share(Part::Shin, Class::Lower, Class::Skin),
            legs_joined: self.rows_joined / self.rows_across_thighs.max(1.0),
        }
    }
}

/// The body's faces with the part each belongs to, and for the upper half of each thigh, the side
/// (rest x ≥ 0 is the left).
struct BodyParts<'a> {
    faces: &'a [[u32; 3]],
    part: Vec<Part>,
    upper_thigh: Vec<Option<bool>>,
}

/// The rows' spans (pixel indices) across the upper halves of both thighs, in the rows where the
/// drawn body shows them apart: a skirt of any length joins them, trousers leave a gap.
fn rows_across_thighs(v: &FrameView, body: &BodyParts) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    for y in 0..v.height {
        let row = y * v.width..(y + 1) * v.width;
        let (mut left, mut right) = (Vec::new(), Vec::new());
        for i in row {
            let f = v.face[i];
            match body.upper_thigh.get(f as usize).copied().flatten() {
                Some(true) => left.push(i),
                Some(false) => right.push(i),
                None => {}
            }
        }
        let (Some(&l0), Some(&l1), Some(&r0), Some(&r1)) =
            (left.first(), left.last(), right.first(), right.last())
        else {
            continue;
        };
        let apart = (l1 + 1..r0).chain(r1 + 1..l0).any(|i| v.face[i] == NO_FACE);
        if apart {
            out.push(l0.min(r0)..l1.max(r1) + 1);
        }
    }
    out
}

/// Each vertex's share of its votes per class, averaged with its neighbours' twice (a spot the
/// clip saw little of takes its neighbours' answer); uniform where no frame saw it.
fn smoothed_shares(votes: &[[f64; CLASSES]], faces: &[[u32; 3]]) -> Vec<Scores> {
    let mut shares: Vec<[f64; CLASSES]> = votes
        .iter()
        .map(|v| {
            let total: f64 = v.iter().sum();
            if total > 1e-6 { v.map(|x| x / total) } else { [1.0 / CLASSES as f64; CLASSES] }
        })
        .collect();
    for _ in 0..2 {
        let mut sum = shares.clone();
        let mut count = vec![1.0; shares.len()];
        for tri in faces {
            for k in 0..3 {
                let (a, b) = (tri[k] as usize, tri[(k + 1) % 3] as usize);
                for (x, y) in [(a, b), (b, a)] {
                    let s = shares[y];
                    sum[x].iter_mut().zip(s).for_each(|(p, q)| *p += q);
                    count[x] += 1.0;
                }
            }
        }
        shares = sum.iter().zip(&count).map(|(s, &n)| s.map(|x| x / n)).collect();
    }
    shares.iter().map(|s| s.map(|x| x as f32)).collect()
}

/// Sets `subject.json`'s `labels` to `legend`, keeping the rest of the file (or making one).
fn write_legend(data: &Path, legend: &[String]) -> Result<(), NgdError> {
    let path = data.join("subject.json");
    let mut json = if path.exists() {
        let text = std::fs::read_to_string(&path)
            .map_err(|source| NgdError::NoLegend { path: path.clone(), source })?;
        serde_json::from_str(&text).map_err(|source| NgdError::NotJson { path: path.clone(), source })?
    } else {
        serde_json::json!({})
    };
    let Some(object) = json.as_object_mut() else {
        return Err(NgdError::file(&path, "not a JSON object"));
    };
    object.insert("labels".into(), serde_json::json!(legend));
    mannequin_io::write_atomic(&path, serde_json::to_string_pretty(&json)?.as_bytes())
        .map_err(|source| NgdError::Write { path, source })
}
