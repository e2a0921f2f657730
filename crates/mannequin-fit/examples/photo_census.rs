//! How many of the committed real photos find a person (issue 36): runs the person finder that
//! `mannequin fit --image` runs ([`PersonModels::people`], then [`pick_person`] with no
//! `--person`) on every photo in `tests/data/photos` (or the folder given) and prints, per photo,
//! how many people it finds ("found": readings of anyone), how many of the people there it
//! reaches ("real": heads marked in `PROVENANCE.md` with some reading's nose on them) of how
//! many there are ("there"), and whether `fit` would take one and if it is real; then "N of M
//! find a person". It calls only the public API, so it measures whatever the finder does now.
//!
//! `cargo run --release -p mannequin-fit --example photo_census [-- FOLDER]`

// Shared with the provenance test, which reads more of each entry than the census does.
#[allow(dead_code)]
#[path = "../tests/photo_provenance/mod.rs"]
mod photo_provenance;

use std::path::PathBuf;
use std::time::Instant;

use mannequin_data::Image;
use mannequin_fit::{Person, PersonModels, pick_person};
use photo_provenance::{Head, folder, photo_files, read_entries};

/// Photos counted by what the finder made of them.
#[derive(Default)]
struct Tally {
    photos: usize,
    /// Found anyone at all.
    found: usize,
    /// Found someone whose nose lies on a marked head.
    real: usize,
    /// `fit` would take a person without `--person`, and that one is real.
    picked_real: usize,
    /// People marked in the photos, and how many of them some reading reached.
    people: usize,
    people_reached: usize,
}

impl Tally {
    fn add(&mut self, found: bool, reached: usize, there: usize, picked_real: bool) {
        self.photos += 1;
        self.found += usize::from(found);
        self.real += usize::from(reached > 0);
        self.picked_real += usize::from(picked_real);
        self.people += there;
        self.people_reached += reached;
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let folder = std::env::args().nth(1).map(PathBuf::from).unwrap_or_else(folder);
    let photos = photo_files(&folder).map_err(|e| format!("{}: {e}", folder.display()))?;
    if photos.is_empty() {
        return Err(format!("{}: no photos", folder.display()).into());
    }
    // A folder without a provenance is still counted, with no heads to tell real people by.
    let entries = read_entries(&folder).unwrap_or_default();
    let models = PersonModels::load()?;
    println!(
        "{:<32} {:>10} {:>5} {:>4} {:>5} {:>7}  fit without --person",
        "photo", "size", "found", "real", "there", "seconds"
    );
    let (mut all, mut originals) = (Tally::default(), Tally::default());
    for path in &photos {
        let name = path.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        let entry = entries.iter().find(|e| e.name == name);
        let heads: &[Head] = entry.and_then(|e| e.heads.as_deref()).unwrap_or_default();
        let image = match Image::read(path) {
            Ok(image) => image,
            Err(e) => {
                println!("{name:<32} unreadable: {e}");
                continue;
            }
        };
        let start = Instant::now();
        let people = models.people(&image, None)?;
        let seconds = start.elapsed().as_secs_f64();
        let on = |p: &Person, h: &Head| p.landmarks.points.first().is_some_and(|n| h.holds([n[0], n[1]]));
        let is_real = |p: &Person| heads.iter().any(|h| on(p, h));
        // Distinct people reached: one person read twice counts once.
        let real = heads.iter().filter(|h| people.iter().any(|p| on(p, h))).count();
        let (verdict, picked_real) = match pick_person(&people, None) {
            Ok(person) => {
                let nose = person.landmarks.points.first().map_or([f32::NAN; 3], |n| *n);
                let place = if is_real(person) { "on a head" } else { "on no head" };
                (format!("yes: nose at ({:.0}, {:.0}), {place}", nose[0], nose[1]), is_real(person))
            }
            Err(e) => (format!("no: {e}"), false),
        };
        all.add(!people.is_empty(), real, heads.len(), picked_real);
        if entry.is_some_and(|e| !e.derived) {
            originals.add(!people.is_empty(), real, heads.len(), picked_real);
        }
        let size = format!("{}×{}", image.width, image.height);
        println!(
            "{name:<32} {size:>10} {:>5} {real:>4} {:>5} {seconds:>7.2}  {verdict}",
            people.len(),
            heads.len()
        );
    }
    for (what, t) in [("photos", &all), ("originals", &originals)] {
        println!(
            "{} of {} {what} find a person; {} find a real one (nose on a marked head); \
             {} give `fit` a real one without --person; {} of their {} people reached",
            t.found, t.photos, t.real, t.picked_real, t.people_reached, t.people
        );
    }
    Ok(())
}
