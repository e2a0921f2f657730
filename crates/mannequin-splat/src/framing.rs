//! Cameras that frame a body: a fixed front view on a point, moved back until a whole box (a
//! body's, or a clip's every frame) fits.

use crate::Camera;

/// A 540×540 camera 3.2 m in front of `centre`, looking along −Z.
pub fn front_camera(centre: [f32; 3]) -> Camera {
    let c = centre.map(f64::from);
    Camera::look_at([c[0], c[1], c[2] + 3.2], c, [0.0, 1.0, 0.0], 0.65, 540, 540)
}

/// Centre of the bounding box of `positions`.
pub fn box_centre(positions: &[[f32; 3]]) -> [f32; 3] {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    std::array::from_fn(|k| 0.5 * (lo[k] + hi[k]))
}

/// [`front_camera`] on the centre of the box `lo`–`hi` (a clip's every frame), moved back until
/// the whole box fits, so the view stays fixed while the body moves through it.
pub fn clip_camera(lo: [f32; 3], hi: [f32; 3]) -> Camera {
    /// Room around the box, as a fraction of its half-size.
    const MARGIN: f64 = 1.1;
    let centre = box_centre(&[lo, hi]);
    let camera = front_camera(centre);
    let c = centre.map(f64::from);
    let distance = camera.centre()[2] - c[2];
    let tan_half = 0.5 * camera.width as f64 / camera.intrinsic[0][0];
    let half = |k: usize| 0.5 * f64::from(hi[k] - lo[k]);
    let needed = MARGIN * half(0).max(half(1)) / tan_half + half(2);
    if needed <= distance {
        return camera;
    }
    let eye = [c[0], c[1], c[2] + needed];
    Camera::look_at(eye, c, [0.0, 1.0, 0.0], 2.0 * tan_half.atan(), camera.width, camera.height)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn a_clip_camera_sees_every_corner_of_its_box() {
        for (lo, hi) in [([-0.3, -1.0, -0.2], [0.3, 0.7, 0.2]), ([-2.5, -1.2, -3.0], [2.5, 0.6, 1.0])] {
            let camera = clip_camera(lo, hi);
            for corner in 0..8 {
                let p = std::array::from_fn(|k| f64::from(if corner >> k & 1 == 0 { lo[k] } else { hi[k] }));
                let pc = camera.world_to_camera(DVec3::from_array(p));
                let [u, v] = camera.project(pc);
                assert!(pc.z > 0.0, "corner {p:?} is behind the camera");
                assert!((0.0..540.0).contains(&u) && (0.0..540.0).contains(&v), "corner {p:?} at ({u}, {v})");
            }
        }
        // A box that fits the front view keeps it.
        let small = clip_camera([-0.1; 3], [0.1; 3]);
        assert_eq!(small.extrinsic, front_camera([0.0; 3]).extrinsic);
    }
}
