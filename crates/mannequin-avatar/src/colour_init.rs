//! Initial Gaussian colours from the training images, so the first iterations refine colour
//! instead of discovering it from grey (3DGS likewise starts from its point cloud's colours).
//! Each Gaussian takes the mean target colour of the pixels it lands on in the views where it
//! faces the camera and is the visible surface (its depth matches the rendered depth).

use glam::DVec3;
use mannequin_splat::sh;

use crate::avatar::Avatar;
use crate::error::AvatarError;
use crate::params::host;
use crate::views::View;

/// Views sampled for the estimate.
const SAMPLED_VIEWS: usize = 24;
/// A Gaussian counts as visible where its depth is within this of the rendered surface (m).
const DEPTH_TOLERANCE: f64 = 0.02;

/// Mean observed RGB per Gaussian, or `None` where no sampled view saw it.
pub fn observed_colours(avatar: &Avatar, views: &[View]) -> Result<Vec<Option<[f32; 3]>>, AvatarError> {
    let g = avatar.num_gaussians();
    let mut sum = vec![[0.0f64; 3]; g];
    let mut count = vec![0u32; g];
    let step = views.len().div_ceil(SAMPLED_VIEWS).max(1);
    for view in views.iter().step_by(step) {
        let posed = avatar.pose(&view.pose, view.transl)?;
        let rendered = avatar.render(&posed, &view.camera)?;
        let (alpha, depth) = (host(rendered.alpha()), host(rendered.depth()));
        let means = host(posed.gaussians.means);
        let normals = host(posed.gaussians.normals);
        let cam = &view.camera;
        let eye = cam.centre();
        let (crop, n, rgb) = (view.crop, view.crop.width * view.crop.height, view.rgb());
        for i in 0..g {
            let p = [0, 1, 2].map(|a| means[3 * i + a] as f64);
            let to_eye = [0, 1, 2].map(|a| eye[a] - p[a]);
            let facing: f64 = (0..3).map(|a| normals[3 * i + a] as f64 * to_eye[a]).sum();
            if facing <= 0.0 {
                continue;
            }
            let c = cam.world_to_camera(DVec3::from(p));
            if c.z <= cam.near {
                continue;
            }
            let [u, v] = cam.project(c);
            if u < 0.0 || v < 0.0 || u >= cam.width as f64 || v >= cam.height as f64 {
                continue;
            }
            let (x, y) = (u as usize, v as usize);
            let px = y * cam.width + x;
            if alpha[px] < 0.5 || (depth[px] as f64 / alpha[px] as f64 - c.z).abs() > DEPTH_TOLERANCE {
                continue;
            }
            if x < crop.x || y < crop.y || x >= crop.x + crop.width || y >= crop.y + crop.height {
                continue;
            }
            let q = (y - crop.y) * crop.width + (x - crop.x);
            if view.mask[q] < 0.5 {
                continue;
            }
            for (ch, acc) in sum[i].iter_mut().enumerate() {
                *acc += rgb[ch * n + q] as f64;
            }
            count[i] += 1;
        }
    }
    Ok(sum.iter().zip(&count).map(|(s, &c)| (c > 0).then(|| s.map(|v| (v / c as f64) as f32))).collect())
}

/// The DC SH coefficients [G · 3] that render `colours` (grey where unobserved).
pub fn dc_coefficients(colours: &[Option<[f32; 3]>]) -> Vec<f32> {
    let mut c0 = [0.0f64];
    sh::basis(0, [0.0, 0.0, 1.0], &mut c0);
    colours.iter().flat_map(|c| c.unwrap_or([0.5; 3]).map(|v| ((v as f64 - 0.5) / c0[0]) as f32)).collect()
}
