//! Bad model and motion files give one-line errors that name the file and the field; never a panic.

mod common;
#[path = "common/scratch.rs"]
mod scratch;

use std::path::PathBuf;

use mannequin_body::{Motion, load_model, parse_model};
use mannequin_io::{NpyArray, Npz, NpzWriter};
use scratch::Scratch;

/// A valid small SMPL-format model as an editable list of arrays.
fn model_arrays() -> Vec<(String, NpyArray)> {
    let bytes = common::random_model::random_model_npz(24, 4, 6, 8);
    let npz = Npz::from_bytes("m.npz".into(), &bytes).unwrap();
    npz.keys().map(|k| (k.to_string(), npz.get(k).unwrap().clone())).collect()
}

fn write(path: &PathBuf, arrays: &[(String, NpyArray)]) {
    let mut w = NpzWriter::new();
    for (k, a) in arrays {
        w.add(k, a.clone());
    }
    w.write(path).unwrap();
}

fn one_line(msg: &str, file: &str, field: &str) {
    assert!(!msg.contains('\n'), "not one line: {msg}");
    assert!(msg.contains(file), "no file name in: {msg}");
    assert!(msg.contains(field), "no field '{field}' in: {msg}");
}

#[test]
fn missing_key_names_file_and_key() {
    let dir = Scratch::new("missing");
    let path = dir.join("no_weights.npz");
    let arrays: Vec<_> = model_arrays().into_iter().filter(|(k, _)| k != "weights").collect();
    write(&path, &arrays);
    let msg = load_model(&path, None).unwrap_err().to_string();
    one_line(&msg, "no_weights.npz", "weights");
}

#[test]
fn wrong_shape_names_field_and_expected_shape() {
    let dir = Scratch::new("shape");
    let path = dir.join("bad_shape.npz");
    let mut arrays = model_arrays();
    for (k, a) in arrays.iter_mut() {
        if k == "J_regressor" {
            a.shape = vec![a.shape[1], a.shape[0]];
        }
    }
    write(&path, &arrays);
    let msg = load_model(&path, None).unwrap_err().to_string();
    one_line(&msg, "bad_shape.npz", "J_regressor");
    assert!(msg.contains("expected shape (24, 48)"), "{msg}");
}

#[test]
fn too_many_betas_requested() {
    let bytes = common::random_model::random_model_npz(24, 4, 6, 8);
    let msg =
        parse_model(&Npz::from_bytes("few.npz".into(), &bytes).unwrap(), Some(10)).unwrap_err().to_string();
    one_line(&msg, "few.npz", "shapedirs");
}

#[test]
fn truncated_npz_is_a_clean_error() {
    let dir = Scratch::new("trunc");
    let full = common::random_model::random_model_npz(24, 4, 6, 8);
    for cut in [0, 20, full.len() / 3, full.len() - 10] {
        let path = dir.join(format!("cut_{cut}.npz"));
        std::fs::write(&path, &full[..cut]).unwrap();
        let msg = load_model(&path, None).unwrap_err().to_string();
        one_line(&msg, &format!("cut_{cut}.npz"), "");
    }
}

fn amass(path: &PathBuf, width: usize, poses: Vec<f64>) {
    let frames = poses.len() / width;
    let mut w = NpzWriter::new();
    w.add("poses", NpyArray::f64(vec![frames, width], poses))
        .add("trans", NpyArray::f64(vec![frames, 3], vec![0.0; frames * 3]))
        .add("betas", NpyArray::f64(vec![16], vec![0.0; 16]))
        .add("mocap_framerate", NpyArray::f64(vec![], vec![60.0]));
    // The bytes, not `write`: the writer refuses the NaN a broken file may hold.
    std::fs::write(path, w.to_bytes()).unwrap();
}

#[test]
fn nan_in_a_pose_names_file_field_and_frame() {
    let dir = Scratch::new("nan");
    let path = dir.join("nan_walk.npz");
    let mut poses = vec![0.1; 3 * 156];
    poses[156 + 40] = f64::NAN;
    amass(&path, 156, poses);
    let msg = Motion::read(&path).unwrap_err().to_string();
    one_line(&msg, "nan_walk.npz", "poses");
    assert!(msg.contains("frame 1"), "{msg}");
}

#[test]
fn motion_with_unmappable_joint_count_is_rejected() {
    let dir = Scratch::new("joints");
    let path = dir.join("odd.npz");
    amass(&path, 30, vec![0.0; 60]);
    let motion = Motion::read(&path).unwrap();
    let bytes = common::random_model::random_model_npz(24, 4, 6, 8);
    let model = parse_model(&Npz::from_bytes("m.npz".into(), &bytes).unwrap(), None).unwrap();
    let msg = motion.poses_for(&model).unwrap_err().to_string();
    one_line(&msg, "odd.npz", "poses");
}

#[test]
fn missing_frame_rate_is_named() {
    let dir = Scratch::new("fps");
    let path = dir.join("nofps.npz");
    let mut w = NpzWriter::new();
    w.add("poses", NpyArray::f64(vec![1, 72], vec![0.0; 72]))
        .add("trans", NpyArray::f64(vec![1, 3], vec![0.0; 3]));
    w.write(&path).unwrap();
    let msg = Motion::read(&path).unwrap_err().to_string();
    one_line(&msg, "nofps.npz", "mocap_framerate");
}

/// A model with no shape components or no joints is an error or a model, never a panic.
#[test]
fn empty_shape_space_and_empty_skeleton() {
    let with = |key: &str, array: NpyArray| {
        let mut w = NpzWriter::new();
        for (k, a) in model_arrays() {
            w.add(&k, if k == key { array.clone() } else { a });
        }
        parse_model(&Npz::from_bytes(format!("no_{key}.npz").into(), &w.to_bytes()).unwrap(), None)
    };
    let vertices = model_arrays().iter().find(|(k, _)| k == "v_template").unwrap().1.shape[0];
    let model = with("shapedirs", NpyArray::f64(vec![vertices, 3, 0], vec![])).unwrap();
    assert_eq!(model.num_betas(), 0);
    let msg = with("kintree_table", NpyArray::i64(vec![2, 0], vec![])).unwrap_err().to_string();
    one_line(&msg, "no_kintree_table.npz", "kintree_table");
    assert!(msg.contains("at least one joint"), "{msg}");
}

/// A clip of no frames is refused where it is read, naming the file and the field, whichever
/// layout it has; and resampling a hand-built empty clip is an error, not a panic.
#[test]
fn motion_of_no_frames_is_refused() {
    let dir = Scratch::new("empty-motion");
    let path = dir.join("empty.npz");
    amass(&path, 72, vec![]);
    let msg = Motion::read(&path).unwrap_err().to_string();
    one_line(&msg, "empty.npz", "poses");
    assert!(msg.contains("at least one frame"), "{msg}");
    let mut w = NpzWriter::new();
    w.add("betas", NpyArray::f32(vec![1, 10], vec![0.0; 10]))
        .add("global_orient", NpyArray::f32(vec![0, 3], vec![]))
        .add("body_pose", NpyArray::f32(vec![0, 69], vec![]))
        .add("transl", NpyArray::f32(vec![0, 3], vec![]));
    let npz = Npz::from_bytes("snap.npz".into(), &w.to_bytes()).unwrap();
    let msg = Motion::from_npz(&npz).unwrap_err().to_string();
    one_line(&msg, "snap.npz", "global_orient");
    let empty = Motion {
        source: "hand.npz".into(),
        poses: vec![],
        joints: 24,
        trans: vec![],
        betas: vec![],
        fps: 60.0,
        gender: None,
    };
    let msg = empty.resample(30.0).unwrap_err().to_string();
    one_line(&msg, "hand.npz", "poses");
}

/// A crafted frame rate cannot make resampling ask for unbounded memory.
#[test]
fn resampling_far_beyond_the_clip_rate_is_refused() {
    let dir = Scratch::new("slow-motion");
    let path = dir.join("slow.npz");
    amass(&path, 72, vec![0.0; 144]);
    let mut motion = Motion::read(&path).unwrap();
    motion.fps = 1e-30;
    let msg = motion.resample(30.0).unwrap_err().to_string();
    assert!(msg.contains("frame rate") && msg.contains("at most 1000 times"), "{msg}");
}

/// Values a motion file may hold but no motion has (issue 42): 2 million frames once took 3 GB
/// in `cloth simulate --max-frames 2`, betas of 1e30 put vertices at 9e28 m, and a translation
/// of 1e30 m is no walk. Each is refused where the file is read, naming the file and field.
#[test]
fn motions_past_the_limits_are_refused() {
    let dir = Scratch::new("limits-motion");
    let frames = mannequin_io::limits::MAX_MOTION_FRAMES + 1;
    let long = dir.join("long.npz");
    let mut w = NpzWriter::new();
    w.add("poses", NpyArray::f32(vec![frames, 3], vec![0.0; frames * 3]))
        .add("trans", NpyArray::f32(vec![frames, 3], vec![0.0; frames * 3]))
        .add("mocap_framerate", NpyArray::f64(vec![], vec![30.0]));
    w.write(&long).unwrap();
    let msg = Motion::read(&long).unwrap_err().to_string();
    one_line(&msg, "long.npz", "poses");
    assert!(msg.contains("at most 100000"), "{msg}");

    let path = dir.join("betas.npz");
    amass(&path, 72, vec![0.0; 144]);
    let npz = Npz::read(&path).unwrap();
    let mut w = NpzWriter::new();
    for k in npz.keys().filter(|&k| k != "betas") {
        w.add(k, npz.get(k).unwrap().clone());
    }
    w.add("betas", NpyArray::f64(vec![2], vec![0.0, 1e30]));
    w.write(&path).unwrap();
    let msg = Motion::read(&path).unwrap_err().to_string();
    one_line(&msg, "betas.npz", "betas");
    assert!(msg.contains("element 1"), "{msg}");

    let far = dir.join("far.npz");
    let mut w = NpzWriter::new();
    w.add("poses", NpyArray::f64(vec![2, 72], vec![0.0; 144]))
        .add("trans", NpyArray::f64(vec![2, 3], vec![0.0, 0.0, 0.0, 1e30, 0.0, 0.0]))
        .add("mocap_framerate", NpyArray::f64(vec![], vec![30.0]));
    w.write(&far).unwrap();
    let msg = Motion::read(&far).unwrap_err().to_string();
    one_line(&msg, "far.npz", "trans");
    assert!(msg.contains("frame 1"), "{msg}");

    let ok = dir.join("ok.npz");
    amass(&ok, 72, vec![0.0; 72 * 200]);
    let mut clip = Motion::read(&ok).unwrap();
    clip.fps = 0.1;
    let msg = clip.resample(100.0).unwrap_err().to_string();
    assert!(msg.contains("frame rate") && msg.contains("at most 100000"), "{msg}");
}
