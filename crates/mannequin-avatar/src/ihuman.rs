//! iHuman's binding (supplement §1.2): one Gaussian at each face centroid, its frame the face's
//! (normal, first edge, their cross product) turned in the face plane by a learned complex
//! number, with learned in-plane scales and a 1 mm normal scale.

use burn::tensor::Tensor;

use crate::canonical::Canonical;
use crate::mesh_gaussians::{FACE_SCALE, GaussianGeometry, MeshIndex, VERTEX_SCALE};

/// s1, the scale along the normal: 1 mm.
pub const NORMAL_SCALE: f64 = 1e-3;

const NORM_EPS: f64 = 1e-20;

fn unit_rows(x: Tensor<2>) -> Tensor<2> {
    x.clone() / (x.square().sum_dim(1) + NORM_EPS).sqrt()
}

/// Centroid Gaussians (Eqs. 1–6) of posed vertices, with `rotation` [F, 2] = (x, y) of the
/// complex in-plane rotation (normalised here) and `log_scales` [F, 2] = log (s2, s3).
pub fn centroid_gaussians(
    vertices: &Tensor<2>,
    index: &MeshIndex,
    rotation: Tensor<2>,
    log_scales: Tensor<2>,
) -> GaussianGeometry {
    let [a, b, c] = index.corner_positions(vertices);
    let means = (a.clone() + b.clone() + c.clone()) / 3.0;
    let edge = b - a.clone();
    let n = unit_rows(edge.clone().cross(c - a, 1)); // R0, Eq. 2
    let r1 = unit_rows(edge); // Eq. 3
    let r2 = unit_rows(n.clone().cross(r1.clone(), 1)); // Eq. 4
    let z = unit_rows(rotation);
    let (cos, sin) = (z.clone().narrow(1, 0, 1), z.narrow(1, 1, 1));
    let t1 = r1.clone() * cos.clone() + r2.clone() * sin.clone();
    let t2 = r2 * cos - r1 * sin;
    let eps = log_scales.clone().narrow(1, 0, 1).zeros_like() + NORMAL_SCALE;
    GaussianGeometry {
        means,
        frames: Tensor::stack(vec![t1, t2, n.clone()], 2),
        scales: Tensor::cat(vec![log_scales.exp(), eps], 1),
        normals: n,
    }
}

fn corner(c: &Canonical, f: [u32; 3], k: usize) -> [f64; 3] {
    c.vertices[f[k] as usize].map(f64::from)
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Canonical face centroids: the colour encoder's inputs.
pub fn face_centroids(c: &Canonical) -> Vec<[f32; 3]> {
    c.faces
        .iter()
        .map(|f| {
            let p: Vec<[f32; 3]> = f.iter().map(|&i| c.vertices[i as usize]).collect();
            [0, 1, 2].map(|k| (p[0][k] + p[1][k] + p[2][k]) / 3.0)
        })
        .collect()
}

/// Initial log (s2, s3) per face: β times the canonical inradius, as Tavatar's face Gaussians.
pub fn log_inradius_scales(c: &Canonical) -> Vec<f32> {
    c.faces
        .iter()
        .flat_map(|&f| {
            let [a, b, cc] = [0, 1, 2].map(|k| corner(c, f, k));
            let (la, lb, lc) = (dist(b, cc), dist(cc, a), dist(a, b));
            let s = 0.5 * (la + lb + lc);
            let area = (s * (s - la) * (s - lb) * (s - lc)).max(0.0).sqrt();
            let r = (FACE_SCALE * area / s.max(1e-12)).max(1e-5);
            [r.ln() as f32; 2]
        })
        .collect()
}

/// Initial log in-plane scales per vertex for learnable vertex Gaussians: γ times the shortest
/// canonical one-ring edge (Eq. 11's value at rest).
pub fn log_edge_scales(c: &Canonical) -> Vec<f32> {
    let mut shortest = vec![f64::INFINITY; c.num_vertices()];
    for &f in &c.faces {
        for k in 0..3 {
            let (i, j) = (f[k] as usize, f[(k + 1) % 3] as usize);
            let l = dist(c.vertices[i].map(f64::from), c.vertices[j].map(f64::from));
            shortest[i] = shortest[i].min(l);
            shortest[j] = shortest[j].min(l);
        }
    }
    shortest
        .iter()
        .flat_map(|&l| {
            let s = if l.is_finite() { (VERTEX_SCALE * l).max(1e-5) } else { 1e-3 };
            [s.ln() as f32; 2]
        })
        .collect()
}
