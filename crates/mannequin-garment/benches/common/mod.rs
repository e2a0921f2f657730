//! What the dressing benches share: one dressing run as the library runs it.

use std::path::Path;
use std::time::Instant;

use mannequin_garment::{DressJob, DressSettings, Wardrobe, dress};

/// Seconds to dress `job` with `settings` and write its outputs (metrics.json among them) into
/// `out`, without the frames `mannequin dress` renders.
pub fn time_dressing(job: &DressJob, settings: &DressSettings, out: &Path) -> f64 {
    let start = Instant::now();
    std::fs::create_dir_all(out).unwrap();
    let wardrobe = Wardrobe::load(job, settings).unwrap();
    let mut dressing = dress(&wardrobe, job, settings, out).unwrap();
    let metrics = dressing.measure();
    dressing.write(out, job, &metrics).unwrap();
    dressing.finish();
    start.elapsed().as_secs_f64()
}

/// The metrics.json a dressing run wrote into `dir`.
pub fn read_metrics(dir: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(dir.join("metrics.json")).unwrap()).unwrap()
}
