//! Tavatar's binding (Eqs. 5–11) of the default body's template, face and vertex Gaussians, on
//! Flex: the fused op against the tensor composition it replaces, timed in the same run, forward
//! alone and forward + backward through autodiff.
//!
//! `cargo bench -p mannequin-avatar --bench binding`

use burn::tensor::{Device, Tensor, TensorData};
use mannequin_avatar::fused_binding::{BindConfig, bind};
use mannequin_avatar::mesh_gaussians::{
    Faces, GaussianGeometry, MeshIndex, face_gaussians, vertex_gaussians,
};
use mannequin_body::BodyModel;

mod timing;

const REPS: usize = 30;

fn tensor_path(v: &Tensor<2>, index: &MeshIndex) -> GaussianGeometry {
    let faces = Faces::of(v, index);
    GaussianGeometry::cat(face_gaussians(&faces), vertex_gaussians(v, &faces, index))
}

/// A scalar that reads every output, so the backward pass visits all of them.
fn loss(g: GaussianGeometry) -> Tensor<1> {
    g.means.sum() + g.frames.sum() + g.scales.sum() + g.normals.sum()
}

fn main() {
    let model = BodyModel::default_body();
    let device = Device::flex().autodiff();
    let nv = model.v_template.len();
    let flat: Vec<f32> = model.v_template.iter().flatten().copied().collect();
    let vertices = || Tensor::<2>::from_data(TensorData::new(flat.clone(), [nv, 3]), &device).require_grad();
    let index = MeshIndex::new(nv, &model.faces, &device);
    let config = BindConfig { mesh: index.mesh.clone(), face_gaussians: true, vertex_gaussians: true };
    println!("binding {} faces + {nv} vertices, median of {REPS} (ms):", model.faces.len());
    let time = |what: &str, fused: &mut dyn FnMut(), tensors: &mut dyn FnMut()| {
        let (ours, _) = timing::median_and_min_ms(REPS, fused);
        let (base, _) = timing::median_and_min_ms(REPS, tensors);
        println!("  {what:<22} fused {ours:7.2}   tensor ops {base:7.2}   speed-up {:.1}×", base / ours);
    };
    time("forward", &mut || drop(bind(vertices(), &config).means.into_data()), &mut || {
        drop(tensor_path(&vertices(), &index).means.into_data())
    });
    time(
        "forward + backward",
        &mut || {
            let v = vertices();
            let grads = loss(bind(v.clone(), &config)).backward();
            drop(v.grad(&grads).expect("gradient").into_data());
        },
        &mut || {
            let v = vertices();
            let grads = loss(tensor_path(&v, &index)).backward();
            drop(v.grad(&grads).expect("gradient").into_data());
        },
    );
}
