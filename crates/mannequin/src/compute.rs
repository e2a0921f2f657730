//! `--device`: where training runs. The CPU (Flex) is the default because it needs nothing
//! installed; the GPU path goes through wgpu on Vulkan and fails with the fix named when no
//! adapter is there, never falling back to the CPU silently.

use anyhow::Result;
use burn::tensor::Device;
use clap::ValueEnum;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Compute {
    /// Flex, the pure-Rust CPU backend, on every core.
    Cpu,
    /// The wgpu backend's CubeCL kernels on the first Vulkan GPU.
    Gpu,
}

impl Compute {
    pub fn device(self) -> Result<Device> {
        Ok(match self {
            Compute::Cpu => Device::flex(),
            Compute::Gpu => mannequin_splat::gpu_device()?,
        })
    }
}
