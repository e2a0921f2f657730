//! The committed real photos of people (`tests/data/photos`) and what their `PROVENANCE.md` says
//! of each, read one way for both the provenance test (`tests/photos.rs`) and the
//! `photo_census` example.

use std::path::{Path, PathBuf};

/// The file beside the photos that lists them.
pub const PROVENANCE: &str = "PROVENANCE.md";

/// What `PROVENANCE.md` says of one photo.
#[derive(Debug, Default)]
pub struct PhotoEntry {
    /// The file name, from the section's heading "## `name`".
    pub name: String,
    /// The text after "- Licence: ".
    pub licence: Option<String>,
    /// How many people a person sees in it, after "- People: ".
    pub people: Option<usize>,
    /// Made from another photo here (marked **Derived**), not a distinct original.
    pub derived: bool,
}

/// The committed photos' folder.
pub fn folder() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/photos")
}

/// Every file in `folder` but the provenance itself, by name: anything put there is a photo
/// that must be listed and must decode.
pub fn photo_files(folder: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(folder)? {
        let path = entry?.path();
        if path.is_file() && path.file_name().is_some_and(|n| n != PROVENANCE) {
            out.push(path);
        }
    }
    out.sort();
    Ok(out)
}

/// The sections of a `PROVENANCE.md`, in order; any other "## " heading ends a section and
/// starts none, so its lines are nobody's.
pub fn entries(text: &str) -> Vec<PhotoEntry> {
    let mut out: Vec<PhotoEntry> = Vec::new();
    let mut in_section = false;
    for line in text.lines() {
        if let Some(heading) = line.strip_prefix("## ") {
            let name = heading.trim().strip_prefix('`').and_then(|h| h.strip_suffix('`'));
            in_section = name.is_some();
            if let Some(name) = name {
                out.push(PhotoEntry { name: name.to_string(), ..PhotoEntry::default() });
            }
            continue;
        }
        let Some(entry) = out.last_mut().filter(|_| in_section) else { continue };
        if let Some(licence) = line.strip_prefix("- Licence: ") {
            entry.licence = Some(licence.trim().to_string());
        } else if let Some(people) = line.strip_prefix("- People: ") {
            entry.people = people.trim().parse().ok();
        } else if line.starts_with("**Derived**") {
            entry.derived = true;
        }
    }
    out
}

/// The entries of the `PROVENANCE.md` in `folder`.
pub fn read_entries(folder: &Path) -> std::io::Result<Vec<PhotoEntry>> {
    Ok(entries(&std::fs::read_to_string(folder.join(PROVENANCE))?))
}
