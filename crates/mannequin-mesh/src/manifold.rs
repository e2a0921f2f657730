//! Whether a triangle mesh is an oriented 2-manifold, possibly with boundary: what the Poisson
//! solve, remeshing and boundary walks take for granted. Checked are repeated corners and
//! zero-area faces, edges with more than two faces or two faces running them the same way
//! (flipped orientation), and vertices whose faces do not form one fan (two cones meeting at a
//! point).

use std::collections::HashMap;

use crate::MeshError;
use crate::normals::face_area_normal;

/// A face whose twice-area is below this share of its longest edge squared (a corner angle of
/// about 1e-6 rad, or a point) counts as degenerate: its cotangent weights would be unbounded.
const MIN_SINE: f32 = 1e-6;

/// `Ok` when `positions`/`faces` is an oriented manifold with boundary, else the first fault.
pub fn check_manifold(positions: &[[f32; 3]], faces: &[[u32; 3]]) -> Result<(), MeshError> {
    let n = positions.len();
    let fault = |reason: String| Err(MeshError::NotManifold(reason));
    let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
    for (f, &t) in faces.iter().enumerate() {
        if let Some(&index) = t.iter().find(|&&i| i as usize >= n) {
            return Err(MeshError::FaceIndex { face: f, index, count: n });
        }
        if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
            return fault(format!("face {f} repeats a corner ({t:?})"));
        }
        let corner = |k: usize| glam::Vec3::from(positions[t[k] as usize]);
        let longest = (0..3).map(|k| corner(k).distance_squared(corner((k + 1) % 3))).fold(0.0, f32::max);
        if face_area_normal(positions, t).length() <= MIN_SINE * longest {
            let corners = t.map(|v| positions[v as usize]);
            return fault(format!("face {f} has no area (vertices {t:?} at {corners:?})"));
        }
        for k in 0..3 {
            let edge = (t[k], t[(k + 1) % 3]);
            if let Some(g) = directed.insert(edge, f) {
                return fault(format!(
                    "faces {g} and {f} both run edge {}–{} the same way (flipped, or more than two faces on it)",
                    edge.0, edge.1
                ));
            }
        }
    }
    // Each vertex's fan: following "the next face round" must visit all of its faces in one walk.
    let mut around: Vec<Vec<(u32, u32)>> = vec![Vec::new(); n];
    for &t in faces {
        for k in 0..3 {
            around[t[k] as usize].push((t[(k + 1) % 3], t[(k + 2) % 3]));
        }
    }
    for (v, wedges) in around.iter().enumerate() {
        if wedges.len() < 2 {
            continue;
        }
        let next: HashMap<u32, u32> = wedges.iter().copied().collect();
        let previous: HashMap<u32, u32> = wedges.iter().map(|&(a, b)| (b, a)).collect();
        // Start at a boundary wedge (one whose first spoke no wedge ends on), if there is one.
        let start = wedges.iter().find(|(a, _)| !previous.contains_key(a)).map_or(wedges[0].0, |w| w.0);
        let mut at = start;
        let mut visited = 0;
        while let Some(&to) = next.get(&at) {
            visited += 1;
            at = to;
            if at == start || visited > wedges.len() {
                break;
            }
        }
        if visited != wedges.len() {
            return fault(format!(
                "vertex {v} joins {} faces that form more than one fan (the surface pinches there)",
                wedges.len()
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A square of two triangles, a tetrahedron and a "bowtie" of two triangles sharing a corner.
    const SQUARE: [[f32; 3]; 4] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];

    fn tetrahedron() -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
        let p = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        (p, vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    }

    #[test]
    fn open_and_closed_manifolds_pass() {
        assert!(check_manifold(&SQUARE, &[[0, 1, 2], [0, 2, 3]]).is_ok());
        let (p, f) = tetrahedron();
        assert!(check_manifold(&p, &f).is_ok());
    }

    #[test]
    fn each_fault_is_named() {
        let err = |p: &[[f32; 3]], f: &[[u32; 3]]| check_manifold(p, f).unwrap_err().to_string();
        assert!(err(&SQUARE, &[[0, 1, 2], [0, 3, 2]]).contains("the same way"));
        assert!(err(&SQUARE, &[[0, 1, 1]]).contains("repeats a corner"));
        let flat = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
        assert!(err(&flat, &[[0, 1, 2]]).contains("no area"));
        // A fin: a third face on edge 0–2 of the square.
        let mut fin = SQUARE.to_vec();
        fin.push([0.5, 0.5, 1.0]);
        assert!(err(&fin, &[[0, 1, 2], [0, 2, 3], [2, 0, 4]]).contains("the same way"));
        // Two triangles meeting only at vertex 0.
        let bowtie = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [-1.0, -1.0, 0.0]];
        assert!(err(&bowtie, &[[0, 1, 2], [0, 3, 4]]).contains("more than one fan"));
        assert!(err(&SQUARE, &[[0, 1, 7]]).contains("vertex 7"));
    }
}
