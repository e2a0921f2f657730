//! gsplat's antialiased mode (Mip-Splatting's 2D filter) for mesh-bound Gaussians: the renderer
//! adds a low-pass variance `d` (px²) to every screen-space covariance, which widens each
//! sub-pixel disk; with opacity 1 the rendered silhouette overshoots the mesh, and fitting it to
//! the mask shrinks the mesh. Scaling each opacity by `sqrt(det Σ₂ / det(Σ₂ + d I))`, as gsplat
//! does outside its kernel (`opacities * compensations`), keeps a filtered Gaussian's total
//! weight that of the unfiltered one, so coverage follows the surface.

use burn::tensor::{Tensor, TensorData};
use mannequin_splat::Camera;

use crate::camera_rotation::rotation_transposed;
use crate::mesh_gaussians::GaussianGeometry;

/// Smallest compensation kept differentiable (a degenerate footprint has det Σ₂ = 0).
const MIN_RATIO: f64 = 1e-12;

/// The opacity factors `[G]` of Gaussians seen through `camera`: the EWA screen covariance
/// `Σ₂ = T Tᵀ` with `T = J W R S` (J the perspective Jacobian at the camera-space mean, W the
/// camera rotation, R S the Gaussian's scaled frame), as the renderer projects it, for the
/// renderer's `dilation`.
pub fn compensation(g: &GaussianGeometry, camera: &Camera, dilation: f64) -> Tensor<1> {
    let device = g.means.device();
    let n = g.len();
    let rt = rotation_transposed(camera, &device);
    // Row i of the rotation W is column i of Wᵀ.
    let row = |i: usize| rt.clone().narrow(1, i, 1).reshape([1, 3]);
    let (w0, w1, w2) = (row(0), row(1), row(2));
    let t: Vec<f32> = (0..3).map(|i| camera.extrinsic[i][3] as f32).collect();
    let pc = g.means.clone().matmul(rt.clone()) + Tensor::<2>::from_data(TensorData::new(t, [1, 3]), &device);
    let col = |k: usize| pc.clone().narrow(1, k, 1);
    let (x, y, z) = (col(0), col(1), col(2));
    let (fx, fy) = (camera.intrinsic[0][0], camera.intrinsic[1][1]);
    // Rows of J W: (fx/z) w₀ − (fx x/z²) w₂ and (fy/z) w₁ − (fy y/z²) w₂, [G, 3] each.
    let inv_z = z.recip();
    let jw0 = w0 * (inv_z.clone() * fx) - w2.clone() * (x * inv_z.clone().square() * fx);
    let jw1 = w1 * (inv_z.clone() * fy) - w2 * (y * inv_z.square() * fy);
    // Rows of T = (J W) M with M = R S (frame columns scaled), [G, 3] each.
    let m = g.frames.clone() * g.scales.clone().reshape([n, 1, 3]);
    let times_m = |r: Tensor<2>| (r.reshape([n, 3, 1]) * m.clone()).sum_dim(1).reshape([n, 3]);
    let (t0, t1) = (times_m(jw0), times_m(jw1));
    let dot = |a: &Tensor<2>, b: &Tensor<2>| (a.clone() * b.clone()).sum_dim(1);
    let (p, q, r) = (dot(&t0, &t0), dot(&t0, &t1), dot(&t1, &t1));
    let det = p.clone() * r.clone() - q.clone().square();
    let det_filtered = (p + dilation) * (r + dilation) - q.square();
    (det / det_filtered).clamp_min(MIN_RATIO).sqrt().reshape([n])
}
