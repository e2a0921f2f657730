//! The constraint graph of a garment: every edge (a stretch constraint) and every interior edge with
//! its two wing vertices (a bending hinge). Cloth must be manifold, so an edge shared by more than
//! two triangles is refused here, where edges are counted anyway.

use crate::error::ClothError;

#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ConstraintGraph {
    /// Every edge once, `[low, high]`, sorted.
    pub edges: Vec<[u32; 2]>,
    /// The faces on each side of each edge (the same face twice on a boundary).
    pub edge_faces: Vec<[usize; 2]>,
    /// `[a, b, c, d]`: edge a–b shared by the triangles (a, b, c) and (a, b, d).
    pub hinges: Vec<[u32; 4]>,
    /// The faces (a, b, c) and (a, b, d) of each hinge.
    pub hinge_faces: Vec<[usize; 2]>,
}

pub(crate) fn constraint_graph(faces: &[[u32; 3]]) -> Result<ConstraintGraph, ClothError> {
    let mut sides: Vec<([u32; 2], u32, usize)> = faces
        .iter()
        .enumerate()
        .flat_map(|(f, &[i, j, k])| {
            [(i, j, k), (j, k, i), (k, i, j)].map(|(a, b, opposite)| ([a.min(b), a.max(b)], opposite, f))
        })
        .collect();
    sides.sort_unstable();
    let mut edges = Vec::new();
    let mut edge_faces = Vec::new();
    let mut hinges = Vec::new();
    let mut hinge_faces = Vec::new();
    for run in sides.chunk_by(|x, y| x.0 == y.0) {
        let [a, b] = run[0].0;
        match *run {
            [(_, _, f)] => edge_faces.push([f, f]),
            [(_, c, f), (_, d, g)] => {
                if c == d {
                    return Err(ClothError::invalid(
                        "faces",
                        format!("faces[{f}] and faces[{g}] are the same triangle"),
                    ));
                }
                hinges.push([a, b, c, d]);
                hinge_faces.push([f, g]);
                edge_faces.push([f, g]);
            }
            _ => return Err(ClothError::NonManifoldEdge { a, b, count: run.len() }),
        }
        edges.push([a, b]);
    }
    Ok(ConstraintGraph { edges, edge_faces, hinges, hinge_faces })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quad_has_five_edges_and_one_hinge() {
        let t = constraint_graph(&[[0, 1, 2], [2, 1, 3]]).unwrap();
        assert_eq!(t.edges, vec![[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]]);
        assert_eq!(t.hinges, vec![[1, 2, 0, 3]]);
        assert_eq!(t.hinge_faces, vec![[0, 1]]);
        assert_eq!(t.edge_faces[2], [0, 1]);
        assert_eq!(t.edge_faces[0], [0, 0]);
    }

    #[test]
    fn a_fin_of_three_triangles_is_refused() {
        let e = constraint_graph(&[[0, 1, 2], [1, 0, 3], [0, 1, 4]]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "faces: edge (0, 1) is shared by 3 triangles; a cloth edge may have at most 2"
        );
    }

    #[test]
    fn a_repeated_triangle_is_refused() {
        let e = constraint_graph(&[[0, 1, 2], [2, 1, 0]]).unwrap_err();
        assert_eq!(e.to_string(), "faces: faces[0] and faces[1] are the same triangle");
    }
}
