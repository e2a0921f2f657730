//! Geometry metrics between a predicted and a ground-truth mesh, in centimetres, from uniform
//! surface samples (both meshes in metres):
//!
//! - **Chamfer**: `½ (mean_p min_q ‖p − q‖ + mean_q min_p ‖q − p‖)` over the two sample sets
//!   (point to point, not squared);
//! - **P2S**: `mean_p dist(p, S_gt)`, predicted samples to the ground-truth surface (point to
//!   triangle), as ICON and its successors report it;
//! - **normal consistency**: `½ (mean_p |n_p · n_q(p)| + mean_q |n_q · n_p(q)|)` with `q(p)` the
//!   nearest sample of the other set (Mescheder et al. 2019).

use rayon::prelude::*;
use serde::Serialize;

use super::kdtree::KdTree;
use super::surface_distance::TriangleBvh;
use super::surface_sampling::{SurfaceSamples, sample_surface};
use mannequin_mesh::TriMesh;

#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GeometryMetrics {
    pub chamfer_cm: f64,
    pub p2s_cm: f64,
    pub normal_consistency: f64,
}

/// Mean nearest distance from `from` into `to`, and mean |cos| between their normals.
fn one_way(from: &SurfaceSamples, to: &SurfaceSamples, tree: &KdTree) -> (f64, f64) {
    let (d, c) = from
        .points
        .par_iter()
        .zip(&from.normals)
        .map(|(p, n)| match tree.nearest(*p) {
            Some((j, d2)) => (d2.sqrt(), n.dot(to.normals[j]).abs()),
            None => (f64::NAN, f64::NAN),
        })
        .reduce(|| (0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1));
    let n = from.points.len() as f64;
    (d / n, c / n)
}

/// The metrics from given samples of both surfaces and the ground-truth mesh.
pub fn metrics_from_samples(
    pred: &SurfaceSamples,
    gt: &SurfaceSamples,
    gt_mesh: &TriMesh,
) -> GeometryMetrics {
    let (tree_pred, tree_gt) = rayon::join(|| KdTree::new(&pred.points), || KdTree::new(&gt.points));
    let (d_pg, c_pg) = one_way(pred, gt, &tree_gt);
    let (d_gp, c_gp) = one_way(gt, pred, &tree_pred);
    let bvh = TriangleBvh::new(&gt_mesh.positions, &gt_mesh.faces);
    let p2s = pred
        .points
        .par_iter()
        .map(|p| bvh.closest(*p).map_or(f64::NAN, |h| h.distance_squared.sqrt()))
        .sum::<f64>()
        / pred.points.len() as f64;
    GeometryMetrics {
        chamfer_cm: 50.0 * (d_pg + d_gp),
        p2s_cm: 100.0 * p2s,
        normal_consistency: 0.5 * (c_pg + c_gp),
    }
}

/// Samples `count` points on each mesh (seeds `seed` and `seed + 1`) and compares them.
pub fn geometry_metrics(pred: &TriMesh, gt: &TriMesh, count: usize, seed: u64) -> GeometryMetrics {
    let (sp, sg) = rayon::join(
        || sample_surface(&pred.positions, &pred.faces, count, seed),
        || sample_surface(&gt.positions, &gt.faces, count, seed.wrapping_add(1)),
    );
    metrics_from_samples(&sp, &sg, gt)
}
