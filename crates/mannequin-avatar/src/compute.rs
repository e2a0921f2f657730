//! Where training runs. The CPU (Flex) is the default because it needs nothing installed; the
//! GPU path goes through wgpu on Vulkan and fails with the fix named when no adapter is there,
//! never falling back to the CPU silently.

use burn::tensor::Device;
use serde::{Deserialize, Serialize};

use crate::error::AvatarError;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Compute {
    /// Flex, the pure-Rust CPU backend, on every core.
    Cpu,
    /// The wgpu backend's CubeCL kernels on the first Vulkan GPU.
    Gpu,
}

impl Compute {
    /// The device this names.
    pub fn device(self) -> Result<Device, AvatarError> {
        Ok(match self {
            Compute::Cpu => Device::flex(),
            Compute::Gpu => mannequin_splat::gpu_device()?,
        })
    }
}
