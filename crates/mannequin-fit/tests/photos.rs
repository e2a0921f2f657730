//! The committed real photos of people keep their provenance: every file in `tests/data/photos`
//! has a section in its `PROVENANCE.md` with a public-domain or CC0 licence and a count of the
//! people in it, every section names a file that is there, and every photo decodes with the
//! image reader `mannequin fit --image` uses. Issue 36 asks for at least 10 distinct originals.

mod photo_provenance;

use std::collections::HashSet;

use mannequin_data::Image;
use photo_provenance::{PhotoEntry, folder, photo_files, read_entries};

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
        assert!(entry.people.is_some_and(|n| n > 0), "{name}: no \"- People: N\" line with N ≥ 1");
        let image = Image::read(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(image.width > 0 && image.height > 0, "{name}: empty");
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
fn the_reader_finds_sections_licences_counts_and_derivations() {
    let text = "# Title\n\nintro `- People: 9`\n\n## `a.jpg`\n\nfrom x\n\n- Licence: CC0 1.0\n- People: 3\n\n\
                ## Not a photo\n\n- People: 7\n\n## `b.png`\n\n**Derived** from `a.jpg`.\n\n- People: two\n";
    let got = photo_provenance::entries(text);
    assert_eq!(got.len(), 2, "{got:?}");
    // "## Not a photo" ended a.jpg's section: its count of 7 is nobody's, and a.jpg keeps 3.
    assert_eq!(
        (got[0].name.as_str(), got[0].licence.as_deref(), got[0].people, got[0].derived),
        ("a.jpg", Some("CC0 1.0"), Some(3), false)
    );
    assert_eq!(
        (got[1].name.as_str(), got[1].licence.as_deref(), got[1].people, got[1].derived),
        ("b.png", None, None, true)
    );
}
