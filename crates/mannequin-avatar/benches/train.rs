//! Training speed on a synthetic subject at 540×540 (Flex, this machine's cores): the mean
//! per-iteration breakdown (skinning, Gaussian derivation, render forward, losses, backward,
//! optimiser), the render's own backward measured alone in the same run, and the projected time
//! of 2,000 iterations against the 5-minute target.
//!
//! `cargo bench -p mannequin-avatar --bench train [-- ITERS]`

use std::time::{Duration, Instant};

use burn::tensor::Device;
use mannequin_avatar::{Avatar, AvatarConfig, Canonical, Method, TrainOptions, Trainer, load_views};
use mannequin_body::BodyModel;
use mannequin_data::Dataset;
use mannequin_data::synth::{SynthOptions, generate};

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn main() {
    let iters: usize = std::env::args().skip(1).find_map(|a| a.parse().ok()).unwrap_or(60);
    let dir = std::env::temp_dir().join(format!("mannequin-train-bench-{}", std::process::id()));
    let model = BodyModel::default_body();
    let options = SynthOptions { seed: 1, ..SynthOptions::default() };
    generate(&model, &dir, &options, &|| {}).expect("synthetic subject");
    let dataset = Dataset::open(&dir, 1).expect("dataset");
    let split = dataset.split("train").expect("train split");
    let views = load_views(&dataset, &split, |_, _| {}).expect("views");
    for method in [Method::Tavatar, Method::Ihuman] {
        let canonical = Canonical::from_body(&model, &split.poses.betas, 0).expect("canonical");
        let avatar =
            Avatar::new(AvatarConfig::new(method, 0), canonical, &Device::flex().autodiff()).expect("avatar");
        let gaussians = avatar.num_gaussians();
        let mut trainer =
            Trainer::new(avatar, views.clone(), TrainOptions::new(method, 2000, 0)).expect("trainer");
        // Warm-up iterations are not timed (allocator, first-touch pages).
        for _ in 0..3 {
            trainer.step().expect("step");
        }
        let mut sum = mannequin_avatar::Timings::default();
        let start = Instant::now();
        for _ in 0..iters {
            let t = trainer.step().expect("step").timings;
            sum.skinning += t.skinning;
            sum.derivation += t.derivation;
            sum.render += t.render;
            sum.losses += t.losses;
            sum.backward += t.backward;
            sum.optimiser += t.optimiser;
        }
        let per_iter = start.elapsed() / iters as u32;
        let render_backward = trainer.render_backward_time(5).expect("render backward");
        let n = iters as u32;
        println!("{method:?}: {gaussians} Gaussians, {iters} iterations at 540×540, per iteration (ms):");
        println!("  skinning (offset field + LBS) {:8.2}", ms(sum.skinning / n));
        println!("  Gaussian derivation           {:8.2}", ms(sum.derivation / n));
        println!("  render forward                {:8.2}", ms(sum.render / n));
        println!("  losses                        {:8.2}", ms(sum.losses / n));
        println!("  backward (all)                {:8.2}", ms(sum.backward / n));
        println!("    of which render backward    {:8.2}  (measured alone)", ms(render_backward));
        println!("  optimiser                     {:8.2}", ms(sum.optimiser / n));
        println!("  total                         {:8.2}", ms(per_iter));
        let projected = per_iter.as_secs_f64() * 2000.0;
        println!(
            "  2,000 iterations: {projected:.0} s projected; target 300 s -> ratio {:.2} ({})",
            300.0 / projected,
            if projected <= 300.0 { "met" } else { "not met" }
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}
