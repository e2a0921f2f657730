//! Pinhole cameras in the OpenCV convention: x right, y down, z forward; `extrinsic` maps world to
//! camera; pixel `(i, j)` has its centre at `(i + 0.5, j + 0.5)`.

use glam::{DMat3, DVec3};

#[derive(Debug, Clone, PartialEq)]
pub struct Camera {
    /// K, row-major, in pixels.
    pub intrinsic: [[f64; 3]; 3],
    /// World → camera, row-major; the last row is `0 0 0 1`.
    pub extrinsic: [[f64; 4]; 4],
    pub width: usize,
    pub height: usize,
}

impl Camera {
    /// A camera at `eye` looking at `target`, with `up` pointing up in the image, a horizontal
    /// field of view of `fov_x` radians and the principal point at the image centre.
    pub fn look_at(
        eye: [f64; 3],
        target: [f64; 3],
        up: [f64; 3],
        fov_x: f64,
        width: usize,
        height: usize,
    ) -> Self {
        let eye = DVec3::from(eye);
        let z = (DVec3::from(target) - eye).normalize();
        let x = z.cross(DVec3::from(up)).normalize();
        let y = z.cross(x);
        let rot = DMat3::from_cols(x, y, z).transpose();
        let t = -(rot * eye);
        let f = 0.5 * width as f64 / (0.5 * fov_x).tan();
        let r = |i: usize| rot.row(i);
        Self {
            intrinsic: [[f, 0.0, 0.5 * width as f64], [0.0, f, 0.5 * height as f64], [0.0, 0.0, 1.0]],
            extrinsic: [
                [r(0).x, r(0).y, r(0).z, t.x],
                [r(1).x, r(1).y, r(1).z, t.y],
                [r(2).x, r(2).y, r(2).z, t.z],
                [0.0, 0.0, 0.0, 1.0],
            ],
            width,
            height,
        }
    }

    /// The same camera for images downscaled by `factor` (box filter on whole blocks): fx, fy, cx,
    /// cy divide by `factor` because pixel centres map as `u' = u / factor`.
    pub fn downscale(&self, factor: usize) -> Self {
        let mut k = self.intrinsic;
        let s = factor as f64;
        for row in &mut k[..2] {
            row.iter_mut().for_each(|v| *v /= s);
        }
        Self {
            intrinsic: k,
            extrinsic: self.extrinsic,
            width: self.width / factor,
            height: self.height / factor,
        }
    }

    pub fn rotation(&self) -> DMat3 {
        let e = &self.extrinsic;
        DMat3::from_cols_array_2d(&[
            [e[0][0], e[1][0], e[2][0]],
            [e[0][1], e[1][1], e[2][1]],
            [e[0][2], e[1][2], e[2][2]],
        ])
    }

    pub fn translation(&self) -> DVec3 {
        DVec3::new(self.extrinsic[0][3], self.extrinsic[1][3], self.extrinsic[2][3])
    }

    pub fn world_to_camera(&self, p: DVec3) -> DVec3 {
        self.rotation() * p + self.translation()
    }

    /// The camera centre in world coordinates.
    pub fn centre(&self) -> DVec3 {
        -(self.rotation().transpose() * self.translation())
    }

    /// Pixel coordinates of a camera-space point (continuous; pixel centres at +0.5).
    pub fn project(&self, pc: DVec3) -> [f64; 2] {
        let k = &self.intrinsic;
        let (x, y) = (pc.x / pc.z, pc.y / pc.z);
        [k[0][0] * x + k[0][1] * y + k[0][2], k[1][1] * y + k[1][2]]
    }

    /// The camera-space direction (z = 1) through continuous pixel coordinates `(u, v)`.
    pub fn unproject(&self, u: f64, v: f64) -> DVec3 {
        let k = &self.intrinsic;
        let y = (v - k[1][2]) / k[1][1];
        let x = (u - k[0][2] - k[0][1] * y) / k[0][0];
        DVec3::new(x, y, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn look_at_puts_the_target_at_the_principal_point() {
        let cam = Camera::look_at([1.0, 1.5, 3.0], [0.0, 1.0, 0.0], [0.0, 1.0, 0.0], 0.8, 540, 540);
        let pc = cam.world_to_camera(DVec3::new(0.0, 1.0, 0.0));
        assert!(pc.z > 0.0);
        let [u, v] = cam.project(pc);
        assert!((u - 270.0).abs() < 1e-9 && (v - 270.0).abs() < 1e-9);
        // A point above the target appears higher in the image (smaller v), as y points down.
        let [_, v_up] = cam.project(cam.world_to_camera(DVec3::new(0.0, 1.2, 0.0)));
        assert!(v_up < v);
        assert!((cam.centre() - DVec3::new(1.0, 1.5, 3.0)).length() < 1e-12);
    }

    #[test]
    fn downscale_maps_pixel_coordinates_by_the_factor() {
        let cam = Camera::look_at([0.3, 0.2, -2.0], [0.0; 3], [0.0, 1.0, 0.0], 0.7, 1080, 1080);
        let small = cam.downscale(2);
        let p = cam.world_to_camera(DVec3::new(0.1, -0.2, 0.05));
        let (a, b) = (cam.project(p), small.project(p));
        assert!((a[0] / 2.0 - b[0]).abs() < 1e-9 && (a[1] / 2.0 - b[1]).abs() < 1e-9);
        assert_eq!((small.width, small.height), (540, 540));
        let d = cam.unproject(a[0], a[1]) * p.z;
        assert!((d - p).length() < 1e-9);
    }
}
