//! How many of the committed real photos find a person (issue 36): runs the person finder that
//! `mannequin fit --image` runs ([`PersonModels::people`], then [`pick_person`] with no
//! `--person`) on every photo in `tests/data/photos` (or the folder given), and prints per photo
//! how many people it finds against how many `PROVENANCE.md` says are there, whether `fit` would
//! take one, and then "N of M find a person". It calls only the public API, so it measures
//! whatever the finder does now.
//!
//! `cargo run --release -p mannequin-fit --example photo_census [-- FOLDER]`

// Shared with the provenance test, which reads more of each entry than the census does.
#[allow(dead_code)]
#[path = "../tests/photo_provenance/mod.rs"]
mod photo_provenance;

use std::path::PathBuf;
use std::time::Instant;

use mannequin_data::Image;
use mannequin_fit::{PersonModels, pick_person};
use photo_provenance::{folder, photo_files, read_entries};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let folder = std::env::args().nth(1).map(PathBuf::from).unwrap_or_else(folder);
    let photos = photo_files(&folder).map_err(|e| format!("{}: {e}", folder.display()))?;
    if photos.is_empty() {
        return Err(format!("{}: no photos", folder.display()).into());
    }
    // A folder without a provenance still gets counted, with nobody's count to compare.
    let entries = read_entries(&folder).unwrap_or_default();
    let models = PersonModels::load()?;
    println!("{:<32} {:>10} {:>11} {:>7}  fit without --person", "photo", "size", "found/there", "seconds");
    let (mut found, mut picked, mut originals, mut originals_found) = (0, 0, 0, 0);
    for path in &photos {
        let name = path.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        let entry = entries.iter().find(|e| e.name == name);
        let there = entry.and_then(|e| e.people);
        let original = entry.is_some_and(|e| !e.derived);
        originals += usize::from(original);
        let image = match Image::read(path) {
            Ok(image) => image,
            Err(e) => {
                println!("{name:<32} unreadable: {e}");
                continue;
            }
        };
        let start = Instant::now();
        let people = models.people(&image)?;
        let seconds = start.elapsed().as_secs_f64();
        let verdict = match pick_person(&people, None) {
            Ok(person) => {
                picked += 1;
                let b = person.detection.bbox;
                format!("yes: x {:.0}–{:.0}, y {:.0}–{:.0}", b[0], b[2], b[1], b[3])
            }
            Err(e) => format!("no: {e}"),
        };
        found += usize::from(!people.is_empty());
        originals_found += usize::from(original && !people.is_empty());
        let size = format!("{}×{}", image.width, image.height);
        let count = format!("{}/{}", people.len(), there.map_or("?".into(), |n| n.to_string()));
        println!("{name:<32} {size:>10} {count:>11} {seconds:>7.2}  {verdict}");
    }
    let total = photos.len();
    println!(
        "{found} of {total} find a person ({originals_found} of {originals} originals); \
         {picked} of {total} give `fit` a person without --person"
    );
    Ok(())
}
