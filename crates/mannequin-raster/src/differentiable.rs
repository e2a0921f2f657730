//! A differentiable mesh rasteriser, split as nvdiffrast splits it (Laine et al. 2020): hard
//! rasterisation gives each pixel its triangle and perspective-correct barycentrics
//! ([`rasterize`]); attributes (colour, normals, UVs, a mask) are interpolated by them; and
//! silhouette edges are antialiased analytically, so that an image loss moves the vertices
//! through the interpolation inside the surface and through the silhouettes at its border.
//!
//! Antialiasing: where two horizontally or vertically neighbouring pixels see different
//! surfaces, and a silhouette edge of the nearer surface's triangle crosses the segment between
//! their centres at t ∈ [0, 1] (from the nearer pixel), the edge is taken to cut the pixels
//! there: past the midpoint (t > ½) the far pixel takes t − ½ of the near pixel's value, short of
//! it (t < ½) the near pixel takes ½ − t of the far one's. The blend moves continuously with the
//! edge's projected corners, which is where a silhouette's gradient comes from.
//!
//! Backward: a pixel's barycentrics are b_k = w_k / Σ_j w_j with w_k = r · (c_{k+1} × c_{k+2}),
//! r the pixel's ray and c the triangle's camera-space corners, whose derivatives are cross
//! products; the edge crossings differentiate through the pinhole projection.

use std::collections::HashMap;

use glam::{DMat3, DVec3};

use crate::hard::{NO_FACE, Raster, RasterMesh, Shading, rasterize};
use mannequin_splat::Camera;

/// One antialiasing blend: pixel `to` gains `alpha` × (value at `from` − its own value).
#[derive(Debug, Clone, Copy)]
struct Blend {
    from: usize,
    to: usize,
    alpha: f64,
    /// The silhouette edge's vertices and the pair's direction, for the gradient of alpha.
    edge: [usize; 2],
    /// +1 when alpha = t − ½ (the far pixel is covered), −1 when alpha = ½ − t.
    sign: f64,
    /// The near pixel and whether the pair is horizontal.
    near: usize,
    horizontal: bool,
}

/// The forward pass: the hard raster, the interpolated and antialiased image, and what the
/// backward pass needs.
pub struct Rendered<const C: usize> {
    pub raster: Raster,
    /// Per pixel, `C` channels, row-major.
    pub image: Vec<[f64; C]>,
    interpolated: Vec<[f64; C]>,
    blends: Vec<Blend>,
    camera_points: Vec<DVec3>,
}

/// The gradients of a scalar loss with respect to the vertices' world positions and attributes.
pub struct Gradients<const C: usize> {
    pub positions: Vec<[f64; 3]>,
    pub attributes: Vec<[f64; C]>,
}

/// Renders `attributes` (one `C`-vector per vertex) of the mesh `positions`/`faces` through
/// `camera`, over `background`.
pub fn render<const C: usize>(
    positions: &[[f32; 3]],
    faces: &[[u32; 3]],
    attributes: &[[f64; C]],
    camera: &Camera,
    background: [f64; C],
) -> Rendered<C> {
    let normals = vec![[0.0, 0.0, 1.0]; positions.len()];
    let mesh = RasterMesh { positions, faces, normals: &normals, shading: Shading::Flat([1.0; 3]) };
    let raster = rasterize(&mesh, camera, [0.0; 3]);
    let interpolated: Vec<[f64; C]> = raster
        .face_id
        .iter()
        .zip(&raster.barycentrics)
        .map(|(&f, b)| match f {
            NO_FACE => background,
            f => {
                let corners = faces[f as usize];
                std::array::from_fn(|c| {
                    (0..3).map(|k| b[k] as f64 * attributes[corners[k] as usize][c]).sum()
                })
            }
        })
        .collect();
    let (rot, t) = (camera.rotation(), camera.translation());
    let camera_points: Vec<DVec3> =
        positions.iter().map(|p| rot * DVec3::from(p.map(f64::from)) + t).collect();
    let blends = silhouette_blends(&raster, faces, &camera_points, camera);
    let mut image = interpolated.clone();
    for b in &blends {
        let (from, to) = (interpolated[b.from], interpolated[b.to]);
        (0..C).for_each(|c| image[b.to][c] += b.alpha * (from[c] - to[c]));
    }
    Rendered { raster, image, interpolated, blends, camera_points }
}

impl<const C: usize> Rendered<C> {
    /// The gradients of a loss whose gradient with respect to `image` is `grad` (per pixel).
    pub fn backward(
        &self,
        grad: &[[f64; C]],
        faces: &[[u32; 3]],
        attributes: &[[f64; C]],
        camera: &Camera,
    ) -> Gradients<C> {
        let n = self.camera_points.len();
        let mut d_camera = vec![DVec3::ZERO; n];
        let mut d_attributes = vec![[0.0; C]; n];
        // Through the blends: to the interpolated values and to each edge's alpha.
        let mut d_interpolated = grad.to_vec();
        for b in &self.blends {
            let (from, to) = (self.interpolated[b.from], self.interpolated[b.to]);
            let g = grad[b.to];
            let mut d_alpha = 0.0;
            for c in 0..C {
                d_interpolated[b.from][c] += b.alpha * g[c];
                d_interpolated[b.to][c] -= b.alpha * g[c];
                d_alpha += g[c] * (from[c] - to[c]);
            }
            let width = self.raster.color.width;
            let (x, y) = ((b.near % width) as f64 + 0.5, (b.near / width) as f64 + 0.5);
            let [a, e] = b.edge;
            let (pa, pb) = (self.camera_points[a], self.camera_points[e]);
            let (da, db) = crossing_gradient(camera, pa, pb, [x, y], b.horizontal, b.far_is_forward());
            d_camera[a] += b.sign * d_alpha * da;
            d_camera[e] += b.sign * d_alpha * db;
        }
        // Through the interpolation: to the attributes and the barycentrics.
        let width = self.raster.color.width;
        for (i, &f) in self.raster.face_id.iter().enumerate() {
            if f == NO_FACE {
                continue;
            }
            let corners = faces[f as usize].map(|v| v as usize);
            let b = self.raster.barycentrics[i];
            let g = d_interpolated[i];
            let mut d_b = [0.0; 3];
            for k in 0..3 {
                for c in 0..C {
                    d_attributes[corners[k]][c] += b[k] as f64 * g[c];
                    d_b[k] += attributes[corners[k]][c] * g[c];
                }
            }
            let ray = camera.unproject((i % width) as f64 + 0.5, (i / width) as f64 + 0.5);
            let p = corners.map(|v| self.camera_points[v]);
            let w: [f64; 3] = std::array::from_fn(|k| ray.dot(p[(k + 1) % 3].cross(p[(k + 2) % 3])));
            let total: f64 = w.iter().sum();
            if total.abs() < 1e-300 {
                continue;
            }
            // ∂L/∂w_j = Σ_k ∂L/∂b_k (δ_kj − b_k) / W.
            let mean: f64 = (0..3).map(|k| d_b[k] * w[k] / total).sum();
            for j in 0..3 {
                let d_w = (d_b[j] - mean) / total;
                // w_j = r · (p_{j+1} × p_{j+2}) = p_{j+1} · (p_{j+2} × r) = p_{j+2} · (r × p_{j+1}).
                d_camera[corners[(j + 1) % 3]] += d_w * p[(j + 2) % 3].cross(ray);
                d_camera[corners[(j + 2) % 3]] += d_w * ray.cross(p[(j + 1) % 3]);
            }
        }
        let rot_t: DMat3 = camera.rotation().transpose();
        Gradients {
            positions: d_camera.iter().map(|d| (rot_t * *d).to_array()).collect(),
            attributes: d_attributes,
        }
    }
}

impl Blend {
    /// Whether the far pixel lies right of (or below) the near one.
    fn far_is_forward(&self) -> bool {
        let far = if self.from == self.near { self.to } else { self.from };
        far > self.near
    }
}

/// Where the edge p_a p_b, projected, crosses the line through the near pixel's centre `at`
/// (horizontal or vertical), as the distance t from that centre toward the far pixel; `None`
/// when it does not cross the unit segment.
fn crossing(
    camera: &Camera,
    pa: DVec3,
    pb: DVec3,
    at: [f64; 2],
    horizontal: bool,
    forward: bool,
) -> Option<f64> {
    let (a, b) = (camera.project(pa), camera.project(pb));
    // Along the pair's axis (u) and across it (v).
    let (ua, va, ub, vb, u0, v0) = match horizontal {
        true => (a[0], a[1], b[0], b[1], at[0], at[1]),
        false => (a[1], a[0], b[1], b[0], at[1], at[0]),
    };
    if (va - v0) * (vb - v0) > 0.0 || va == vb {
        return None;
    }
    let s = (v0 - va) / (vb - va);
    let u = ua + s * (ub - ua);
    let t = if forward { u - u0 } else { u0 - u };
    (0.0..=1.0).contains(&t).then_some(t)
}

/// ∂t/∂p_a and ∂t/∂p_b (camera space) for [`crossing`].
fn crossing_gradient(
    camera: &Camera,
    pa: DVec3,
    pb: DVec3,
    at: [f64; 2],
    horizontal: bool,
    forward: bool,
) -> (DVec3, DVec3) {
    let (a, b) = (camera.project(pa), camera.project(pb));
    let (axis, across) = if horizontal { (0, 1) } else { (1, 0) };
    let (ua, va, ub, vb, v0) = (a[axis], a[across], b[axis], b[across], at[across]);
    let s = (v0 - va) / (vb - va);
    // u = ua + s (ub − ua); ∂s/∂va = (s − 1)/(vb − va), ∂s/∂vb = −s/(vb − va).
    let du = [1.0 - s, (ub - ua) * (s - 1.0) / (vb - va), s, -(ub - ua) * s / (vb - va)];
    let sign = if forward { 1.0 } else { -1.0 };
    let pixel_grad = |p: DVec3, d_axis: f64, d_across: f64| -> DVec3 {
        let mut d = [0.0; 2];
        d[axis] = d_axis;
        d[across] = d_across;
        sign * projection_vjp(camera, p, d)
    };
    (pixel_grad(pa, du[0], du[1]), pixel_grad(pb, du[2], du[3]))
}

/// dᵀ ∂(u, v)/∂p for the pinhole projection of the camera-space point p.
fn projection_vjp(camera: &Camera, p: DVec3, d: [f64; 2]) -> DVec3 {
    let k = &camera.intrinsic;
    let (fx, skew, fy) = (k[0][0], k[0][1], k[1][1]);
    let z2 = p.z * p.z;
    let du = DVec3::new(fx / p.z, skew / p.z, -(fx * p.x + skew * p.y) / z2);
    let dv = DVec3::new(0.0, fy / p.z, -fy * p.y / z2);
    d[0] * du + d[1] * dv
}

/// Each neighbouring pixel pair across a silhouette edge of the nearer surface, as a blend.
fn silhouette_blends(raster: &Raster, faces: &[[u32; 3]], points: &[DVec3], camera: &Camera) -> Vec<Blend> {
    let facing: Vec<bool> = faces
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(|v| points[v as usize]);
            (b - a).cross(c - a).dot(a) < 0.0
        })
        .collect();
    let mut sides: HashMap<[u32; 2], Vec<usize>> = HashMap::new();
    for (i, f) in faces.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            sides.entry([a.min(b), a.max(b)]).or_default().push(i);
        }
    }
    // A silhouette edge: on the mesh's border, or between a front- and a back-facing triangle.
    let silhouette = |a: u32, b: u32| {
        let around = &sides[&[a.min(b), a.max(b)]];
        around.len() == 1 || around.iter().any(|&f| !facing[f])
    };
    let (w, h) = (raster.color.width, raster.color.height);
    let mut blends = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let p = y * w + x;
            for (q, horizontal) in
                [(x + 1 < w).then(|| p + 1), (y + 1 < h).then(|| p + w)].into_iter().zip([true, false])
            {
                let Some(q) = q else { continue };
                let (fp, fq) = (raster.face_id[p], raster.face_id[q]);
                if fp == fq {
                    continue;
                }
                let near_is_p = match (fp, fq) {
                    (NO_FACE, _) => false,
                    (_, NO_FACE) => true,
                    _ => raster.depth.depth[p] <= raster.depth.depth[q],
                };
                let (near, far) = if near_is_p { (p, q) } else { (q, p) };
                let tri = faces[raster.face_id[near] as usize];
                let at = [(near % w) as f64 + 0.5, (near / w) as f64 + 0.5];
                let forward = far > near;
                for k in 0..3 {
                    let (a, b) = (tri[k], tri[(k + 1) % 3]);
                    if !silhouette(a, b) {
                        continue;
                    }
                    let (pa, pb) = (points[a as usize], points[b as usize]);
                    let Some(t) = crossing(camera, pa, pb, at, horizontal, forward) else { continue };
                    let edge = [a as usize, b as usize];
                    let blend = match t > 0.5 {
                        true => {
                            Blend { from: near, to: far, alpha: t - 0.5, edge, sign: 1.0, near, horizontal }
                        }
                        false => {
                            Blend { from: far, to: near, alpha: 0.5 - t, edge, sign: -1.0, near, horizontal }
                        }
                    };
                    blends.push(blend);
                    break;
                }
            }
        }
    }
    blends
}
