//! 3DGS's view-dependent colour of 40k Gaussians (SH degree 2) on Flex: the fused op against the
//! tensor composition it replaces, timed in the same run, forward alone and forward + backward
//! through autodiff.
//!
//! `cargo bench -p mannequin-avatar --bench colour`

use burn::tensor::{Device, Tensor, TensorData};
use mannequin_avatar::sh_colour::{ColourConfig, sh_colour, sh_colour_tensors};
use mannequin_io::rng::SplitMix64;

mod timing;

const REPS: usize = 30;
const GAUSSIANS: usize = 40_000;

fn main() {
    let device = Device::flex().autodiff();
    let mut rng = SplitMix64::new(1);
    let config = ColourConfig { eye: [0.0, 0.0, 3.0], degree: 2 };
    let mut values = |n: usize, r: f64| (0..n).map(|_| rng.range(-r, r) as f32).collect::<Vec<_>>();
    let (means, coeffs) = (values(GAUSSIANS * 3, 0.8), values(GAUSSIANS * 27, 1.0));
    let inputs = || {
        let t = |v: &Vec<f32>, w| Tensor::<2>::from_data(TensorData::new(v.clone(), [GAUSSIANS, w]), &device);
        (t(&means, 3).require_grad(), t(&coeffs, 27).require_grad())
    };
    let tensors = |m, c| sh_colour_tensors(m, c, &config).expect("degree 2");
    println!("colour of {GAUSSIANS} Gaussians, SH degree 2, median of {REPS} (ms):");
    let time = |what: &str, fused: &mut dyn FnMut(), tensors: &mut dyn FnMut()| {
        let (ours, _) = timing::median_and_min_ms(REPS, fused);
        let (base, _) = timing::median_and_min_ms(REPS, tensors);
        println!("  {what:<22} fused {ours:7.2}   tensor ops {base:7.2}   speed-up {:.1}×", base / ours);
    };
    time(
        "forward",
        &mut || {
            let (m, c) = inputs();
            drop(sh_colour(m, c, &config).into_data())
        },
        &mut || {
            let (m, c) = inputs();
            drop(tensors(m, c).into_data())
        },
    );
    let backward = |fused: bool| {
        let (m, c) = inputs();
        let rgb =
            if fused { sh_colour(m.clone(), c.clone(), &config) } else { tensors(m.clone(), c.clone()) };
        let grads = rgb.sum().backward();
        drop((
            m.grad(&grads).expect("mean gradient").into_data(),
            c.grad(&grads).expect("SH gradient").into_data(),
        ));
    };
    time("forward + backward", &mut || backward(true), &mut || backward(false));
}
