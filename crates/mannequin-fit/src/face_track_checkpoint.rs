//! A face track's checkpoint: the run's record and what the track has done so far (each frame's
//! face mesh, the video's shape, each frame's fit), so a stopped track resumes where it stopped
//! and a checkpoint of another run is refused naming what changed.

use std::path::{Path, PathBuf};

use glam::DVec3;
use mannequin_io::run_record::{check_run, write_run};
use mannequin_io::{NpyArray, Npz, NpzWriter};

use crate::crop::RotatedRect;
use crate::error::FitError;
use crate::face_fit::{FaceFit, FaceFitter};
use crate::face_landmarker::{FaceLandmarks, NUM_LANDMARKS};
use crate::output::create_dir;

/// What changes a track's result: a checkpoint of other settings is refused.
#[derive(serde::Serialize, serde::Deserialize, PartialEq)]
pub(crate) struct TrackRun {
    /// Each source frame's file name and hash, or the video's.
    pub source: Vec<String>,
    pub fps: Option<f64>,
    pub max_frames: Option<usize>,
    pub focal: Option<f64>,
}

/// What a track has done so far: per frame read, its face mesh (None: no face); the video's
/// shape once fitted; per frame fitted, its fit.
#[derive(Default)]
pub(crate) struct Done {
    pub landmarks: Vec<Option<FaceLandmarks>>,
    pub shape: Option<Vec<f32>>,
    pub fits: Vec<Option<FaceFit>>,
}

pub(crate) fn write_checkpoint(path: &Path, run: &TrackRun, done: &Done) -> Result<(), FitError> {
    let dir = path.parent().map_or_else(PathBuf::new, Path::to_path_buf);
    create_dir(&dir)?;
    let mut w = NpzWriter::new();
    write_run(&mut w, run);
    let found: Vec<&FaceLandmarks> = done.landmarks.iter().flatten().collect();
    let k = found.len();
    w.add(
        "found",
        NpyArray::i64(
            vec![done.landmarks.len()],
            done.landmarks.iter().map(|l| l.is_some() as i64).collect(),
        ),
    );
    w.add(
        "points",
        NpyArray::f32(
            vec![k, NUM_LANDMARKS, 3],
            found.iter().flat_map(|l| l.points.iter().flatten().copied()).collect(),
        ),
    );
    let rect = |r: &RotatedRect| [r.cx, r.cy, r.width, r.height, r.rotation];
    w.add("roi", NpyArray::f32(vec![k, 5], found.iter().flat_map(|l| rect(&l.roi)).collect()));
    w.add("flag", NpyArray::f32(vec![k], found.iter().map(|l| l.flag).collect()));
    if let Some(shape) = &done.shape {
        w.add("shape", NpyArray::f32(vec![shape.len()], shape.clone()));
    }
    w.add(
        "fitted",
        NpyArray::i64(vec![done.fits.len()], done.fits.iter().map(|f| f.is_some() as i64).collect()),
    );
    let fits: Vec<&FaceFit> = done.fits.iter().flatten().collect();
    let m = fits.len();
    w.add(
        "rotation_vector",
        NpyArray::f64(vec![m, 3], fits.iter().flat_map(|f| f.rotation_vector.to_array()).collect()),
    );
    w.add(
        "translation",
        NpyArray::f64(vec![m, 3], fits.iter().flat_map(|f| f.translation.to_array()).collect()),
    );
    let e = fits.first().map_or(0, |f| f.expression.len());
    w.add(
        "expression",
        NpyArray::f32(vec![m, e], fits.iter().flat_map(|f| f.expression.iter().copied()).collect()),
    );
    w.write(path).map_err(|e| FitError::within(format!("writing {}", path.display()), e))
}

/// What [`write_checkpoint`] stored, the fits rebuilt on their landmarks; refused when it is
/// another run's.
pub(crate) fn read_checkpoint(path: &Path, run: &TrackRun, fitter: &FaceFitter) -> Result<Done, FitError> {
    let npz = Npz::read(path)?;
    check_run(&npz, run, &[]).map_err(FitError::Checkpoint)?;
    let flags = |key: &str| -> Result<Vec<bool>, FitError> {
        let v = npz.require(key)?.to_i64().ok_or_else(|| npz.field_error(key, "0 or 1 per frame"))?;
        Ok(v.into_iter().map(|x| x != 0).collect())
    };
    let read = |key: &str, shape: &[Option<usize>]| -> Result<Vec<f64>, FitError> {
        Ok(npz.f64_with_shape(key, shape)?.1)
    };
    let found = flags("found")?;
    let k = Some(found.iter().filter(|f| **f).count());
    let points = read("points", &[k, Some(NUM_LANDMARKS), Some(3)])?;
    let roi = read("roi", &[k, Some(5)])?;
    let flag = read("flag", &[k])?;
    let mut next = 0;
    let landmarks: Vec<Option<FaceLandmarks>> = found
        .iter()
        .map(|&f| {
            f.then(|| {
                let i = next;
                next += 1;
                let r = &roi[5 * i..5 * i + 5];
                FaceLandmarks {
                    roi: RotatedRect {
                        cx: r[0] as f32,
                        cy: r[1] as f32,
                        width: r[2] as f32,
                        height: r[3] as f32,
                        rotation: r[4] as f32,
                    },
                    flag: flag[i] as f32,
                    points: points[i * 3 * NUM_LANDMARKS..(i + 1) * 3 * NUM_LANDMARKS]
                        .chunks_exact(3)
                        .map(|p| [p[0] as f32, p[1] as f32, p[2] as f32])
                        .collect(),
                }
            })
        })
        .collect();
    let shape: Option<Vec<f32>> = match npz.contains("shape") {
        true => Some(read("shape", &[None])?.into_iter().map(|v| v as f32).collect()),
        false => None,
    };
    let fitted = flags("fitted")?;
    if fitted.len() > landmarks.len() || (!fitted.is_empty() && shape.is_none()) {
        return Err(FitError::input(
            path.display().to_string(),
            "fitted: more frames fitted than read, or fits without the shape",
        ));
    }
    let m = fitted.iter().filter(|f| **f).count();
    let rotation = read("rotation_vector", &[Some(m), Some(3)])?;
    let translation = read("translation", &[Some(m), Some(3)])?;
    let expression = read("expression", &[Some(m), None])?;
    let e = expression.len() / m.max(1);
    let mut next = 0;
    let mut fits = Vec::with_capacity(fitted.len());
    for (i, &f) in fitted.iter().enumerate() {
        let (Some(face), true) = (&landmarks[i], f) else {
            fits.push(None);
            continue;
        };
        let j = next;
        next += 1;
        let r = &rotation[3 * j..3 * j + 3];
        let t = &translation[3 * j..3 * j + 3];
        let coefficients: Vec<f32> = expression[e * j..e * (j + 1)].iter().map(|&v| v as f32).collect();
        let fit = fitter.at(
            face,
            shape.as_deref().expect("checked above"),
            &coefficients,
            DVec3::new(r[0], r[1], r[2]),
            DVec3::new(t[0], t[1], t[2]),
        )?;
        fits.push(Some(fit));
    }
    Ok(Done { landmarks, shape, fits })
}
