//! Cloth that holds, over issue 38's whole matrix: every category alone and the outfits pants +
//! T-shirt, skirt + T-shirt and pants + shirt + long coat (the dress is a category), each made
//! at size M on the default body, worn on five body shapes (the default, ±2 on β₁ and on β₂)
//! through the walk and the jog, with the cloth–cloth contacts on. Per run, at the worst frame:
//! cloth vertices inside the body, triangle pairs crossing the layers under and crossing the
//! garment itself (exact triangle–triangle tests, independent of the solver), and each
//! garment's p99 edge stretch against its material's limit. The baseline in the same run is
//! the same job skinned only (Eqs. 3.2-3.3), whose counts say what the simulation resolved.
//!
//! `cargo bench -p mannequin-garment --bench hold [-- --seconds 1] [--only pants,tshirt]
//! [--shapes 5] [--motions walk,jog]`

use std::path::Path;

use mannequin_body::{BodyModel, Motion};
use mannequin_cloth::Performer;
use mannequin_garment::{DressJob, DressSettings};

mod common;
use common::{read_metrics, time_dressing};

/// Inner layer first.
const OUTFITS: [&str; 10] = [
    "pants",
    "short-pants",
    "shirt",
    "tshirt",
    "long-coat",
    "skirt",
    "dress",
    "pants,tshirt",
    "skirt,tshirt",
    "pants,shirt,long-coat",
];
const SHAPES: [[f32; 2]; 5] = [[0.0, 0.0], [2.0, 0.0], [-2.0, 0.0], [0.0, 2.0], [0.0, -2.0]];

fn option<'a>(args: &'a [String], name: &str) -> Option<&'a str> {
    args.iter().position(|a| a == name).and_then(|i| args.get(i + 1)).map(String::as_str)
}

/// Per garment of the run in `dir`: (name, inside, crossing the layers under, crossing itself,
/// p99 stretch, the material's limit).
fn worst(dir: &Path) -> Vec<(String, u64, u64, u64, f64, f64)> {
    let metrics = read_metrics(dir);
    let count = |g: &serde_json::Value, k: &str| g[k].as_u64().unwrap_or(0);
    metrics["garments"]
        .as_array()
        .unwrap()
        .iter()
        .map(|g| {
            (
                g["name"].as_str().unwrap().to_string(),
                count(g, "max_vertices_inside_body"),
                count(g, "max_crossings_with_inner_layers"),
                count(g, "max_self_intersecting_pairs"),
                g["max_p99_edge_stretch"].as_f64().unwrap(),
                g["strain_limit"].as_f64().unwrap(),
            )
        })
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let seconds: f32 = option(&args, "--seconds").map_or(1.0, |s| s.parse().expect("--seconds: a number"));
    let shapes: usize = option(&args, "--shapes").map_or(5, |s| s.parse().expect("--shapes: 1 to 5"));
    let only = option(&args, "--only");
    let motions: Vec<&str> = option(&args, "--motions").unwrap_or("walk,jog").split(',').collect();
    let dir = std::env::temp_dir().join(format!("mq-bench-hold-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // SAFETY: set before any other thread starts; the templates are made into a fresh cache.
    unsafe { std::env::set_var("XDG_CACHE_HOME", dir.join("cache")) };
    let model = BodyModel::from_spec("default", None).unwrap();
    println!("hold: {seconds} s at 30 fps, size M, cloth–cloth contacts on; worst frame per run");
    println!("  outfit | betas | motion | skinned only: inside/crossing/self | simulated: per garment");
    let (mut runs, mut held, mut garments, mut within) = (0, 0, 0, 0);
    for motion_name in &motions {
        let path = dir.join(format!("{motion_name}.npz"));
        let clip = match *motion_name {
            "walk" => Motion::walk_cycle(seconds, 30.0),
            "jog" => Motion::jog_cycle(seconds, 30.0),
            other => panic!("--motions: walk or jog, got {other}"),
        };
        clip.write_amass(&path).unwrap();
        let motion = Motion::read(&path).unwrap();
        for outfit in OUTFITS.iter().filter(|o| only.is_none_or(|x| x == **o)) {
            let names: Vec<String> = outfit.split(',').map(String::from).collect();
            for betas in &SHAPES[..shapes.clamp(1, SHAPES.len())] {
                let job = DressJob {
                    garments: &names,
                    performer: Performer {
                        model: &model,
                        body: "default",
                        betas,
                        motion: &motion,
                        motion_path: &path,
                    },
                };
                let run = dir.join(format!("{motion_name}-{outfit}-{}-{}", betas[0], betas[1]));
                let skinning = DressSettings { no_simulation: true, ..DressSettings::default() };
                time_dressing(&job, &skinning, &run.join("skinned"));
                let skinned = worst(&run.join("skinned"))
                    .iter()
                    .fold((0, 0, 0), |a, g| (a.0 + g.1, a.1 + g.2, a.2 + g.3));
                let seconds_taken = time_dressing(&job, &DressSettings::default(), &run.join("simulated"));
                let simulated = worst(&run.join("simulated"));
                let mut line = format!(
                    "  {outfit} | {betas:?} | {motion_name} | {}/{}/{} | {seconds_taken:.1} s:",
                    skinned.0, skinned.1, skinned.2
                );
                runs += 1;
                held += usize::from(simulated.iter().all(|g| g.1 + g.2 + g.3 == 0));
                for (name, inside, crossing, own, p99, limit) in &simulated {
                    garments += 1;
                    within += usize::from(p99 <= limit);
                    line += &format!(
                        " {name} {inside}/{crossing}/{own}, p99 {:.1} % ({:.0} %);",
                        100.0 * p99,
                        100.0 * limit
                    );
                }
                println!("{line}");
                std::fs::remove_dir_all(&run).ok();
            }
        }
    }
    println!(
        "  held (0 inside, 0 crossing, 0 self at every frame): {held} of {runs} runs ({:.2}); p99 stretch \
         within the material's limit: {within} of {garments} garments ({:.2}); target: all",
        held as f64 / runs.max(1) as f64,
        within as f64 / garments.max(1) as f64
    );
    std::fs::remove_dir_all(&dir).ok();
}
