//! The ground-truth renderer: a CPU triangle rasterizer (not differentiable) with a z-buffer,
//! perspective-correct barycentrics and bilinear texture sampling.
//!
//! Camera conventions are the splat renderer's: OpenCV axes, pixel `(i, j)` sampled at its
//! centre `(i + 0.5, j + 0.5)`. A pixel is covered when its centre lies inside or on the
//! triangle; on shared edges the nearer face wins and, at equal depth, the lower face index.
//! Faces with a corner closer than [`NEAR`] to the camera plane are dropped, not clipped.

use glam::{DMat3, DVec3, Vec2, Vec3};
use mannequin_mesh::UvLayout;
use rayon::prelude::*;

use mannequin_data::image::{Image, Mask};
use mannequin_data::maps::{DepthMap, NormalMap};
use mannequin_splat::Camera;

/// The face id of pixels that no triangle covers.
pub const NO_FACE: u32 = u32::MAX;
/// Smallest camera-space depth a rendered vertex may have, in metres.
pub const NEAR: f64 = 1e-3;
/// Rows per work item; bands are rasterized in parallel.
const BAND: usize = 16;

/// How a covered pixel gets its colour.
#[derive(Debug, Clone, Copy)]
pub enum Shading<'a> {
    /// Bilinear lookup (clamped at the borders) of `texture` at the interpolated UV; the
    /// texture's top row is v = 1, as in OBJ.
    Texture { uv: &'a UvLayout, texture: &'a Image },
    /// One colour everywhere.
    Flat([f32; 3]),
    /// A colour per vertex, interpolated by the (perspective-correct) barycentrics.
    Vertex(&'a [[f32; 3]]),
}

/// A triangle mesh in world coordinates, with per-vertex normals used for shading normals.
#[derive(Debug, Clone, Copy)]
pub struct RasterMesh<'a> {
    pub positions: &'a [[f32; 3]],
    pub faces: &'a [[u32; 3]],
    pub normals: &'a [[f32; 3]],
    pub shading: Shading<'a>,
}

/// Everything the renderer produces for one view.
#[derive(Debug, Clone)]
pub struct Raster {
    pub color: Image,
    pub mask: Mask,
    /// Interpolated vertex normals, normalised, in camera space.
    pub normals: NormalMap,
    /// Camera-space z.
    pub depth: DepthMap,
    pub face_id: Vec<u32>,
    /// The covered pixels' perspective-correct barycentrics in their face (zero elsewhere).
    pub barycentrics: Vec<[f32; 3]>,
}

/// A triangle in screen space: pixel coordinates and camera-space depth per corner.
struct ScreenTri {
    p: [[f64; 2]; 3],
    z: [f64; 3],
    inv_area: f64,
    x0: usize,
    x1: usize,
    y0: usize,
    y1: usize,
}

/// Twice the signed area of (a, b, p).
fn edge(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
}

fn screen_triangles(mesh: &RasterMesh, camera: &Camera) -> Vec<Option<ScreenTri>> {
    let rot = camera.rotation();
    let t = camera.translation();
    let cam: Vec<DVec3> = mesh.positions.iter().map(|p| rot * DVec3::from(p.map(f64::from)) + t).collect();
    let (w, h) = (camera.width as f64, camera.height as f64);
    mesh.faces
        .par_iter()
        .map(|f| {
            let c = f.map(|i| cam[i as usize]);
            if c.iter().any(|v| v.z < NEAR) {
                return None;
            }
            let p = c.map(|v| camera.project(v));
            let area = edge(p[0], p[1], p[2]);
            if area == 0.0 || !area.is_finite() {
                return None;
            }
            let lo = |k: usize| p.iter().map(|q| q[k]).fold(f64::INFINITY, f64::min);
            let hi = |k: usize| p.iter().map(|q| q[k]).fold(f64::NEG_INFINITY, f64::max);
            // Pixels whose centres (i + 0.5) can fall inside [lo, hi].
            let (fx0, fx1) = ((lo(0) - 0.5).ceil().max(0.0), (hi(0) - 0.5).floor().min(w - 1.0));
            let (fy0, fy1) = ((lo(1) - 0.5).ceil().max(0.0), (hi(1) - 0.5).floor().min(h - 1.0));
            if fx0 > fx1 || fy0 > fy1 {
                return None;
            }
            Some(ScreenTri {
                p,
                z: c.map(|v| v.z),
                inv_area: 1.0 / area,
                x0: fx0 as usize,
                x1: fx1 as usize,
                y0: fy0 as usize,
                y1: fy1 as usize,
            })
        })
        .collect()
}

/// Face indices per band of rows, ascending within each band.
fn bin_by_band(tris: &[Option<ScreenTri>], bands: usize) -> Vec<Vec<u32>> {
    let mut bins = vec![Vec::new(); bands];
    for (f, t) in tris.iter().enumerate() {
        if let Some(t) = t {
            for bin in &mut bins[t.y0 / BAND..=t.y1 / BAND] {
                bin.push(f as u32);
            }
        }
    }
    bins
}

/// Per pixel of one band: nearest face, its depth and perspective-correct barycentrics.
struct Visibility {
    face: Vec<u32>,
    depth: Vec<f64>,
    bary: Vec<[f64; 3]>,
}

fn resolve_band(
    tris: &[Option<ScreenTri>],
    faces: &[u32],
    y_start: usize,
    rows: usize,
    width: usize,
) -> Visibility {
    let mut vis = Visibility {
        face: vec![NO_FACE; rows * width],
        depth: vec![f64::INFINITY; rows * width],
        bary: vec![[0.0; 3]; rows * width],
    };
    for &f in faces {
        let Some(t) = &tris[f as usize] else { continue };
        for y in t.y0.max(y_start)..=t.y1.min(y_start + rows - 1) {
            for x in t.x0..=t.x1 {
                let p = [x as f64 + 0.5, y as f64 + 0.5];
                let s = [edge(t.p[1], t.p[2], p), edge(t.p[2], t.p[0], p), edge(t.p[0], t.p[1], p)]
                    .map(|e| e * t.inv_area);
                if s.iter().any(|&b| b < 0.0) {
                    continue;
                }
                // Screen-space barycentrics become camera-space ones by weighting with 1/z.
                let q = [s[0] / t.z[0], s[1] / t.z[1], s[2] / t.z[2]];
                let z = 1.0 / (q[0] + q[1] + q[2]);
                let i = (y - y_start) * width + x;
                if z < vis.depth[i] {
                    vis.depth[i] = z;
                    vis.face[i] = f;
                    vis.bary[i] = q.map(|v| v * z);
                }
            }
        }
    }
    vis
}

/// Bilinear sample with clamp-to-edge; `(u, v)` with v up, texel centres at `(i + 0.5) / w`.
pub fn sample_bilinear(texture: &Image, uv: Vec2) -> [f32; 3] {
    let (w, h) = (texture.width, texture.height);
    let x = (uv.x * w as f32 - 0.5).clamp(0.0, (w - 1) as f32);
    let y = ((1.0 - uv.y) * h as f32 - 0.5).clamp(0.0, (h - 1) as f32);
    let (x0, y0) = (x.floor() as usize, y.floor() as usize);
    let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
    let (fx, fy) = (x - x0 as f32, y - y0 as f32);
    let mix = |a: [f32; 3], b: [f32; 3], t: f32| [0, 1, 2].map(|c| a[c] + (b[c] - a[c]) * t);
    mix(mix(texture.at(x0, y0), texture.at(x1, y0), fx), mix(texture.at(x0, y1), texture.at(x1, y1), fx), fy)
}

/// Renders `mesh` through `camera`; uncovered pixels get `background`, zero normal, zero depth.
pub fn rasterize(mesh: &RasterMesh, camera: &Camera, background: [f32; 3]) -> Raster {
    let (w, h) = (camera.width, camera.height);
    let tris = screen_triangles(mesh, camera);
    let bins = bin_by_band(&tris, h.div_ceil(BAND));
    let rot: DMat3 = camera.rotation();
    let rot32 = glam::Mat3::from_cols(rot.x_axis.as_vec3(), rot.y_axis.as_vec3(), rot.z_axis.as_vec3());
    let mut color = vec![background; w * h];
    let mut normals = vec![[0.0f32; 3]; w * h];
    let mut depth = vec![0.0f32; w * h];
    let mut face_id = vec![NO_FACE; w * h];
    let mut barycentrics = vec![[0.0f32; 3]; w * h];
    color
        .par_chunks_mut(BAND * w)
        .zip(normals.par_chunks_mut(BAND * w))
        .zip(depth.par_chunks_mut(BAND * w))
        .zip(face_id.par_chunks_mut(BAND * w))
        .zip(barycentrics.par_chunks_mut(BAND * w))
        .enumerate()
        .for_each(|(band, ((((color, normals), depth), face_id), barycentrics))| {
            let rows = color.len() / w;
            let vis = resolve_band(&tris, &bins[band], band * BAND, rows, w);
            for i in 0..rows * w {
                let f = vis.face[i];
                if f == NO_FACE {
                    continue;
                }
                let b = vis.bary[i].map(|v| v as f32);
                let corners = mesh.faces[f as usize];
                let n: Vec3 =
                    (0..3).map(|k| Vec3::from(mesh.normals[corners[k] as usize]) * b[k]).sum::<Vec3>();
                normals[i] = (rot32 * n).normalize_or_zero().to_array();
                depth[i] = vis.depth[i] as f32;
                face_id[i] = f;
                barycentrics[i] = b;
                color[i] = match mesh.shading {
                    Shading::Flat(c) => c,
                    Shading::Vertex(colours) => std::array::from_fn(|c| {
                        (0..3).map(|k| colours[corners[k] as usize][c] * b[k]).sum::<f32>()
                    }),
                    Shading::Texture { uv, texture } => {
                        let t = uv.faces[f as usize];
                        let st: Vec2 = (0..3).map(|k| Vec2::from(uv.coords[t[k] as usize]) * b[k]).sum();
                        sample_bilinear(texture, st)
                    }
                };
            }
        });
    let mask = Mask { width: w, height: h, values: face_id.iter().map(|&f| f != NO_FACE).collect() };
    Raster {
        color: Image { width: w, height: h, pixels: color },
        mask,
        normals: NormalMap { width: w, height: h, normals },
        depth: DepthMap { width: w, height: h, depth },
        face_id,
        barycentrics,
    }
}
