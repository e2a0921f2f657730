//! E_s's MLP head (32 → 64 → 64 → 3, ReLU) on the default body's 13,380 vertices on Flex: the
//! fused op against the same network through Burn's ops, timed in the same run, forward alone
//! and forward + backward through autodiff.
//!
//! `cargo bench -p mannequin-avatar --bench mlp`

use burn::tensor::{Device, Tensor, TensorData};
use mannequin_avatar::fused_mlp::mlp;
use mannequin_avatar::mlp::mlp_tensors;
use mannequin_io::rng::SplitMix64;

mod timing;

const REPS: usize = 30;
const ROWS: usize = 13_380;

fn main() {
    let device = Device::flex().autodiff();
    let mut rng = SplitMix64::new(1);
    let shapes = [[ROWS, 32], [32, 64], [1, 64], [64, 64], [1, 64], [64, 3], [1, 3]];
    let values: Vec<Vec<f32>> =
        shapes.iter().map(|&[r, c]| (0..r * c).map(|_| rng.range(-0.3, 0.3) as f32).collect()).collect();
    let inputs = || -> Vec<Tensor<2>> {
        values
            .iter()
            .zip(shapes)
            .map(|(v, s)| Tensor::<2>::from_data(TensorData::new(v.clone(), s), &device).require_grad())
            .collect()
    };
    let network = |fused: bool, t: &[Tensor<2>]| {
        if fused {
            mlp(
                t[0].clone(),
                [t[1].clone(), t[3].clone(), t[5].clone()],
                [t[2].clone(), t[4].clone(), t[6].clone()],
            )
        } else {
            mlp_tensors(t[0].clone(), [1, 3, 5].into_iter().map(|l| (t[l].clone(), t[l + 1].clone())))
        }
    };
    let forward = |fused: bool| drop(network(fused, &inputs()).into_data());
    let backward = |fused: bool| {
        let t = inputs();
        let grads = network(fused, &t).sum().backward();
        t.iter().for_each(|t| drop(t.grad(&grads).expect("gradient").into_data()));
    };
    println!("MLP 32 → 64 → 64 → 3 on {ROWS} rows, median of {REPS} (ms):");
    for (what, f) in [("forward", &forward as &dyn Fn(bool)), ("forward + backward", &backward)] {
        let (ours, _) = timing::median_and_min_ms(REPS, || f(true));
        let (base, _) = timing::median_and_min_ms(REPS, || f(false));
        println!("  {what:<22} fused {ours:7.2}   Burn ops {base:7.2}   speed-up {:.1}×", base / ours);
    }
}
