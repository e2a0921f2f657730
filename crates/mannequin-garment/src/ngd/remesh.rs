//! NGD's gradient-based adaptive remeshing (§3.2). Every so many steps, the faces whose summed
//! loss gradient ‖∂ℓ/∂M_t‖ lies in the top quantile α(t), and whose edges are all longer than
//! δ(t), have their edges split at the midpoints, and edges are flipped toward valence 6 (4 on a
//! boundary); α and δ fall linearly over the schedule, so detail is added where the images ask
//! for it, finer as the fit settles. The static field J^s and Adam's moments move to the new faces,
//! and the skinning weights to the new vertices, by inverse-distance weighting of the K nearest
//! old face centres or vertices (Eqs. 9–10).

use glam::DVec3;
use mannequin_mesh::kdtree::KdTree;
use mannequin_mesh::poisson::Jacobian;
use mannequin_mesh::remesh::split_and_flip;
use serde::Serialize;

/// Neighbours in Eqs. 9–10.
const NEIGHBOURS: usize = 3;
/// ε of Eq. 9 (metres): a face or vertex where an old one was copies it.
const EPSILON: f64 = 1e-7;

/// When and how much to remesh.
#[derive(Debug, Clone, Serialize)]
pub struct RemeshSchedule {
    /// Steps between remeshings.
    pub every: usize,
    /// The last remeshing comes before this share of the steps.
    pub until: f64,
    /// α at the first and the last remeshing: faces whose gradient norm is at or above this
    /// quantile are candidates.
    pub quantile: [f64; 2],
    /// δ at the first and the last remeshing (metres): a candidate is split only if all its
    /// edges are longer.
    pub length: [f64; 2],
}

impl Default for RemeshSchedule {
    fn default() -> Self {
        Self { every: 100, until: 0.7, quantile: [0.95, 0.8], length: [0.012, 0.006] }
    }
}

impl RemeshSchedule {
    /// α and δ at step `step` of `steps`, if a remeshing is due after it.
    pub fn due(&self, step: usize, steps: usize) -> Option<(f64, f64)> {
        let last = (self.until * steps as f64) as usize;
        if self.every == 0 || step == 0 || !step.is_multiple_of(self.every) || step > last {
            return None;
        }
        let t = step as f64 / last.max(1) as f64;
        let lerp = |[a, b]: [f64; 2]| a + (b - a) * t;
        Some((lerp(self.quantile), lerp(self.length)))
    }
}

/// The edges of the faces selected by gradient quantile `alpha` and edge length `delta`.
pub fn selected_edges(
    positions: &[[f32; 3]],
    faces: &[[u32; 3]],
    gradient_norms: &[f64],
    alpha: f64,
    delta: f64,
) -> Vec<[u32; 2]> {
    let mut sorted = gradient_norms.to_vec();
    sorted.sort_by(f64::total_cmp);
    let Some(&threshold) =
        sorted.get(((alpha * sorted.len() as f64) as usize).min(sorted.len().saturating_sub(1)))
    else {
        return Vec::new();
    };
    let length = |a: u32, b: u32| {
        let (p, q) = (positions[a as usize], positions[b as usize]);
        f64::from((0..3).map(|c| (p[c] - q[c]).powi(2)).sum::<f32>().sqrt())
    };
    let mut edges: Vec<[u32; 2]> = faces
        .iter()
        .zip(gradient_norms)
        .filter(|&(t, &g)| g >= threshold && g > 0.0 && (0..3).all(|k| length(t[k], t[(k + 1) % 3]) > delta))
        .flat_map(|(t, _)| (0..3).map(move |k| [t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3])]))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    edges
}

/// The old mesh's attributes on the new one.
pub struct Carried {
    pub positions: Vec<[f32; 3]>,
    pub faces: Vec<[u32; 3]>,
    pub field: Vec<Jacobian>,
    pub first: Vec<Jacobian>,
    pub second: Vec<Jacobian>,
    /// N × J skinning weights.
    pub weights: Vec<f32>,
}

/// Splits `edges` of the base `positions`/`faces` and carries the per-face `field`, Adam's
/// moments `first`/`second` and the per-vertex `weights` (`joints` each) to the result.
pub fn remesh_and_carry(
    positions: &[[f32; 3]],
    faces: &[[u32; 3]],
    edges: &[[u32; 2]],
    field: &[Jacobian],
    [first, second]: [&[Jacobian]; 2],
    weights: &[f32],
    joints: usize,
) -> Carried {
    let (new_positions, new_faces) = split_and_flip(positions, faces, edges);
    let centres = |p: &[[f32; 3]], f: &[[u32; 3]]| -> Vec<DVec3> {
        f.iter()
            .map(|t| t.iter().map(|&v| DVec3::from(p[v as usize].map(f64::from))).sum::<DVec3>() / 3.0)
            .collect()
    };
    let old_centres = KdTree::new(&centres(positions, faces));
    let face_weights: Vec<Vec<(usize, f64)>> =
        centres(&new_positions, &new_faces).iter().map(|&c| inverse_distance(&old_centres, c)).collect();
    let carry = |values: &[Jacobian]| -> Vec<Jacobian> {
        face_weights
            .iter()
            .map(|w| {
                let mut m = [[0.0; 3]; 3];
                for &(k, wk) in w {
                    (0..9).for_each(|i| m[i / 3][i % 3] += wk * values[k][i / 3][i % 3]);
                }
                m
            })
            .collect()
    };
    let old_vertices =
        KdTree::new(&positions.iter().map(|p| DVec3::from(p.map(f64::from))).collect::<Vec<_>>());
    let mut new_weights = vec![0.0f32; new_positions.len() * joints];
    for (v, p) in new_positions.iter().enumerate() {
        for (k, wk) in inverse_distance(&old_vertices, DVec3::from(p.map(f64::from))) {
            for j in 0..joints {
                new_weights[v * joints + j] += wk as f32 * weights[k * joints + j];
            }
        }
    }
    Carried {
        field: carry(field),
        first: carry(first),
        second: carry(second),
        positions: new_positions,
        faces: new_faces,
        weights: new_weights,
    }
}

/// Eq. 9's weights of the nearest old points to `q`.
fn inverse_distance(tree: &KdTree, q: DVec3) -> Vec<(usize, f64)> {
    let near = tree.k_nearest(q, NEIGHBOURS);
    let inverse: Vec<f64> = near.iter().map(|&(_, d2)| 1.0 / (d2.sqrt() + EPSILON)).collect();
    let total: f64 = inverse.iter().sum();
    near.iter().zip(&inverse).map(|(&(k, _), w)| (k, w / total)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_schedule_narrows_and_stops() {
        let s = RemeshSchedule { every: 100, until: 0.5, quantile: [0.9, 0.7], length: [0.02, 0.01] };
        assert_eq!(s.due(0, 1000), None);
        assert_eq!(s.due(150, 1000), None);
        let (a, d) = s.due(100, 1000).unwrap();
        assert!((a - 0.86).abs() < 1e-12 && (d - 0.018).abs() < 1e-12);
        let (a, d) = s.due(500, 1000).unwrap();
        assert!((a - 0.7).abs() < 1e-12 && (d - 0.01).abs() < 1e-12);
        assert_eq!(s.due(600, 1000), None);
    }

    /// Two triangles of a square; the one with the larger gradient has its edges split, and a
    /// constant field, moments and weights stay constant wherever they are carried (Eq. 10 is a
    /// convex combination).
    #[test]
    fn selection_and_carrying() {
        let p = [[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.1, 0.1, 0.0], [0.0, 0.1, 0.0]];
        let f = [[0, 1, 2], [0, 2, 3]];
        let edges = selected_edges(&p, &f, &[1.0, 5.0], 0.5, 0.05);
        assert_eq!(edges, vec![[0, 2], [0, 3], [2, 3]]);
        assert!(selected_edges(&p, &f, &[1.0, 5.0], 0.5, 0.2).is_empty(), "edges shorter than δ are kept");
        let field = [[[2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]; 2];
        let moments = [[[0.5; 3]; 3]; 2];
        let weights = [0.25f32, 0.75, 0.25, 0.75, 0.25, 0.75, 0.25, 0.75];
        let carried = remesh_and_carry(&p, &f, &edges, &field, [&moments, &moments], &weights, 2);
        assert_eq!(carried.positions.len(), 7);
        assert!(carried.field.iter().all(|m| (m[0][0] - 2.0).abs() < 1e-12 && (m[1][1] - 1.0).abs() < 1e-12));
        assert!(carried.first.iter().flatten().flatten().all(|x| (x - 0.5).abs() < 1e-12));
        assert!(carried.weights.chunks(2).all(|w| (w[0] - 0.25).abs() < 1e-6 && (w[1] - 0.75).abs() < 1e-6));
        mannequin_mesh::manifold::check_manifold(&carried.positions, &carried.faces).unwrap();
    }
}
