//! Dressing at the size: pants under a T-shirt (size M, made on the default body) on a
//! 4 s walk at 30 fps, against its 20 s target on a 2-core CPU. Each run's per-stage times come
//! from its metrics.json. The baseline in the same run is the same job skinned only (Eqs.
//! 3.2-3.3, `no_simulation`), so the ratio says what the cloth simulation costs; the job without
//! cloth–cloth contacts (`--no-self-collision`) is timed beside it. The pipeline is
//! timed as the library runs it: without the frames `mannequin dress` renders.
//!
//! `cargo bench -p mannequin-garment --bench dress [-- --seconds 4]`

use std::path::Path;

use mannequin_body::{BodyModel, Motion};
use mannequin_cloth::Performer;
use mannequin_garment::{DressJob, DressSettings};

mod common;
use common::{read_metrics, time_dressing};

/// The target for the whole job, seconds.
const TARGET_S: f64 = 20.0;

fn stages(dir: &Path) -> String {
    let metrics = read_metrics(dir);
    let mut parts: Vec<String> = metrics["stage_s"]
        .as_object()
        .unwrap()
        .iter()
        .map(|(k, v)| format!("{k} {:.2}", v.as_f64().unwrap_or(0.0)))
        .collect();
    parts.sort();
    parts.join(", ")
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let seconds: f32 = args
        .iter()
        .position(|a| a == "--seconds")
        .and_then(|i| args.get(i + 1))
        .map_or(4.0, |s| s.parse().expect("--seconds: a number"));
    let dir = std::env::temp_dir().join(format!("mq-bench-dress-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // SAFETY: set before any other thread starts; the templates are made into a fresh cache.
    unsafe { std::env::set_var("XDG_CACHE_HOME", dir.join("cache")) };
    let walk_path = dir.join("walk.npz");
    Motion::walk_cycle(seconds, 30.0).write_amass(&walk_path).unwrap();
    let motion = Motion::read(&walk_path).unwrap();
    let model = BodyModel::from_spec("default", None).unwrap();
    let garments = ["pants".to_string(), "tshirt".to_string()];
    let job = DressJob {
        garments: &garments,
        performer: Performer {
            model: &model,
            body: "default",
            betas: &[],
            motion: &motion,
            motion_path: &walk_path,
        },
    };
    let skinning = DressSettings { no_simulation: true, ..DressSettings::default() };
    // Make (and cache) the templates first, so both runs below time dressing only.
    time_dressing(&job, &skinning, &dir.join("warm"));

    println!("dress: pants + T-shirt (size M) on a {seconds} s walk at 30 fps, default body");
    let skinned = time_dressing(&job, &skinning, &dir.join("skinned"));
    println!("  skinned only (baseline): {skinned:.1} s  [{}]", stages(&dir.join("skinned")));
    let apart = DressSettings { self_collision: false, ..DressSettings::default() };
    let crossing = time_dressing(&job, &apart, &dir.join("crossing"));
    println!("  no self-collision:       {crossing:.1} s  [{}]", stages(&dir.join("crossing")));
    let simulated = time_dressing(&job, &DressSettings::default(), &dir.join("simulated"));
    println!("  simulated (default):     {simulated:.1} s  [{}]", stages(&dir.join("simulated")));
    println!(
        "  simulation costs {:.1}× skinning; target {TARGET_S} s: {:.2} of it ({})",
        simulated / skinned,
        simulated / TARGET_S,
        if simulated <= TARGET_S { "met" } else { "NOT met" }
    );
    std::fs::remove_dir_all(&dir).ok();
}
