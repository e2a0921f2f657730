//! A capture's checkpoint: the run's record and what the capture has done so far that the
//! dataset does not already hold (the frames looked at, each kept frame's landmarks, the clip
//! fit's passes), so a stopped capture resumes where it stopped and a checkpoint of another run
//! is refused naming what changed.

use std::path::{Path, PathBuf};

use mannequin_data::Image;
use mannequin_data::layout;
use mannequin_data::maps::read_mask_npy;
use mannequin_io::run_record::{check_run, write_run};
use mannequin_io::{NpyArray, Npz, NpzWriter};

use crate::body_fit::FramePose;
use crate::clip_fit::ClipProgress;
use crate::crop::RotatedRect;
use crate::error::FitError;
use crate::pose_landmarker::{NUM_LANDMARKS, PoseLandmarks};

/// What changes a capture's result: a checkpoint of other settings is refused.
#[derive(serde::Serialize, serde::Deserialize, PartialEq)]
pub(crate) struct CaptureRun {
    /// Each source frame's file name and hash, or the video's.
    pub source: Vec<String>,
    pub fps: Option<f64>,
    pub max_frames: Option<usize>,
    pub body: String,
    pub focal: Option<f64>,
    /// The person followed (`--person`).
    pub person: Option<usize>,
}

/// What a capture has done so far: frames tracked (the kept ones written to the dataset as they
/// come), and the fit's passes.
#[derive(Default)]
pub(crate) struct Saved {
    /// Source frames looked at, kept or not.
    pub tracked: usize,
    pub kept: Vec<(PathBuf, Image)>,
    pub people: Vec<PoseLandmarks>,
    pub skipped: Vec<PathBuf>,
    pub fit: ClipProgress,
}

/// Stores what `saved` holds but the dataset already has (each kept frame's image and mask).
pub(crate) fn write_checkpoint(path: &Path, run: &CaptureRun, saved: &Saved) -> Result<(), FitError> {
    let mut w = NpzWriter::new();
    write_run(&mut w, run);
    let k = saved.people.len();
    let names = |files: &mut dyn Iterator<Item = &PathBuf>| -> String {
        serde_json::to_string(&files.map(|f| f.display().to_string()).collect::<Vec<_>>())
            .expect("a list of names serialises")
    };
    w.add("tracked", NpyArray::i64(vec![1], vec![saved.tracked as i64]));
    w.add("kept", NpyArray::text(&names(&mut saved.kept.iter().map(|(f, _)| f))));
    w.add("skipped", NpyArray::text(&names(&mut saved.skipped.iter())));
    let per_landmark = |f: &dyn Fn(&PoseLandmarks) -> Vec<f32>, width: usize| {
        NpyArray::f32(vec![k, NUM_LANDMARKS, width], saved.people.iter().flat_map(f).collect())
    };
    w.add("points", per_landmark(&|l| l.points.iter().flatten().copied().collect(), 3));
    w.add("world", per_landmark(&|l| l.world.iter().flatten().copied().collect(), 3));
    w.add("visibility", per_landmark(&|l| l.visibility.clone(), 1));
    w.add("presence", per_landmark(&|l| l.presence.clone(), 1));
    let rect = |r: &RotatedRect| [r.cx, r.cy, r.width, r.height, r.rotation];
    w.add("roi", NpyArray::f32(vec![k, 5], saved.people.iter().flat_map(|l| rect(&l.roi)).collect()));
    w.add(
        "next_roi",
        NpyArray::f32(vec![k, 5], saved.people.iter().flat_map(|l| rect(&l.next_roi)).collect()),
    );
    w.add("flag", NpyArray::f32(vec![k], saved.people.iter().map(|l| l.flag).collect()));
    let fit = &saved.fit;
    w.add("passes", NpyArray::i64(vec![1], vec![fit.passes as i64]));
    w.add("betas", NpyArray::f32(vec![fit.betas.len()], fit.betas.clone()));
    let poses = fit.frames.iter().flat_map(|f| f.pose.iter().copied()).collect();
    w.add("poses", NpyArray::f32(vec![fit.frames.len(), 72], poses));
    w.add(
        "transl",
        NpyArray::f32(vec![fit.frames.len(), 3], fit.frames.iter().flat_map(|f| f.transl).collect()),
    );
    w.write(path)?;
    Ok(())
}

/// What [`write_checkpoint`] stored, with the kept frames' images and masks read back from the
/// dataset `out`; refused when it is another run's.
pub(crate) fn read_checkpoint(path: &Path, run: &CaptureRun, out: &Path) -> Result<Saved, FitError> {
    let npz = Npz::read(path)?;
    check_run(&npz, run, &[]).map_err(FitError::Checkpoint)?;
    let count = |key: &str| -> Result<usize, FitError> {
        let v = npz.require(key)?.to_i64().and_then(|n| n.first().copied()).unwrap_or(-1);
        Ok(usize::try_from(v).map_err(|_| npz.field_error(key, "a count"))?)
    };
    let names = |key: &str| -> Result<Vec<PathBuf>, FitError> {
        let names: Vec<String> = serde_json::from_str(npz.text(key)?).map_err(|e| {
            FitError::within(format!("{}: {key}: expected a JSON list of file names", path.display()), e)
        })?;
        Ok(names.into_iter().map(PathBuf::from).collect())
    };
    let kept_files = names("kept")?;
    let k = kept_files.len();
    let read = |key: &str, shape: &[Option<usize>]| -> Result<Vec<f32>, FitError> {
        Ok(npz.f64_with_shape(key, shape)?.1.into_iter().map(|v| v as f32).collect())
    };
    let (n, k3) = (Some(NUM_LANDMARKS), Some(k));
    let points = read("points", &[k3, n, Some(3)])?;
    let world = read("world", &[k3, n, Some(3)])?;
    let visibility = read("visibility", &[k3, n, Some(1)])?;
    let presence = read("presence", &[k3, n, Some(1)])?;
    let roi = read("roi", &[k3, Some(5)])?;
    let next_roi = read("next_roi", &[k3, Some(5)])?;
    let flag = read("flag", &[k3])?;
    let rect = |r: &[f32]| RotatedRect { cx: r[0], cy: r[1], width: r[2], height: r[3], rotation: r[4] };
    let mut kept = Vec::with_capacity(k);
    let mut people = Vec::with_capacity(k);
    for (i, file) in kept_files.into_iter().enumerate() {
        let image = Image::read(&layout::image(out, i))?;
        let mask = read_mask_npy(&layout::mask(out, i))?;
        let triples = |v: &[f32]| {
            v[i * 3 * NUM_LANDMARKS..(i + 1) * 3 * NUM_LANDMARKS]
                .chunks_exact(3)
                .map(|p| [p[0], p[1], p[2]])
                .collect()
        };
        let singles = |v: &[f32]| v[i * NUM_LANDMARKS..(i + 1) * NUM_LANDMARKS].to_vec();
        people.push(PoseLandmarks {
            roi: rect(&roi[5 * i..5 * i + 5]),
            flag: flag[i],
            points: triples(&points),
            visibility: singles(&visibility),
            presence: singles(&presence),
            world: triples(&world),
            next_roi: rect(&next_roi[5 * i..5 * i + 5]),
            // The mask as the fit reads it: the person where the probability passed one half.
            mask: mask.values.iter().map(|&b| if b { 1.0 } else { 0.0 }).collect(),
        });
        kept.push((file, image));
    }
    let passes = count("passes")?;
    let betas = read("betas", &[None])?;
    let frames = if passes > 0 {
        let poses = read("poses", &[k3, Some(72)])?;
        let transl = read("transl", &[k3, Some(3)])?;
        (0..k)
            .map(|i| FramePose {
                pose: poses[72 * i..72 * i + 72].to_vec(),
                transl: [transl[3 * i], transl[3 * i + 1], transl[3 * i + 2]],
            })
            .collect()
    } else {
        Vec::new()
    };
    Ok(Saved {
        tracked: count("tracked")?,
        kept,
        people,
        skipped: names("skipped")?,
        fit: ClipProgress { passes, betas, frames },
    })
}
