//! The one GPU device every wgpu caller (tests included) goes through.
//!
//! `Device::wgpu` lets wgpu pick the graphics API, and on a machine without a Vulkan driver it
//! picks OpenGL, where the kernels' WGSL fails validation with a bare panic. So the device here is
//! pinned to the APIs the kernels run on, and their absence is an error that says what to install.

use std::sync::OnceLock;

use burn::tensor::Device;
use burn::tensor::wgpu::{WgpuBackend, WgpuInitError};

/// The graphics APIs the kernels run on, best first, among those wgpu builds for this platform.
#[cfg(target_os = "macos")]
const APIS: &[WgpuBackend] = &[WgpuBackend::Metal];
#[cfg(target_os = "windows")]
const APIS: &[WgpuBackend] = &[WgpuBackend::Vulkan, WgpuBackend::Dx12];
#[cfg(not(any(target_os = "macos", target_os = "windows")))]
const APIS: &[WgpuBackend] = &[WgpuBackend::Vulkan];

/// No GPU adapter on an API the kernels run on; `reasons` says what each API answered.
#[derive(Debug, Clone, thiserror::Error)]
#[error(
    "no GPU for the wgpu kernels ({reasons}): install a Vulkan driver \
     (`sudo apt-get install mesa-vulkan-drivers libvulkan1` gives Mesa's CPU one) or run on the CPU"
)]
pub struct GpuUnavailable {
    reasons: String,
}

/// The wgpu device on the first of Vulkan (Metal on macOS, DirectX 12 after Vulkan on Windows)
/// that has an adapter, never OpenGL. Initialised once per process: wgpu's runtime cannot be set
/// up twice, so every later call returns the same device, or the same error.
pub fn gpu_device() -> Result<Device, GpuUnavailable> {
    static DEVICE: OnceLock<Result<Device, GpuUnavailable>> = OnceLock::new();
    DEVICE.get_or_init(init).clone()
}

fn init() -> Result<Device, GpuUnavailable> {
    let mut reasons = Vec::new();
    for &api in APIS {
        match Device::wgpu_options().graphics_api(api).init() {
            Ok(device) => return Ok(device),
            Err(e) => reasons.push(reason(api, &e)),
        }
    }
    Err(GpuUnavailable { reasons: reasons.join("; ") })
}

/// What `api` answered, on one line.
fn reason(api: WgpuBackend, e: &WgpuInitError) -> String {
    match e {
        WgpuInitError::AdapterUnavailable { .. } => format!("no {api:?} adapter"),
        WgpuInitError::UnsupportedGraphicsApi { .. } => format!("{api:?} not in this build"),
        e => format!("{api:?}: {}", e.to_string().replace('\n', " ")),
    }
}
