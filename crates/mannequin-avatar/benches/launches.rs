//! Kernel launches per training iteration on the wgpu device, by phase, from CubeCL's profile
//! log: the launch count is what makes GPU training slow (each launch costs ~100 µs whatever it
//! computes), and unlike a time it is the same on any machine, so this runs on lavapipe too.
//!
//! Trains Tavatar on a small synthetic subject (`--size`, default 128 px) for `--warmup`
//! iterations (kernels compile; default 3), then counts the launches of `--iters` more (default
//! 4), with the device waited for at each phase boundary, and prints launches per iteration for
//! each phase with its most frequent kernels, the total against the target (100), and the
//! per-phase times (meaningful on a real GPU only).
//!
//! `--top K` lists K kernels a phase (default 5); the kernels that take the most device time
//! (as the profiler times each one alone) follow.
//!
//! `cargo bench -p mannequin-avatar --bench launches -- [--iters N] [--warmup N] [--size PX] [--seed S] [--top K]`

use std::collections::BTreeMap;
use std::io::{Read, Seek, SeekFrom};
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use mannequin_avatar::{
    Avatar, AvatarConfig, Canonical, Method, Phase, SkirtMode, Timings, TrainOptions, Trainer, load_views,
};
use mannequin_body::BodyModel;
use mannequin_data::Dataset;
use mannequin_synth::{SynthOptions, generate};

#[path = "../../../tools/bench_args.rs"]
mod bench_args;
use bench_args::arg;

/// The target: launches per training iteration.
const TARGET: f64 = 100.0;

/// What the profile log has said since the last look, by phase and kernel.
struct Tally {
    log: PathBuf,
    offset: u64,
    counting: bool,
    launches: BTreeMap<String, BTreeMap<String, usize>>,
    /// Device seconds by kernel, over every phase.
    seconds: BTreeMap<String, f64>,
}

fn phase_name(phase: Option<Phase>) -> String {
    phase.map_or_else(|| "before the first phase".into(), |p| format!("{p:?}").to_lowercase())
}

/// The kernel and the seconds of a profile line `| 1.2ms | Name | …`, or `None` for any other
/// line.
fn kernel(line: &str) -> Option<(&str, f64)> {
    let mut cells = line.strip_prefix('|')?.split('|').map(str::trim);
    let time = cells.next()?;
    let digits = time.trim_end_matches(|c: char| !(c.is_ascii_digit() || c == '.'));
    let scale = match &time[digits.len()..] {
        "ns" => 1e-9,
        "µs" => 1e-6,
        "ms" => 1e-3,
        "s" => 1.0,
        _ => return None,
    };
    let seconds = digits.parse::<f64>().ok()? * scale;
    let name = cells.next()?;
    Some((name.split_once('_').map_or(name, |(head, _)| head), seconds))
}

impl Tally {
    /// Charges the log's new lines to `phase`.
    fn charge(&mut self, phase: Option<Phase>) {
        // CubeCL creates the log at its first line.
        let Ok(mut file) = std::fs::File::open(&self.log) else { return };
        file.seek(SeekFrom::Start(self.offset)).expect("seek");
        let mut bytes = Vec::new();
        file.read_to_end(&mut bytes).expect("read");
        // Only whole lines; a partial one (perhaps cut inside a character) waits for the next look.
        let whole = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
        self.offset += whole as u64;
        if !self.counting {
            return;
        }
        let text = String::from_utf8_lossy(&bytes[..whole]);
        let by_kernel = self.launches.entry(phase_name(phase)).or_default();
        for (name, seconds) in text.lines().filter_map(kernel) {
            *by_kernel.entry(name.to_string()).or_default() += 1;
            *self.seconds.entry(name.to_string()).or_default() += seconds;
        }
    }
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn main() {
    let iters: usize = arg("--iters", 4).max(1);
    let warmup: usize = arg("--warmup", 3);
    let size: usize = arg("--size", 128);
    let seed: u64 = arg("--seed", 0);
    let top_kernels: usize = arg("--top", 5);
    let dir = std::env::temp_dir().join(format!("mannequin-launches-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("bench folder");
    let log = dir.join("cubecl.log");
    // SAFETY: set before any thread starts and before CubeCL reads its configuration.
    unsafe {
        std::env::set_var("CUBECL_DEBUG_LOG", &log);
        std::env::set_var("CUBECL_DEBUG_OPTION", "profile");
    }

    let model = BodyModel::default_body();
    let data = dir.join("subject");
    let options = SynthOptions {
        seed,
        size,
        supersample: 1,
        capture_frames: 6,
        train_frames: 5,
        view_poses: 1,
        motion_frames: 1,
        // The launches do not depend on the cloth: the faster simulation.
        self_collision: false,
    };
    generate(&model, &data, &options, &|_| {}).expect("synth");
    let dataset = Dataset::open(&data, 1).expect("dataset");
    let split = dataset.split("train").expect("split");
    let views = load_views(&dataset, &split, |_, _| {}).expect("views");
    let (canonical, skirt) =
        Canonical::for_subject(&model, &split.poses.betas, 0, &views, SkirtMode::Auto, &[])
            .expect("canonical");
    let device = mannequin_splat::gpu_device().unwrap_or_else(|e| panic!("{e}"));
    let mut config = AvatarConfig::new(Method::Tavatar, seed);
    config.skirt_layer = skirt.is_some();
    let avatar = Avatar::new(config, canonical, &device.clone().autodiff()).expect("avatar");
    let gaussians = avatar.num_gaussians();
    let train = TrainOptions {
        half_resolution_share: 0.0,
        ..TrainOptions::new(Method::Tavatar, warmup + iters, seed)
    };
    let mut trainer = Trainer::new(avatar, views, train).expect("trainer");

    let tally = Arc::new(Mutex::new(Tally {
        log,
        offset: 0,
        counting: false,
        launches: BTreeMap::new(),
        seconds: BTreeMap::new(),
    }));
    let hook = tally.clone();
    trainer.on_phase = Some(Box::new(move |phase| hook.lock().expect("tally").charge(phase)));
    trainer.profile = true;
    let mut sum = Timings::default();
    for i in 0..warmup + iters {
        if i == warmup {
            let mut t = tally.lock().expect("tally");
            t.charge(None);
            t.counting = true;
        }
        let t = trainer.step().expect("step").timings;
        if i >= warmup {
            for (total, part) in [
                (&mut sum.skinning, t.skinning),
                (&mut sum.derivation, t.derivation),
                (&mut sum.render, t.render),
                (&mut sum.losses, t.losses),
                (&mut sum.backward, t.backward),
                (&mut sum.optimiser, t.optimiser),
            ] {
                *total += part;
            }
        }
    }

    let tally = tally.lock().expect("tally");
    let n = iters as f64;
    let times = [sum.skinning, sum.derivation, sum.render, sum.losses, sum.backward, sum.optimiser];
    println!(
        "Tavatar, {gaussians} Gaussians, {size}×{size}, on {device:?}: launches per iteration \
         (mean of {iters} after {warmup} warm-up)"
    );
    println!("{:<24} {:>9} {:>9}   most frequent kernels", "phase", "launches", "ms");
    let mut total = 0.0;
    let phases = std::iter::once(None).chain(Phase::ALL.map(Some));
    for (k, phase) in phases.enumerate() {
        let by_kernel = tally.launches.get(&phase_name(phase)).cloned().unwrap_or_default();
        let count = by_kernel.values().sum::<usize>() as f64 / n;
        total += count;
        let mut top: Vec<_> = by_kernel.into_iter().collect();
        top.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
        let top: Vec<String> =
            top.iter().take(top_kernels).map(|(name, c)| format!("{name} {:.1}", *c as f64 / n)).collect();
        let time = k.checked_sub(1).map_or(String::from("-"), |i| format!("{:.2}", ms(times[i]) / n));
        println!("{:<24} {count:>9.1} {time:>9}   {}", phase_name(phase), top.join(", "));
    }
    println!(
        "total {total:.1} launches per iteration; target ≤ {TARGET}: ratio {:.2} ({})",
        total / TARGET,
        if total <= TARGET { "met" } else { "NOT met" }
    );
    let mut by_time: Vec<_> = tally.seconds.iter().collect();
    by_time.sort_by(|a, b| b.1.total_cmp(a.1).then(a.0.cmp(b.0)));
    let device_ms: f64 = tally.seconds.values().sum::<f64>() * 1e3 / n;
    println!(
        "device time per iteration, as CubeCL's profiler times each kernel: {device_ms:.2} ms; longest:"
    );
    for (name, seconds) in by_time.iter().take(top_kernels.max(12)) {
        println!("  {name:<28} {:>8.3} ms", *seconds * 1e3 / n);
    }
    std::fs::remove_dir_all(&dir).ok();
}
