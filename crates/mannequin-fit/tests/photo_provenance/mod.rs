//! The committed real photos of people (`tests/data/photos`) and what their `PROVENANCE.md` says
//! of each, read one way for both the provenance test (`tests/photos.rs`) and the
//! `photo_census` example.

use std::path::{Path, PathBuf};

/// The file beside the photos that lists them.
pub const PROVENANCE: &str = "PROVENANCE.md";

/// Where one person's head is, in the photo's pixels, marked by eye.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Head {
    pub x: [f32; 2],
    pub y: [f32; 2],
}

impl Head {
    /// Whether the point lies on this head, the box grown by a quarter of its size each way
    /// (boxes marked by eye, a nose near a chin or an ear).
    pub fn holds(&self, point: [f32; 2]) -> bool {
        let near = |[lo, hi]: [f32; 2], v: f32| (lo - 0.25 * (hi - lo)..=hi + 0.25 * (hi - lo)).contains(&v);
        near(self.x, point[0]) && near(self.y, point[1])
    }

    /// "x A–B, y C–D", as `PROVENANCE.md` writes a head.
    fn parse(text: &str) -> Option<Self> {
        let range = |t: &str| -> Option<[f32; 2]> {
            let (lo, hi) = t.split_once('–')?;
            let (lo, hi) = (lo.trim().parse().ok()?, hi.trim().parse().ok()?);
            (lo < hi).then_some([lo, hi])
        };
        let (x, y) = text.trim().split_once(", ")?;
        Some(Self { x: range(x.strip_prefix("x ")?)?, y: range(y.strip_prefix("y ")?)? })
    }
}

/// What `PROVENANCE.md` says of one photo.
#[derive(Debug, Default)]
pub struct PhotoEntry {
    /// The file name, from the section's heading "## `name`".
    pub name: String,
    /// The text after "- Licence: ".
    pub licence: Option<String>,
    /// Every person's head, after "- Heads: " ("x A–B, y C–D" joined by "; "); None when the
    /// line is missing or any box in it does not read.
    pub heads: Option<Vec<Head>>,
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
        } else if let Some(heads) = line.strip_prefix("- Heads: ") {
            entry.heads = heads.split(';').map(Head::parse).collect();
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
