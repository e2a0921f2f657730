//! Where the avatar's fused host ops run. The binding, the SH colour, the MLP head and the mesh
//! regularisers each have one op with a hand-written backward for Flex (CPU), where composing them from
//! small tensor ops costs most of a training step; other backends keep the tensor compositions,
//! which a GPU runs well, and the tests hold the two to the same values and gradients.

use burn::backend::DispatchDevice;
use burn::backend::flex::FlexTensor;
use burn::tensor::Device;

/// Whether `device` runs the fused host ops (Flex, with or without autodiff).
pub fn supported(device: &Device) -> bool {
    device.clone().inner() == Device::flex()
}

/// Whether `device` is a CubeCL device (wgpu here), with or without autodiff: where the GPU
/// forms of the fused ops run.
pub fn on_cube(device: &Device) -> bool {
    matches!(device.clone().inner().as_dispatch(), DispatchDevice::Cube(_))
}

/// `t` with a contiguous buffer (the host passes read tensors as plain slices).
pub(crate) fn contiguous(t: FlexTensor) -> FlexTensor {
    if t.is_contiguous() { t } else { t.to_contiguous() }
}
