//! The committed real photos of people keep their provenance: every file in `tests/data/photos`
//! has a section in its `PROVENANCE.md` with a public-domain or CC0 licence and the head of each
//! person in it (inside the picture), every section names a file that is there, and every photo
//! decodes with the image reader `mannequin fit --image` uses. Issue 36 asks for at least 10
//! distinct originals.

mod photo_provenance;

use std::collections::HashSet;

use mannequin_data::Image;
use photo_provenance::{Head, PhotoEntry, folder, photo_files, read_entries};

/// Issue 36: "at least 10 public-domain or CC0 real photos of people".
const MIN_ORIGINALS: usize = 10;
/// The licences a photo here may have: none that asks anything of the project.
const LICENCES: [&str; 2] = ["public domain", "CC0 1.0"];

fn entries() -> Vec<PhotoEntry> {
    read_entries(&folder()).expect("tests/data/photos/PROVENANCE.md")
}

#[test]
fn every_photo_is_listed_with_a_free_licence_and_decodes() {
    let entries = entries();
    let files = photo_files(&folder()).unwrap();
    assert!(!files.is_empty(), "no photos in {}", folder().display());
    for path in files {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let entry = entries
            .iter()
            .find(|e| e.name == name)
            .unwrap_or_else(|| panic!("{name} has no \"## `{name}`\" section in PROVENANCE.md"));
        let licence = entry.licence.as_deref().unwrap_or_else(|| panic!("{name}: no \"- Licence:\" line"));
        assert!(LICENCES.contains(&licence), "{name}: licence {licence:?} is not one of {LICENCES:?}");
        let heads = entry.heads.as_deref().unwrap_or_else(|| panic!("{name}: no readable \"- Heads:\" line"));
        assert!(!heads.is_empty(), "{name}: no heads");
        let image = Image::read(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        let (w, h) = (image.width as f32, image.height as f32);
        for head in heads {
            let inside = head.x[0] >= 0.0 && head.x[1] <= w && head.y[0] >= 0.0 && head.y[1] <= h;
            assert!(inside, "{name}: head {head:?} is outside the {w}×{h} picture");
        }
    }
}

#[test]
fn every_section_names_a_photo_that_is_there_once() {
    let mut seen = HashSet::new();
    for entry in entries() {
        assert!(
            folder().join(&entry.name).is_file(),
            "PROVENANCE.md lists {}, which is not there",
            entry.name
        );
        assert!(seen.insert(entry.name.clone()), "PROVENANCE.md lists {} twice", entry.name);
    }
}

#[test]
fn at_least_ten_distinct_originals() {
    let originals = entries().iter().filter(|e| !e.derived).count();
    assert!(originals >= MIN_ORIGINALS, "{originals} originals, issue 36 asks for {MIN_ORIGINALS}");
}

#[test]
fn the_reader_finds_sections_licences_heads_and_derivations() {
    let text = "# Title\n\nintro `- Heads: x 1–2, y 1–2`\n\n## `a.jpg`\n\nfrom x\n\n- Licence: CC0 1.0\n\
                - Heads: x 10–20, y 30–50; x 5–8, y 0–4\n\n## Not a photo\n\n- Heads: x 0–1, y 0–1\n\n\
                ## `b.png`\n\n**Derived** from `a.jpg`.\n\n- Heads: x 10–20, y 50–30\n";
    let got = photo_provenance::entries(text);
    assert_eq!(got.len(), 2, "{got:?}");
    let two = vec![Head { x: [10.0, 20.0], y: [30.0, 50.0] }, Head { x: [5.0, 8.0], y: [0.0, 4.0] }];
    // "## Not a photo" ended a.jpg's section: its head is nobody's, and a.jpg keeps its two.
    assert_eq!(
        (got[0].name.as_str(), got[0].licence.as_deref(), got[0].heads.as_ref(), got[0].derived),
        ("a.jpg", Some("CC0 1.0"), Some(&two), false)
    );
    // A box whose range runs backwards does not read, so the line gives no heads at all.
    assert_eq!(
        (got[1].name.as_str(), got[1].licence.as_deref(), got[1].heads.as_ref(), got[1].derived),
        ("b.png", None, None, true)
    );
}

#[test]
fn a_head_holds_points_a_quarter_of_its_size_beyond_its_box() {
    let head = Head { x: [100.0, 200.0], y: [0.0, 40.0] };
    assert!(head.holds([150.0, 20.0]) && head.holds([76.0, -9.0]) && head.holds([224.0, 49.0]));
    assert!(!head.holds([74.0, 20.0]) && !head.holds([226.0, 20.0]) && !head.holds([150.0, 51.0]));
}
