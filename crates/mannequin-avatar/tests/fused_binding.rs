//! The fused binding op (f32) against the tensor composition of Eqs. 5–11 in f64, differentiated
//! by Burn's autodiff: same Gaussians and same vertex gradients on the default body's template,
//! jittered so that no face or edge is special, with every ablation's set of Gaussians.
//! The CubeCL op is held to the Flex one.

use std::sync::Arc;

use burn::tensor::{DType, Device, Tensor, TensorData};
use mannequin_avatar::fused_binding::{BindConfig, PACKED, bind};
use mannequin_avatar::host_ops::supported;
use mannequin_avatar::mesh_gaussians::{
    Faces, GaussianGeometry, MeshIndex, face_gaussians, vertex_gaussians,
};
use mannequin_avatar::one_ring_mesh::OneRingMesh;
use mannequin_body::BodyModel;
use mannequin_io::rng::SplitMix64;

fn host<const D: usize>(t: Tensor<D>) -> Vec<f32> {
    t.into_data().convert::<f32>().iter::<f32>().collect()
}

/// The template with every vertex moved by up to 3 mm (edges are ~1–2 cm).
fn jittered_template() -> (Vec<f32>, Vec<[u32; 3]>) {
    let model = BodyModel::default_body();
    let mut rng = SplitMix64::new(11);
    let v = model.v_template.iter().flatten().map(|&x| x + rng.range(-0.003, 0.003) as f32).collect();
    (v, model.faces.clone())
}

fn tensor_path(v: &Tensor<2>, index: &MeshIndex, faces: bool, vertices: bool) -> GaussianGeometry {
    let f = Faces::of(v, index);
    match (faces, vertices) {
        (true, true) => GaussianGeometry::cat(face_gaussians(&f), vertex_gaussians(v, &f, index)),
        (true, false) => face_gaussians(&f),
        (false, true) => vertex_gaussians(v, &f, index),
        (false, false) => unreachable!(),
    }
}

/// The outputs as `[G, k]` rows: means, frames, scales, normals.
fn outputs(g: GaussianGeometry) -> [Tensor<2>; 4] {
    let n = g.len();
    [g.means, g.frames.reshape([n, 9]), g.scales, g.normals]
}

const NAMES: [&str; 4] = ["means", "frames", "scales", "normals"];

/// Every entry within `tol` of the reference, relative to the entry itself plus the reference's
/// root-mean-square (so that entries near zero are held to an absolute bound).
fn assert_close(what: &str, got: &[f32], want: &[f32], tol: f32) {
    assert_eq!(got.len(), want.len(), "{what}: lengths");
    let rms = (want.iter().map(|x| x * x).sum::<f32>() / want.len() as f32).sqrt();
    let (worst, at) = got.iter().zip(want).enumerate().fold((0.0f32, 0), |m, (i, (a, b))| {
        let e = (a - b).abs() / (b.abs() + rms);
        if e > m.0 { (e, i) } else { m }
    });
    assert!(
        worst <= tol,
        "{what}: worst relative error {worst:e} at {at} ({} vs {}), rms {rms}",
        got[at],
        want[at]
    );
}

#[test]
fn fused_binding_matches_the_tensor_composition_and_its_autodiff() {
    let device = Device::flex().autodiff();
    assert!(supported(&device) && supported(&Device::flex()));
    let (flat, faces) = jittered_template();
    let nv = flat.len() / 3;
    let index = MeshIndex::new(nv, &faces, &device);
    // The fused op runs in f32; the reference in f64, so its own rounding does not count.
    let vertices = |fused: bool| {
        let dtype = if fused { DType::F32 } else { DType::F64 };
        Tensor::<2>::from_data(TensorData::new(flat.clone(), [nv, 3]), (&device, dtype))
    };
    let mut rng = SplitMix64::new(5);
    for (with_faces, with_vertices) in [(true, true), (true, false), (false, true)] {
        let config = BindConfig {
            mesh: index.mesh.clone(),
            face_gaussians: with_faces,
            vertex_gaussians: with_vertices,
        };
        let what = format!("faces {with_faces}, vertices {with_vertices}");
        let run = |fused: bool, v: &Tensor<2>| {
            outputs(if fused {
                bind(v.clone(), &config)
            } else {
                tensor_path(v, &index, with_faces, with_vertices)
            })
        };
        let (got, want) = (run(true, &vertices(true)), run(false, &vertices(false)));
        for (name, (a, b)) in NAMES.iter().zip(got.into_iter().zip(want)) {
            assert_eq!(a.dims(), b.dims(), "{what}: {name}");
            assert_close(&format!("{what}: {name}"), &host(a), &host(b), 1e-5);
        }
        // Each output's gradient path alone, at its own scale.
        for (k, name) in NAMES.iter().enumerate() {
            let [g, width] = run(true, &vertices(true))[k].dims();
            let w: Vec<f32> = (0..g * width).map(|_| rng.range(-1.0, 1.0) as f32).collect();
            let gradient = |fused: bool| {
                let v = vertices(fused).require_grad();
                let w = Tensor::<2>::from_data(TensorData::new(w.clone(), [g, width]), (&device, v.dtype()));
                let [a, b, c, d] = run(fused, &v);
                let grads = ([a, b, c, d][k].clone() * w).sum().backward();
                host(v.grad(&grads).unwrap())
            };
            assert_close(
                &format!("{what}: vertex gradient through {name}"),
                &gradient(true),
                &gradient(false),
                5e-5,
            );
        }
    }
}

/// The op on the GPU backend (lavapipe where there is no GPU) against the Flex op, through
/// autodiff: every plane's values, and the vertex gradient of a random upstream gradient on each
/// plane alone (at its own scale) and on all four at once (their gradients gather in one buffer
/// on the GPU), with every ablation's set of Gaussians. Both run in f32 but
/// sum in different orders.
#[test]
fn fused_binding_on_wgpu_matches_flex() {
    let (flat, faces) = jittered_template();
    let nv = flat.len() / 3;
    let mesh = Arc::new(OneRingMesh::new(nv, &faces));
    let mut rng = SplitMix64::new(7);
    for (with_faces, with_vertices) in [(true, true), (true, false), (false, true)] {
        let config =
            BindConfig { mesh: mesh.clone(), face_gaussians: with_faces, vertex_gaussians: with_vertices };
        let g = config.num_gaussians();
        let w: Vec<f32> = (0..g * PACKED).map(|_| rng.range(-1.0, 1.0) as f32).collect();
        let run = |device: Device| {
            let device = device.autodiff();
            let vertices = || {
                Tensor::<2>::from_data(TensorData::new(flat.clone(), [nv, 3]), (&device, DType::F32))
                    .require_grad()
            };
            let values = outputs(bind(vertices(), &config)).map(host);
            // Each plane alone (the others get no gradient), then all four at once.
            let grads = std::array::from_fn::<_, 5, _>(|which| {
                let v = vertices();
                let mut at = 0;
                let mut loss = None;
                for (k, plane) in outputs(bind(v.clone(), &config)).into_iter().enumerate() {
                    let width = plane.dims()[1];
                    let part = TensorData::new(w[at..at + g * width].to_vec(), [g, width]);
                    at += g * width;
                    if which == k || which == 4 {
                        let term = (plane * Tensor::<2>::from_data(part, (&device, DType::F32))).sum();
                        loss = Some(loss.map_or(term.clone(), |l| l + term));
                    }
                }
                let grads = loss.expect("a plane").backward();
                host(v.grad(&grads).expect("a vertex gradient"))
            });
            (values, grads)
        };
        let (want, want_grads) = run(Device::flex());
        let (got, got_grads) = run(mannequin_splat::gpu_device().unwrap_or_else(|e| panic!("{e}")));
        let what = format!("faces {with_faces}, vertices {with_vertices}");
        for (k, name) in NAMES.iter().enumerate() {
            assert_close(&format!("wgpu {what}: {name}"), &got[k], &want[k], 1e-5);
            let through = format!("wgpu {what}: vertex gradient through {name}");
            assert_close(&through, &got_grads[k], &want_grads[k], 1e-4);
        }
        let through = format!("wgpu {what}: vertex gradient through all four");
        assert_close(&through, &got_grads[4], &want_grads[4], 1e-4);
    }
}
