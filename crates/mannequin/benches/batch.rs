//! Batch throughput (issue 41): `mannequin batch local` over tiny synthetic people, `--jobs 2`
//! (one thread per task) against `--jobs 1` (both cores in the one task) in the same run, and
//! `--jobs 1 --threads 1` beside them to show how well one task uses the second core. Each run
//! starts from a fresh run folder; the subjects are made once and kept.
//!
//! `cargo bench -p mannequin --bench batch -- [--people 4] [--size 96] [--iters 600] [--samples 2000]`

use std::path::Path;

#[path = "../../../tools/bench_args.rs"]
mod bench_args;
#[path = "../../../tools/bench_cli.rs"]
mod bench_cli;
use bench_args::arg;
use bench_cli::mannequin;

/// The target: `--jobs 2` people per hour over `--jobs 1`'s.
const TARGET: f64 = 1.8;

fn main() {
    let people: usize = arg("--people", 4);
    let size: usize = arg("--size", 96);
    let iters: usize = arg("--iters", 600);
    let samples: usize = arg("--samples", 2000);
    let root = Path::new(env!("CARGO_TARGET_TMPDIR")).join("bench_batch");
    let cache = root.join("cache");
    let mut rows = Vec::new();
    for seed in 0..people {
        let data = root.join(format!("subject-{size}-{seed}"));
        if !data.join("subject.json").exists() {
            let _ = std::fs::remove_dir_all(&data);
            let synth = format!(
                "synth --seed {seed} --size {size} --supersample 1 --frames 20 --train 18 --body default-lod1 --out"
            );
            let mut args: Vec<String> = synth.split(' ').map(String::from).collect();
            args.push(data.display().to_string());
            mannequin(&args, &cache);
        }
        rows.push(format!("p{seed},{},train+export+eval,{iters},default-lod1,{samples}", data.display()));
    }
    let manifest = root.join("people.csv");
    std::fs::write(
        &manifest,
        format!("id,input,steps,train.iters,train.body,eval.samples\n{}\n", rows.join("\n")),
    )
    .unwrap();
    println!(
        "{people} people of {size}², train ({iters} iterations) + export + eval ({samples} surface samples) each"
    );
    let time = |name: &str, jobs: usize, threads: usize| {
        let run = root.join(format!("run-{name}"));
        let _ = std::fs::remove_dir_all(&run);
        let plan =
            ["batch", "plan", "--manifest", &manifest.display().to_string(), "--engine", "local", "--out"];
        mannequin(&[&plan[..], &[&run.display().to_string()]].concat(), &cache);
        let local = ["batch", "local", "--run", &run.display().to_string()];
        let seconds = mannequin(
            &[&local[..], &["--jobs", &jobs.to_string(), "--threads", &threads.to_string()]].concat(),
            &cache,
        );
        let per_hour = people as f64 * 3600.0 / seconds;
        println!("  {name:<22} {seconds:>8.1} s  {per_hour:>8.0} people/hour");
        seconds
    };
    let one = time("jobs 1, 2 threads", 1, 2);
    let single = time("jobs 1, 1 thread", 1, 1);
    let two = time("jobs 2, 1 thread each", 2, 1);
    println!("one task on 2 threads against 1: {:.2}x", single / one);
    println!("--jobs 2 against --jobs 1 on 2 threads: {:.2}x the throughput (target {TARGET}x)", one / two);
    println!("--jobs 2 against --jobs 1 on 1 thread: {:.2}x the throughput", single / two);
}
