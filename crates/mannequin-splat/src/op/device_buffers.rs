//! Device buffers as the CubeCL kernels use them: allocation, upload and read-back of 32-bit
//! words, and the launch shape for one unit per element. Shared by every kernel file below the
//! op's glue (`cube.rs`).

use burn::backend::TensorMetadata;
use burn::backend::ops::FloatTensorOps;
use burn::backend::tensor::FloatTensor;
use burn::backend::wgpu::{CubeBackend, CubeTensor};
use burn::tensor::{FloatDType, TensorData, read_sync};
use burn_cubecl::cubecl::prelude::{CubeCount, CubeDim};

/// Units per cube for the per-Gaussian (and per-chunk) kernels.
const GROUP: u32 = 256;

pub(super) fn read(t: FloatTensor<CubeBackend>) -> Vec<f32> {
    read_sync(CubeBackend::float_into_data(t))
        .expect("reading a splat tensor from the device")
        .try_to_vec::<f32>()
        .expect("f32 tensor")
}

pub(super) fn upload(v: Vec<f32>, like: &CubeTensor) -> CubeTensor {
    let n = v.len();
    CubeBackend::float_from_data(TensorData::new(v, vec![n]), &like.device())
}

pub(super) fn zeros(shape: Vec<usize>, like: &CubeTensor) -> CubeTensor {
    CubeBackend::float_zeros(shape.into(), &like.device(), FloatDType::F32)
}

/// An uninitialised `f32` buffer of `shape` that a kernel fills whole.
pub(super) fn empty(shape: Vec<usize>, like: &CubeTensor) -> CubeTensor {
    CubeBackend::float_empty(shape.into(), &like.device(), FloatDType::F32)
}

/// A buffer of `len` 32-bit words that a kernel fills (kernels read `f32` buffers as `u32` too).
pub(super) fn buffer(len: usize, like: &CubeTensor) -> CubeTensor {
    empty(vec![len], like)
}

pub(super) fn u32_of(v: usize) -> u32 {
    u32::try_from(v).expect("splat buffers index within u32")
}

/// Enough cubes of [`units_dim`] for `n` units.
pub(super) fn units_grid(n: usize) -> CubeCount {
    CubeCount::Static(u32_of(n).div_ceil(GROUP).max(1), 1, 1)
}

pub(super) fn units_dim() -> CubeDim {
    CubeDim::new_1d(GROUP)
}

/// Device buffers for the kernels' unit tests, on [`crate::gpu_device`].
#[cfg(test)]
pub(super) mod testing {
    use burn::backend::DispatchDevice;
    use burn::backend::ops::FloatTensorOps;
    use burn::backend::wgpu::{CubeBackend, CubeTensor};
    use burn::tensor::TensorData;
    use burn_cubecl::CubeDevice;

    /// The kernels' device, or a panic whose message is [`crate::GpuUnavailable`]'s one line.
    pub fn device() -> CubeDevice {
        match crate::gpu_device().unwrap_or_else(|e| panic!("{e}")).as_dispatch() {
            DispatchDevice::Cube(device) => device.clone(),
            other => unreachable!("gpu_device gives a wgpu device, not {other:?}"),
        }
    }

    pub fn floats(v: &[f32], shape: Vec<usize>, device: &CubeDevice) -> CubeTensor {
        CubeBackend::float_from_data(TensorData::new(v.to_vec(), shape), device)
    }

    /// `u32`s travel as the bit patterns of `f32`s, as the kernels read them.
    pub fn words(v: &[u32], device: &CubeDevice) -> CubeTensor {
        floats(&v.iter().map(|&x| f32::from_bits(x)).collect::<Vec<_>>(), vec![v.len()], device)
    }

    pub fn read_words(t: CubeTensor, len: usize) -> Vec<u32> {
        super::read(t).iter().take(len).map(|v| v.to_bits()).collect()
    }
}
