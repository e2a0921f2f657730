//! Gradients of the differentiable forward pass against f64 central finite differences, for
//! shape, pose, translation and the template; and its values against the smplx fixture.

mod common;

use burn::tensor::{DType, Device, Tensor, TensorData};
use mannequin_body::{BodyModel, BodyTensors, forward_tensors, parse_model};
use mannequin_io::Npz;

/// A small random SMPL-format model (24 joints, 8×10 grid), enough to exercise every term.
fn small_model() -> BodyModel {
    let bytes = common::random_model::random_model_npz(24, 4, 8, 10);
    parse_model(&Npz::from_bytes("small.npz".into(), &bytes).unwrap(), None).unwrap()
}

fn t2(values: &[f64], rows: usize, cols: usize, device: &Device) -> Tensor<2> {
    Tensor::from_data(TensorData::new(values.to_vec(), [rows, cols]), (device, DType::F64))
}

/// The four inputs (template, shape, pose, translation) as tensors of their shapes.
fn leaves(x: &[Vec<f64>; 4], v: usize, n: usize, device: &Device) -> [Tensor<2>; 4] {
    [
        t2(&x[0], v, 3, device),
        t2(&x[1], n, x[1].len() / n, device),
        t2(&x[2], n, x[2].len() / n, device),
        t2(&x[3], n, 3, device),
    ]
}

/// A fixed, non-symmetric scalar loss of the outputs.
fn loss(bt: &BodyTensors, inputs: [Tensor<2>; 4]) -> Tensor<1> {
    let [template, shape, pose, transl] = inputs;
    let device = template.device();
    let n = shape.dims()[0];
    let (v, j) = (bt.v_template.dims()[0], bt.parents.len());
    let out = forward_tensors(bt, template, shape, pose, transl);
    let pattern = |len: usize, a: usize, m: usize, shift: f64| -> Vec<f64> {
        (0..len).map(|i| ((i * a) % m) as f64 / m as f64 - shift).collect()
    };
    let wv = Tensor::<3>::from_data(
        TensorData::new(pattern(n * v * 3, 7919, 13, 0.4), [n, v, 3]),
        (&device, DType::F64),
    );
    let wj = Tensor::<3>::from_data(
        TensorData::new(pattern(n * j * 3, 104729, 11, 0.5), [n, j, 3]),
        (&device, DType::F64),
    );
    (out.vertices * wv).sum() + (out.joints.square() * wj).sum()
}

fn scalar(t: Tensor<1>) -> f64 {
    t.into_data().iter::<f64>().next().unwrap()
}

#[test]
fn gradients_match_central_differences() {
    let model = small_model();
    let plain = Device::flex();
    let device = Device::flex().autodiff();
    let bt = BodyTensors::new(&model, &device, DType::F64);
    let bt_plain = BodyTensors::new(&model, &plain, DType::F64);
    let (n, v, j) = (2, model.num_vertices(), model.num_joints());
    let template: Vec<f64> = model.v_template.iter().flatten().map(|&x| x as f64).collect();
    let shape: Vec<f64> = (0..n * 4).map(|i| (i as f64 * 0.37).sin()).collect();
    let pose: Vec<f64> = (0..n * 3 * j).map(|i| 0.5 * (i as f64 * 1.3).cos()).collect();
    let transl: Vec<f64> = (0..n * 3).map(|i| 0.1 * i as f64).collect();
    let x = [template, shape, pose, transl];

    let tracked = leaves(&x, v, n, &device).map(|t| t.require_grad());
    let grads = loss(&bt, tracked.clone()).backward();

    let h = 1e-6;
    for (which, name) in ["template", "shape", "pose", "translation"].iter().enumerate() {
        let g: Vec<f64> = tracked[which].grad(&grads).unwrap().into_data().iter::<f64>().collect();
        // A spread of entries (all of them for the small inputs).
        let step = (x[which].len() / 40).max(1);
        for i in (0..x[which].len()).step_by(step) {
            let at = |delta: f64| {
                let mut xd = x.clone();
                xd[which][i] += delta;
                scalar(loss(&bt_plain, leaves(&xd, v, n, &plain)))
            };
            let fd = (at(h) - at(-h)) / (2.0 * h);
            let err = (g[i] - fd).abs();
            assert!(
                err < 1e-6 * (1.0 + fd.abs()),
                "{name}[{i}]: autodiff {} vs finite difference {fd}",
                g[i]
            );
        }
    }
}

#[test]
fn tensor_forward_matches_smplx() {
    let fx = Npz::read(format!("{}/tests/fixtures/smplx_smpl.npz", env!("CARGO_MANIFEST_DIR"))).unwrap();
    let bytes = common::random_model::random_model_npz(24, 10, 65, 106);
    let model = parse_model(&Npz::from_bytes("random.npz".into(), &bytes).unwrap(), None).unwrap();
    let device = Device::flex();
    let bt = BodyTensors::new(&model, &device, DType::F32);
    let get = |k: &str| fx.require(k).unwrap().to_f32().unwrap();
    let (betas, pose, transl) = (get("betas"), get("pose"), get("transl"));
    let n = transl.len() / 3;
    let t = |v: Vec<f32>, c: usize| Tensor::<2>::from_data(TensorData::new(v, [n, c]), (&device, DType::F32));
    let out = forward_tensors(&bt, bt.v_template.clone(), t(betas, 10), t(pose, 72), t(transl, 3));
    let verts: Vec<f32> = out.vertices.into_data().iter::<f32>().collect();
    let ids = fx.require("vertex_ids").unwrap().to_i64().unwrap();
    let want = fx.require("vertices").unwrap().to_f64().unwrap();
    let v = model.num_vertices();
    let mut worst = 0.0f64;
    for f in 0..n {
        for (i, &id) in ids.iter().enumerate() {
            for c in 0..3 {
                let got = verts[(f * v + id as usize) * 3 + c] as f64;
                worst = worst.max((got - want[(f * ids.len() + i) * 3 + c]).abs());
            }
        }
    }
    assert!(worst < 1e-5, "worst vertex error {worst} m");
    let joints: Vec<f32> = out.joints.into_data().iter::<f32>().collect();
    let want_j = fx.require("joints").unwrap().to_f64().unwrap();
    let worst_j = joints.iter().zip(&want_j).map(|(a, b)| (*a as f64 - b).abs()).fold(0.0, f64::max);
    assert!(worst_j < 1e-5, "worst joint error {worst_j} m");
}
