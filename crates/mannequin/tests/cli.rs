//! The command line as a user runs it: the demo on the embedded body, and one-line errors on bad
//! files (exit code 1, no panic).

mod common;
use common::{mannequin, one_line_error, scratch};

#[test]
fn demo_trains_evaluates_animates_and_exports() {
    let out = scratch("cli-demo");
    // A short, small run of the README's main job: every stage, every output.
    let o = mannequin(&[
        "demo",
        "--out",
        out.to_str().unwrap(),
        "--iters",
        "4",
        "--size",
        "96",
        "--frames",
        "10",
        "--walk-frames",
        "3",
        "--no-self-collision",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in [
        "walk.npz",
        "avatar.glb",
        "avatar_gaussians.ply",
        "avatar_squat.obj",
        "eval.json",
        "walk/frame_0002.png",
    ] {
        assert!(out.join(f).metadata().is_ok_and(|m| m.len() > 200), "{f} missing");
    }
    let scores: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("eval.json")).unwrap()).unwrap();
    // The images-only path: the held-out frames of what `capture` recovered, their poses fitted
    // with the avatar frozen, scored against the subject's truth.
    assert!(scores["test"]["psnr"].as_f64().is_some_and(f64::is_finite), "{scores}");
    assert_eq!(scores["test"]["test_poses"]["mode"], "fit", "{scores}");
    assert!(out.join("captured/origin.json").exists() && out.join("avatar/refined_poses.npz").exists());
    // The walk written by the demo drives the plain body as a skinned glTF too.
    let again = out.join("again.glb");
    let walk = out.join("walk.npz");
    let o = mannequin(&[
        "body",
        "animate",
        "--body",
        "default-lod1",
        "--motion",
        walk.to_str().unwrap(),
        "--fps",
        "15",
        "-o",
        again.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(&std::fs::read(&again).unwrap()[..4], b"glTF");
    std::fs::remove_dir_all(out).unwrap();
}

#[test]
fn body_pose_writes_obj_and_ply() {
    let dir = scratch("cli-pose");
    for ext in ["obj", "ply"] {
        let path = dir.join(format!("squat.{ext}"));
        let o = mannequin(&[
            "body",
            "pose",
            "--body",
            "default-lod1",
            "--betas",
            "1,-0.5",
            "--named-pose",
            "squat",
            "-o",
            path.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(path.exists());
    }
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn bad_files_give_one_line_errors() {
    let dir = scratch("cli-bad");
    let model = dir.join("broken_model.npz");
    std::fs::write(&model, b"PK\x03\x04 not really a zip").unwrap();
    let out = dir.join("x.obj");
    one_line_error(&mannequin(&["body", "info", "--body", model.to_str().unwrap()]), &["broken_model.npz"]);
    let motion = dir.join("missing.npz");
    let glb = dir.join("x.glb");
    one_line_error(
        &mannequin(&["body", "animate", "--motion", motion.to_str().unwrap(), "-o", glb.to_str().unwrap()]),
        &["missing.npz"],
    );
    let o = mannequin(&["body", "pose", "--named-pose", "cartwheel", "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "a typo in an enumerated flag is a usage error");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("cartwheel") && err.contains("arms-raised"), "{err}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn info_verbs_print_results_on_stdout_as_a_table_or_json() {
    let lod1 = mannequin_body::BodyModel::from_spec("default-lod1", None).unwrap();
    let o = mannequin(&["body", "info", "--body", "default-lod1", "--joints", "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // stdout holds the JSON and nothing else.
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["vertices"].as_u64(), Some(lod1.num_vertices() as u64));
    assert_eq!(v["faces"].as_u64(), Some(lod1.faces.len() as u64));
    assert_eq!(v["joints"].as_u64(), Some(24));
    let joints = v["joint_list"].as_array().unwrap();
    assert_eq!(joints.len(), 24);
    assert_eq!(joints[0]["parent"], serde_json::Value::Null);
    assert_eq!(joints[1]["parent"].as_str(), Some(lod1.joint_names[0].as_str()));
    let table = mannequin(&["body", "info", "--body", "default-lod1"]);
    let text = String::from_utf8_lossy(&table.stdout);
    assert!(text.contains(&format!("vertices     {}", lod1.num_vertices())), "{text}");
    assert!(!text.contains("face "), "the face model is the full default body's: {text}");
    let face = mannequin_body::FaceModel::default_face();
    let full = String::from_utf8_lossy(&mannequin(&["body", "info"]).stdout).to_string();
    let line =
        full.lines().find(|l| l.starts_with("face ")).unwrap_or_else(|| panic!("no face line: {full}"));
    assert!(line.contains(&format!("{} shape components", face.num_shape())), "{line}");
    assert!(line.contains("52 expression units"), "{line}");

    let dir = scratch("cli-splat-info");
    let ply = dir.join("two.ply");
    let scene = mannequin_splat::SplatScene {
        means: vec![0.0, 1.0, 2.0, -1.0, 3.0, 0.5],
        quaternions: vec![1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0],
        scales: vec![0.1, 0.2, 0.3, 0.1, 0.1, 0.1],
        opacities: vec![0.25, 0.75],
        sh_degree: 0,
        sh: vec![0.0; 6],
    };
    scene.write_ply(&ply).unwrap();
    let o = mannequin(&["splat", "info", ply.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["gaussians"].as_u64(), Some(2));
    let near = |x: &serde_json::Value, want: f64| (x.as_f64().unwrap() - want).abs() < 1e-5;
    assert!(near(&v["opacity"]["min"], 0.25) && near(&v["opacity"]["max"], 0.75), "{v}");
    assert!(near(&v["mean_x"]["mean"], -0.5) && near(&v["mean_y"]["max"], 3.0), "{v}");
    assert!(near(&v["scale"]["max"], 0.3), "{v}");

    // Logs go to stderr: a verb that writes a file prints nothing on stdout.
    let obj = dir.join("rest.obj");
    let o = mannequin(&["body", "pose", "--body", "default-lod1", "-o", obj.to_str().unwrap()]);
    assert!(o.status.success() && o.stdout.is_empty(), "{}", String::from_utf8_lossy(&o.stdout));
    assert!(String::from_utf8_lossy(&o.stderr).contains("wrote"));
    std::fs::remove_dir_all(dir).unwrap();
}

/// `animate --fps` on a motion of no frames used to panic while resampling; it is a one-line
/// error naming the file at read.
#[test]
fn animate_refuses_a_motion_of_no_frames() {
    use mannequin_io::{NpyArray, NpzWriter};
    let dir = scratch("cli-empty-motion");
    let motion = dir.join("empty.npz");
    let mut w = NpzWriter::new();
    w.add("poses", NpyArray::f64(vec![0, 72], vec![]))
        .add("trans", NpyArray::f64(vec![0, 3], vec![]))
        .add("mocap_framerate", NpyArray::f64(vec![], vec![60.0]));
    w.write(&motion).unwrap();
    let out = dir.join("x.glb");
    let o = mannequin(&[
        "body",
        "animate",
        "--motion",
        motion.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--fps",
        "30",
    ]);
    one_line_error(&o, &["empty.npz", "poses", "at least one frame"]);
    std::fs::remove_dir_all(dir).unwrap();
}
