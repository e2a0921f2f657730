//! Adam's fused update against an independent f64 scalar Adam written out here (several steps,
//! learning rates and a parameter that first gets a gradient late), the analytic first step
//! (bias correction makes it `lr · sign(g)`), Flex against wgpu (lavapipe on machines without a
//! GPU), parameters without a gradient, a value held elsewhere while it is updated, and a
//! save/load round trip that continues bit for bit.

use std::path::PathBuf;

use burn::tensor::{DType, Device, Tensor, TensorData};
use mannequin_avatar::adam::Adam;
use mannequin_avatar::params::Param;
use mannequin_io::limits::FLOAT32;
use mannequin_io::rng::SplitMix64;
use mannequin_io::{Npz, NpzWriter};

/// Name, shape, learning rate and the first step with a gradient, per parameter.
const SPECS: [(&str, [usize; 2], f64, usize); 3] =
    [("small_lr", [7, 3], 1e-3, 1), ("large_lr", [5, 2], 0.5, 1), ("late", [4, 4], 5e-2, 3)];

fn random(n: usize, seed: u64) -> Vec<f64> {
    let mut rng = SplitMix64::new(seed);
    (0..n).map(|_| rng.range(-1.0, 1.0)).collect()
}

fn tensor(v: &[f64], shape: [usize; 2], dtype: DType, device: &Device) -> Tensor<2> {
    let t = Tensor::<2>::from_data(TensorData::new(v.to_vec(), shape), (device, DType::F64));
    t.cast(dtype)
}

fn values(t: &Tensor<2>) -> Vec<f64> {
    t.clone().into_data().iter::<f64>().collect()
}

fn params(dtype: DType, device: &Device) -> Vec<Param> {
    SPECS
        .iter()
        .enumerate()
        .map(|(k, &(name, shape, lr, _))| {
            Param::new(name, tensor(&random(shape[0] * shape[1], k as u64), shape, dtype, device), lr)
        })
        .collect()
}

/// Backpropagates `Σ_k Σ w_k ⊙ p_k` over the parameters whose first step has come, so the
/// gradient of `p_k` is a fresh random `w_k` each step; returns the gradients as host values.
fn backward(params: &[Param], step: usize) -> (burn::tensor::Gradients, Vec<Option<Vec<f64>>>) {
    let mut loss = None;
    for (k, (p, &(_, shape, _, first))) in params.iter().zip(&SPECS).enumerate() {
        if step < first {
            continue;
        }
        let w = random(shape[0] * shape[1], 100 * step as u64 + k as u64);
        let term = (p.value.clone() * tensor(&w, shape, p.value.dtype(), &p.value.device())).sum();
        loss = Some(match loss {
            None => term,
            Some(l) => l + term,
        });
    }
    let grads = loss.expect("some parameter trains").backward();
    let host = params.iter().map(|p| p.value.grad(&grads).map(|g| values(&g))).collect();
    (grads, host)
}

/// Adam in f64 as Kingma & Ba write it, with one step counter for all parameters.
struct ReferenceAdam {
    t: i32,
    m: Vec<Vec<f64>>,
    v: Vec<Vec<f64>>,
}

impl ReferenceAdam {
    fn new(params: &[Vec<f64>]) -> Self {
        let zeros: Vec<Vec<f64>> = params.iter().map(|p| vec![0.0; p.len()]).collect();
        Self { t: 0, m: zeros.clone(), v: zeros }
    }

    fn update(&mut self, params: &mut [Vec<f64>], grads: &[Option<Vec<f64>>]) {
        let (beta1, beta2, epsilon) = (0.9f64, 0.999f64, 1e-15);
        self.t += 1;
        for (k, (p, g)) in params.iter_mut().zip(grads).enumerate() {
            let Some(g) = g else { continue };
            let lr = SPECS[k].2;
            for i in 0..p.len() {
                self.m[k][i] = beta1 * self.m[k][i] + (1.0 - beta1) * g[i];
                self.v[k][i] = beta2 * self.v[k][i] + (1.0 - beta2) * g[i] * g[i];
                let m_hat = self.m[k][i] / (1.0 - beta1.powi(self.t));
                let v_hat = self.v[k][i] / (1.0 - beta2.powi(self.t));
                p[i] -= lr * m_hat / (v_hat.sqrt() + epsilon);
            }
        }
    }
}

/// `|a − b| ≤ tol · max(|b|, lr)`: relative, with the step size as the floor for values near 0.
fn assert_close(found: &[f64], expected: &[f64], lr: f64, tol: f64, what: &str) {
    assert_eq!(found.len(), expected.len());
    for (i, (a, b)) in found.iter().zip(expected).enumerate() {
        assert!((a - b).abs() <= tol * b.abs().max(lr), "{what}[{i}]: {a} vs {b}");
    }
}

#[test]
fn the_fused_update_matches_an_f64_reference_adam() {
    let device = Device::flex().autodiff();
    for (dtype, tol) in [(DType::F64, 1e-12), (DType::F32, 1e-6)] {
        let mut params = params(dtype, &device);
        let mut expected: Vec<Vec<f64>> = params.iter().map(|p| values(&p.value)).collect();
        let mut reference = ReferenceAdam::new(&expected);
        let mut adam = Adam::new(&params);
        for step in 1..=6 {
            let (grads, host) = backward(&params, step);
            adam.update(&mut params, &grads);
            reference.update(&mut expected, &host);
            for (k, p) in params.iter().enumerate() {
                let what = format!("{dtype:?} step {step} {}", p.name);
                assert_close(&values(&p.value), &expected[k], p.lr, tol, &what);
            }
        }
    }
}

#[test]
fn the_first_step_moves_each_entry_by_the_learning_rate_against_its_gradient() {
    // At t = 1 the bias corrections make m̂ = g and v̂ = g², so p₁ = p₀ − lr · sign(g).
    let device = Device::flex().autodiff();
    let mut params = params(DType::F64, &device);
    let before: Vec<Vec<f64>> = params.iter().map(|p| values(&p.value)).collect();
    let (grads, host) = backward(&params, 1);
    Adam::new(&params).update(&mut params, &grads);
    for (k, p) in params.iter().enumerate() {
        let after = values(&p.value);
        let Some(g) = &host[k] else {
            assert_eq!(after, before[k], "{} has no gradient yet", p.name);
            continue;
        };
        let expected: Vec<f64> = before[k].iter().zip(g).map(|(x, g)| x - p.lr * g.signum()).collect();
        assert_close(&after, &expected, p.lr, 1e-12, &p.name);
    }
}

/// The kernels' GPU device; without one the test fails with `GpuUnavailable`'s one line.
fn wgpu() -> Device {
    mannequin_splat::gpu_device().unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn flex_and_wgpu_agree() {
    let run = |device: &Device| {
        let mut params = params(DType::F32, device);
        let mut adam = Adam::new(&params);
        for step in 1..=4 {
            let (grads, _) = backward(&params, step);
            adam.update(&mut params, &grads);
        }
        params
    };
    let (flex, gpu) = (run(&Device::flex().autodiff()), run(&wgpu().autodiff()));
    for (a, b) in flex.iter().zip(&gpu) {
        assert_close(&values(&b.value), &values(&a.value), a.lr, 1e-6, &a.name);
    }
}

/// The checkpoint entries of `adam` (and of the parameters), keyed as the trainer writes them.
fn checkpoint(params: &[Param], adam: &Adam) -> Npz {
    let mut w = NpzWriter::uncompressed();
    for p in params {
        p.save(&mut w, "param/");
    }
    adam.save(params, &mut w, "");
    Npz::from_bytes(PathBuf::from("memory.npz"), &w.to_bytes()).unwrap()
}

fn entry(npz: &Npz, key: &str) -> Vec<f64> {
    npz.require(key).unwrap().to_f64().unwrap()
}

#[test]
fn parameters_without_a_gradient_keep_their_values_and_moments() {
    let device = Device::flex().autodiff();
    let mut params = params(DType::F32, &device);
    let late = params.iter().position(|p| p.name == "late").unwrap();
    let before = values(&params[late].value);
    let mut adam = Adam::new(&params);
    for step in 1..SPECS[late].3 {
        let (grads, host) = backward(&params, step);
        assert!(host[late].is_none());
        adam.update(&mut params, &grads);
    }
    assert_eq!(values(&params[late].value), before);
    let npz = checkpoint(&params, &adam);
    for moment in ["adam_m/late", "adam_v/late"] {
        assert!(entry(&npz, moment).iter().all(|&x| x == 0.0), "{moment}");
    }
    assert!(entry(&npz, "adam_m/small_lr").iter().any(|&x| x != 0.0));
}

#[test]
fn a_value_held_elsewhere_is_not_overwritten() {
    // The op updates buffers in place only when nothing else holds them.
    let device = Device::flex().autodiff();
    let run = |hold: bool| {
        let mut params = params(DType::F32, &device);
        let mut adam = Adam::new(&params);
        for step in 1..=3 {
            let (grads, _) = backward(&params, step);
            let held: Vec<Tensor<2>> = params.iter().filter(|_| hold).map(|p| p.value.clone()).collect();
            let copies: Vec<Vec<f64>> = held.iter().map(values).collect();
            adam.update(&mut params, &grads);
            for (t, copy) in held.iter().zip(&copies) {
                assert_eq!(&values(t), copy);
            }
        }
        params.iter().map(|p| values(&p.value)).collect::<Vec<_>>()
    };
    assert_eq!(run(true), run(false));
}

#[test]
fn a_saved_and_loaded_optimiser_continues_bit_for_bit() {
    let device = Device::flex().autodiff();
    let train = |params: &mut Vec<Param>, adam: &mut Adam, steps: std::ops::RangeInclusive<usize>| {
        for step in steps {
            let (grads, _) = backward(params, step);
            adam.update(params, &grads);
        }
    };
    let mut straight = params(DType::F32, &device);
    let mut adam = Adam::new(&straight);
    train(&mut straight, &mut adam, 1..=5);
    let expected = checkpoint(&straight, &adam);

    let mut first = params(DType::F32, &device);
    let mut adam = Adam::new(&first);
    train(&mut first, &mut adam, 1..=2);
    let saved = checkpoint(&first, &adam);
    assert_eq!(entry(&saved, "adam_step"), [2.0]);

    // Fresh parameters (at their initial values), overwritten by the checkpoint.
    let mut resumed = params(DType::F32, &device);
    for p in &mut resumed {
        p.load(&saved, "param/", FLOAT32).unwrap();
    }
    let mut adam = Adam::load(&resumed, &saved, 2, "").unwrap();
    train(&mut resumed, &mut adam, 3..=5);
    let found = checkpoint(&resumed, &adam);

    let mut keys: Vec<&str> = expected.keys().collect();
    keys.sort();
    assert_eq!(keys.len(), 1 + 3 * SPECS.len());
    for key in keys {
        let (a, b) = (entry(&found, key), entry(&expected, key));
        assert!(a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()) && a.len() == b.len(), "{key}");
    }
}
