//! What the avatar's CubeCL ops launch with: one unit per element in cubes of 256 (the cube
//! count spreads over the grid's dimensions when one would exceed its limit; kernels read the
//! linear `ABSOLUTE_POS`), fresh f32 buffers, and sizes that must fit the kernels' u32 indices.

use burn::backend::ops::FloatTensorOps;
use burn::backend::wgpu::{CubeBackend, CubeTensor};
use burn::tensor::FloatDType;
use burn_cubecl::cubecl;
use cubecl::prelude::*;

/// Units per cube.
const GROUP: u32 = 256;

/// `v` as a kernel's u32 size; tensors past 2³² elements are out of this crate's range.
pub(crate) fn u32_of(v: usize) -> u32 {
    u32::try_from(v).expect("kernel sizes index within u32")
}

/// An uninitialised f32 buffer of `shape` on `like`'s device, for a kernel to fill.
pub(crate) fn empty_f32(shape: Vec<usize>, like: &CubeTensor) -> CubeTensor {
    CubeBackend::float_empty(shape.into(), &like.device, FloatDType::F32)
}

/// Launch geometry for one unit per element of `n`.
pub(crate) fn per_element(like: &CubeTensor, n: usize) -> (CubeCount, CubeDim) {
    let dim = CubeDim::new_1d(GROUP);
    (cubecl::calculate_cube_count_elemwise(&like.client, n.max(1), dim), dim)
}
