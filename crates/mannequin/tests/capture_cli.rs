//! `mannequin capture` as a user runs it, on a clip cut from a real photo (`camera.png`, CC0): a
//! 448² window sliding 8 px to the right per frame, so the person slides 8 px to the left. The
//! dataset it writes must open as a training set, and the fitted body must slide with the
//! person, an expectation the fit never sees.

use std::path::Path;

mod common;
use common::{mannequin, ok, one_line_error, s, scratch};
use mannequin_data::{Dataset, Image};

const STEP: usize = 8;
const SIDE: usize = 448;

fn camera_png() -> Image {
    Image::read(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../mannequin-fit/tests/data/camera.png"))
        .unwrap()
}

fn window(image: &Image, x0: usize) -> Image {
    let pixels = (0..SIDE)
        .flat_map(|y| (0..SIDE).map(move |x| (x, y)))
        .map(|(x, y)| image.at(x0 + x, 32 + y))
        .collect();
    Image { width: SIDE, height: SIDE, pixels }
}

#[test]
fn a_sliding_clip_becomes_a_dataset_whose_body_slides_with_the_person() {
    let dir = scratch("capture_slide");
    let frames = sliding_frames(&dir);
    let out = dir.join("dataset");
    ok(mannequin(&["capture", "--frames", s(&frames), "--out", s(&out)]));
    let data = Dataset::open(&out, 1).unwrap();
    let train = data.split("train").unwrap();
    let test = data.split("test").unwrap();
    assert_eq!((train.frames.len(), test.frames.len()), (4, 1));
    let model = mannequin_body::BodyModel::default_body();
    let mut poses = train.poses.clone();
    poses.append(&test.poses);
    let camera = data.camera(0);
    // The head and neck: seen in every frame, unlike the legs (out of the picture) or the hands
    // (on the camera, where the landmarks jump by tens of pixels as the crop moves).
    let head_u: Vec<f64> = (0..5)
        .map(|i| {
            let posed =
                mannequin_body::forward(&model, &poses.betas, &poses.pose72(i), &poses.transl[i]).unwrap();
            let u = |j: usize| {
                let p = glam::Vec3::from_slice(&posed.joints[3 * j..3 * j + 3]).as_dvec3();
                camera.project(camera.world_to_camera(p))[0]
            };
            (u(mannequin_body::smpl_joint::HEAD) + u(mannequin_body::smpl_joint::NECK)) / 2.0
        })
        .collect();
    println!("head and neck u per frame: {head_u:?}");
    let moved = head_u[4] - head_u[0];
    let want = -4.0 * STEP as f64;
    assert!((moved - want).abs() < 6.0, "head and neck moved {moved:.1} px over the clip, the person {want}");
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("capture.json")).unwrap()).unwrap();
    for f in report["frames"].as_array().unwrap() {
        let e = f["median_landmark_error_px"].as_f64().unwrap();
        assert!(e < 8.0, "median landmark error {e} px in {}", f["source"]);
    }
    // The coat widens the mask beyond the body (the photo alone gives 0.64).
    let iou = report["mean_mask_iou"].as_f64().unwrap();
    assert!(iou > 0.5, "mean mask IoU {iou}");
    // The same clip as a still person and a moving camera: every frame's body must land where
    // the static camera saw it.
    let still = dir.join("still");
    ok(mannequin(&["capture", "--frames", s(&frames), "--out", s(&still), "--moving-camera"]));
    let moved = Dataset::open(&still, 1).unwrap();
    let (a, b) = (moved.split("train").unwrap().poses, moved.split("test").unwrap().poses);
    for i in 0..5 {
        let (pose, transl) = if i < 4 { (a.pose72(i), a.transl[i]) } else { (b.pose72(0), b.transl[0]) };
        assert_eq!((&pose[..3], transl), (&a.pose72(0)[..3], a.transl[0]), "the body holds still");
        let seen = mannequin_body::forward(&model, &a.betas, &pose, &transl).unwrap();
        let want = mannequin_body::forward(&model, &poses.betas, &poses.pose72(i), &poses.transl[i]).unwrap();
        for (p, q) in seen.vertices.chunks_exact(3).zip(want.vertices.chunks_exact(3)).step_by(97) {
            let uv = |c: &mannequin_data::Camera, p: &[f32]| {
                c.project(c.world_to_camera(glam::Vec3::from_slice(p).as_dvec3()))
            };
            let (x, y) = (uv(moved.camera(i), p), uv(camera, q));
            assert!((x[0] - y[0]).hypot(x[1] - y[1]) < 0.05, "frame {i}: {x:?} against {y:?}");
        }
    }
    let overlay = Image::read(&out.join("overlay/frame_0004.png")).unwrap();
    assert_eq!((overlay.width, overlay.height), (SIDE, SIDE));
    let frame = data.frame(2).unwrap();
    let share = frame.mask.count() as f64 / (SIDE * SIDE) as f64;
    assert!(share > 0.2 && share < 0.8, "the mask covers {share:.2} of the frame");
}

fn sliding_frames(dir: &Path) -> std::path::PathBuf {
    let frames = dir.join("frames");
    std::fs::create_dir_all(&frames).unwrap();
    let photo = camera_png();
    for k in 0..5 {
        window(&photo, STEP * k).write_png(&frames.join(format!("f{k}.png"))).unwrap();
    }
    frames
}

/// A capture killed once its first checkpoint is written resumes from it and ends with what an
/// uninterrupted capture writes; a checkpoint of other settings is refused, naming them.
#[test]
fn a_killed_capture_resumes_to_the_same_dataset() {
    let dir = scratch("capture_resume");
    let frames = sliding_frames(&dir);
    let whole = dir.join("whole");
    ok(mannequin(&["capture", "--frames", s(&frames), "--out", s(&whole)]));
    let cut = dir.join("cut");
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_mannequin"))
        .args(["capture", "--frames", s(&frames), "--out", s(&cut)])
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let checkpoint = cut.join("checkpoint.npz");
    while !checkpoint.exists() {
        assert!(child.try_wait().unwrap().is_none(), "the capture ended before writing a checkpoint");
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(!cut.join("capture.json").exists(), "the capture finished before it was killed");
    one_line_error(
        &mannequin(&["capture", "--frames", s(&frames), "--out", s(&cut), "--focal", "500"]),
        &["checkpoint.npz", "another run", "focal", "--restart"],
    );
    let resumed = ok(mannequin(&["capture", "--frames", s(&frames), "--out", s(&cut)]));
    assert!(String::from_utf8_lossy(&resumed.stderr).contains("resuming"));
    assert!(!checkpoint.exists(), "a finished capture leaves no checkpoint");
    for file in
        ["poses/anim_nerf_train.npz", "poses/anim_nerf_test.npz", "cameras.npz", "masks/mask_0003.npy"]
    {
        assert_eq!(
            std::fs::read(whole.join(file)).unwrap(),
            std::fs::read(cut.join(file)).unwrap(),
            "{file}"
        );
    }
}

#[test]
fn clips_that_cannot_make_a_dataset_are_refused_in_one_line() {
    let dir = scratch("capture_refusals");
    let frames = dir.join("one");
    std::fs::create_dir_all(&frames).unwrap();
    window(&camera_png(), 0).write_png(&frames.join("f0.png")).unwrap();
    let out = dir.join("out");
    one_line_error(
        &mannequin(&["capture", "--frames", s(&frames), "--out", s(&out)]),
        &["1 frame(s)", "at least 2"],
    );
    assert!(!out.exists(), "a refused capture writes nothing");
    one_line_error(
        &mannequin(&["capture", "--video", s(&dir.join("missing.mp4")), "--out", s(&out)]),
        &["missing.mp4", "no such video file"],
    );
}
