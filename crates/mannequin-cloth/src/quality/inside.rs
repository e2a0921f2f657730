//! Points inside a closed triangle mesh, by the parity of a ray's crossings: the ray runs along +x,
//! and a triangle is crossed when the point, projected on the y–z plane, lies inside the triangle's
//! projection. Edges and vertices hit exactly are settled by Simulation of Simplicity: the point is
//! taken as moved by (ε, ε²) in (y, z), which puts it strictly on one side of every edge, the same
//! side for both triangles sharing it, so each crossing counts once.

use std::cmp::Ordering::{self, Equal};

use super::exact::orient2d;

/// A grid over the mesh's y–z bounds listing each triangle in the cells its projection covers.
struct Columns {
    origin: [f64; 2],
    cell: f64,
    size: [usize; 2],
    cells: Vec<Vec<u32>>,
}

/// At most this many cells per axis.
const MAX_CELLS: usize = 512;

impl Columns {
    fn new(positions: &[[f64; 3]], faces: &[[u32; 3]]) -> Self {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        let mut extents = 0.0;
        for f in faces {
            let (flo, fhi) = bounds(positions, *f);
            for k in 0..2 {
                lo[k] = lo[k].min(flo[k]);
                hi[k] = hi[k].max(fhi[k]);
            }
            extents += (fhi[0] - flo[0]).max(fhi[1] - flo[1]);
        }
        let span = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(f64::MIN_POSITIVE);
        let cell = (2.0 * extents / faces.len() as f64).max(span / MAX_CELLS as f64);
        let size = [0, 1].map(|k| ((hi[k] - lo[k]) / cell) as usize + 1);
        let mut columns = Columns { origin: lo, cell, size, cells: vec![Vec::new(); size[0] * size[1]] };
        for (k, f) in faces.iter().enumerate() {
            let (flo, fhi) = bounds(positions, *f);
            let (a, b) = (columns.cell_of(flo), columns.cell_of(fhi));
            for i in a[0]..=b[0] {
                for j in a[1]..=b[1] {
                    columns.cells[i * size[1] + j].push(k as u32);
                }
            }
        }
        columns
    }

    fn cell_of(&self, p: [f64; 2]) -> [usize; 2] {
        [0, 1].map(|k| (((p[k] - self.origin[k]) / self.cell).max(0.0) as usize).min(self.size[k] - 1))
    }

    fn triangles_at(&self, p: [f64; 2]) -> &[u32] {
        let inside = (0..2)
            .all(|k| p[k] >= self.origin[k] && p[k] <= self.origin[k] + self.cell * self.size[k] as f64);
        if !inside {
            return &[];
        }
        let [i, j] = self.cell_of(p);
        &self.cells[i * self.size[1] + j]
    }
}

fn bounds(positions: &[[f64; 3]], f: [u32; 3]) -> ([f64; 2], [f64; 2]) {
    let ys = f.map(|i| positions[i as usize][1]);
    let zs = f.map(|i| positions[i as usize][2]);
    let min = |v: [f64; 3]| v[0].min(v[1]).min(v[2]);
    let max = |v: [f64; 3]| v[0].max(v[1]).max(v[2]);
    ([min(ys), min(zs)], [max(ys), max(zs)])
}

/// How many of `points` lie inside the closed mesh (`positions`, `faces`). Faces with an index out
/// of range are ignored; on a mesh with holes the parity is only a guess.
pub fn count_inside(points: &[[f32; 3]], positions: &[[f32; 3]], faces: &[[u32; 3]]) -> usize {
    let positions: Vec<[f64; 3]> = positions.iter().map(|p| p.map(f64::from)).collect();
    let faces: Vec<[u32; 3]> =
        faces.iter().copied().filter(|f| f.iter().all(|&i| (i as usize) < positions.len())).collect();
    if faces.is_empty() {
        return 0;
    }
    let columns = Columns::new(&positions, &faces);
    points
        .iter()
        .filter(|p| {
            let p = p.map(f64::from);
            let crossings = columns
                .triangles_at([p[1], p[2]])
                .iter()
                .filter(|&&f| crosses(p, faces[f as usize].map(|i| positions[i as usize])))
                .count();
            crossings % 2 == 1
        })
        .count()
}

/// The ray from `p` along +x passes through the triangle.
fn crosses(p: [f64; 3], t: [[f64; 3]; 3]) -> bool {
    let flat = |q: [f64; 3]| [q[1], q[2]];
    let sides = [(0, 1), (1, 2), (2, 0)].map(|(i, j)| perturbed_side(flat(t[i]), flat(t[j]), flat(p)));
    if !(sides[0] == sides[1] && sides[1] == sides[2]) {
        return false;
    }
    // The plane's x above (p.y, p.z); its normal has an x part, since the projection has area.
    let (u, v) = ([0, 1, 2].map(|k| t[1][k] - t[0][k]), [0, 1, 2].map(|k| t[2][k] - t[0][k]));
    let n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
    let x = t[0][0] - (n[1] * (p[1] - t[0][1]) + n[2] * (p[2] - t[0][2])) / n[0];
    x > p[0]
}

/// Which side of the edge a→b the point p + (ε, ε²) lies on: the exact sign, or when p is on
/// the edge's line, the sign of the ε and then the ε² term.
fn perturbed_side(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> Ordering {
    match orient2d(a, b, p) {
        Equal => match (a[1] - b[1]).total_cmp(&0.0) {
            Equal => (b[0] - a[0]).total_cmp(&0.0),
            s => s,
        },
        s => s,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube() -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
        let positions = (0..8).map(|k: u32| [0, 1, 2].map(|a| (k >> a & 1) as f32)).collect();
        let faces = vec![
            [0, 2, 3],
            [0, 3, 1],
            [4, 5, 7],
            [4, 7, 6],
            [0, 1, 5],
            [0, 5, 4],
            [2, 6, 7],
            [2, 7, 3],
            [0, 4, 6],
            [0, 6, 2],
            [1, 3, 7],
            [1, 7, 5],
        ];
        (positions, faces)
    }

    #[test]
    fn points_inside_and_outside_a_cube() {
        let (positions, faces) = cube();
        let inside = [[0.5, 0.5, 0.5], [0.1, 0.9, 0.2], [0.99, 0.01, 0.5]];
        let outside =
            [[1.5, 0.5, 0.5], [-0.5, 0.5, 0.5], [0.5, 1.2, 0.5], [0.5, 0.5, -0.01], [3.0, 3.0, 3.0]];
        assert_eq!(count_inside(&inside, &positions, &faces), 3);
        assert_eq!(count_inside(&outside, &positions, &faces), 0);
    }

    /// Rays through the cube's diagonal edges and corners: the perturbation counts each crossing
    /// once, so the parity stays right.
    #[test]
    fn rays_through_edges_and_corners_count_once() {
        let (positions, faces) = cube();
        let on_diagonals =
            [[0.5, 0.5, 0.5], [0.3, 0.25, 0.25], [-1.0, 0.25, 0.25], [-1.0, 0.0, 0.0], [-1.0, 1.0, 1.0]];
        let inside: Vec<usize> =
            on_diagonals.iter().map(|p| count_inside(&[*p], &positions, &faces)).collect();
        assert_eq!(inside, [1, 1, 0, 0, 0]);
    }
}
