//! The pinhole camera, in the OpenCV convention: x right, y down, z forward, `K` in pixels,
//! a rigid world→camera transform, and pixel centres at +0.5. The renderer, the datasets and the
//! ground-truth rasterizer all use this one type.

use glam::{DMat3, DVec3};

use mannequin_io::limits::{
    FOCAL_RANGE_PER_SIDE, MAX_DISTANCE, MAX_PRINCIPAL_OFFSET_SIDES, check_image_size,
};

use crate::SplatError;
use crate::real::Real;

/// A pinhole camera. Build it field by field, with [`Camera::new`] or with [`Camera::look_at`],
/// then [`Camera::validate`] (the renderer does this for you).
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub width: usize,
    pub height: usize,
    /// Intrinsics in pixels, row-major `[[fx, 0, cx], [0, fy, cy], [0, 0, 1]]` (no skew).
    pub intrinsic: [[f64; 3]; 3],
    /// Rigid world→camera transform, row-major 4×4 with last row `[0, 0, 0, 1]`.
    pub extrinsic: [[f64; 4]; 4],
    /// Gaussians whose camera-space depth is not strictly between `near` and `far` are culled.
    pub near: f64,
    pub far: f64,
}

impl Camera {
    /// A camera from its matrices, clipping at near 0.01 and far 1e10: nothing a human-scale
    /// scene holds is culled, so callers that want a tighter depth range set it themselves.
    pub fn new(width: usize, height: usize, intrinsic: [[f64; 3]; 3], extrinsic: [[f64; 4]; 4]) -> Self {
        Camera { width, height, intrinsic, extrinsic, near: 0.01, far: 1e10 }
    }

    /// A camera at `eye` looking at `target`, with world `up` pointing up in the image, a
    /// horizontal field of view `fov_x` (radians), square pixels and the principal point at the
    /// image centre; near and far as in [`Camera::new`].
    pub fn look_at(
        eye: [f64; 3],
        target: [f64; 3],
        up: [f64; 3],
        fov_x: f64,
        width: usize,
        height: usize,
    ) -> Self {
        let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
        };
        let unit = |a: [f64; 3]| {
            let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
            [a[0] / n, a[1] / n, a[2] / n]
        };
        // OpenCV axes: z forward, x = z × up (right), y = z × x (down).
        let z = unit(sub(target, eye));
        let x = unit(cross(z, up));
        let y = cross(z, x);
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let f = 0.5 * width as f64 / (0.5 * fov_x).tan();
        Camera::new(
            width,
            height,
            [[f, 0.0, 0.5 * width as f64], [0.0, f, 0.5 * height as f64], [0.0, 0.0, 1.0]],
            [
                [x[0], x[1], x[2], -dot(x, eye)],
                [y[0], y[1], y[2], -dot(y, eye)],
                [z[0], z[1], z[2], -dot(z, eye)],
                [0.0, 0.0, 0.0, 1.0],
            ],
        )
    }

    /// The same camera for images downscaled by `factor` (box filter on whole blocks): fx, fy, cx,
    /// cy divide by `factor` because pixel centres map as `u' = u / factor`.
    pub fn downscale(&self, factor: usize) -> Self {
        let mut k = self.intrinsic;
        let s = factor as f64;
        for row in &mut k[..2] {
            row.iter_mut().for_each(|v| *v /= s);
        }
        Camera { intrinsic: k, width: self.width / factor, height: self.height / factor, ..self.clone() }
    }

    /// The camera whose image is the `width`×`height` window at pixel `(x, y)` of this one: the
    /// principal point moves by the offset, so every pixel sees exactly what it saw before and a
    /// renderer spends nothing outside the window.
    pub fn crop(&self, x: usize, y: usize, width: usize, height: usize) -> Self {
        let mut k = self.intrinsic;
        k[0][2] -= x as f64;
        k[1][2] -= y as f64;
        Camera { intrinsic: k, width, height, ..self.clone() }
    }

    /// World→camera rotation `R`.
    pub fn rotation(&self) -> DMat3 {
        let e = &self.extrinsic;
        DMat3::from_cols_array_2d(&[
            [e[0][0], e[1][0], e[2][0]],
            [e[0][1], e[1][1], e[2][1]],
            [e[0][2], e[1][2], e[2][2]],
        ])
    }

    /// World→camera translation `t`.
    pub fn translation(&self) -> DVec3 {
        DVec3::new(self.extrinsic[0][3], self.extrinsic[1][3], self.extrinsic[2][3])
    }

    pub fn world_to_camera(&self, p: DVec3) -> DVec3 {
        self.rotation() * p + self.translation()
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

    /// Checks that the camera can form an image, with a message naming the faulty part.
    pub fn validate(&self) -> Result<(), SplatError> {
        let err = |m: String| Err(SplatError::Camera(m));
        if self.width == 0 || self.height == 0 {
            return err(format!("image size {}×{} is empty", self.width, self.height));
        }
        if let Err(e) = check_image_size(self.width, self.height) {
            return err(e);
        }
        let k = &self.intrinsic;
        if k.iter().flatten().any(|v| !v.is_finite()) {
            return err(format!("intrinsic K has a non-finite entry: {k:?}"));
        }
        if !(k[0][0] > 0.0 && k[1][1] > 0.0) {
            return err(format!(
                "intrinsic K needs positive focal lengths, found fx={} fy={}",
                k[0][0], k[1][1]
            ));
        }
        if k[0][1] != 0.0 || k[1][0] != 0.0 || k[2] != [0.0, 0.0, 1.0] {
            return err(format!("intrinsic K must be [[fx, 0, cx], [0, fy, cy], [0, 0, 1]], found {k:?}"));
        }
        let side = self.width.max(self.height) as f64;
        let (lo, hi) = FOCAL_RANGE_PER_SIDE;
        if [k[0][0], k[1][1]].iter().any(|&f| f < lo * side || f > hi * side) {
            return err(format!(
                "intrinsic K's focal lengths fx={} fy={}: expected {lo}–{hi} times the image's longer side ({side} px)",
                k[0][0], k[1][1]
            ));
        }
        let reach = MAX_PRINCIPAL_OFFSET_SIDES * side;
        if k[0][2] < -reach
            || k[0][2] > self.width as f64 + reach
            || k[1][2] < -reach
            || k[1][2] > self.height as f64 + reach
        {
            return err(format!(
                "intrinsic K's principal point ({}, {}): expected within {MAX_PRINCIPAL_OFFSET_SIDES} image sides of the image",
                k[0][2], k[1][2]
            ));
        }
        let e = &self.extrinsic;
        if e.iter().flatten().any(|v| !v.is_finite()) {
            return err(format!("extrinsic has a non-finite entry: {e:?}"));
        }
        if e[3] != [0.0, 0.0, 0.0, 1.0] {
            return err(format!("extrinsic last row must be [0, 0, 0, 1], found {:?}", e[3]));
        }
        // R Rᵀ = I and det R = +1, within what a float-stored rotation keeps.
        for i in 0..3 {
            for j in 0..3 {
                let d: f64 = (0..3).map(|k| e[i][k] * e[j][k]).sum::<f64>() - if i == j { 1.0 } else { 0.0 };
                if d.abs() > 1e-4 {
                    return err(format!(
                        "extrinsic rotation is not orthonormal (R Rᵀ[{i}][{j}] off by {d:.2e})"
                    ));
                }
            }
        }
        let det = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1])
            - e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0])
            + e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
        if det < 0.0 {
            return err("extrinsic rotation is a reflection (det = -1)".into());
        }
        let t = [e[0][3], e[1][3], e[2][3]];
        if t.iter().map(|v| v * v).sum::<f64>().sqrt() > MAX_DISTANCE {
            return err(format!(
                "extrinsic translation {t:?}: expected within {MAX_DISTANCE} m of the origin"
            ));
        }
        if !(self.near > 0.0 && self.near.is_finite() && self.far > self.near) {
            return err(format!("need 0 < near < far, found near={} far={}", self.near, self.far));
        }
        Ok(())
    }

    /// The camera centre in world space, `−Rᵀ t`.
    pub fn centre(&self) -> [f64; 3] {
        let e = &self.extrinsic;
        [0, 1, 2].map(|j| -(0..3).map(|i| e[i][j] * e[i][3]).sum::<f64>())
    }

    /// Number of 16×16 tiles across and down.
    pub fn tiles(&self) -> (usize, usize) {
        (self.width.div_ceil(crate::TILE), self.height.div_ceil(crate::TILE))
    }
}

/// The camera converted once to the renderer's scalar type, with gsplat's frustum limits for the
/// projection Jacobian precomputed.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CameraParams<T> {
    pub fx: T,
    pub fy: T,
    pub cx: T,
    pub cy: T,
    /// World→camera rotation, row-major.
    pub r: [T; 9],
    pub t: [T; 3],
    pub centre: [T; 3],
    pub near: T,
    pub far: T,
    pub width: T,
    pub height: T,
    /// `x/z` is clamped to `[−lim_x_neg, lim_x_pos]` inside the Jacobian (1.3× the frustum).
    pub lim_x: (T, T),
    pub lim_y: (T, T),
}

impl<T: Real> CameraParams<T> {
    pub fn new(cam: &Camera) -> Self {
        let k = &cam.intrinsic;
        let e = &cam.extrinsic;
        let (w, h) = (cam.width as f64, cam.height as f64);
        let (fx, fy, cx, cy) = (k[0][0], k[1][1], k[0][2], k[1][2]);
        let (tan_x, tan_y) = (0.5 * w / fx, 0.5 * h / fy);
        let c = cam.centre();
        let t = T::from_f64;
        CameraParams {
            fx: t(fx),
            fy: t(fy),
            cx: t(cx),
            cy: t(cy),
            r: [e[0][0], e[0][1], e[0][2], e[1][0], e[1][1], e[1][2], e[2][0], e[2][1], e[2][2]].map(t),
            t: [e[0][3], e[1][3], e[2][3]].map(t),
            centre: c.map(t),
            near: t(cam.near),
            far: t(cam.far.min(f64::MAX)),
            width: t(w),
            height: t(h),
            lim_x: (t(cx / fx + 0.3 * tan_x), t((w - cx) / fx + 0.3 * tan_x)),
            lim_y: (t(cy / fy + 0.3 * tan_y), t((h - cy) / fy + 0.3 * tan_y)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn good() -> Camera {
        Camera::look_at([0.0, 1.0, 2.5], [0.0, 1.0, 0.0], [0.0, 1.0, 0.0], 0.8, 64, 48)
    }

    #[test]
    fn look_at_puts_the_target_at_the_principal_point_and_up_at_the_top() {
        let cam = good();
        cam.validate().unwrap();
        let e = cam.extrinsic;
        let to_cam = |p: [f64; 3]| [0, 1, 2].map(|i| (0..3).map(|j| e[i][j] * p[j]).sum::<f64>() + e[i][3]);
        let t = to_cam([0.0, 1.0, 0.0]);
        assert!(t[0].abs() < 1e-12 && t[1].abs() < 1e-12 && (t[2] - 2.5).abs() < 1e-12);
        // A point above the target has negative camera y (image up).
        assert!(to_cam([0.0, 1.5, 0.0])[1] < 0.0);
        let c = cam.centre();
        assert!((c[0]).abs() < 1e-12 && (c[1] - 1.0).abs() < 1e-12 && (c[2] - 2.5).abs() < 1e-12);
    }

    /// Projection agrees with the explicit extrinsic: the target lands on the principal point and
    /// a point above it lands higher in the image (y points down).
    #[test]
    fn project_puts_the_target_at_the_principal_point() {
        let cam = Camera::look_at([1.0, 1.5, 3.0], [0.0, 1.0, 0.0], [0.0, 1.0, 0.0], 0.8, 540, 540);
        let pc = cam.world_to_camera(DVec3::new(0.0, 1.0, 0.0));
        assert!(pc.z > 0.0);
        let [u, v] = cam.project(pc);
        assert!((u - 270.0).abs() < 1e-9 && (v - 270.0).abs() < 1e-9);
        let [_, v_up] = cam.project(cam.world_to_camera(DVec3::new(0.0, 1.2, 0.0)));
        assert!(v_up < v);
        let c = cam.rotation().transpose() * -cam.translation();
        assert!(
            (c - DVec3::new(1.0, 1.5, 3.0)).length() < 1e-12
                && (c - DVec3::from(cam.centre())).length() < 1e-12
        );
    }

    #[test]
    fn downscale_maps_pixel_coordinates_by_the_factor() {
        let cam = Camera::look_at([0.3, 0.2, -2.0], [0.0; 3], [0.0, 1.0, 0.0], 0.7, 1080, 1080);
        let small = cam.downscale(2);
        let p = cam.world_to_camera(DVec3::new(0.1, -0.2, 0.05));
        let (a, b) = (cam.project(p), small.project(p));
        assert!((a[0] / 2.0 - b[0]).abs() < 1e-9 && (a[1] / 2.0 - b[1]).abs() < 1e-9);
        assert_eq!((small.width, small.height, small.near, small.far), (540, 540, cam.near, cam.far));
        let d = cam.unproject(a[0], a[1]) * p.z;
        assert!((d - p).length() < 1e-9);
    }

    #[test]
    fn degenerate_cameras_are_rejected_with_the_reason() {
        let mut c = good();
        c.width = 0;
        assert!(c.validate().unwrap_err().to_string().contains("empty"));
        let mut c = good();
        c.intrinsic[0][0] = 0.0;
        assert!(c.validate().unwrap_err().to_string().contains("focal"));
        let mut c = good();
        c.intrinsic[1][1] = f64::NAN;
        assert!(c.validate().unwrap_err().to_string().contains("non-finite"));
        let mut c = good();
        c.extrinsic[0][0] *= 2.0;
        assert!(c.validate().unwrap_err().to_string().contains("orthonormal"));
        let mut c = good();
        c.extrinsic[0] = c.extrinsic[0].map(|v| -v);
        c.extrinsic[0][3] = -c.extrinsic[0][3];
        assert!(c.validate().unwrap_err().to_string().contains("reflection"));
        let mut c = good();
        c.near = 0.0;
        assert!(c.validate().unwrap_err().to_string().contains("near"));
        let mut c = good();
        c.intrinsic[0][1] = 1.0;
        assert!(c.validate().unwrap_err().to_string().contains("must be"));
    }

    /// Values a file may hold but no capture has (issue 42): fx = 1e300 once put the body
    /// 1.5e27 m away, and a 32768² camera asked `render` for 25.8 GB.
    #[test]
    fn cameras_out_of_any_capture_are_rejected_with_the_limit() {
        let mut c = good();
        c.intrinsic[0][0] = 1e300;
        assert!(c.validate().unwrap_err().to_string().contains("times the image's longer side"));
        let mut c = good();
        c.intrinsic[1][1] = 1e-3;
        assert!(c.validate().unwrap_err().to_string().contains("times the image's longer side"));
        let mut c = good();
        c.intrinsic[0][2] = -1e9;
        assert!(c.validate().unwrap_err().to_string().contains("principal point"));
        let mut c = good();
        c.extrinsic[2][3] = 1e6;
        assert!(c.validate().unwrap_err().to_string().contains("of the origin"));
        let mut c = good();
        (c.width, c.height) = (32768, 32768);
        c.intrinsic = [[20000.0, 0.0, 16384.0], [0.0, 20000.0, 16384.0], [0.0, 0.0, 1.0]];
        assert!(c.validate().unwrap_err().to_string().contains("at most"));
        good().validate().unwrap();
    }
}
