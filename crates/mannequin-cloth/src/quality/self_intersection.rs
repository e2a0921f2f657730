//! Counts pairs of triangles of one mesh, or across two meshes, that intersect, skipping pairs
//! that share a vertex (those touch by construction). Candidates come from a uniform grid of the
//! triangles' boxes; each overlapping pair is tested once, in the cell holding the low corner of
//! the boxes' overlap.

use std::collections::HashMap;

use super::exact::Point;
use super::triangle_intersection::triangles_intersect;

/// A box spanning more grid cells than this along an axis is tested against every other box
/// rather than listed in the cells it covers: one triangle stretched across the scene (a particle
/// flung far) would otherwise be listed in the cube of its span, billions of cells (issue 42).
const MAX_SPAN_CELLS: i64 = 16;

/// The number of intersecting pairs of triangles with no vertex in common. Faces with an index out
/// of range are ignored.
pub fn self_intersecting_pairs(positions: &[[f32; 3]], faces: &[[u32; 3]]) -> usize {
    self_intersections(positions, faces).len()
}

/// Where the pair of `faces` `[first, second]` lies, the mean of its six corners: the place an
/// error about a crossing names.
pub fn pair_place(positions: &[[f32; 3]], faces: &[[u32; 3]], [first, second]: [usize; 2]) -> [f32; 3] {
    let corners = faces[first].iter().chain(&faces[second]).map(|&v| positions[v as usize]);
    let sum = corners.fold([0.0; 3], |s, p| [s[0] + p[0], s[1] + p[1], s[2] + p[2]]);
    sum.map(|c| c / 6.0)
}

/// The intersecting pairs of triangles with no vertex in common, as face indices (i < j), in
/// ascending order: where a mesh crosses itself.
pub fn self_intersections(positions: &[[f32; 3]], faces: &[[u32; 3]]) -> Vec<[usize; 2]> {
    intersecting_pairs(positions, faces, |_, _| true)
}

/// The number of pairs of a triangle of mesh `a` and one of mesh `b` that intersect: how often
/// one layer of cloth passes through another.
pub fn crossing_pairs(a: &[[f32; 3]], a_faces: &[[u32; 3]], b: &[[f32; 3]], b_faces: &[[u32; 3]]) -> usize {
    let mut positions = a.to_vec();
    positions.extend_from_slice(b);
    let n = a.len() as u32;
    // Faces of `b` are shifted past `a`'s vertices; one of `a`'s faces out of range must not
    // reach into `b`, so it is dropped here.
    let mut faces: Vec<[u32; 3]> = a_faces.iter().copied().filter(|f| f.iter().all(|&i| i < n)).collect();
    let first_of_b = faces.len();
    faces.extend(b_faces.iter().map(|t| t.map(|i| i.saturating_add(n))));
    intersecting_pairs(&positions, &faces, |i, j| (i < first_of_b) != (j < first_of_b)).len()
}

/// Intersecting pairs of faces `i` < `j` (indices into `faces`) for which `counts(i, j)` holds,
/// in ascending order.
fn intersecting_pairs(
    positions: &[[f32; 3]],
    faces: &[[u32; 3]],
    counts: impl Fn(usize, usize) -> bool,
) -> Vec<[usize; 2]> {
    let faces: Vec<(usize, [u32; 3])> = faces
        .iter()
        .copied()
        .enumerate()
        .filter(|(_, f)| f.iter().all(|&i| (i as usize) < positions.len()))
        .collect();
    if faces.is_empty() {
        return Vec::new();
    }
    let corners = |f: [u32; 3]| -> [Point; 3] { f.map(|i| positions[i as usize].map(f64::from)) };
    let boxes: Vec<(Point, Point)> = faces
        .iter()
        .map(|&(_, f)| {
            let c = corners(f);
            let lo = [0, 1, 2].map(|k| c[0][k].min(c[1][k]).min(c[2][k]));
            let hi = [0, 1, 2].map(|k| c[0][k].max(c[1][k]).max(c[2][k]));
            (lo, hi)
        })
        .collect();
    // The median box's size: a few triangles stretched across the scene do not coarsen it.
    let mut extents: Vec<f64> =
        boxes.iter().map(|(lo, hi)| (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max)).collect();
    extents.sort_by(f64::total_cmp);
    let cell = extents[extents.len() / 2].max(f64::MIN_POSITIVE);
    let key = |p: Point| p.map(|x| (x / cell).floor() as i64);
    let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    let mut large = vec![false; boxes.len()];
    for (k, (lo, hi)) in boxes.iter().enumerate() {
        let (a, b) = (key(*lo), key(*hi));
        if (0..3).any(|d| b[d].saturating_sub(a[d]) >= MAX_SPAN_CELLS) {
            large[k] = true;
            continue;
        }
        for x in a[0]..=b[0] {
            for y in a[1]..=b[1] {
                for z in a[2]..=b[2] {
                    grid.entry([x, y, z]).or_default().push(k as u32);
                }
            }
        }
    }
    let overlap = |i: usize, j: usize| {
        let ((lo_i, hi_i), (lo_j, hi_j)) = (boxes[i], boxes[j]);
        !(0..3).any(|k| lo_i[k] > hi_j[k] || lo_j[k] > hi_i[k])
    };
    let intersect = |i: usize, j: usize| {
        let ((i, fi), (j, fj)) = (faces[i], faces[j]);
        counts(i, j) && !fi.iter().any(|v| fj.contains(v)) && triangles_intersect(corners(fi), corners(fj))
    };
    let mut found = Vec::new();
    let mut note = |i: usize, j: usize| found.push([faces[i.min(j)].0, faces[i.max(j)].0]);
    for (cell_key, members) in &grid {
        for (n, &i) in members.iter().enumerate() {
            for &j in &members[n + 1..] {
                let (i, j) = (i as usize, j as usize);
                if !overlap(i, j) || key([0, 1, 2].map(|k| boxes[i].0[k].max(boxes[j].0[k]))) != *cell_key {
                    continue;
                }
                if intersect(i, j) {
                    note(i, j);
                }
            }
        }
    }
    // Each large box against every other (a pair of large ones once).
    for i in (0..boxes.len()).filter(|&i| large[i]) {
        for j in (0..boxes.len()).filter(|&j| j != i && !(large[j] && j < i)) {
            if overlap(i, j) && intersect(i, j) {
                note(i, j);
            }
        }
    }
    found.sort_unstable();
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Appends the n×n grid of triangles spanning `origin + s·u + t·v` (s, t in [0, 1]).
    fn square(
        origin: [f32; 3],
        u: [f32; 3],
        v: [f32; 3],
        n: usize,
        positions: &mut Vec<[f32; 3]>,
        faces: &mut Vec<[u32; 3]>,
    ) {
        let base = positions.len() as u32;
        for j in 0..=n {
            for i in 0..=n {
                let (s, t) = (i as f32 / n as f32, j as f32 / n as f32);
                positions.push([0, 1, 2].map(|k| origin[k] + s * u[k] + t * v[k]));
            }
        }
        let at = |i: usize, j: usize| base + (j * (n + 1) + i) as u32;
        for j in 0..n {
            for i in 0..n {
                faces.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                faces.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
    }

    /// Two separate squares, one poked through the other, and the count of crossing pairs found
    /// by testing every pair directly.
    #[test]
    fn the_grid_finds_what_every_pair_finds() {
        let mut positions: Vec<[f32; 3]> = Vec::new();
        let mut faces: Vec<[u32; 3]> = Vec::new();
        square([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 6, &mut positions, &mut faces);
        square([0.33, 0.21, -0.4], [0.1, 0.3, 0.8], [0.35, -0.05, 0.1], 4, &mut positions, &mut faces);
        let brute = (0..faces.len())
            .flat_map(|i| (i + 1..faces.len()).map(move |j| (i, j)))
            .filter(|&(i, j)| !faces[i].iter().any(|v| faces[j].contains(v)))
            .filter(|&(i, j)| {
                let c = |f: [u32; 3]| f.map(|k| positions[k as usize].map(f64::from));
                triangles_intersect(c(faces[i]), c(faces[j]))
            })
            .count();
        assert!(brute > 0);
        assert_eq!(self_intersecting_pairs(&positions, &faces), brute);
    }

    /// Mesh `a` is two squares crossing each other, `b` a third square through one of them: only
    /// the pairs of a triangle of `a` and one of `b` count, as testing every such pair finds.
    #[test]
    fn crossings_count_only_pairs_across_the_meshes() {
        let (mut a, mut a_faces, mut b, mut b_faces) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        square([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 5, &mut a, &mut a_faces);
        square([0.2, 0.3, -0.5], [0.6, 0.1, 0.0], [0.0, 0.2, 1.0], 4, &mut a, &mut a_faces);
        square([0.1, 0.6, -0.3], [0.7, -0.2, 0.1], [0.1, 0.1, 0.9], 3, &mut b, &mut b_faces);
        let corners = |p: &[[f32; 3]], f: [u32; 3]| f.map(|k| p[k as usize].map(f64::from));
        let brute = a_faces
            .iter()
            .flat_map(|&fa| b_faces.iter().map(move |&fb| (fa, fb)))
            .filter(|&(fa, fb)| triangles_intersect(corners(&a, fa), corners(&b, fb)))
            .count();
        assert!(brute > 0 && self_intersecting_pairs(&a, &a_faces) > 0);
        assert_eq!(crossing_pairs(&a, &a_faces, &b, &b_faces), brute);
    }

    /// Issue 42: a particle flung 1e30 m away stretched its triangles across billions of grid
    /// cells and the count hung. A sliver from under the sheet through it to there is counted,
    /// as testing every pair counts it.
    #[test]
    fn a_flung_particle_neither_hangs_nor_hides_a_crossing() {
        let (mut positions, mut faces) = (Vec::new(), Vec::new());
        square([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 6, &mut positions, &mut faces);
        let base = positions.len() as u32;
        positions.extend([[0.3, 0.3, -0.5], [0.32, 0.3, -0.5], [1e30, 1e30, 1e30]]);
        faces.push([base, base + 1, base + 2]);
        let corners = |f: [u32; 3]| f.map(|k| positions[k as usize].map(f64::from));
        let brute = (0..faces.len())
            .flat_map(|i| (i + 1..faces.len()).map(move |j| (i, j)))
            .filter(|&(i, j)| !faces[i].iter().any(|v| faces[j].contains(v)))
            .filter(|&(i, j)| triangles_intersect(corners(faces[i]), corners(faces[j])))
            .count();
        assert!(brute > 0);
        assert_eq!(self_intersecting_pairs(&positions, &faces), brute);
    }

    #[test]
    fn a_flat_sheet_does_not_intersect_itself() {
        let positions: Vec<[f32; 3]> = (0..25).map(|k| [(k % 5) as f32, (k / 5) as f32, 0.0]).collect();
        let faces: Vec<[u32; 3]> = (0..4u32)
            .flat_map(|j| {
                (0..4u32).flat_map(move |i| {
                    let at = |i: u32, j: u32| j * 5 + i;
                    [[at(i, j), at(i + 1, j), at(i + 1, j + 1)], [at(i, j), at(i + 1, j + 1), at(i, j + 1)]]
                })
            })
            .collect();
        assert_eq!(self_intersecting_pairs(&positions, &faces), 0);
    }
}
