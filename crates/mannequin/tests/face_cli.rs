//! `mannequin face fit` as a user runs it, on the public-domain portrait `astronaut.png`: the
//! face model fitted to MediaPipe's face mesh within the 3 % of the eyes' distance, and
//! the pictures it cannot fit refused in one line with nothing written.

use std::path::Path;

mod common;
use common::{mannequin, ok, one_line_error, s, scratch};
use mannequin_data::Image;

fn picture(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../mannequin-fit/tests/data").join(name)
}

#[test]
fn a_portrait_gets_its_face_fitted_within_three_percent_of_the_eyes_distance() {
    let dir = scratch("face_fit");
    let out = dir.join("astronaut");
    ok(mannequin(&["face", "fit", "--image", s(&picture("astronaut.png")), "--out", s(&out)]));
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("fit.json")).unwrap()).unwrap();
    let mean = report["landmark_error_iod"]["mean"].as_f64().unwrap();
    println!("astronaut: mean landmark error {:.2} % of the eyes' distance", 100.0 * mean);
    assert!(mean < 0.03, "mean landmark error {mean} of the inter-ocular distance");
    let expression = report["expression"].as_array().unwrap();
    assert_eq!(expression.len(), 52);
    assert!(expression.iter().all(|e| (-0.1..=1.1).contains(&e.as_f64().unwrap())), "{expression:?}");
    let overlay = Image::read(&out.join("overlay.png")).unwrap();
    assert_eq!((overlay.width, overlay.height), (512, 512));
    let text = std::fs::read_to_string(out.join("face.obj")).unwrap();
    let coloured = text.lines().filter(|l| l.starts_with("v ") && l.split_whitespace().count() == 7).count();
    assert!(coloured > 4000, "{coloured} coloured vertices");
}

#[test]
fn pictures_without_a_fittable_face_are_refused_in_one_line() {
    let dir = scratch("face_refusals");
    let photo = Image::read(&picture("astronaut.png")).unwrap();
    let small = dir.join("small.png");
    photo.downscale(4).write_png(&small).unwrap();
    let out = dir.join("out");
    one_line_error(
        &mannequin(&["face", "fit", "--image", s(&small), "--out", s(&out)]),
        &["small.png", "pixels across", "at least 48"],
    );
    let sky = dir.join("sky.png");
    let camera = Image::read(&picture("camera.png")).unwrap();
    let pixels =
        (0..200).flat_map(|y| (300..500).map(move |x| (x, y))).map(|(x, y)| camera.at(x, y)).collect();
    Image { width: 200, height: 200, pixels }.write_png(&sky).unwrap();
    one_line_error(
        &mannequin(&["face", "fit", "--image", s(&sky), "--out", s(&out)]),
        &["sky.png", "no face found"],
    );
    one_line_error(
        &mannequin(&[
            "face",
            "fit",
            "--image",
            s(&picture("astronaut.png")),
            "--body",
            "default-lod1",
            "--out",
            s(&out),
        ]),
        &["--body default-lod1", "default body"],
    );
    assert!(!out.exists(), "a refused fit writes nothing");
}
