//! A capture's dataset beyond its frames: the cameras, the poses per split and the splits, in
//! the PeopleSnapshot layout `mannequin train` reads. One static camera with the body turning
//! in front of it, or the body held still and a camera per frame.

use std::path::Path;

use glam::{DMat3, DMat4, DVec3};
use mannequin_body::BodyModel;
use mannequin_body::rodrigues::axis_angle_quat;
use mannequin_data::splits::SplitRange;
use mannequin_data::{Camera, Cameras, DatasetWriter, PoseOrigin, Poses, Splits};

use crate::body_fit::BodyFit;
use crate::error::FitError;

/// The last tenth of the frames (at least one) is held out as the test split.
const TEST_SHARE: usize = 10;

/// The dataset's cameras, poses and splits (its frames are written as they are tracked): one
/// static camera, or with `moving_camera` the body held still and a camera per frame.
pub(crate) fn write_dataset(
    out: &Path,
    model: &BodyModel,
    fits: &[BodyFit],
    moving_camera: bool,
) -> Result<(), FitError> {
    let writer = DatasetWriter::new(out);
    let mut all = Poses {
        betas: fits[0].betas.clone(),
        global_orient: fits.iter().map(|f| [f.pose[0], f.pose[1], f.pose[2]]).collect(),
        body_pose: fits.iter().flat_map(|f| f.pose[3..].iter().copied()).collect(),
        transl: fits.iter().map(|f| f.transl).collect(),
    };
    if moving_camera {
        writer.write_cameras(&Cameras::PerFrame(moving_cameras(model, fits)?))?;
        let (orient, transl) = (all.global_orient[0], all.transl[0]);
        all.global_orient.fill(orient);
        all.transl.fill(transl);
    } else {
        writer.write_cameras(&Cameras::Static(fits[0].camera.clone()))?;
    }
    let n = fits.len();
    let test = (n / TEST_SHARE).max(1);
    let mut splits = Splits::new();
    splits.insert("train".into(), SplitRange::new(0, n - test - 1, 1));
    splits.insert("test".into(), SplitRange::new(n - test, n - 1, 1));
    splits.insert("val".into(), SplitRange::new(n - test, n - test, 1));
    for (name, range) in &splits {
        writer.write_poses(name, &all.select(&range.frames()))?;
    }
    writer.write_splits(&splits)?;
    writer.write_origin(PoseOrigin::Estimated, "mannequin capture")?;
    Ok(())
}

/// The clip seen the other way, for a person standing still while the camera moves: the body
/// held where frame 0 has it, and a camera per frame. Frame i's body is its root-relative pose
/// moved by Mᵢ (its orientation about the rest root joint, then its translation), so the camera
/// E·Mᵢ·M₀⁻¹ sees frame 0's placement exactly as E sees frame i's.
fn moving_cameras(model: &BodyModel, fits: &[BodyFit]) -> Result<Vec<Camera>, FitError> {
    let rest = mannequin_body::forward(model, &fits[0].betas, &[0.0; 72], &[0.0; 3])?;
    let root = DVec3::new(rest.joints[0] as f64, rest.joints[1] as f64, rest.joints[2] as f64);
    let placement = |f: &BodyFit| {
        let turn = DMat3::from_quat(axis_angle_quat([f.pose[0], f.pose[1], f.pose[2]]).as_dquat());
        let t = DVec3::new(f.transl[0] as f64, f.transl[1] as f64, f.transl[2] as f64);
        DMat4::from_mat3_translation(turn, root + t - turn * root)
    };
    let first = placement(&fits[0]).inverse();
    Ok(fits
        .iter()
        .map(|f| {
            let seen = DMat4::from_cols_array_2d(&f.camera.extrinsic).transpose() * placement(f) * first;
            Camera { extrinsic: seen.transpose().to_cols_array_2d(), ..f.camera.clone() }
        })
        .collect())
}
