//! Geometry metrics between a predicted and a ground-truth mesh, in centimetres, from uniform
//! surface samples (both meshes in metres):
//!
//! - **Chamfer**: `½ (mean_p dist(p, S_gt) + mean_q dist(q, S_pred))`, samples of each mesh to
//!   the other's surface (point to triangle, not squared), as PIFu, ICON and ECON report it.
//!   Point-to-point distances between two sample sets would add the sample spacing itself
//!   (≈ 2 mm at 100k samples on a body) to every reconstruction, however exact;
//! - **P2S**: `mean_p dist(p, S_gt)`, the first half of that sum;
//! - **normal consistency**: `½ (mean_p |n_p · n_q(p)| + mean_q |n_q · n_p(q)|)` with `q(p)` the
//!   nearest sample of the other set (Mescheder et al. 2019).

use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;

use super::surface_distance::TriangleBvh;
use super::surface_sampling::{SurfaceSamples, sample_surface};
use mannequin_mesh::TriMesh;
use mannequin_mesh::kdtree::KdTree;

#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GeometryMetrics {
    pub chamfer_cm: f64,
    pub p2s_cm: f64,
    pub normal_consistency: f64,
}

/// Mean |cos| between the normals of `from` and of their nearest samples in `to`.
fn normal_agreement(from: &SurfaceSamples, to: &SurfaceSamples, tree: &KdTree) -> f64 {
    let c: f64 = from
        .points
        .par_iter()
        .zip(&from.normals)
        .map(|(p, n)| tree.nearest(*p).map_or(f64::NAN, |(j, _)| n.dot(to.normals[j]).abs()))
        .sum();
    c / from.points.len() as f64
}

/// Mean distance from `points` to the surface of `mesh`.
fn surface_distance(points: &[DVec3], mesh: &TriMesh) -> f64 {
    let bvh = TriangleBvh::new(&mesh.positions, &mesh.faces);
    let sum: f64 =
        points.par_iter().map(|p| bvh.closest(*p).map_or(f64::NAN, |h| h.distance_squared.sqrt())).sum();
    sum / points.len() as f64
}

/// The metrics from given samples of both surfaces and both meshes.
pub fn metrics_from_samples(
    pred: &SurfaceSamples,
    gt: &SurfaceSamples,
    pred_mesh: &TriMesh,
    gt_mesh: &TriMesh,
) -> GeometryMetrics {
    let (tree_pred, tree_gt) = rayon::join(|| KdTree::new(&pred.points), || KdTree::new(&gt.points));
    let normal_consistency =
        0.5 * (normal_agreement(pred, gt, &tree_gt) + normal_agreement(gt, pred, &tree_pred));
    let (p2s, s2p) =
        rayon::join(|| surface_distance(&pred.points, gt_mesh), || surface_distance(&gt.points, pred_mesh));
    GeometryMetrics { chamfer_cm: 50.0 * (p2s + s2p), p2s_cm: 100.0 * p2s, normal_consistency }
}

/// Samples `count` points on each mesh (seeds `seed` and `seed + 1`) and compares them.
pub fn geometry_metrics(pred: &TriMesh, gt: &TriMesh, count: usize, seed: u64) -> GeometryMetrics {
    let (sp, sg) = rayon::join(
        || sample_surface(&pred.positions, &pred.faces, count, seed),
        || sample_surface(&gt.positions, &gt.faces, count, seed.wrapping_add(1)),
    );
    metrics_from_samples(&sp, &sg, pred, gt)
}
