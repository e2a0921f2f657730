//! `mannequin capture` as a user runs it: a video file (made by ffmpeg from a synthetic
//! subject's frames, so the person's true masks are known) captured to a dataset, and the clips
//! a capture must refuse, each in one line naming the file or frame, with nothing left behind.
//! These tests need the ffmpeg program (CI installs it in `.ci/run`); without it they fail.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use mannequin_data::Image;
use mannequin_data::maps::read_mask_npy;

mod common;
use common::{mannequin, ok, one_line_error, s, scratch};

/// Frames the capture takes from the clip (`--max-frames`): fewer than the clip has, so the
/// test sees that no more were decoded.
const TAKEN: usize = 6;

/// A small synthetic subject (`synth`'s fewest frames, 128², the light body), made once for all
/// the tests here: its `images/` and true `masks/`.
fn subject() -> &'static Path {
    static SUBJECT: OnceLock<PathBuf> = OnceLock::new();
    SUBJECT.get_or_init(|| {
        let dir = scratch("capture_subject").join("data");
        ok(mannequin(&[
            "synth",
            "--no-self-collision",
            "--seed",
            "2",
            "--size",
            "128",
            "--supersample",
            "1",
            "--frames",
            "9",
            "--train",
            "8",
            "--body",
            "default-lod1",
            "--out",
            s(&dir),
        ]));
        dir
    })
}

/// Runs ffmpeg with `args`, failing the test with what to install when it is missing.
fn ffmpeg(args: &[&str]) {
    let out = Command::new("ffmpeg").args(["-loglevel", "error", "-y"]).args(args).output();
    let out = match out {
        Ok(o) => o,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            panic!("this test needs the ffmpeg program on PATH (Debian/Ubuntu: apt-get install ffmpeg)")
        }
        Err(e) => panic!("running ffmpeg: {e}"),
    };
    assert!(out.status.success(), "ffmpeg {args:?}: {}", String::from_utf8_lossy(&out.stderr));
}

/// An H.264 clip of the subject's frames `first..first + count`.
fn clip(path: &Path, first: usize, count: usize) {
    let pattern = subject().join("images/image_%04d.png");
    ffmpeg(&[
        "-framerate",
        "10",
        "-start_number",
        &first.to_string(),
        "-i",
        s(&pattern),
        "-frames:v",
        &count.to_string(),
        "-pix_fmt",
        "yuv420p",
        "-c:v",
        "libx264",
        s(path),
    ]);
}

fn files(dir: &Path) -> usize {
    std::fs::read_dir(dir).map_or(0, |d| d.count())
}

#[test]
fn a_video_is_captured_into_a_dataset_that_holds_the_person() {
    let dir = scratch("capture_video");
    let video = dir.join("clip.mp4");
    clip(&video, 0, 9);
    let out = dir.join("out");
    ok(mannequin(&[
        "capture",
        "--video",
        s(&video),
        "--max-frames",
        &TAKEN.to_string(),
        "--person",
        "0",
        "--out",
        s(&out),
    ]));
    assert_eq!(files(&out.join("images")), TAKEN, "one dataset frame per frame taken");
    assert!(!out.join(".frames").exists(), "the decoded frames are removed");
    assert!(!out.join("checkpoint.npz").exists(), "a finished capture leaves no checkpoint");
    let dataset = mannequin_data::Dataset::open(&out, 1).unwrap();
    assert_eq!(dataset.frame_count, TAKEN);
    // The masks the capture found against the subject's true ones (as rendered, before the
    // clip's lossy encoding).
    for i in 0..TAKEN {
        let found = dataset.frame(i).unwrap().mask;
        let truth = read_mask_npy(&subject().join(format!("masks/mask_{i:04}.npy"))).unwrap();
        let iou = found.iou(&truth);
        println!("frame {i}: mask IoU {iou:.3} with the truth");
        assert!(iou > 0.6, "frame {i}: the captured mask overlaps the true one by IoU {iou:.3}");
    }
}

#[test]
fn a_clip_too_short_to_split_is_refused_before_tracking() {
    let dir = scratch("capture_short");
    let video = dir.join("one_frame.mp4");
    clip(&video, 0, 1);
    let out = dir.join("out");
    one_line_error(
        &mannequin(&["capture", "--video", s(&video), "--out", s(&out)]),
        &["one_frame.mp4", "1 frame(s)", "at least 2"],
    );
    assert!(!out.exists(), "nothing is written");
}

#[test]
fn frames_of_different_sizes_are_refused_naming_the_odd_one() {
    let dir = scratch("capture_sizes");
    let frames = dir.join("frames");
    std::fs::create_dir_all(&frames).unwrap();
    let first = Image::read(&subject().join("images/image_0000.png")).unwrap();
    first.write_png(&frames.join("a.png")).unwrap();
    first.downscale(2).write_png(&frames.join("b.png")).unwrap();
    let out = dir.join("out");
    one_line_error(
        &mannequin(&["capture", "--frames", s(&frames), "--out", s(&out)]),
        &["b.png", "64×64", "128×128"],
    );
    assert!(!out.exists(), "nothing is written");
}

#[test]
fn a_person_lost_for_most_of_the_clip_is_refused_naming_the_first_frame_without_them() {
    let dir = scratch("capture_lost");
    let frames = dir.join("frames");
    std::fs::create_dir_all(&frames).unwrap();
    for i in 0..2 {
        std::fs::copy(subject().join(format!("images/image_{i:04}.png")), frames.join(format!("{i}.png")))
            .unwrap();
    }
    let empty = Image { width: 128, height: 128, pixels: vec![[0.5; 3]; 128 * 128] };
    for i in 2..6 {
        empty.write_png(&frames.join(format!("{i}.png"))).unwrap();
    }
    let out = dir.join("out");
    one_line_error(
        &mannequin(&["capture", "--frames", s(&frames), "--out", s(&out)]),
        &["2.png", "found in 2 of 6", "at least 3"],
    );
    assert!(!out.exists(), "nothing is left: not the frames tracked, nor a checkpoint");
}

#[test]
fn a_person_index_out_of_range_is_refused_naming_the_frame_and_how_many_were_found() {
    let dir = scratch("capture_person");
    let frames = dir.join("frames");
    std::fs::create_dir_all(&frames).unwrap();
    for i in 0..3 {
        std::fs::copy(subject().join(format!("images/image_{i:04}.png")), frames.join(format!("{i}.png")))
            .unwrap();
    }
    let out = dir.join("out");
    one_line_error(
        &mannequin(&["capture", "--frames", s(&frames), "--person", "2", "--out", s(&out)]),
        &["0.png", "--person 2", "found 1 person"],
    );
    assert!(!out.exists(), "nothing is written");
}

/// Frames with two people side by side on a 256 × 128 canvas: the subject's frame i on the
/// left and its frame i + 4 on the right.
fn two_people(frames: &Path, count: usize) {
    std::fs::create_dir_all(frames).unwrap();
    for i in 0..count {
        let read = |k: usize| Image::read(&subject().join(format!("images/image_{k:04}.png"))).unwrap();
        let (left, right) = (read(i), read(i + 4));
        let pixels = (0..256 * 128)
            .map(|p| {
                let (x, y) = (p % 256, p / 256);
                if x < 128 { left.at(x, y) } else { right.at(x - 128, y) }
            })
            .collect();
        Image { width: 256, height: 128, pixels }.write_png(&frames.join(format!("{i}.png"))).unwrap();
    }
}

/// Whether a mask lies on the canvas's left half (ten times more of it there than on the right),
/// its right half, or neither (None).
fn side(mask: &mannequin_data::Mask) -> Option<bool> {
    let left =
        (0..mask.height).flat_map(|y| (0..128).map(move |x| (x, y))).filter(|&(x, y)| mask.at(x, y)).count();
    let right = mask.count() - left;
    println!("mask: {left} px on the left, {right} on the right");
    match (left > 10 * right.max(1), right > 10 * left.max(1)) {
        (true, _) => Some(true),
        (_, true) => Some(false),
        _ => None,
    }
}

#[test]
fn the_person_asked_for_is_followed_through_the_clip() {
    let dir = scratch("capture_two");
    let frames = dir.join("frames");
    two_people(&frames, 4);
    let mut sides = Vec::new();
    for person in ["0", "1"] {
        let out = dir.join(format!("person_{person}"));
        ok(mannequin(&["capture", "--frames", s(&frames), "--person", person, "--out", s(&out)]));
        let dataset = mannequin_data::Dataset::open(&out, 1).unwrap();
        assert_eq!(dataset.frame_count, 4, "--person {person}: the person is in every frame");
        let first = side(&dataset.frame(0).unwrap().mask);
        assert!(first.is_some(), "--person {person}: frame 0's mask covers both people");
        for i in 1..4 {
            assert_eq!(
                side(&dataset.frame(i).unwrap().mask),
                first,
                "--person {person}, frame {i}: another person"
            );
        }
        sides.push(first);
    }
    assert_ne!(sides[0], sides[1], "--person 0 and --person 1 follow different people");
}

#[test]
fn a_resumed_capture_following_another_person_is_refused() {
    let dir = scratch("capture_resume");
    let frames = dir.join("frames");
    std::fs::create_dir_all(&frames).unwrap();
    for i in 0..2 {
        std::fs::copy(subject().join(format!("images/image_{i:04}.png")), frames.join(format!("{i}.png")))
            .unwrap();
    }
    let out = dir.join("out");
    // A focal length far off the frames' size is refused only once they are tracked and
    // checkpointed: a stopped capture with a checkpoint to resume from.
    let stopped = mannequin(&["capture", "--frames", s(&frames), "--focal", "1", "--out", s(&out)]);
    one_line_error(&stopped, &["--focal"]);
    assert!(out.join("checkpoint.npz").exists(), "the tracked frames are checkpointed");
    one_line_error(
        &mannequin(&["capture", "--frames", s(&frames), "--focal", "1", "--person", "0", "--out", s(&out)]),
        &["checkpoint.npz", "person was null, now 0"],
    );
    assert!(out.join("checkpoint.npz").exists(), "the refused checkpoint is kept");
}
