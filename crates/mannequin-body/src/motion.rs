//! Motion clips: AMASS `.npz` (`poses, trans, betas, mocap_framerate | mocap_frame_rate`) and
//! PeopleSnapshot pose files (`betas, global_orient, body_pose, transl`), mapping between the
//! SMPL, SMPL-H and SMPL-X joint layouts, and resampling to a frame rate.

use std::path::{Path, PathBuf};

use glam::Quat;
use mannequin_io::limits::{MAX_BETA, MAX_DISTANCE, MAX_MOTION_FRAMES};
use mannequin_io::{NpyArray, NpyData, Npz, NpzWriter};

use crate::error::BodyError;
use crate::model::{BodyModel, ModelFamily};
use crate::rodrigues::{axis_angle_quat, quat_axis_angle};

/// Joints shared by SMPL, SMPL-H and SMPL-X: pelvis to wrists (0..=21), same order everywhere.
const BODY_JOINTS: usize = 22;

/// PeopleSnapshot files carry no frame rate; their videos were captured at 30 fps.
pub const PEOPLE_SNAPSHOT_FPS: f32 = 30.0;

/// Most output frames per input frame [`Motion::resample`] makes: far beyond any real use, and
/// what keeps a crafted frame rate (a clip "at" 1e-30 fps) from asking for unbounded memory.
const MAX_RESAMPLE_RATIO: f64 = 1000.0;

/// A pose sequence as stored in its file (axis-angle, parent-relative).
#[derive(Debug, Clone)]
pub struct Motion {
    pub source: PathBuf,
    /// F × (3 × joints in the file's layout).
    pub poses: Vec<f32>,
    /// Joints per frame in `poses`.
    pub joints: usize,
    /// F × 3.
    pub trans: Vec<f32>,
    pub betas: Vec<f32>,
    pub fps: f32,
    pub gender: Option<String>,
}

fn scalar_f64(npz: &Npz, key: &str) -> Result<f64, BodyError> {
    let a = npz.require(key)?;
    match a.to_f64().as_deref() {
        Some([x]) => Ok(*x),
        _ => Err(npz.field_error(key, format!("expected one number, found shape {:?}", a.shape)).into()),
    }
}

/// A clip needs a first frame: every use of one (resampling, posing, export) starts there; and
/// at most [`MAX_MOTION_FRAMES`], since every use also allocates per frame.
fn check_frames(npz: &Npz, key: &str, shape: &[usize]) -> Result<(), BodyError> {
    if shape[0] == 0 || shape[0] > MAX_MOTION_FRAMES {
        return Err(npz
            .field_error(
                key,
                format!("expected at least one frame and at most {MAX_MOTION_FRAMES}, found shape {shape:?}"),
            )
            .into());
    }
    Ok(())
}

/// Shape coefficients, finite and within [`MAX_BETA`].
fn check_betas(npz: &Npz, betas: &[f64]) -> Result<(), BodyError> {
    match betas.iter().position(|b| !b.is_finite() || b.abs() > MAX_BETA) {
        Some(i) => Err(npz
            .field_error("betas", format!("element {i} is {}: expected within ±{MAX_BETA}", betas[i]))
            .into()),
        None => Ok(()),
    }
}

/// Every value finite and within `bound` where there is one (rotations need only be finite; a
/// translation is held to [`MAX_DISTANCE`]).
fn check_values(
    npz: &Npz,
    key: &str,
    values: &[f32],
    per_frame: usize,
    bound: Option<f64>,
) -> Result<(), BodyError> {
    let within = |x: f32| x.is_finite() && bound.is_none_or(|b| f64::from(x.abs()) <= b);
    match values.iter().position(|&x| !within(x)) {
        Some(i) => {
            let expected =
                bound.map_or("a finite value".to_string(), |b| format!("a finite value within ±{b}"));
            let frame = i / per_frame.max(1);
            Err(npz
                .field_error(key, format!("frame {frame} holds {}: expected {expected}", values[i]))
                .into())
        }
        None => Ok(()),
    }
}

impl Motion {
    pub fn num_frames(&self) -> usize {
        self.trans.len() / 3
    }

    /// An AMASS clip.
    pub fn from_amass(npz: &Npz) -> Result<Self, BodyError> {
        let (shape, poses) = npz.f64_with_shape("poses", &[None, None])?;
        check_frames(npz, "poses", &shape)?;
        let (frames, width) = (shape[0], shape[1]);
        if !width.is_multiple_of(3) || width == 0 {
            return Err(npz
                .field_error("poses", format!("expected 3 values per joint, found {width} per frame"))
                .into());
        }
        let (_, trans) = npz.f64_with_shape("trans", &[Some(frames), Some(3)])?;
        let betas = match npz.get("betas") {
            Some(a) => a.to_f64().ok_or_else(|| npz.field_error("betas", "expected numbers"))?,
            None => Vec::new(),
        };
        check_betas(npz, &betas)?;
        let fps_key = ["mocap_framerate", "mocap_frame_rate"]
            .into_iter()
            .find(|k| npz.contains(k))
            .ok_or_else(|| {
                npz.field_error(
                    "mocap_framerate",
                    "missing: expected 'mocap_framerate' or 'mocap_frame_rate'",
                )
            })?;
        let fps = scalar_f64(npz, fps_key)? as f32;
        if !(fps.is_finite() && fps > 0.0) {
            return Err(npz
                .field_error(fps_key, format!("expected a positive frame rate, found {fps}"))
                .into());
        }
        let gender = match npz.get("gender").map(|a| &a.data) {
            Some(NpyData::Str(s)) => s.first().cloned(),
            _ => None,
        };
        let poses: Vec<f32> = poses.into_iter().map(|x| x as f32).collect();
        let trans: Vec<f32> = trans.into_iter().map(|x| x as f32).collect();
        check_values(npz, "poses", &poses, width, None)?;
        check_values(npz, "trans", &trans, 3, Some(MAX_DISTANCE))?;
        Ok(Self {
            source: npz.path.clone(),
            poses,
            joints: width / 3,
            trans,
            betas: betas.into_iter().map(|x| x as f32).collect(),
            fps,
            gender,
        })
    }

    /// A PeopleSnapshot `poses/anim_nerf_*.npz` file (SMPL layout, 30 fps).
    pub fn from_people_snapshot(npz: &Npz) -> Result<Self, BodyError> {
        let (shape, go) = npz.f64_with_shape("global_orient", &[None, Some(3)])?;
        check_frames(npz, "global_orient", &shape)?;
        let frames = shape[0];
        let (_, body) = npz.f64_with_shape("body_pose", &[Some(frames), Some(69)])?;
        let (_, transl) = npz.f64_with_shape("transl", &[Some(frames), Some(3)])?;
        let (_, betas) = npz.f64_with_shape("betas", &[Some(1), None])?;
        check_betas(npz, &betas)?;
        let mut poses = Vec::with_capacity(frames * 72);
        for f in 0..frames {
            poses.extend(go[3 * f..3 * f + 3].iter().map(|&x| x as f32));
            poses.extend(body[69 * f..69 * f + 69].iter().map(|&x| x as f32));
        }
        let trans: Vec<f32> = transl.iter().map(|&x| x as f32).collect();
        check_values(npz, "global_orient/body_pose", &poses, 72, None)?;
        check_values(npz, "transl", &trans, 3, Some(MAX_DISTANCE))?;
        Ok(Self {
            source: npz.path.clone(),
            poses,
            joints: 24,
            trans,
            betas: betas.iter().map(|&x| x as f32).collect(),
            fps: PEOPLE_SNAPSHOT_FPS,
            gender: None,
        })
    }

    /// Reads an AMASS or a PeopleSnapshot file, told apart by their keys.
    pub fn read(path: &Path) -> Result<Self, BodyError> {
        Self::from_npz(&Npz::read(path)?)
    }

    /// An AMASS or a PeopleSnapshot clip already in memory, told apart by its keys.
    pub fn from_npz(npz: &Npz) -> Result<Self, BodyError> {
        if npz.contains("poses") { Self::from_amass(npz) } else { Self::from_people_snapshot(npz) }
    }

    /// Writes the clip as an AMASS `.npz` (`poses, trans, betas, mocap_framerate, gender`).
    pub fn write_amass(&self, path: &Path) -> Result<(), BodyError> {
        let f = self.num_frames();
        let mut w = NpzWriter::new();
        w.add(
            "poses",
            NpyArray::f64(vec![f, 3 * self.joints], self.poses.iter().map(|&x| x as f64).collect()),
        )
        .add("trans", NpyArray::f64(vec![f, 3], self.trans.iter().map(|&x| x as f64).collect()))
        .add("betas", NpyArray::f64(vec![self.betas.len()], self.betas.iter().map(|&x| x as f64).collect()))
        .add("mocap_framerate", NpyArray::f64(vec![], vec![self.fps as f64]))
        .add(
            "gender",
            NpyArray {
                shape: vec![],
                data: NpyData::Str(vec![self.gender.clone().unwrap_or("neutral".into())]),
            },
        );
        Ok(w.write(path)?)
    }

    /// The poses in `model`'s joint layout, F × 3J.
    ///
    /// Between SMPL-family layouts only the 22 body joints carry over. SMPL's joints 22–23 are
    /// whole hands, while SMPL-H/X joints 22+ are fingers (or jaw and eyes), so those are set to
    /// the rest rotation rather than copied from a joint that means something else.
    pub fn poses_for(&self, model: &BodyModel) -> Result<Vec<f32>, BodyError> {
        self.poses_for_joints(model.num_joints())
    }

    /// The pose (3·`joints` values, mapped as [`Motion::poses_for_joints`]) and translation of
    /// one frame.
    pub fn frame_pose(&self, frame: usize, joints: usize) -> Result<(Vec<f32>, [f32; 3]), BodyError> {
        if frame >= self.num_frames() {
            return Err(BodyError::field(
                &self.source,
                "poses",
                format!("frame {frame} asked, the motion has {} frames", self.num_frames()),
            ));
        }
        let poses = self.poses_for_joints(joints)?;
        let pose = poses[frame * 3 * joints..(frame + 1) * 3 * joints].to_vec();
        Ok((pose, [0, 1, 2].map(|k| self.trans[3 * frame + k])))
    }

    /// [`Motion::poses_for`] for a body with `target` joints.
    pub fn poses_for_joints(&self, target: usize) -> Result<Vec<f32>, BodyError> {
        if self.joints == target {
            return Ok(self.poses.clone());
        }
        let family_layout = |j: usize| matches!(ModelFamily::from_joint_count(j), ModelFamily::Other(_));
        if family_layout(self.joints) || family_layout(target) {
            return Err(BodyError::field(
                &self.source,
                "poses",
                format!(
                    "{} joints per frame, but the model has {target} and no known mapping exists",
                    self.joints
                ),
            ));
        }
        let mut out = vec![0.0f32; self.num_frames() * 3 * target];
        for (src, dst) in self.poses.chunks_exact(3 * self.joints).zip(out.chunks_exact_mut(3 * target)) {
            dst[..3 * BODY_JOINTS].copy_from_slice(&src[..3 * BODY_JOINTS]);
        }
        Ok(out)
    }

    /// Resamples to `fps` by spherical interpolation of every joint rotation and linear
    /// interpolation of the translation, over the clip's original duration.
    pub fn resample(&self, fps: f32) -> Result<Self, BodyError> {
        if !(fps.is_finite() && fps > 0.0) {
            return Err(BodyError::input("frame rate", format!("expected a positive number, found {fps}")));
        }
        let n = self.num_frames();
        if n == 0 || !(self.fps.is_finite() && self.fps > 0.0) {
            return Err(BodyError::field(
                &self.source,
                "poses",
                format!(
                    "cannot resample {n} frames at {} fps: expected at least one frame at a positive rate",
                    self.fps
                ),
            ));
        }
        let ratio = fps as f64 / self.fps as f64;
        if ratio > MAX_RESAMPLE_RATIO {
            return Err(BodyError::input(
                "frame rate",
                format!(
                    "{fps} fps is {ratio:.0} times the clip's {} fps: expected at most {MAX_RESAMPLE_RATIO} times",
                    self.fps
                ),
            ));
        }
        let duration = (n - 1) as f64 / self.fps as f64;
        let out_frames = (duration * fps as f64 + 1e-6).floor() as usize + 1;
        if out_frames > MAX_MOTION_FRAMES {
            return Err(BodyError::input(
                "frame rate",
                format!(
                    "{fps} fps makes {out_frames} frames of the clip's {n}: expected at most {MAX_MOTION_FRAMES}"
                ),
            ));
        }
        let per = 3 * self.joints;
        let mut poses = Vec::with_capacity(out_frames * per);
        let mut trans = Vec::with_capacity(out_frames * 3);
        for i in 0..out_frames {
            let src = (i as f64 / fps as f64 * self.fps as f64).min((n - 1) as f64);
            let a = src.floor() as usize;
            let b = (a + 1).min(n - 1);
            let t = (src - a as f64) as f32;
            for k in 0..self.joints {
                let r = |f: usize| {
                    let s = &self.poses[f * per + 3 * k..f * per + 3 * k + 3];
                    axis_angle_quat([s[0], s[1], s[2]])
                };
                let q: Quat = r(a).slerp(r(b), t);
                poses.extend_from_slice(&quat_axis_angle(q));
            }
            for c in 0..3 {
                trans.push(self.trans[3 * a + c] * (1.0 - t) + self.trans[3 * b + c] * t);
            }
        }
        Ok(Self { poses, trans, fps, ..self.clone() })
    }
}
