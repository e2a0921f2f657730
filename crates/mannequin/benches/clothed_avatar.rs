//! A clothed avatar (`mannequin train --garments auto`, issue 20) against the same avatar with
//! the skirt layer instead of garment layers, trained in the same run on a synthetic subject
//! (540², 2,000 iterations, this machine's CPU): novel-view and novel-pose PSNR and SSIM, the
//! whole clothed surface's Chamfer, and each garment layer's Chamfer and normal consistency
//! against its ground-truth meshes. The target is 31 dB on the dress subject's novel views.
//!
//! `cargo bench -p mannequin --bench clothed_avatar -- [--seed 1] [--iters 2000]`

use std::path::{Path, PathBuf};

#[path = "../../../tools/bench_args.rs"]
mod bench_args;
#[path = "../../../tools/bench_cli.rs"]
mod bench_cli;
use bench_cli::{mannequin, subject};

/// The novel-view target on the dress subject, dB.
const TARGET_DB: f64 = 31.0;

/// Trains an avatar on `data` into `out` with `extra` arguments, scores it; (seconds, scores).
fn train_and_score(
    data: &Path,
    out: &Path,
    iters: usize,
    extra: &[&str],
    cache: &Path,
) -> (f64, serde_json::Value) {
    let mut args: Vec<String> =
        ["train", "--data", &data.display().to_string(), "--out", &out.display().to_string()]
            .iter()
            .map(|s| s.to_string())
            .collect();
    args.extend(["--iters".into(), iters.to_string(), "--restart".into()]);
    args.extend(extra.iter().map(|s| s.to_string()));
    let seconds = mannequin(&args, cache);
    let json = out.join("scores.json");
    let (model, data, json_arg) =
        (out.display().to_string(), data.display().to_string(), json.display().to_string());
    mannequin(
        &["eval", "--avatar", &model, "--data", &data, "--samples", "20000", "--json", &json_arg],
        cache,
    );
    (seconds, serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap())
}

fn print_row(name: &str, seconds: f64, scores: &serde_json::Value) {
    let f = |v: &serde_json::Value| v.as_f64().unwrap_or(f64::NAN);
    println!(
        "  {name:<28} {:>8.2} {:>7.4} {:>8.2} {:>9.3} {:>8.0}",
        f(&scores["novel_view"]["psnr"]),
        f(&scores["novel_view"]["ssim"]),
        f(&scores["novel_pose"]["psnr"]),
        f(&scores["geometry"]["chamfer_cm"]),
        seconds
    );
    for set in ["novel_view", "novel_pose"] {
        if let Some(garments) = scores[set]["garments"].as_object() {
            for (garment, m) in garments {
                println!(
                    "    {garment} layer, {set}: Chamfer {:.3} cm, normal consistency {:.3}",
                    f(&m["chamfer_cm"]),
                    f(&m["normal_consistency"])
                );
            }
        }
    }
}

fn main() {
    let seed: u64 = bench_args::arg("--seed", 1);
    let iters: usize = bench_args::arg("--iters", 2000);
    // The subjects are the garment fit bench's.
    let root = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("garment-fit-bench");
    let cache = root.join("cache");
    std::fs::create_dir_all(&cache).unwrap();
    let data = subject(seed, &root, &cache);
    println!("seed {seed}, {iters} iterations:");
    println!(
        "  {:<28} {:>8} {:>7} {:>8} {:>9} {:>8}",
        "avatar", "view dB", "SSIM", "pose dB", "Chamfer", "s"
    );
    let (base_s, base) =
        train_and_score(&data, &root.join(format!("avatar-{seed}-skirt-layer")), iters, &[], &cache);
    print_row("skirt layer (baseline)", base_s, &base);
    let (s, clothed) = train_and_score(
        &data,
        &root.join(format!("avatar-{seed}-garments")),
        iters,
        &["--garments", "auto"],
        &cache,
    );
    print_row("garment layers (NGD)", s, &clothed);
    let (psnr, base_psnr) =
        (clothed["novel_view"]["psnr"].as_f64().unwrap(), base["novel_view"]["psnr"].as_f64().unwrap());
    println!(
        "novel view: {psnr:.2} dB against the baseline's {base_psnr:.2} dB ({:+.2} dB) and the {TARGET_DB} dB target; time ratio {:.2}",
        psnr - base_psnr,
        s / base_s
    );
}
