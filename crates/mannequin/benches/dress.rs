//! `mannequin dress` at the size: pants under a T-shirt (size M, made on the default
//! body) on a 4 s walk at 30 fps, against its 20 s target on a 2-core CPU. Each run's per-stage
//! times come from its metrics.json. The baseline in the same run is the same job skinned only
//! (Eqs. 3.2-3.3, `--no-simulation`), so the ratio says what the cloth simulation costs.
//!
//! `cargo bench -p mannequin --bench dress [-- --seconds 4]`

use std::path::Path;

#[path = "../../../tools/bench_cli.rs"]
mod bench_cli;
use bench_cli::mannequin;

/// The target for the whole job, seconds.
const TARGET_S: f64 = 20.0;

fn stages(dir: &Path) -> String {
    let metrics: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("metrics.json")).unwrap()).unwrap();
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
    let seconds = args
        .iter()
        .position(|a| a == "--seconds")
        .and_then(|i| args.get(i + 1))
        .cloned()
        .unwrap_or_else(|| "4".into());
    let dir = std::env::temp_dir().join(format!("mq-bench-dress-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (walk, cache) = (dir.join("walk.npz"), dir.join("cache"));
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let walk_arg = s(&walk);
    mannequin(&["motion", "walk", "-o", &walk_arg, "--seconds", &seconds, "--fps", "30"], &cache);
    let dress = |out: &str, extra: &[&str]| {
        let mut args = vec!["dress", "--garments", "pants,tshirt", "--motion", &walk_arg, "--out", out];
        args.extend_from_slice(extra);
        mannequin(&args, &cache)
    };
    // Make (and cache) the templates first, so both runs below time dressing only.
    dress(&s(&dir.join("warm")), &["--no-simulation", "--no-frames"]);

    println!("dress: pants + T-shirt (size M) on a {seconds} s walk at 30 fps, default body");
    let skinned = dress(&s(&dir.join("skinned")), &["--no-simulation"]);
    println!("  skinned only (baseline): {skinned:.1} s  [{}]", stages(&dir.join("skinned")));
    let simulated = dress(&s(&dir.join("simulated")), &[]);
    println!("  simulated (default):     {simulated:.1} s  [{}]", stages(&dir.join("simulated")));
    println!(
        "  simulation costs {:.1}× skinning; target {TARGET_S} s: {:.2} of it ({})",
        simulated / skinned,
        simulated / TARGET_S,
        if simulated <= TARGET_S { "met" } else { "NOT met" }
    );
    std::fs::remove_dir_all(&dir).ok();
}
