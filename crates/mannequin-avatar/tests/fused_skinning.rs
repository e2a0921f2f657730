//! The fused skinning on wgpu (lavapipe on machines without a GPU) against the tensor composition
//! `mannequin_body::skin_tensors` on Flex, an independent formulation: posed vertices and the
//! gradients of rest vertices, rest joints, pose and translation under a random upstream
//! gradient, on the default body with pose correctives. And a rig whose joint tree is out of
//! order is refused.

use burn::tensor::{Device, Tensor, TensorData};
use mannequin_avatar::fused_skinning::SkinRig;
use mannequin_body::lbs::regress_joints;
use mannequin_body::{BodyModel, Rig, skin_tensors};
use mannequin_io::rng::SplitMix64;

fn wgpu() -> Device {
    mannequin_splat::gpu_device().unwrap_or_else(|e| panic!("{e}"))
}

fn random(n: usize, scale: f64, seed: u64) -> Vec<f32> {
    let mut rng = SplitMix64::new(seed);
    (0..n).map(|_| rng.range(-scale, scale) as f32).collect()
}

fn tensor(v: &[f32], shape: [usize; 2], device: &Device) -> Tensor<2> {
    Tensor::from_data(TensorData::new(v.to_vec(), shape), device)
}

fn values(t: Tensor<2>) -> Vec<f32> {
    t.into_data().iter::<f32>().collect()
}

/// The inputs: the template with noise, its regressed joints moved a little, a pose of up to
/// ±0.8 rad per component with one joint at exactly zero rotation, and a translation.
struct Inputs {
    vertices: Vec<f32>,
    joints: Vec<f32>,
    pose: Vec<f32>,
    transl: Vec<f32>,
    upstream: Vec<f32>,
}

fn inputs(model: &BodyModel) -> Inputs {
    let (v, j) = (model.num_vertices(), model.num_joints());
    let template: Vec<f32> = model.v_template.iter().flatten().copied().collect();
    let vertices: Vec<f32> = template.iter().zip(random(3 * v, 0.01, 1)).map(|(a, b)| a + b).collect();
    let joints: Vec<f32> = regress_joints(model, &template)
        .iter()
        .flat_map(|p| p.to_array())
        .zip(random(3 * j, 0.01, 2))
        .map(|(a, b)| a + b)
        .collect();
    let mut pose = random(3 * j, 0.8, 3);
    pose[3..6].fill(0.0);
    Inputs { vertices, joints, pose, transl: random(3, 0.5, 4), upstream: random(3 * v, 1.0, 5) }
}

/// Posed vertices and the gradients of (vertices, joints, pose, transl) of ⟨posed, upstream⟩.
fn run(
    x: &Inputs,
    device: &Device,
    skin: impl Fn(Tensor<2>, Tensor<2>, Tensor<2>, Tensor<2>) -> Tensor<2>,
) -> [Vec<f32>; 5] {
    let (v, j) = (x.vertices.len() / 3, x.joints.len() / 3);
    let leaf = |d: &[f32], shape| tensor(d, shape, device).require_grad();
    let (vertices, joints) = (leaf(&x.vertices, [v, 3]), leaf(&x.joints, [j, 3]));
    let (pose, transl) = (leaf(&x.pose, [1, 3 * j]), leaf(&x.transl, [1, 3]));
    let posed = skin(vertices.clone(), joints.clone(), pose.clone(), transl.clone());
    let grads = (posed.clone() * tensor(&x.upstream, [v, 3], device)).sum().backward();
    let grad = |t: &Tensor<2>| values(t.grad(&grads).expect("gradient"));
    [values(posed), grad(&vertices), grad(&joints), grad(&pose), grad(&transl)]
}

#[test]
fn the_fused_skinning_matches_the_tensor_composition() {
    let model = BodyModel::default_body();
    let (v, j) = (model.num_vertices(), model.num_joints());
    let x = inputs(&model);
    let flex = Device::flex().autodiff();
    let weights = tensor(model.weights(), [v, j], &flex);
    // The default body has no pose correctives; random ones exercise that path.
    let features = 9 * (j - 1);
    let correctives = random(features * 3 * v, 1e-3, 6);
    let posedirs = tensor(&correctives, [features, 3 * v], &flex);
    let composed = run(&x, &flex, |verts, joints, pose, transl| {
        let rig = Rig { weights: &weights, posedirs: Some(&posedirs), parents: model.parents() };
        skin_tensors(&rig, verts.reshape([1, v, 3]), joints.reshape([1, j, 3]), pose, transl)
            .vertices
            .reshape([v, 3])
    });

    let gpu = wgpu().autodiff();
    let gpu_posedirs = tensor(&correctives, [features, 3 * v], &gpu);
    let rig = SkinRig::new(model.weights(), v, Some(&gpu_posedirs), model.parents(), &gpu).expect("rig");
    let fused = run(&x, &gpu, |verts, joints, pose, transl| rig.skin(verts, joints, pose, transl));

    for (name, (want, got)) in
        ["posed", "d vertices", "d joints", "d pose", "d transl"].iter().zip(composed.iter().zip(&fused))
    {
        let scale = want.iter().fold(0f32, |m, w| m.max(w.abs())).max(1e-6);
        let worst = want.iter().zip(got).map(|(w, g)| (w - g).abs()).fold(0f32, f32::max);
        // f32 sums of thousands of vertices in another order: 1e-4 of the largest value.
        assert!(worst <= 1e-4 * scale, "{name}: worst difference {worst} against a scale of {scale}");
    }
}

#[test]
fn a_joint_tree_out_of_order_is_refused() {
    let gpu = wgpu();
    let parents = [None, Some(2), Some(0)];
    let err = SkinRig::new(&[1.0; 6], 2, None, &parents, &gpu).unwrap_err().to_string();
    assert!(err.contains("joint 1's parent Some(2) does not come before it"), "{err}");
}
