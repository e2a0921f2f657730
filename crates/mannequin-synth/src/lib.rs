//! Synthetic subjects whose every answer is known: a textured person from the default body,
//! dressed in the garment library's garments simulated on the motion, captured like
//! PeopleSnapshot (one static camera, the person turning in an A-pose), with novel-view and
//! novel-pose test sets, written in the dataset layout with ground-truth normals, depth, meshes
//! (the whole and each garment), label maps and hand masks (see `docs/dataset-format.md`,
//! "Synthetic subjects").

pub mod error;
pub mod motion;
pub mod scene;
pub mod step;
pub mod subject;
pub mod texture;
pub mod wardrobe;

pub use error::SynthError;
pub use step::Step;

use std::path::Path;

use rayon::prelude::*;
use serde::Serialize;

use mannequin_body::BodyModel;
use mannequin_data::dataset::{Cameras, Frame};
use mannequin_data::poses::{BODY_POSE_LEN, Poses};
use mannequin_data::splits::{SplitRange, Splits};
use mannequin_data::writer::DatasetWriter;
use mannequin_data::{Camera, PoseOrigin};
use scene::{PosedSequence, Scene};
use subject::Subject;

/// The capture's frame rate: 120 frames turn the subject 1.25 times in 4 s.
const CAPTURE_FPS: f32 = 30.0;
/// The capture's turns.
const CAPTURE_TURNS: f32 = 1.25;
/// The most the subject turns between two poses the cloth simulator sees, in degrees, one
/// [`CAPTURE_FPS`] frame apart: twice the pace of the 120-frame capture. The body moves linearly
/// between poses, cutting the corner of its turn by 1 − cos(θ/2) of its radius (21 % at the 75°
/// of a 6-frame capture), so a sparse capture played at its own pace is a body that shrinks and
/// widens again, spun at 2,250°/s, and its garments' truth is of that. A sparser capture is
/// slower, with poses blended between its frames. (Before the solver took more substeps for a
/// fast body, the 75° capture left 770–872 vertices inside the body.)
const MAX_TURN_PER_POSE: f32 = 7.5;
/// Poses the cloth simulator sees per frame of the out-of-distribution motions (about 30 fps).
const NOVEL_SUBFRAMES: usize = 4;
/// What `origin.json` names as the dataset's writer.
const SYNTHESISED_BY: &str = "mannequin synth";

/// Sizes of the generated dataset.
#[derive(Debug, Clone, Serialize)]
pub struct SynthOptions {
    pub seed: u64,
    /// Output images are `size × size`.
    pub size: usize,
    /// Ground truth is rendered at `supersample × size` and box-filtered down.
    pub supersample: usize,
    /// Frames of the turning capture; the first `train_frames` are the training split and the
    /// rest the test split.
    pub capture_frames: usize,
    pub train_frames: usize,
    /// Training poses re-rendered from each novel camera.
    pub view_poses: usize,
    /// Frames of each out-of-distribution motion.
    pub motion_frames: usize,
    /// Cloth–cloth contacts in the simulation: each garment kept from crossing itself and the
    /// layers under it. Off, it runs about 2.5× faster but folds and layers may pass through
    /// each other.
    pub self_collision: bool,
}

impl Default for SynthOptions {
    fn default() -> Self {
        Self {
            seed: 0,
            size: 540,
            supersample: 2,
            capture_frames: 120,
            train_frames: 96,
            view_poses: 8,
            motion_frames: 8,
            self_collision: true,
        }
    }
}

impl SynthOptions {
    /// Frames written in all.
    pub fn total_frames(&self) -> usize {
        self.capture_frames + self.view_poses * scene::NOVEL_VIEWS + 4 * self.motion_frames
    }

    fn check(&self) -> Result<(), SynthError> {
        let ok = self.size >= 32
            && self.supersample >= 1
            && self.train_frames >= 1
            && self.capture_frames > self.train_frames
            && self.view_poses >= 1
            && self.view_poses <= self.train_frames
            && self.motion_frames >= 1;
        if ok {
            Ok(())
        } else {
            Err(SynthError::Invalid(format!(
                "synthetic capture needs size ≥ 32, supersample ≥ 1, 1 ≤ train frames < capture frames, \
                 1 ≤ view poses ≤ train frames and motion frames ≥ 1; got {self:?}"
            )))
        }
    }
}

/// What was generated, written to `subject.json`.
#[derive(Debug, Clone, Serialize)]
pub struct SynthSummary {
    pub options: SynthOptions,
    pub subject: Subject,
    pub vertices: usize,
    pub faces: usize,
    pub novel_view_cameras: Vec<&'static str>,
    pub novel_pose_motions: Vec<&'static str>,
    /// The label maps' values, by index.
    pub labels: Vec<&'static str>,
}

fn split_poses(betas: &[f32], poses72: &[f32], transl: &[[f32; 3]]) -> Poses {
    let mut b = betas.to_vec();
    b.resize(10.max(betas.len()), 0.0);
    Poses {
        betas: b,
        global_orient: poses72.chunks_exact(72).map(|p| [p[0], p[1], p[2]]).collect(),
        body_pose: poses72.chunks_exact(72).flat_map(|p| p[3..3 + BODY_POSE_LEN].to_vec()).collect(),
        transl: transl.to_vec(),
    }
}

fn one_split(name: &str, frames: usize) -> Splits {
    [(name.to_string(), SplitRange::new(0, frames - 1, 1))].into()
}

/// Renders and writes every frame of `seq` under `writer`, one camera per frame.
fn write_frames(
    scene: &Scene,
    seq: &PosedSequence,
    cameras: &[Camera],
    writer: &DatasetWriter,
    supersample: usize,
    on_step: &(dyn Fn(Step) + Sync),
) -> Result<(), SynthError> {
    (0..seq.len()).into_par_iter().try_for_each(|i| {
        let mesh = seq.mesh(scene, i);
        let r = scene.render(&mesh, &cameras[i], supersample);
        writer.write_frame(&Frame {
            index: i,
            image: r.color,
            mask: r.mask,
            normals: Some(r.normals),
            depth: Some(r.depth),
        })?;
        writer.write_labels(i, &r.labels, &r.hands)?;
        writer.write_mesh(i, &mesh)?;
        for (name, garment) in seq.garment_meshes(scene, i) {
            writer.write_garment_mesh(i, name, &garment)?;
        }
        on_step(Step::Written);
        Ok(())
    })
}

/// Generates the dataset under `out`: the capture at the root, `test/novel_view/` and
/// `test/novel_pose/` beside it, reporting each frame simulated and written to `on_step`.
/// Deterministic in `options`.
pub fn generate(
    model: &BodyModel,
    out: &Path,
    options: &SynthOptions,
    on_step: &(dyn Fn(Step) + Sync),
) -> Result<SynthSummary, SynthError> {
    options.check()?;
    on_step(Step::Planned(options.total_frames()));
    let subject = Subject::random(options.seed, model.num_betas().min(10));
    let scene = Scene::new(model, &subject)?;
    let mut rng =
        mannequin_io::rng::SplitMix64::new(options.seed.wrapping_mul(0x2545_F491_4F6C_DD1D) ^ 0xCA97);

    // The capture: one camera, the subject turning. The camera also frames the novel poses,
    // which are seen from it too.
    let capture_poses = motion::turning_a_pose(options.capture_frames, CAPTURE_TURNS, &mut rng)?;
    let turn = 360.0 * CAPTURE_TURNS / options.capture_frames as f32;
    let capture_subframes = (turn / MAX_TURN_PER_POSE).ceil() as usize;
    let (motion_names, novel_poses) = motion::novel_poses(options.motion_frames, &mut rng)?;
    // The capture and each motion simulated apart, side by side (much of the cloth solver
    // runs on one core), each motion from rest: one after another they would jump between motions.
    let contacts = options.self_collision;
    let clips: Vec<(&[f32], f32, usize)> =
        std::iter::once((&capture_poses[..], CAPTURE_FPS / capture_subframes as f32, capture_subframes))
            .chain(
                novel_poses
                    .chunks(72 * options.motion_frames)
                    .map(|clip| (clip, motion::novel_pose_fps(options.motion_frames), NOVEL_SUBFRAMES)),
            )
            .collect();
    let mut played = clips
        .into_par_iter()
        .map(|(poses, fps, subframes)| scene.pose(model, (poses, fps, subframes), contacts, on_step))
        .collect::<Result<Vec<_>, _>>()?
        .into_iter();
    let capture = played.next().expect("the capture is the first sequence");
    let mut novel = PosedSequence { vertices: Vec::new(), transl: Vec::new() };
    for clip in played {
        novel.vertices.extend(clip.vertices);
        novel.transl.extend(clip.transl);
    }
    let camera = scene.framing_camera(&[&capture, &novel], scene::TRAIN_VIEW, options.size);
    let root = DatasetWriter::new(out);
    root.write_cameras(&Cameras::Static(camera.clone()))?;
    let (train, test) = (options.train_frames, options.capture_frames);
    root.write_splits(
        &[
            ("train".to_string(), SplitRange::new(0, train - 1, 1)),
            ("val".to_string(), SplitRange::new(train, train, 1)),
            ("test".to_string(), SplitRange::new(train, test - 1, 1)),
        ]
        .into(),
    )?;
    root.write_origin(PoseOrigin::Truth, SYNTHESISED_BY)?;
    let all = split_poses(&subject.betas, &capture_poses, &capture.transl);
    root.write_poses("train", &all.select(&(0..train).collect::<Vec<_>>()))?;
    root.write_poses("val", &all.select(&[train]))?;
    root.write_poses("test", &all.select(&(train..test).collect::<Vec<_>>()))?;
    write_frames(
        &scene,
        &capture,
        &vec![camera.clone(); capture.len()],
        &root,
        options.supersample,
        on_step,
    )?;

    // Novel views: evenly spaced training poses from each of the novel cameras.
    let picks: Vec<usize> = (0..options.view_poses).map(|k| k * train / options.view_poses).collect();
    let view_frames: Vec<usize> = (0..scene::NOVEL_VIEWS).flat_map(|_| picks.iter().copied()).collect();
    let view_poses: Vec<f32> =
        view_frames.iter().flat_map(|&f| capture_poses[72 * f..72 * f + 72].to_vec()).collect();
    // The capture's frames, garments as they were then.
    let views = capture.select(&view_frames);
    let view_cameras: Vec<Camera> = (0..scene::NOVEL_VIEWS)
        .flat_map(|v| {
            let cam = scene.framing_camera(&[&views], scene::NOVEL_VIEW_SETUPS[v].1, options.size);
            vec![cam; picks.len()]
        })
        .collect();
    let nv = DatasetWriter::new(out.join("test/novel_view"));
    nv.write_cameras(&Cameras::PerFrame(view_cameras.clone()))?;
    nv.write_splits(&one_split("test", views.len()))?;
    nv.write_origin(PoseOrigin::Truth, SYNTHESISED_BY)?;
    nv.write_poses("test", &split_poses(&subject.betas, &view_poses, &views.transl))?;
    write_frames(&scene, &views, &view_cameras, &nv, options.supersample, on_step)?;

    // Novel poses: out-of-distribution motions from the training camera.
    let np = DatasetWriter::new(out.join("test/novel_pose"));
    np.write_cameras(&Cameras::Static(camera.clone()))?;
    np.write_splits(&one_split("test", novel.len()))?;
    np.write_origin(PoseOrigin::Truth, SYNTHESISED_BY)?;
    np.write_poses("test", &split_poses(&subject.betas, &novel_poses, &novel.transl))?;
    write_frames(&scene, &novel, &vec![camera; novel.len()], &np, options.supersample, on_step)?;

    scene.texture.write_png(&out.join("texture.png"))?;
    let mut motions: Vec<&'static str> = motion_names;
    motions.dedup();
    let summary = SynthSummary {
        options: options.clone(),
        subject,
        vertices: scene.positions.len(),
        faces: scene.faces.len(),
        novel_view_cameras: scene::NOVEL_VIEW_SETUPS.iter().map(|s| s.0).collect(),
        novel_pose_motions: motions,
        labels: scene.legend(),
    };
    let path = out.join("subject.json");
    let text = serde_json::to_string_pretty(&summary).map_err(|e| SynthError::file(&path, e.to_string()))?;
    mannequin_io::write_atomic(&path, text.as_bytes()).map_err(|e| SynthError::os(&path, e))?;
    Ok(summary)
}
