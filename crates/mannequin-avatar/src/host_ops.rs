//! Where the avatar's fused ops run. The binding, the SH colour, the MLP head and the mesh
//! regularisers each have one op with a hand-written backward, as host passes on Flex (CPU) and
//! as CubeCL kernels on a GPU: composed from small tensor ops they cost most of a CPU training
//! step, and on a GPU hundreds of kernel launches. The skinning and the image loss are fused on
//! the GPU only, where the composition's launches cost; Flex runs their compositions well. Any
//! other backend keeps the compositions, which the tests hold the fused ops to.

use burn::backend::DispatchDevice;
use burn::backend::flex::FlexTensor;
use burn::tensor::Device;

/// Whether `device` runs the fused binding, colour, MLP and mesh regularisers: Flex or a CubeCL
/// device, with or without autodiff.
pub fn supported(device: &Device) -> bool {
    on_flex(device) || on_cube(device)
}

/// Whether `device` is Flex, with or without autodiff.
pub fn on_flex(device: &Device) -> bool {
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
