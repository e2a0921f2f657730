//! The face's colour fitted by the photometric term E_I (thesis Eq. 2.20): the fitted head is
//! rasterised in each view's camera, and a colour per head vertex (the albedo) and a light per
//! view are found that make the rendered face most like the photos over the face:
//!
//! E_I = Σ_views Σ_pixels ‖I(p) − s_v(n_p) Σ_k b_k(p) c_k‖² + smoothness + symmetry,
//!
//! over the pixels the head covers,
//!
//! with b_k the pixel's barycentrics, n_p its normal and s_v(n) = a + n·d the view's light (an
//! ambient term and one direction: first-order spherical harmonics). The thesis fits a PCA
//! texture model (Eq. 2.19); none is licence-free, so the albedo is free per vertex, held smooth
//! over the mesh's edges and, where no view sees it, to its mirror vertex. Albedo and light are
//! solved in turn: the light by a 4 × 4 least squares, the albedo by conjugate gradients on its
//! normal equations. The geometry stays as the landmark fit left it: moving it by E_I needs a
//! differentiable rasteriser.

use glam::DVec3;
use mannequin_data::{Camera, Image};
use mannequin_mesh::normals::vertex_normals;
use mannequin_raster::{NO_FACE, RasterMesh, Shading, rasterize};

use crate::error::FitError;

/// Relative weights of the priors (per edge, per mirrored vertex) against one pixel.
const SMOOTHNESS: f64 = 0.5;
const SYMMETRY: f64 = 0.2;
/// A small pull to the mean colour keeps vertices no pixel and no neighbour reaches determined.
const RIDGE: f64 = 1e-3;
const ROUNDS: usize = 4;
const CG_STEPS: usize = 60;

/// One picture of the head: its vertices in that camera's space and the photo.
pub struct View<'a> {
    /// Head vertices, camera space (x right, y down, z ahead).
    pub points: &'a [DVec3],
    pub camera: &'a Camera,
    pub image: &'a Image,
}

/// The fitted colour and lights.
#[derive(Debug, Clone)]
pub struct Texture {
    /// Per head vertex, in [0, 1].
    pub albedo: Vec<[f32; 3]>,
    /// Per view: ambient a, then direction d (camera axes).
    pub lights: Vec<[f32; 4]>,
    /// E_I's root mean square per channel over the head's pixels, in [0, 1] units.
    pub rms: f32,
    /// Whether some pixel of some view saw the vertex.
    pub seen: Vec<bool>,
}

/// A covered pixel: its photo colour, normal, corners and barycentrics.
struct Sample {
    colour: [f64; 3],
    normal: DVec3,
    corners: [usize; 3],
    weights: [f64; 3],
}

/// Fits albedo and lights to `views` of the head (`faces` over its vertices) over every pixel
/// the head covers; `mirror[v]` is the vertex mirroring v ([`mirror_vertices`]).
pub fn fit_texture(views: &[View], faces: &[[u32; 3]], mirror: &[usize]) -> Result<Texture, FitError> {
    let n = mirror.len();
    if let Some(v) = views.iter().find(|v| v.points.len() != n) {
        return Err(FitError::input(
            "face texture",
            format!("a view of {} vertices; the head has {n}", v.points.len()),
        ));
    }
    let samples: Vec<Vec<Sample>> = views.iter().map(|v| samples(v, faces)).collect();
    let count: usize = samples.iter().map(Vec::len).sum();
    if count < 100 {
        return Err(FitError::Picture(format!(
            "the face covers {count} pixels; its colour needs at least 100"
        )));
    }
    let mut seen = vec![false; n];
    samples.iter().flatten().for_each(|s| s.corners.iter().for_each(|&c| seen[c] = true));
    let edges = edges(faces);
    let mut lights: Vec<[f64; 4]> = vec![[1.0, 0.0, 0.0, 0.0]; views.len()];
    let mut albedo = vec![[0.5f64; 3]; n];
    for _ in 0..ROUNDS {
        albedo = solve_albedo(&samples, &lights, &edges, mirror, &seen, &albedo);
        for (light, view) in lights.iter_mut().zip(&samples) {
            *light = solve_light(view, &albedo).unwrap_or(*light);
        }
        // Albedo × k and light / k render alike: keep the lights' mean shade over the face at 1.
        let shade: f64 = samples
            .iter()
            .zip(&lights)
            .flat_map(|(view, l)| view.iter().map(move |s| shade(l, s.normal)))
            .sum::<f64>()
            / count as f64;
        if shade > 1e-6 {
            lights.iter_mut().for_each(|l| l.iter_mut().for_each(|x| *x /= shade));
            albedo.iter_mut().for_each(|c| c.iter_mut().for_each(|x| *x *= shade));
        }
    }
    let residual: f64 = samples
        .iter()
        .zip(&lights)
        .flat_map(|(view, l)| view.iter().map(move |s| (s, l)))
        .map(|(s, l)| {
            let model = rendered(s, l, &albedo);
            (0..3).map(|c| (s.colour[c] - model[c]).powi(2)).sum::<f64>()
        })
        .sum();
    Ok(Texture {
        albedo: albedo.iter().map(|c| c.map(|x| x.clamp(0.0, 1.0) as f32)).collect(),
        lights: lights.iter().map(|l| l.map(|x| x as f32)).collect(),
        rms: (residual / (3 * count) as f64).sqrt() as f32,
        seen,
    })
}

/// For each vertex of a rest head (the default body's axes: x to the subject's left), the vertex
/// nearest its mirror image x → −x.
pub fn mirror_vertices(rest: &[[f32; 3]]) -> Vec<usize> {
    let distance = |a: &[f32; 3], b: [f32; 3]| (0..3).map(|c| (a[c] - b[c]).powi(2)).sum::<f32>();
    rest.iter()
        .map(|p| {
            let image = [-p[0], p[1], p[2]];
            (0..rest.len())
                .min_by(|&a, &b| distance(&rest[a], image).total_cmp(&distance(&rest[b], image)))
                .unwrap_or(0)
        })
        .collect()
}

fn shade(light: &[f64; 4], n: DVec3) -> f64 {
    light[0] + light[1] * n.x + light[2] * n.y + light[3] * n.z
}

fn rendered(s: &Sample, light: &[f64; 4], albedo: &[[f64; 3]]) -> [f64; 3] {
    let k = shade(light, s.normal);
    std::array::from_fn(|c| k * (0..3).map(|j| s.weights[j] * albedo[s.corners[j]][c]).sum::<f64>())
}

/// The head's covered pixels in one view.
fn samples(view: &View, faces: &[[u32; 3]]) -> Vec<Sample> {
    // The rasteriser's world is the camera's axes with y and z flipped (`picture_camera`).
    let world: Vec<[f32; 3]> = view.points.iter().map(|x| [x.x as f32, -x.y as f32, -x.z as f32]).collect();
    let normals = vertex_normals(&world, faces);
    let mesh = RasterMesh { positions: &world, faces, normals: &normals, shading: Shading::Flat([1.0; 3]) };
    let raster = rasterize(&mesh, view.camera, [0.0; 3]);
    let mut out = Vec::new();
    for (i, &f) in raster.face_id.iter().enumerate() {
        if f == NO_FACE {
            continue;
        }
        let corners = faces[f as usize].map(|v| v as usize);
        let n = raster.normals.normals[i];
        let (x, y) = (i % view.image.width, i / view.image.width);
        out.push(Sample {
            colour: view.image.at(x, y).map(f64::from),
            normal: DVec3::new(n[0] as f64, n[1] as f64, n[2] as f64),
            corners,
            weights: raster.barycentrics[i].map(f64::from),
        });
    }
    out
}

/// Each undirected edge of the mesh once.
fn edges(faces: &[[u32; 3]]) -> Vec<[usize; 2]> {
    let mut e: Vec<[usize; 2]> = faces
        .iter()
        .flat_map(|f| [[f[0], f[1]], [f[1], f[2]], [f[2], f[0]]])
        .map(|[a, b]| [a.min(b) as usize, a.max(b) as usize])
        .collect();
    e.sort_unstable();
    e.dedup();
    e
}

/// The least-squares light of one view for a fixed albedo: I ≈ (a + n·d) ρ(p).
fn solve_light(view: &[Sample], albedo: &[[f64; 3]]) -> Option<[f64; 4]> {
    let mut m = glam::DMat4::ZERO;
    let mut b = glam::DVec4::ZERO;
    for s in view {
        let rho: [f64; 3] =
            std::array::from_fn(|c| (0..3).map(|j| s.weights[j] * albedo[s.corners[j]][c]).sum());
        let basis = glam::DVec4::new(1.0, s.normal.x, s.normal.y, s.normal.z);
        for (rho, colour) in rho.iter().zip(s.colour) {
            let row = basis * *rho;
            m += glam::DMat4::from_cols(row * row.x, row * row.y, row * row.z, row * row.w);
            b += row * colour;
        }
    }
    (m.determinant().abs() > 1e-12).then(|| (m.inverse() * b).to_array())
}

/// The albedo minimising E_I for fixed lights, per channel by conjugate gradients on
/// (JᵀJ + priors) c = Jᵀ I, started from `start`.
fn solve_albedo(
    samples: &[Vec<Sample>],
    lights: &[[f64; 4]],
    edges: &[[usize; 2]],
    mirror: &[usize],
    seen: &[bool],
    start: &[[f64; 3]],
) -> Vec<[f64; 3]> {
    let n = start.len();
    let rows: Vec<(&Sample, f64)> = samples
        .iter()
        .zip(lights)
        .flat_map(|(view, l)| view.iter().map(move |s| (s, shade(l, s.normal))))
        .collect();
    let apply = |x: &[f64], out: &mut [f64]| {
        out.iter_mut().zip(x).for_each(|(o, v)| *o = RIDGE * v);
        for (s, k) in &rows {
            let value: f64 = (0..3).map(|j| k * s.weights[j] * x[s.corners[j]]).sum();
            (0..3).for_each(|j| out[s.corners[j]] += k * s.weights[j] * value);
        }
        for &[a, b] in edges {
            let d = SMOOTHNESS * (x[a] - x[b]);
            out[a] += d;
            out[b] -= d;
        }
        for v in (0..n).filter(|&v| !seen[v]) {
            out[v] += SYMMETRY * (x[v] - x[mirror[v]]);
        }
    };
    let mut albedo = start.to_vec();
    for c in 0..3 {
        let mean = start.iter().map(|a| a[c]).sum::<f64>() / n as f64;
        let mut rhs = vec![RIDGE * mean; n];
        for (s, k) in &rows {
            (0..3).for_each(|j| rhs[s.corners[j]] += k * s.weights[j] * s.colour[c]);
        }
        let mut x: Vec<f64> = start.iter().map(|a| a[c]).collect();
        let mut ax = vec![0.0; n];
        apply(&x, &mut ax);
        let mut r: Vec<f64> = rhs.iter().zip(&ax).map(|(b, a)| b - a).collect();
        let mut p = r.clone();
        let mut rr: f64 = r.iter().map(|v| v * v).sum();
        let mut ap = vec![0.0; n];
        for _ in 0..CG_STEPS {
            if rr < 1e-14 {
                break;
            }
            apply(&p, &mut ap);
            let alpha = rr / p.iter().zip(&ap).map(|(a, b)| a * b).sum::<f64>();
            x.iter_mut().zip(&p).for_each(|(x, p)| *x += alpha * p);
            r.iter_mut().zip(&ap).for_each(|(r, a)| *r -= alpha * a);
            let next: f64 = r.iter().map(|v| v * v).sum();
            p.iter_mut().zip(&r).for_each(|(p, r)| *p = r + next / rr * *p);
            rr = next;
        }
        albedo.iter_mut().zip(&x).for_each(|(a, v)| a[c] = *v);
    }
    albedo
}

#[cfg(test)]
mod tests {
    use glam::DQuat;
    use mannequin_body::{BodyModel, FaceModel};

    use super::*;
    use crate::body_fit::picture_camera;
    use crate::face_render::{LitHead, render_head};

    /// The default head painted with a known colour, symmetric left to right, and shown turned a
    /// quarter to one side under even light: E_I's albedo is the paint where the picture sees it,
    /// and its mirror image where it does not.
    #[test]
    fn the_albedo_is_the_paint_seen_and_its_mirror_unseen() {
        let (body, face) = (BodyModel::default_body(), FaceModel::default_face());
        let faces = face.head_faces(&body);
        let rest: Vec<[f32; 3]> = face.vertices.iter().map(|&v| body.v_template[v]).collect();
        let paint: Vec<[f32; 3]> = rest
            .iter()
            .map(|p| {
                [
                    0.5 + 0.3 * (40.0 * p[1]).sin(),
                    0.4 + 0.3 * (25.0 * p[0].abs()).cos(),
                    0.3 + 2.0 * (p[2] - 0.05).abs(),
                ]
            })
            .map(|c| c.map(|x| x.clamp(0.0, 1.0)))
            .collect();
        let centre = rest.iter().map(|p| DVec3::from(p.map(f64::from))).sum::<DVec3>() / rest.len() as f64;
        let rotation = DQuat::from_rotation_x(std::f64::consts::PI) * DQuat::from_rotation_y(0.7);
        let points: Vec<DVec3> = rest
            .iter()
            .map(|p| rotation * (DVec3::from(p.map(f64::from)) - centre) + DVec3::new(0.0, 0.0, 0.45))
            .collect();
        let camera = picture_camera(320, 320, 400.0);
        let head = LitHead { points: &points, faces: &faces, colours: &paint, light: DVec3::Z, ambient: 1.0 };
        let (image, _) = render_head(&head, &camera, [0.2; 3]);
        let view = View { points: &points, camera: &camera, image: &image };
        let mirror = mirror_vertices(&rest);
        let texture = fit_texture(&[view], &faces, &mirror).unwrap();
        let gap = |v: usize| (0..3).map(|c| (texture.albedo[v][c] - paint[v][c]).abs()).sum::<f32>() / 3.0;
        let mean = |set: &[usize]| set.iter().map(|&v| gap(v)).sum::<f32>() / set.len() as f32;
        let seen: Vec<usize> = (0..rest.len()).filter(|&v| texture.seen[v]).collect();
        let mirrored: Vec<usize> =
            (0..rest.len()).filter(|&v| !texture.seen[v] && texture.seen[mirror[v]]).collect();
        println!(
            "seen {} vertices off by {:.4}, {} unseen with a seen mirror off by {:.4}; rms {:.4}",
            seen.len(),
            mean(&seen),
            mirrored.len(),
            mean(&mirrored),
            texture.rms
        );
        assert!(
            seen.len() > 1000 && mirrored.len() > 300,
            "{} seen, {} mirrored",
            seen.len(),
            mirrored.len()
        );
        assert!(mean(&seen) < 0.03, "seen vertices' albedo off by {}", mean(&seen));
        assert!(mean(&mirrored) < 0.08, "unseen vertices' albedo off by {}", mean(&mirrored));
        assert!(texture.rms < 0.03, "E_I's rms {}", texture.rms);
    }
}
