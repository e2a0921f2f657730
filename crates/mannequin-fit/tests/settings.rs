//! Each pipeline's settings parsed from a command line that gives only the required flags equal
//! the settings' `Default`: the flags' defaults are read from it, not written a second time.

use clap::Parser;
use mannequin_fit::frame_source::FrameSource;
use mannequin_fit::{CaptureSettings, FaceTrackSettings, FitSettings};

#[derive(Parser)]
struct Fit {
    #[command(flatten)]
    settings: FitSettings,
}

#[derive(Parser)]
struct Capture {
    #[command(flatten)]
    settings: CaptureSettings,
}

#[derive(Parser)]
struct Track {
    #[command(flatten)]
    settings: FaceTrackSettings,
}

fn frames() -> FrameSource {
    FrameSource { frames: Some("clip".into()), ..FrameSource::default() }
}

#[test]
fn flag_defaults_are_the_settings_defaults() {
    assert_eq!(Fit::parse_from(["fit"]).settings, FitSettings::default());
    let capture = Capture::parse_from(["capture", "--frames", "clip", "--out", "data"]).settings;
    assert_eq!(
        capture,
        CaptureSettings { input: frames(), out: "data".into(), ..CaptureSettings::default() }
    );
    let track = Track::parse_from(["track", "--frames", "clip", "--out", "face"]).settings;
    assert_eq!(
        track,
        FaceTrackSettings { input: frames(), out: "face".into(), ..FaceTrackSettings::default() }
    );
}

#[test]
fn a_focal_length_that_is_no_length_is_refused_naming_the_flag() {
    let settings = Fit::parse_from(["fit", "--focal", "0"]).settings;
    assert_eq!(
        settings.check().unwrap_err().to_string(),
        "--focal: expected a positive number of pixels, found 0"
    );
    let e = FitSettings { body: "default-lod1".into(), focal: None }.check_face_body().unwrap_err();
    assert!(
        e.to_string().starts_with("--body default-lod1: the face model is the embedded default body's"),
        "{e}"
    );
}
