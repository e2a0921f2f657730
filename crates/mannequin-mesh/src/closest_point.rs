//! The closest point of a triangle mesh to a query point, through a uniform grid of the
//! triangles' boxes: what binds a garment vertex to the body surface under it (the indicator
//! I^g of the thesis's Eq. 3.1) and keeps a remeshed surface on the one it came from.

use std::collections::HashMap;

use glam::Vec3;

use crate::barycentric::{at_barycentric, closest_barycentric};

/// A point on a mesh: its face and barycentric coordinates there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    pub face: u32,
    pub bary: [f32; 3],
}

impl SurfacePoint {
    /// Where the point is on a mesh of these positions and faces.
    pub fn locate(&self, positions: &[[f32; 3]], faces: &[[u32; 3]]) -> Vec3 {
        let [a, b, c] = faces[self.face as usize].map(|i| Vec3::from(positions[i as usize]));
        at_barycentric(self.bary, a, b, c)
    }

    /// The barycentric mean of a per-vertex attribute (`width` values per vertex).
    pub fn interpolate(&self, faces: &[[u32; 3]], values: &[f32], width: usize) -> Vec<f32> {
        let tri = faces[self.face as usize];
        (0..width).map(|k| (0..3).map(|c| self.bary[c] * values[tri[c] as usize * width + k]).sum()).collect()
    }
}

/// Triangles binned by their boxes in cubic cells.
#[derive(Debug, Clone)]
pub struct ClosestPoint {
    positions: Vec<Vec3>,
    faces: Vec<[u32; 3]>,
    cell: f32,
    cells: HashMap<[i32; 3], Vec<u32>>,
}

impl ClosestPoint {
    /// An index of `faces` (indices into `positions`) with cells of `cell` metres: about the
    /// distance of the queries from the surface keeps each query to a few cells.
    pub fn new(positions: &[[f32; 3]], faces: &[[u32; 3]], cell: f32) -> Self {
        let positions: Vec<Vec3> = positions.iter().map(|&p| Vec3::from(p)).collect();
        let mut cells: HashMap<[i32; 3], Vec<u32>> = HashMap::new();
        for (f, tri) in faces.iter().enumerate() {
            let corners = tri.map(|i| positions[i as usize]);
            let lo = key(corners[0].min(corners[1]).min(corners[2]), cell);
            let hi = key(corners[0].max(corners[1]).max(corners[2]), cell);
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        cells.entry([x, y, z]).or_default().push(f as u32);
                    }
                }
            }
        }
        Self { positions, faces: faces.to_vec(), cell, cells }
    }

    /// The closest point of the mesh to `p`, searching shells of cells outwards until no
    /// unsearched cell can hold anything closer; `None` for a mesh without faces.
    pub fn query(&self, p: Vec3) -> Option<(SurfacePoint, Vec3)> {
        // Past this many shells, fall back to all faces, unless the search has already found
        // something nearer than any cell it left out can hold.
        let shells: i32 = 64;
        match self.search(p, shells) {
            Some((d, s, q)) if d < ((shells - 1) as f32 * self.cell).powi(2) => Some((s, q)),
            _ => self.brute_force(p),
        }
    }

    /// The closest point of the mesh to `p` if it is within `radius`: only the cells that
    /// distance reaches are searched, so a point far from the surface costs no more than one
    /// near it (a shell of cells `s` away holds (2s + 1)³ − (2s − 1)³ of them).
    pub fn query_within(&self, p: Vec3, radius: f32) -> Option<(SurfacePoint, Vec3)> {
        // A point r away lies in a cell at most ⌊r / cell⌋ + 1 shells out.
        let shells = (radius / self.cell).floor() as i32 + 2;
        self.search(p, shells).filter(|(d, ..)| *d <= radius * radius).map(|(_, s, q)| (s, q))
    }

    /// The nearest point of the faces in the first `shells` shells of cells around `p` (its
    /// squared distance, where, and the point), stopping early once no unsearched cell can
    /// hold anything closer.
    fn search(&self, p: Vec3, shells: i32) -> Option<(f32, SurfacePoint, Vec3)> {
        let centre = key(p, self.cell);
        let mut best: Option<(f32, SurfacePoint, Vec3)> = None;
        let mut seen = std::collections::HashSet::new();
        for shell in 0..shells {
            // A point in a cell `shell` away is at least (shell − 1) cells from p.
            if let Some((d, ..)) = best
                && d < ((shell as f32 - 1.0).max(0.0) * self.cell).powi(2)
            {
                break;
            }
            for x in -shell..=shell {
                for y in -shell..=shell {
                    for z in -shell..=shell {
                        if x.abs().max(y.abs()).max(z.abs()) != shell {
                            continue;
                        }
                        let Some(list) = self.cells.get(&[centre[0] + x, centre[1] + y, centre[2] + z])
                        else {
                            continue;
                        };
                        for &f in list {
                            if !seen.insert(f) {
                                continue;
                            }
                            let candidate = self.on_face(f, p);
                            if best.is_none_or(|(d, ..)| candidate.0 < d) {
                                best = Some(candidate);
                            }
                        }
                    }
                }
            }
        }
        best
    }

    fn on_face(&self, f: u32, p: Vec3) -> (f32, SurfacePoint, Vec3) {
        let [a, b, c] = self.faces[f as usize].map(|i| self.positions[i as usize]);
        let bary = closest_barycentric(p, a, b, c);
        let q = at_barycentric(bary, a, b, c);
        (q.distance_squared(p), SurfacePoint { face: f, bary }, q)
    }

    fn brute_force(&self, p: Vec3) -> Option<(SurfacePoint, Vec3)> {
        (0..self.faces.len() as u32)
            .map(|f| self.on_face(f, p))
            .min_by(|x, y| x.0.total_cmp(&y.0))
            .map(|(_, s, q)| (s, q))
    }
}

fn key(p: Vec3, cell: f32) -> [i32; 3] {
    (p / cell).floor().to_array().map(|x| x as i32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Against a scan of every face, on a bumpy grid and points above, below and beside it.
    #[test]
    fn finds_what_a_scan_of_every_face_finds() {
        let n = 12;
        let mut positions = Vec::new();
        for i in 0..=n {
            for j in 0..=n {
                let (x, z) = (i as f32 * 0.05, j as f32 * 0.05);
                positions.push([x, 0.02 * (7.0 * x).sin() * (5.0 * z).cos(), z]);
            }
        }
        let at = |i: usize, j: usize| (i * (n + 1) + j) as u32;
        let mut faces = Vec::new();
        for i in 0..n {
            for j in 0..n {
                faces.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                faces.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        let index = ClosestPoint::new(&positions, &faces, 0.04);
        let mut state = 1u32;
        let mut next = || {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 8) as f32 / (1u32 << 24) as f32
        };
        for _ in 0..300 {
            let p = Vec3::new(next() * 0.9 - 0.15, next() * 0.4 - 0.2, next() * 0.9 - 0.15);
            let (s, q) = index.query(p).unwrap();
            let (_, q_all) = index.brute_force(p).unwrap();
            assert!((q.distance(p) - q_all.distance(p)).abs() < 1e-6, "{p}: {q} vs {q_all}");
            assert!(s.locate(&positions, &faces).distance(q) < 1e-6);
            // Within a radius: the same point where the scan's is that near, nothing where not.
            let radius = 0.01 + 0.1 * next();
            let near = index.query_within(p, radius);
            match q_all.distance(p) <= radius {
                true => assert!((near.unwrap().1.distance(p) - q_all.distance(p)).abs() < 1e-6, "{p}"),
                false => assert!(near.is_none(), "{p}: {near:?} beyond {radius}"),
            }
        }
    }
}
