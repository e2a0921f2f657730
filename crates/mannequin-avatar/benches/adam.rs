//! One Adam update on Flex (f32) of a hash-grid-sized parameter: Tavatar's table (2^17 · 16 rows
//! × 2 features = 4.2M floats) and iHuman's two F = 4 tables together (16.8M floats). The fused
//! op (`Adam::update`) against the tensor-op chain it replaced, kept here as the baseline, timed
//! in the same run; both start from the same values and must end bit-identical.
//!
//! `cargo bench -p mannequin-avatar --bench adam` (add `-- --quick` for fewer repetitions).
//! Times are medians of the update alone (the gradient is computed untimed before each update),
//! with the fastest run in brackets (the CPU may be shared).

use std::time::Instant;

use burn::tensor::{DType, Device, Gradients, Tensor, TensorData};
use mannequin_avatar::adam::Adam;
use mannequin_avatar::params::Param;
use mannequin_io::rng::SplitMix64;

/// The optimiser before the fused op: one Burn tensor op per term.
struct TensorOpAdam {
    step: usize,
    m: Vec<Tensor<2>>,
    v: Vec<Tensor<2>>,
}

impl TensorOpAdam {
    const BETA1: f64 = 0.9;
    const BETA2: f64 = 0.999;
    const EPSILON: f64 = 1e-15;

    fn new(params: &[Param]) -> Self {
        let zeros = || params.iter().map(|p| p.value.clone().inner().zeros_like()).collect();
        Self { step: 0, m: zeros(), v: zeros() }
    }

    fn update(&mut self, params: &mut [Param], grads: &Gradients) {
        let (beta1, beta2) = (Self::BETA1, Self::BETA2);
        self.step += 1;
        let t = self.step as i32;
        let (c1, c2) = (1.0 - beta1.powi(t), 1.0 - beta2.powi(t));
        for (k, p) in params.iter_mut().enumerate() {
            let Some(g) = p.value.grad(grads) else { continue };
            self.m[k] = self.m[k].clone() * beta1 + g.clone() * (1.0 - beta1);
            self.v[k] = self.v[k].clone() * beta2 + g.square() * (1.0 - beta2);
            let step = (self.m[k].clone() / c1) / ((self.v[k].clone() / c2).sqrt() + Self::EPSILON) * p.lr;
            p.value = (p.value.clone().inner() - step).autodiff().require_grad();
        }
    }
}

fn random(n: usize, seed: u64, device: &Device) -> Tensor<2> {
    let mut rng = SplitMix64::new(seed);
    let v: Vec<f32> = (0..n).map(|_| rng.range(-1.0, 1.0) as f32).collect();
    Tensor::from_data(TensorData::new(v, [n / 4, 4]), (device, DType::F32))
}

/// Runs `reps + 1` updates (the first a warm-up) with a fresh gradient `∂ Σ w ⊙ p / ∂p = w`
/// before each; returns the median and fastest update time in ms and the final values.
fn run(n: usize, reps: usize, mut update: impl FnMut(&mut [Param], &Gradients)) -> (f64, f64, Vec<f32>) {
    let device = Device::flex().autodiff();
    let mut params = vec![Param::new("table", random(n, 1, &device), 1e-2)];
    let w = random(n, 2, &device);
    let mut t: Vec<f64> = (0..=reps)
        .map(|_| {
            let grads = (params[0].value.clone() * w.clone()).sum().backward();
            let start = Instant::now();
            update(&mut params, &grads);
            start.elapsed().as_secs_f64() * 1e3
        })
        .skip(1)
        .collect();
    t.sort_by(f64::total_cmp);
    (t[reps / 2], t[0], params[0].value.clone().into_data().iter::<f32>().collect())
}

fn main() {
    let reps = if std::env::args().any(|a| a == "--quick") { 5 } else { 15 };
    println!("Adam update on Flex, f32, {} threads, {reps} updates each", rayon::current_num_threads());
    for (label, n) in [("Tavatar table, 4.2M", 1 << 22), ("iHuman tables, 16.8M", 1 << 24)] {
        let mut old = None;
        let (old_ms, old_min, old_values) = run(n, reps, |params, grads| {
            old.get_or_insert_with(|| TensorOpAdam::new(params)).update(params, grads)
        });
        let mut fused = None;
        let (ms, min, values) = run(n, reps, |params, grads| {
            fused.get_or_insert_with(|| Adam::new(params)).update(params, grads)
        });
        let same = old_values.iter().zip(&values).all(|(a, b)| a.to_bits() == b.to_bits());
        println!(
            "{label:>22}: tensor ops {old_ms:7.2} ms [{old_min:6.2}]   fused {ms:6.2} ms [{min:6.2}]   ×{:.1}   \
             bit-identical: {}",
            old_ms / ms,
            if same { "yes" } else { "NO" }
        );
    }
}
