//! Midpoint (1-to-4) subdivision: every edge gains its midpoint and every triangle becomes four.
//! New vertices are plain averages of their edge's ends, so any per-vertex attribute (skinning
//! weights, pose correctives, UVs) interpolates the same way and stays consistent.

use std::collections::HashMap;

/// The refined connectivity, and for each new vertex the edge it splits.
#[derive(Debug, Clone, PartialEq)]
pub struct Subdivision {
    pub num_vertices: usize,
    pub faces: Vec<[u32; 3]>,
    /// New vertex `num_original + i` is the midpoint of `midpoints[i]`.
    pub midpoints: Vec<[u32; 2]>,
}

impl Subdivision {
    /// Splits every face of a mesh with `num_vertices` vertices; faces must index below it.
    pub fn new(num_vertices: usize, faces: &[[u32; 3]]) -> Self {
        let mut index: HashMap<(u32, u32), u32> = HashMap::new();
        let mut midpoints = Vec::new();
        let mut mid = |a: u32, b: u32| {
            let key = (a.min(b), a.max(b));
            *index.entry(key).or_insert_with(|| {
                midpoints.push([key.0, key.1]);
                (num_vertices + midpoints.len() - 1) as u32
            })
        };
        let mut out = Vec::with_capacity(4 * faces.len());
        for &[a, b, c] in faces {
            let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
            out.extend_from_slice(&[[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        Self { num_vertices: num_vertices + midpoints.len(), faces: out, midpoints }
    }

    /// Extends per-vertex rows of `width` values (row-major) to the refined mesh.
    pub fn interpolate(&self, values: &[f32], width: usize) -> Vec<f32> {
        let mut out = values.to_vec();
        out.reserve(self.midpoints.len() * width);
        for &[a, b] in &self.midpoints {
            let (a, b) = (a as usize * width, b as usize * width);
            for k in 0..width {
                out.push(0.5 * (values[a + k] + values[b + k]));
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_triangles_become_eight_with_five_new_vertices() {
        // A quad split along its diagonal: 5 distinct edges.
        let s = Subdivision::new(4, &[[0, 1, 2], [0, 2, 3]]);
        assert_eq!(s.faces.len(), 8);
        assert_eq!(s.num_vertices, 9);
        assert_eq!(s.midpoints.len(), 5);
        // The shared diagonal is split once.
        assert_eq!(s.midpoints.iter().filter(|m| **m == [0, 2]).count(), 1);
        let pos = s.interpolate(&[0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0], 2);
        let diag = 4 + s.midpoints.iter().position(|m| *m == [0, 2]).unwrap();
        assert_eq!(&pos[2 * diag..2 * diag + 2], &[0.5, 0.5]);
        // Every child keeps its parent's winding: signed areas are all positive here.
        for f in &s.faces {
            let p = |i: u32| (pos[2 * i as usize] as f64, pos[2 * i as usize + 1] as f64);
            let ((ax, ay), (bx, by), (cx, cy)) = (p(f[0]), p(f[1]), p(f[2]));
            assert!((bx - ax) * (cy - ay) - (by - ay) * (cx - ax) > 0.0, "{f:?}");
        }
    }
}
