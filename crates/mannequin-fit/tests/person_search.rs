//! The search for a person the whole-picture detector misses: a person small at one side of a
//! wide landscape picture (the detector sees the whole picture shrunk to 224², the person a
//! dozen pixels tall) is found in the overlapping windows, where they are.

use std::path::PathBuf;
use std::sync::OnceLock;

use mannequin_data::Image;
use mannequin_fit::PersonModels;

fn models() -> &'static PersonModels {
    static MODELS: OnceLock<PersonModels> = OnceLock::new();
    MODELS.get_or_init(|| PersonModels::load().unwrap())
}

fn picture(name: &str) -> Image {
    Image::read(&PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)).unwrap()
}

/// `person` shrunk `factor` times and pasted on a grey `width` × `height` canvas with its top-left
/// corner at `at`.
fn landscape(person: &Image, factor: usize, width: usize, height: usize, at: [usize; 2]) -> Image {
    let small = person.downscale(factor);
    let mut canvas = Image { width, height, pixels: vec![[0.5; 3]; width * height] };
    for y in 0..small.height {
        for x in 0..small.width {
            canvas.pixels[(at[1] + y) * width + at[0] + x] = small.at(x, y);
        }
    }
    canvas
}

#[test]
fn a_small_person_in_a_wide_picture_is_found_in_the_windows_where_they_are() {
    let astronaut = picture("astronaut.png");
    let whole = models().people(&astronaut, None).unwrap();
    let nose = whole[0].landmarks.points[0];
    let (factor, at) = (4, [1750, 200]);
    let canvas = landscape(&astronaut, factor, 2000, 400, at);
    assert!(
        models().in_whole_picture(&canvas).unwrap().is_empty(),
        "the whole-picture detector should miss the person, or the test tests nothing"
    );
    let people = models().people(&canvas, None).unwrap();
    assert_eq!(
        people.len(),
        1,
        "one person: {:?}",
        people.iter().map(|p| p.detection.bbox).collect::<Vec<_>>()
    );
    let found = people[0].landmarks.points[0];
    let want = [at[0] as f32 + nose[0] / factor as f32, at[1] as f32 + nose[1] / factor as f32];
    let off = (found[0] - want[0]).hypot(found[1] - want[1]);
    println!("nose at {found:?}, expected {want:?}: {off:.1} px");
    assert!(off < 4.0, "the nose is {off:.1} px from where the person was pasted ({found:?} vs {want:?})");
}

#[test]
fn an_upper_body_portrait_gives_its_body_from_the_face() {
    let hopper = picture("grace_hopper.jpg");
    let people = models().below_faces(&hopper).unwrap();
    assert!(!people.is_empty(), "no body below Grace Hopper's face");
    let face = people[0].detection.bbox;
    let nose = people[0].landmarks.points[0];
    println!("face box {face:?}, nose {nose:?}, flag {}", people[0].landmarks.flag);
    assert!(
        nose[0] > face[0] && nose[0] < face[2] && nose[1] > face[1] && nose[1] < face[3],
        "the body's nose {nose:?} lies outside the face it was seeded from {face:?}"
    );
}
