//! The binding on the CubeCL backends (wgpu, CUDA, …): forward one launch over faces and one
//! over vertices; backward one over vertices, one over faces and a gather onto vertices. Works
//! in f32; other float types are converted on the way in and out. The mesh's index tables go to
//! each device once and stay there while the mesh lives.

use std::sync::{Arc, Mutex};

use burn::backend::ops::{FloatTensorOps, IntTensorOps};
use burn::backend::tensor::FloatTensor;
use burn::backend::wgpu::{CubeBackend, CubeTensor};
use burn::tensor::{IntDType, TensorData};
use burn_cubecl::CubeDevice;

use super::kernels::{ParamsLaunch, bind_faces, bind_vertices, face_terms, gather_vertices, vertex_terms};
use super::{BindConfig, BindingBackend, PACKED, plane_starts};
use crate::cube_launch::{empty_f32, per_element, u32_of};
use crate::losses::blur::as_f32;
use crate::mesh_gaussians::{FACE_SCALE, NORM_EPS, NORMAL_SCALE, VERTEX_SCALE};
use crate::mesh_tables::{TableCache, cached, csr};
use crate::one_ring_mesh::OneRingMesh;

type B = CubeBackend;

/// A mesh's index tables on one device, laid out as `kernels.rs` reads them.
#[derive(Clone)]
struct Tables {
    faces: CubeTensor,
    corner_start: CubeTensor,
    corners: CubeTensor,
    ring_start: CubeTensor,
    rings: CubeTensor,
}

impl Tables {
    fn upload(mesh: &OneRingMesh, device: &CubeDevice) -> Self {
        let nv = mesh.num_vertices;
        // Each vertex's corners (3f + k) in ascending face order.
        let (corner_start, corners) =
            csr(nv, mesh.faces.iter().flatten().enumerate().map(|(k, &i)| (i as usize, u32_of(k))));
        let (ring_start, rings) = csr(nv, (0..nv).flat_map(|i| mesh.ring(i).iter().map(move |&j| (i, j))));
        let upload = |t: Vec<u32>| {
            let n = t.len();
            B::int_from_data(TensorData::new(t, [n]), device)
        };
        Self {
            faces: upload(mesh.faces.concat()),
            corner_start: upload(corner_start),
            corners: upload(corners),
            ring_start: upload(ring_start),
            rings: upload(rings),
        }
    }

    /// The tables of `mesh` on `device`, uploaded on first use.
    fn of(mesh: &Arc<OneRingMesh>, device: &CubeDevice) -> Self {
        static CACHE: TableCache<OneRingMesh, Tables> = Mutex::new(Vec::new());
        cached(&CACHE, mesh, device, || Self::upload(mesh, device))
    }
}

fn params(config: &BindConfig) -> ParamsLaunch {
    let [_, frames, scales, normals] = plane_starts(config.num_gaussians()).map(u32_of);
    let faces = config.mesh.faces.len();
    ParamsLaunch::new(
        u32_of(faces),
        u32_of(config.mesh.num_vertices),
        u32_of(if config.face_gaussians { faces } else { 0 }),
        frames,
        scales,
        normals,
        NORM_EPS as f32,
        FACE_SCALE as f32,
        VERTEX_SCALE as f32,
        NORMAL_SCALE as f32,
    )
}

impl BindingBackend for CubeBackend {
    fn tavatar_bind_forward(vertices: FloatTensor<Self>, config: BindConfig) -> FloatTensor<Self> {
        let (v, back) = as_f32(vertices);
        let t = Tables::of(&config.mesh, &v.device);
        let out = empty_f32(vec![config.num_gaussians() * PACKED], &v);
        let client = &v.client;
        if config.face_gaussians {
            let (count, dim) = per_element(&v, config.mesh.faces.len());
            bind_faces::launch(
                client,
                count,
                dim,
                v.clone().into_buffer_arg(),
                t.faces.clone().into_buffer_arg(),
                out.clone().into_buffer_arg(),
                params(&config),
            );
        }
        if config.vertex_gaussians {
            let (count, dim) = per_element(&v, config.mesh.num_vertices);
            bind_vertices::launch(
                client,
                count,
                dim,
                v.clone().into_buffer_arg(),
                t.faces.into_buffer_arg(),
                t.corner_start.into_buffer_arg(),
                t.corners.into_buffer_arg(),
                t.ring_start.into_buffer_arg(),
                t.rings.into_buffer_arg(),
                out.clone().into_buffer_arg(),
                params(&config),
            );
        }
        back(out)
    }

    fn tavatar_bind_backward(
        vertices: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        config: BindConfig,
    ) -> FloatTensor<Self> {
        let (v, back) = as_f32(vertices);
        let (grad, _) = as_f32(grad);
        let t = Tables::of(&config.mesh, &v.device);
        let (nf, nv) = (config.mesh.faces.len(), config.mesh.num_vertices);
        let client = &v.client;
        // Read only with vertex Gaussians.
        let terms = empty_f32(vec![6 * nv], &v);
        let nearest = B::int_empty([nv].into(), &v.device, IntDType::U32);
        if config.vertex_gaussians {
            let (count, dim) = per_element(&v, nv);
            vertex_terms::launch(
                client,
                count,
                dim,
                v.clone().into_buffer_arg(),
                t.faces.clone().into_buffer_arg(),
                t.corner_start.clone().into_buffer_arg(),
                t.corners.clone().into_buffer_arg(),
                t.ring_start.clone().into_buffer_arg(),
                t.rings.clone().into_buffer_arg(),
                grad.clone().into_buffer_arg(),
                terms.clone().into_buffer_arg(),
                nearest.clone().into_buffer_arg(),
                params(&config),
            );
        }
        let corner_grads = empty_f32(vec![9 * nf], &v);
        let (count, dim) = per_element(&v, nf);
        face_terms::launch(
            client,
            count,
            dim,
            v.clone().into_buffer_arg(),
            t.faces.into_buffer_arg(),
            grad.clone().into_buffer_arg(),
            terms.clone().into_buffer_arg(),
            corner_grads.clone().into_buffer_arg(),
            params(&config),
            config.face_gaussians,
            config.vertex_gaussians,
        );
        let d = empty_f32(vec![3 * nv], &v);
        let (count, dim) = per_element(&v, nv);
        gather_vertices::launch(
            client,
            count,
            dim,
            t.corner_start.into_buffer_arg(),
            t.corners.into_buffer_arg(),
            t.ring_start.into_buffer_arg(),
            t.rings.into_buffer_arg(),
            grad.into_buffer_arg(),
            corner_grads.into_buffer_arg(),
            terms.into_buffer_arg(),
            nearest.into_buffer_arg(),
            d.clone().into_buffer_arg(),
            params(&config),
            config.vertex_gaussians,
        );
        back(B::float_reshape(d, [nv, 3].into()))
    }
}
