//! Lumped (diagonal) mass matrices: the area each vertex stands for, which turns the cotangent
//! Laplacian's integrated values into pointwise ones and weights per-vertex losses by area.

use faer::sparse::{SparseColMat, Triplet};

use crate::area::corners;

/// How a triangle's area is shared among its corners.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MassKind {
    /// A third of the area to each corner: simple, and positive on any mesh.
    Barycentric,
    /// Meyer et al. 2003's mixed Voronoi area: each corner gets its Voronoi cell inside
    /// non-obtuse triangles; an obtuse triangle gives half its area to the obtuse corner and a
    /// quarter to each other one. Matches libigl's default `massmatrix` for triangles.
    Voronoi,
}

/// The diagonal of the mass matrix: one area per vertex.
pub fn vertex_areas(positions: &[[f32; 3]], faces: &[[u32; 3]], kind: MassKind) -> Vec<f64> {
    let mut areas = vec![0.0; positions.len()];
    for &tri in faces {
        let p = corners(positions, tri);
        let area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
        let share = match kind {
            MassKind::Barycentric => [area / 3.0; 3],
            MassKind::Voronoi => mixed_voronoi_shares(p, area),
        };
        for k in 0..3 {
            areas[tri[k] as usize] += share[k];
        }
    }
    areas
}

/// The V×V diagonal mass matrix.
pub fn mass_matrix(positions: &[[f32; 3]], faces: &[[u32; 3]], kind: MassKind) -> SparseColMat<usize, f64> {
    let areas = vertex_areas(positions, faces, kind);
    let n = areas.len();
    let diagonal: Vec<_> = areas.into_iter().enumerate().map(|(i, a)| Triplet::new(i, i, a)).collect();
    SparseColMat::try_new_from_triplets(n, n, &diagonal).expect("diagonal indices are below the vertex count")
}

/// Each corner's share of one triangle (Meyer et al. 2003, Fig. 4).
fn mixed_voronoi_shares(p: [glam::DVec3; 3], area: f64) -> [f64; 3] {
    let edge = |a: usize, b: usize| p[b] - p[a];
    // The cosine's sign at corner k tells whether the triangle is obtuse there.
    let dots: [f64; 3] = std::array::from_fn(|k| edge(k, (k + 1) % 3).dot(edge(k, (k + 2) % 3)));
    if let Some(obtuse) = dots.iter().position(|&d| d < 0.0) {
        return std::array::from_fn(|k| if k == obtuse { area / 2.0 } else { area / 4.0 });
    }
    if area == 0.0 {
        return [0.0; 3];
    }
    // cot at corner k = dot / |cross| = dot / (2 area).
    let cot = dots.map(|d| d / (2.0 * area));
    std::array::from_fn(|k| {
        let (j, l) = ((k + 1) % 3, (k + 2) % 3);
        (edge(k, j).length_squared() * cot[l] + edge(k, l).length_squared() * cot[j]) / 8.0
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_kinds_conserve_total_area() {
        // An acute and an obtuse triangle with areas 1 and 0.5.
        let p = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, -0.25, 0.0], [4.0, -0.25, 0.0]];
        let f = [[0, 1, 2], [3, 4, 1]];
        for kind in [MassKind::Barycentric, MassKind::Voronoi] {
            let total: f64 = vertex_areas(&p, &f, kind).iter().sum();
            assert!((total - 1.5).abs() < 1e-12, "{kind:?}: {total}");
        }
    }

    /// In a right triangle the circumcentre is the hypotenuse's midpoint: the right-angle corner's
    /// cell is half the triangle and each other corner's a quarter.
    #[test]
    fn right_triangle_voronoi_cells() {
        let a = vertex_areas(
            &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            &[[0, 1, 2]],
            MassKind::Voronoi,
        );
        for (got, want) in a.iter().zip([0.25, 0.125, 0.125]) {
            assert!((got - want).abs() < 1e-12, "{a:?}");
        }
    }
}
