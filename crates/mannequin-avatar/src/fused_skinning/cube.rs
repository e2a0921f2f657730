//! The op on the CubeCL backends: the chain in one unit, the vertices one unit each, and the
//! backward's two reductions over vertices as products over vertices ([`crate::tall_product`];
//! the blend matrix's row of ones sums the translation's gradient in the same product).

use burn::backend::TensorMetadata;
use burn::backend::tensor::{FloatTensor, IntTensor};
use burn::backend::wgpu::{CubeBackend, CubeTensor};
use burn_cubecl::cubecl;
use burn_cubecl::kernel::into_contiguous;
use cubecl::prelude::*;

use super::SkinningBackend;
use super::kernels::{CHAIN, chain_backward, chain_forward, skin_vertices, skin_vertices_backward};
use crate::cube_launch::{empty_f32, per_element, u32_of};
use crate::tall_product::{Left, Product, tall_products};

/// One unit, for the chain's sequential passes.
fn single() -> (CubeCount, CubeDim) {
    (CubeCount::Static(1, 1, 1), CubeDim::new_1d(1))
}

/// The chain's record `[J, CHAIN]` of `pose` and `joints`.
fn chain(pose: &CubeTensor, joints: &CubeTensor, parents: &CubeTensor) -> CubeTensor {
    let count = joints.shape()[0];
    let record = empty_f32(vec![count, CHAIN], joints);
    let (cubes, dim) = single();
    chain_forward::launch(
        &joints.client,
        cubes,
        dim,
        pose.clone().into_buffer_arg(),
        joints.clone().into_buffer_arg(),
        parents.clone().into_buffer_arg(),
        record.clone().into_buffer_arg(),
        u32_of(count),
    );
    record
}

impl SkinningBackend for CubeBackend {
    fn lbs_forward(
        vertices: FloatTensor<Self>,
        joints: FloatTensor<Self>,
        pose: FloatTensor<Self>,
        transl: FloatTensor<Self>,
        blend: FloatTensor<Self>,
        posedirs: FloatTensor<Self>,
        parents: IntTensor<Self>,
        features: usize,
    ) -> FloatTensor<Self> {
        let [vertices, joints, pose, transl, blend, posedirs, parents] =
            [vertices, joints, pose, transl, blend, posedirs, parents].map(into_contiguous);
        let (n, count) = (vertices.shape()[0], joints.shape()[0]);
        let record = chain(&pose, &joints, &parents);
        let posed = empty_f32(vec![n, 3], &vertices);
        let (cubes, dim) = per_element(&vertices, n);
        skin_vertices::launch(
            &vertices.client,
            cubes,
            dim,
            vertices.clone().into_buffer_arg(),
            record.into_buffer_arg(),
            blend.into_buffer_arg(),
            posedirs.into_buffer_arg(),
            transl.into_buffer_arg(),
            posed.clone().into_buffer_arg(),
            u32_of(n),
            u32_of(count),
            u32_of(features),
        );
        posed
    }

    fn lbs_backward(
        vertices: FloatTensor<Self>,
        joints: FloatTensor<Self>,
        pose: FloatTensor<Self>,
        blend: FloatTensor<Self>,
        posedirs: FloatTensor<Self>,
        parents: IntTensor<Self>,
        features: usize,
        grad: FloatTensor<Self>,
    ) -> (FloatTensor<Self>, FloatTensor<Self>, FloatTensor<Self>, FloatTensor<Self>) {
        let [vertices, joints, pose, blend, posedirs, parents, grad] =
            [vertices, joints, pose, blend, posedirs, parents, grad].map(into_contiguous);
        let (n, count) = (vertices.shape()[0], joints.shape()[0]);
        let record = chain(&pose, &joints, &parents);
        let (d_vertices, outer) = (empty_f32(vec![n, 3], &vertices), empty_f32(vec![n, 12], &vertices));
        let (cubes, dim) = per_element(&vertices, n);
        skin_vertices_backward::launch(
            &vertices.client,
            cubes,
            dim,
            vertices.clone().into_buffer_arg(),
            record.clone().into_buffer_arg(),
            blend.clone().into_buffer_arg(),
            posedirs.clone().into_buffer_arg(),
            grad.into_buffer_arg(),
            d_vertices.clone().into_buffer_arg(),
            outer.clone().into_buffer_arg(),
            u32_of(n),
            u32_of(count),
            u32_of(features),
        );
        // Σ_v w_vj·outer_v for every joint, and Σ_v g_v in the row of ones; and the correctives'
        // features: posedirs · v_P's gradient (which is the rest vertices'). Both in two launches.
        let weights = Left::Strided { a: blend, columns: count + 1, stride_k: 1, stride_m: n };
        let mut products = vec![Product { a: weights, b: outer.clone(), k: n, n: 12 }];
        if features > 0 {
            let correctives = Left::Strided { a: posedirs, columns: features, stride_k: 1, stride_m: 3 * n };
            products.push(Product { a: correctives, b: d_vertices.clone(), k: 3 * n, n: 1 });
        }
        let mut sums = tall_products(products).into_iter();
        let d_transforms = sums.next().expect("the transforms' product");
        let d_features = sums.next().unwrap_or_else(|| empty_f32(vec![1, 1], &vertices));
        let work = empty_f32(vec![count, 12], &vertices);
        let (d_pose, d_joints, d_transl) = (
            empty_f32(vec![1, 3 * count], &vertices),
            empty_f32(vec![count, 3], &vertices),
            empty_f32(vec![1, 3], &vertices),
        );
        let (cubes, dim) = single();
        chain_backward::launch(
            &vertices.client,
            cubes,
            dim,
            pose.into_buffer_arg(),
            joints.into_buffer_arg(),
            parents.into_buffer_arg(),
            record.into_buffer_arg(),
            into_contiguous(d_transforms).into_buffer_arg(),
            into_contiguous(d_features).into_buffer_arg(),
            work.into_buffer_arg(),
            d_pose.clone().into_buffer_arg(),
            d_joints.clone().into_buffer_arg(),
            d_transl.clone().into_buffer_arg(),
            u32_of(count),
            u32_of(features),
        );
        (d_vertices, d_joints, d_pose, d_transl)
    }
}
