//! The avatar verbs as a user runs them, on a tiny synthetic subject trained for three
//! iterations: `export` (meshes, skinned glTF, 3DGS splats) and `animate --avatar`.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use burn::tensor::Device;
use mannequin_avatar::Avatar;
use mannequin_body::named_pose;
use mannequin_splat::SplatScene;

mod common;
use common::{mannequin, ok, one_line_error, s, scratch, tiny_avatar, usage_error};

#[path = "../../../tools/node_checks.rs"]
mod node_checks;
use node_checks::KHRONOS_VALIDATOR;

/// One model folder for every test: synthesised and trained once (a few seconds).
fn model() -> &'static Path {
    static MODEL: OnceLock<PathBuf> = OnceLock::new();
    MODEL.get_or_init(|| {
        let dir = scratch("avatar-cli-model");
        let (_, model) = tiny_avatar(&dir);
        ok(mannequin(&["motion", "walk", "--seconds", "1", "-o", s(&dir.join("walk.npz"))]));
        model
    })
}

fn walk() -> PathBuf {
    model().parent().unwrap().join("walk.npz")
}

fn close(a: &[f32], b: &[f32], tol: f32, what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: lengths");
    let worst = a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0f32, f32::max);
    assert!(worst <= tol, "{what}: differ by {worst}");
}

fn host(t: burn::tensor::Tensor<2>) -> Vec<f32> {
    t.into_data().iter::<f32>().collect()
}

/// Width and height from a PNG's IHDR chunk.
fn png_size(path: &Path) -> (u32, u32) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(&bytes[1..4], b"PNG", "{}", path.display());
    let be = |at: usize| u32::from_be_bytes(bytes[at..at + 4].try_into().unwrap());
    (be(16), be(20))
}

#[test]
fn export_writes_meshes_glb_and_splats() {
    let out = scratch("avatar-cli-export");
    let avatar = Avatar::load(model(), &Device::flex()).unwrap();
    let v = avatar.canonical.num_vertices();

    // Canonical OBJ: V_s itself, with a colour per vertex.
    let obj = out.join("canonical.obj");
    ok(mannequin(&["export", "--avatar", s(model()), "-o", s(&obj)]));
    let mesh = mannequin_mesh::obj::read_obj(&obj).unwrap();
    assert_eq!(mesh.vertex_count(), v);
    let canonical = avatar.pose(&[0.0; 72], [0.0; 3]).unwrap();
    close(&mesh.positions.concat(), &host(canonical.personalised), 1e-6, "canonical vertices");
    assert!(
        mesh.colors
            .as_ref()
            .is_some_and(|c| c.len() == v && c.concat().iter().all(|x| (0.0..=1.0).contains(x)))
    );

    // Posed PLY at a named pose.
    let ply = out.join("squat.ply");
    ok(mannequin(&["export", "--avatar", s(model()), "--named-pose", "squat", "-o", s(&ply)]));
    let posed_mesh = mannequin_mesh::ply::read(&ply).unwrap().mesh;
    let squat = avatar.pose_mesh(&named_pose("squat").unwrap(), [0.0; 3]).unwrap();
    close(&posed_mesh.positions.concat(), &squat.concat(), 1e-5, "squat vertices");

    // Skinned glTF.
    let glb = out.join("avatar.glb");
    ok(mannequin(&["export", "--avatar", s(model()), "-o", s(&glb)]));
    assert_eq!(&std::fs::read(&glb).unwrap()[..4], b"glTF");
    if let Some(report) = KHRONOS_VALIDATOR.run(&glb) {
        assert!(report.contains(" 0 errors"), "validator:\n{report}");
    }

    // Animated: the skinned glTF with the walk as its animation, and the canonical Gaussians with
    // their skinning as extra float properties after the INRIA ones (docs/viewer.md).
    let (animated, skinned) = (out.join("walk.glb"), out.join("skinned.ply"));
    ok(mannequin(&[
        "export",
        "--avatar",
        s(model()),
        "-o",
        s(&animated),
        "--animation",
        s(&walk()),
        "--skinned-gaussians",
        s(&skinned),
    ]));
    if let Some(report) = KHRONOS_VALIDATOR.run(&animated) {
        assert!(report.contains(" 0 errors"), "validator:\n{report}");
    }
    assert!(String::from_utf8_lossy(&std::fs::read(&animated).unwrap()[..4096]).contains("\"animations\""));
    let scene = SplatScene::read_ply(&skinned).unwrap();
    close(&scene.means, &host(canonical.gaussians.means.clone()), 1e-5, "canonical Gaussian means");
    let bytes = std::fs::read(&skinned).unwrap();
    let end = bytes.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    let header = String::from_utf8_lossy(&bytes[..end]);
    let names: Vec<&str> = header.lines().filter_map(|l| l.strip_prefix("property float ")).collect();
    let column = |n: &str| names.iter().position(|&m| m == n).unwrap_or_else(|| panic!("no property {n}"));
    let value = |g: usize, n: &str| {
        let at = end + 4 * (g * names.len() + column(n));
        f32::from_le_bytes(bytes[at..at + 4].try_into().unwrap())
    };
    for g in (0..scene.len()).step_by(97) {
        let sum: f32 = (0..4).map(|k| value(g, &format!("weight_{k}"))).sum();
        assert!((sum - 1.0).abs() < 1e-5, "Gaussian {g}: weights sum to {sum}");
        assert!(
            (0..4).all(|k| value(g, &format!("joint_{k}")) < 24.0 && value(g, &format!("weight_{k}")) >= 0.0)
        );
    }

    // 3DGS splats at a motion frame: the avatar's posed Gaussians.
    let splats = out.join("splats.ply");
    ok(mannequin(&[
        "export",
        "--avatar",
        s(model()),
        "--motion",
        s(&walk()),
        "--frame",
        "7",
        "--gaussians",
        s(&splats),
    ]));
    let scene = SplatScene::read_ply(&splats).unwrap();
    assert_eq!(scene.len(), avatar.num_gaussians());
    let motion = mannequin_body::Motion::read(&walk()).unwrap();
    let pose = &motion.poses_for_joints(24).unwrap()[7 * 72..8 * 72];
    let transl = [0, 1, 2].map(|k| motion.trans[21 + k]);
    let posed = avatar.pose(pose, transl).unwrap();
    close(&scene.means, &host(posed.gaussians.means), 1e-5, "Gaussian means");
    assert!(scene.opacities.iter().all(|&o| o > 0.9999));

    // A splat viewer with the avatar's screen filter sees what the avatar renders: the file
    // through `splat render` and the avatar through `render`, same frame and camera (white
    // background), give the same 8-bit image.
    let camera = out.join("camera.json");
    std::fs::write(
        &camera,
        r#"{"K": [[240, 0, 64], [0, 240, 48], [0, 0, 1]], "extrinsic": [[1, 0, 0, 0], [0, -1, 0, 0.2],
            [0, 0, -1, 3.2], [0, 0, 0, 1]], "width": 128, "height": 96, "background": [1, 1, 1]}"#,
    )
    .unwrap();
    let (from_file, from_avatar) = (out.join("file.png"), out.join("avatar.png"));
    let dilation = mannequin_avatar::AVATAR_DILATION.to_string();
    ok(mannequin(&[
        "splat",
        "render",
        "--ply",
        s(&splats),
        "--camera",
        s(&camera),
        "--dilation",
        &dilation,
        "-o",
        s(&from_file),
    ]));
    ok(mannequin(&[
        "render",
        "--avatar",
        s(model()),
        "--motion",
        s(&walk()),
        "--frame",
        "7",
        "--camera",
        s(&camera),
        "-o",
        s(&from_avatar),
    ]));
    let a = mannequin_data::Image::read_png(&from_file).unwrap();
    let b = mannequin_data::Image::read_png(&from_avatar).unwrap();
    assert!(a.pixels.iter().any(|p| p[0] < 0.9), "the body is in view");
    close(&a.pixels.concat(), &b.pixels.concat(), 2.0 / 255.0, "splat file vs avatar render");
    std::fs::remove_dir_all(out).unwrap();
}

/// A stand-in `ffmpeg` that records its arguments and writes its output file (the last one).
fn fake_ffmpeg(dir: &Path) {
    use std::os::unix::fs::PermissionsExt;
    let script = dir.join("ffmpeg");
    // Shell built-ins only: PATH holds nothing else.
    let body =
        "#!/bin/sh\necho \"$@\" > \"${0%/*}/args.txt\"\nfor last; do :; done\necho video > \"$last\"\n";
    std::fs::write(&script, body).unwrap();
    std::fs::set_permissions(&script, std::fs::Permissions::from_mode(0o755)).unwrap();
}

#[test]
fn animate_renders_frames_and_video() {
    let out = scratch("avatar-cli-animate");
    let frames = out.join("frames");
    let no_tools = out.join("empty-path");
    std::fs::create_dir_all(&no_tools).unwrap();
    let walk = walk();
    let run = |extra: &[&str], path: &Path| {
        let mut args = vec![
            "animate",
            "--avatar",
            s(model()),
            "--motion",
            s(&walk),
            "--max-frames",
            "3",
            "-o",
            s(&frames),
        ];
        args.extend_from_slice(extra);
        ok(Command::new(env!("CARGO_BIN_EXE_mannequin")).args(&args).env("PATH", path).output().unwrap())
    };
    // No ffmpeg: frames at the front camera's size, and one line saying why there is no video.
    let o = run(&[], &no_tools);
    for f in 0..3 {
        assert_eq!(png_size(&frames.join(format!("frame_{f:04}.png"))), (540, 540));
    }
    assert!(!frames.join("frame_0003.png").exists(), "--max-frames 3");
    assert!(!frames.join("animation.mp4").exists());
    let log = String::from_utf8_lossy(&o.stderr);
    assert_eq!(
        log.lines().filter(|l| l.contains("no video written") && l.contains("ffmpeg")).count(),
        1,
        "{log}"
    );

    // A camera file sets the size; with ffmpeg on PATH the video is encoded as H.264 yuv420p.
    let camera = out.join("camera.json");
    std::fs::write(
        &camera,
        r#"{"K": [[200, 0, 40], [0, 200, 30], [0, 0, 1]], "extrinsic": [[1, 0, 0, 0], [0, -1, 0, 0.2],
            [0, 0, -1, 4], [0, 0, 0, 1]], "width": 80, "height": 60}"#,
    )
    .unwrap();
    let tools = out.join("tools");
    std::fs::create_dir_all(&tools).unwrap();
    fake_ffmpeg(&tools);
    run(&["--camera", s(&camera), "--what", "normals"], &tools);
    assert_eq!(png_size(&frames.join("frame_0002.png")), (80, 60));
    let args = std::fs::read_to_string(tools.join("args.txt")).unwrap();
    for needed in ["libx264", "yuv420p", "frame_%04d.png", "-frames:v 3"] {
        assert!(args.contains(needed), "'{needed}' not in ffmpeg arguments: {args}");
    }
    assert!(frames.join("animation.mp4").exists());
    std::fs::remove_dir_all(out).unwrap();
}

/// --max-frames cuts the clip before it is resampled: a four-second walk at 30,000 fps would
/// be 119,001 frames (past the motion limit) if resampled whole, and two are all that play.
#[test]
fn animate_resamples_only_the_frames_it_plays() {
    let out = scratch("avatar-cli-animate-cut");
    let walk = out.join("walk4.npz");
    ok(mannequin(&["motion", "walk", "--seconds", "4", "-o", s(&walk)]));
    let frames = out.join("frames");
    let camera = out.join("camera.json");
    std::fs::write(
        &camera,
        r#"{"K": [[60, 0, 16], [0, 60, 16], [0, 0, 1]], "extrinsic": [[1, 0, 0, 0], [0, -1, 0, 0.2],
            [0, 0, -1, 4], [0, 0, 0, 1]], "width": 32, "height": 32}"#,
    )
    .unwrap();
    let args = ["--fps", "30000", "--max-frames", "2", "--camera", s(&camera), "-o", s(&frames)];
    ok(mannequin(&[&["animate", "--avatar", s(model()), "--motion", s(&walk)][..], &args].concat()));
    assert!(frames.join("frame_0001.png").exists() && !frames.join("frame_0002.png").exists());
    std::fs::remove_dir_all(out).unwrap();
}

#[test]
fn bad_inputs_give_one_line_errors() {
    let out = scratch("avatar-cli-bad");
    let missing = out.join("no_such_model");
    let obj = out.join("x.obj");
    one_line_error(&mannequin(&["export", "--avatar", s(&missing), "-o", s(&obj)]), &["no_such_model"]);
    one_line_error(
        &mannequin(&["animate", "--avatar", s(&missing), "--motion", s(&walk()), "-o", s(&out)]),
        &["no_such_model"],
    );
    one_line_error(
        &mannequin(&["export", "--avatar", s(model()), "--named-pose", "squat", "-o", s(&out.join("a.glb"))]),
        &["a.glb", "bind pose"],
    );
    one_line_error(&mannequin(&["export", "--avatar", s(model()), "-o", s(&out.join("a.fbx"))]), &["a.fbx"]);
    one_line_error(
        &mannequin(&["export", "--avatar", s(model()), "--frame", "3", "-o", s(&obj)]),
        &["--frame", "--motion"],
    );
    assert!(!obj.exists());
    // Enumerated flags fail at once, before any file is read, and list the choices.
    usage_error(
        &mannequin(&["export", "--avatar", s(&missing), "--named-pose", "cartwheel", "-o", s(&obj)]),
        &["cartwheel", "t-pose", "arms-crossed"],
    );
    usage_error(
        &mannequin(&["render", "--avatar", s(&missing), "--what", "colour", "-o", s(&obj)]),
        &["colour", "rgb", "normals", "alpha", "depth"],
    );
    usage_error(
        &mannequin(&[
            "animate",
            "--avatar",
            s(&missing),
            "--motion",
            s(&walk()),
            "--what",
            "x",
            "-o",
            s(&out),
        ]),
        &["rgb", "normals"],
    );
    // A body model is --body and a trained avatar --avatar, on every verb.
    usage_error(
        &mannequin(&["animate", "--model", "default", "--motion", s(&walk()), "-o", s(&out)]),
        &["--model"],
    );
    std::fs::remove_dir_all(out).unwrap();
}

/// `eval --json` as a value.
fn scores(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn eval_scores_each_test_set_afresh_in_one_layout() {
    let out = scratch("avatar-cli-eval");
    let data = model().parent().unwrap().join("data");
    // A stale prediction left in the avatar's eval folder by an earlier run is removed.
    let stale = model().join("eval/novel_view/images/image_0099.png");
    std::fs::create_dir_all(stale.parent().unwrap()).unwrap();
    std::fs::write(&stale, b"stale").unwrap();
    let json = out.join("avatar.json");
    let o = ok(mannequin(&[
        "eval",
        "--avatar",
        s(model()),
        "--data",
        s(&data),
        "--samples",
        "2000",
        "--json",
        s(&json),
    ]));
    assert!(!stale.exists(), "stale prediction left in place");
    let v = scores(&json);
    let keys: Vec<&String> = v.as_object().unwrap().keys().collect();
    assert_eq!(keys, ["geometry", "novel_pose", "novel_view", "test"], "{v}");
    // synth's test sets: 6 novel-view and 2 novel-pose frames at this size; no same-camera set.
    assert!(v["test"].is_null(), "{v}");
    assert_eq!(
        v["novel_view"]["frames"].as_u64(),
        Some(mannequin_data::Dataset::open(data.join("test/novel_view"), 1).unwrap().frame_count as u64)
    );
    assert!(v["geometry"]["chamfer_cm"].as_f64().is_some_and(|c| c > 0.0));
    // The table goes to stdout.
    let table = String::from_utf8_lossy(&o.stdout);
    assert!(table.contains("novel_view") && table.contains("geometry:"), "{table}");

    // A folder without test/ sets is scored on its own held-out frames, named `test`.
    let own = out.join("own.json");
    ok(mannequin(&[
        "eval",
        "--avatar",
        s(model()),
        "--data",
        s(&data.join("test/novel_pose")),
        "--samples",
        "2000",
        "--json",
        s(&own),
    ]));
    let v = scores(&own);
    assert!(v["novel_view"].is_null() && v["test"]["frames"].as_u64().is_some(), "{v}");

    // Predictions against a ground truth: only the ground truth's test frames are scored (here
    // 8 and 9 of the capture), whatever else the folder holds, in the same layout.
    let pred = out.join("pred");
    std::fs::create_dir_all(pred.join("images")).unwrap();
    let gt = mannequin_data::Dataset::open(&data, 1).unwrap();
    let test: Vec<usize> = gt.splits["test"].frames();
    assert_eq!(test, [8, 9]);
    for f in 0..gt.frame_count {
        let mut img = gt.frame(f).unwrap().image;
        if !test.contains(&f) {
            // Frames outside the test split hold garbage that would drag the score down.
            img.pixels.iter_mut().for_each(|p| *p = [0.0, 1.0, 0.0]);
        }
        img.write_png(&pred.join(format!("images/image_{f:04}.png"))).unwrap();
    }
    let pg = out.join("pred.json");
    ok(mannequin(&["eval", "--pred", s(&pred), "--gt", s(&data), "--json", s(&pg)]));
    let v = scores(&pg);
    let keys: Vec<&String> = v.as_object().unwrap().keys().collect();
    assert_eq!(keys, ["geometry", "novel_pose", "novel_view", "test"], "{v}");
    assert_eq!(v["test"]["frames"].as_u64(), Some(2), "{v}");
    let frames: Vec<u64> =
        v["test"]["per_frame"].as_array().unwrap().iter().map(|f| f["frame"].as_u64().unwrap()).collect();
    assert_eq!(frames, [8, 9]);
    // A missing prediction for a test frame is an error naming it, not a skipped frame.
    std::fs::remove_file(pred.join("images/image_0009.png")).unwrap();
    one_line_error(&mannequin(&["eval", "--pred", s(&pred), "--gt", s(&data)]), &["image_0009.png"]);
    std::fs::remove_dir_all(out).unwrap();
}

/// A copy of the trained model in `dir`: its avatar files, not its checkpoint.
fn model_copy(dir: &Path) -> PathBuf {
    let copy = dir.join("model");
    std::fs::create_dir_all(&copy).unwrap();
    for file in ["avatar.json", "avatar.npz"] {
        std::fs::copy(model().join(file), copy.join(file)).unwrap();
    }
    copy
}

/// [`model_copy`] with `key` of `avatar.npz` replaced by `array`.
fn model_with(dir: &Path, key: &str, array: mannequin_io::NpyArray) -> PathBuf {
    let copy = model_copy(dir);
    let npz = mannequin_io::Npz::read(model().join("avatar.npz")).unwrap();
    let mut w = mannequin_io::NpzWriter::new();
    for k in npz.keys().filter(|&k| k != key) {
        w.add(k, npz.get(k).unwrap().clone());
    }
    w.add(key, array);
    // As bytes: the writer refuses the NaN these files are made of.
    std::fs::write(copy.join("avatar.npz"), w.to_bytes()).unwrap();
    copy
}

/// An avatar with a non-finite or meaningless value is refused when it loads, naming the file
/// and the array: `render` once blamed the camera for it, and `export --gaussians` wrote a `.ply`
/// of NaN.
#[test]
fn a_corrupt_avatar_is_refused_by_field() {
    use mannequin_io::NpyArray;
    let out = scratch("avatar-cli-corrupt");
    let npz = mannequin_io::Npz::read(model().join("avatar.npz")).unwrap();
    let spoiled = |key: &str, i: usize, value: f32| {
        let a = npz.get(key).unwrap();
        let mut v = a.to_f32().unwrap();
        v[i] = value;
        NpyArray::f32(a.shape.clone(), v)
    };
    for (key, array, expected) in [
        ("vertices", spoiled("vertices", 7, f32::NAN), "element 7 is NaN"),
        ("joints", spoiled("joints", 2, f32::INFINITY), "element 2 is inf"),
        ("weights", spoiled("weights", 30, f32::NAN), "element 30 is NaN"),
        ("offset_gate", spoiled("offset_gate", 4, 2.0), "element 4 is 2: expected 0–1"),
        ("posedirs", NpyArray::f32(vec![5, 3], vec![0.0; 15]), "expected shape"),
    ] {
        let model = model_with(&out.join(key), key, array);
        let (png, ply) = (out.join("a.png"), out.join("g.ply"));
        for args in [
            &["render", "--avatar", s(&model), "-o", s(&png)][..],
            &["export", "--avatar", s(&model), "--gaussians", s(&ply)],
        ] {
            one_line_error(&mannequin(args), &["avatar.npz", &format!("'{key}'"), expected]);
        }
        assert!(!png.exists() && !ply.exists(), "{key}: an output was written");
    }
    std::fs::remove_dir_all(out).unwrap();
}

/// An `eval` that fails writes nothing: its predictions replace an earlier run's only once every
/// set is scored, and the geometry scores are numbers or an error, never null.
#[test]
fn a_failing_eval_leaves_the_model_folder_as_it_was() {
    let out = scratch("avatar-cli-eval-fails");
    let copy = model_copy(&out);
    let earlier = copy.join("eval/novel_view/images/image_0000.png");
    std::fs::create_dir_all(earlier.parent().unwrap()).unwrap();
    std::fs::write(&earlier, b"earlier").unwrap();
    // The second set fails after the first is rendered and scored.
    let data = out.join("data");
    ok(Command::new("cp").arg("-r").arg(model().parent().unwrap().join("data")).arg(&data).output().unwrap());
    std::fs::write(data.join("test/novel_pose/splits.json"), b"{").unwrap();
    let before: Vec<PathBuf> = walk_files(&copy);
    one_line_error(
        &mannequin(&["eval", "--avatar", s(&copy), "--data", s(&data), "--samples", "500"]),
        &["novel_pose", "splits.json"],
    );
    assert_eq!(walk_files(&copy), before, "the failed eval changed the model folder");
    assert_eq!(std::fs::read(&earlier).unwrap(), b"earlier");
    usage_error(
        &mannequin(&["eval", "--avatar", s(&copy), "--data", s(&data), "--samples", "0"]),
        &["--samples"],
    );
    std::fs::remove_dir_all(out).unwrap();
}

/// Every file under `dir`, sorted.
fn walk_files(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            files.extend(walk_files(&path));
        } else {
            files.push(path);
        }
    }
    files.sort();
    files
}
