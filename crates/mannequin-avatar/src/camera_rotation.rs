//! A camera's rotation as a tensor, for turning world vectors (Gaussian means, normals) into
//! camera space; the renderer and the antialiasing compensation both read it.

use burn::tensor::{Device, Tensor};
use mannequin_splat::Camera;

use crate::params::tensor_from;

/// The camera's world→camera rotation transposed, [3, 3]: rows of world vectors times it are
/// camera-space vectors.
pub fn rotation_transposed(camera: &Camera, device: &Device) -> Tensor<2> {
    let e = &camera.extrinsic;
    let rt: Vec<f32> = (0..3).flat_map(|i| (0..3).map(move |j| e[j][i] as f32)).collect();
    tensor_from(rt, 3, 3, device)
}
