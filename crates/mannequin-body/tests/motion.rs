//! Motion files: AMASS and PeopleSnapshot reading, layout mapping and resampling.

mod common;
#[path = "common/scratch.rs"]
mod scratch;

use mannequin_body::{Motion, parse_model};
use mannequin_io::{NpyArray, Npz, NpzWriter};
use scratch::Scratch;

fn smpl() -> mannequin_body::BodyModel {
    let bytes = common::random_model::random_model_npz(24, 4, 6, 8);
    parse_model(&Npz::from_bytes("m.npz".into(), &bytes).unwrap(), None).unwrap()
}

#[test]
fn smplh_clip_maps_body_joints_and_rests_the_hands() {
    let dir = Scratch::new("motion-smplh");
    let path = dir.join("smplh.npz");
    let poses: Vec<f64> = (0..2 * 156).map(|i| i as f64 * 1e-3).collect();
    let mut w = NpzWriter::new();
    w.add("poses", NpyArray::f64(vec![2, 156], poses.clone()))
        .add("trans", NpyArray::f64(vec![2, 3], vec![0.5; 6]))
        .add("betas", NpyArray::f64(vec![16], vec![0.1; 16]))
        .add("mocap_frame_rate", NpyArray::f64(vec![], vec![120.0]))
        .add(
            "gender",
            mannequin_io::NpyArray { shape: vec![], data: mannequin_io::NpyData::Str(vec!["female".into()]) },
        );
    w.write(&path).unwrap();
    let m = Motion::read(&path).unwrap();
    assert_eq!((m.joints, m.fps, m.gender.as_deref(), m.betas.len()), (52, 120.0, Some("female"), 16));
    let mapped = m.poses_for(&smpl()).unwrap();
    assert_eq!(mapped.len(), 2 * 72);
    for f in 0..2 {
        for i in 0..66 {
            assert_eq!(mapped[f * 72 + i], poses[f * 156 + i] as f32);
        }
        // SMPL-H joint 22 is a finger, not SMPL's hand: the hands stay at rest.
        assert!(mapped[f * 72 + 66..f * 72 + 72].iter().all(|&x| x == 0.0));
    }
}

#[test]
fn people_snapshot_poses_concatenate_orient_and_body() {
    let dir = Scratch::new("motion-anim_nerf_train");
    let path = dir.join("anim_nerf_train.npz");
    let mut w = NpzWriter::new();
    w.add("betas", NpyArray::f32(vec![1, 10], vec![0.2; 10]))
        .add("global_orient", NpyArray::f32(vec![3, 3], (0..9).map(|i| i as f32).collect()))
        .add("body_pose", NpyArray::f32(vec![3, 69], (0..207).map(|i| -(i as f32)).collect()))
        .add("transl", NpyArray::f32(vec![3, 3], vec![1.0; 9]));
    w.write(&path).unwrap();
    let m = Motion::read(&path).unwrap();
    assert_eq!((m.num_frames(), m.joints), (3, 24));
    assert_eq!(&m.poses[72..75], &[3.0, 4.0, 5.0]);
    assert_eq!(m.poses[75], -69.0);
}

#[test]
fn resampling_halves_the_rate_and_slerps() {
    // 5 frames at 60 fps: a rotation about z growing 0.1 rad per frame, translation along x.
    let frames = 5;
    let mut poses = vec![0.0f32; frames * 72];
    let mut trans = vec![0.0f32; frames * 3];
    for f in 0..frames {
        poses[f * 72 + 2] = 0.1 * f as f32;
        trans[f * 3] = f as f32;
    }
    let m =
        Motion { source: "clip".into(), poses, joints: 24, trans, betas: vec![], fps: 60.0, gender: None };
    let half = m.resample(30.0).unwrap();
    assert_eq!(half.num_frames(), 3);
    assert!((half.poses[72 + 2] - 0.2).abs() < 1e-6);
    assert_eq!(half.trans[3], 2.0);
    // Upsampling interpolates between frames: 120 fps puts a frame halfway.
    let double = m.resample(120.0).unwrap();
    assert_eq!(double.num_frames(), 9);
    assert!((double.poses[72 + 2] - 0.05).abs() < 1e-6);
    assert!((double.trans[3] - 0.5).abs() < 1e-6);
}

#[test]
fn amass_write_read_round_trip() {
    let walk = Motion::walk_cycle(1.0, 30.0);
    let dir = Scratch::new("motion-walk");
    let path = dir.join("walk.npz");
    walk.write_amass(&path).unwrap();
    let back = Motion::read(&path).unwrap();
    assert_eq!((back.num_frames(), back.joints, back.fps), (30, 24, 30.0));
    assert_eq!(back.poses, walk.poses);
    assert_eq!(back.trans, walk.trans);
}
