//! Mesh connectivity: edges, vertex one-rings, and face neighbours across edges. The equilateral
//! and Laplacian regularisers walk edges and one-rings; the normal-consistency loss compares the
//! normals of faces that share an edge.

/// Every undirected edge once, as `[low, high]`, sorted.
pub fn edges(faces: &[[u32; 3]]) -> Vec<[u32; 2]> {
    let mut e: Vec<[u32; 2]> =
        faces.iter().flat_map(|&t| face_edges(t).map(|(a, b, _)| sorted(a, b))).collect();
    e.sort_unstable();
    e.dedup();
    e
}

/// For each vertex, its neighbours along edges, sorted.
pub fn one_rings(vertex_count: usize, faces: &[[u32; 3]]) -> Vec<Vec<u32>> {
    let mut rings = vec![Vec::new(); vertex_count];
    for [a, b] in edges(faces) {
        rings[a as usize].push(b);
        rings[b as usize].push(a);
    }
    for r in &mut rings {
        r.sort_unstable();
    }
    rings
}

/// For each face and each k, the face across the edge from corner k to corner k+1 (libigl's
/// `triangle_triangle_adjacency` layout). `None` on a boundary edge, and on a non-manifold edge
/// (shared by more than two faces), where "the" neighbour is not defined.
pub fn face_neighbors(faces: &[[u32; 3]]) -> Vec<[Option<u32>; 3]> {
    let mut half: Vec<([u32; 2], u32, usize)> = faces
        .iter()
        .enumerate()
        .flat_map(|(f, &t)| face_edges(t).map(move |(a, b, k)| (sorted(a, b), f as u32, k)))
        .collect();
    half.sort_unstable();
    let mut neighbors = vec![[None; 3]; faces.len()];
    for run in half.chunk_by(|x, y| x.0 == y.0) {
        if let [(_, f, k), (_, g, l)] = *run {
            neighbors[f as usize][k] = Some(g);
            neighbors[g as usize][l] = Some(f);
        }
    }
    neighbors
}

/// The boundary loops of the manifold mesh `positions`/`faces`, lowest mean height (y) first:
/// a garment's hem first and its waist or neckline last.
pub fn boundary_loops_by_height(positions: &[[f32; 3]], faces: &[[u32; 3]]) -> Vec<Vec<u32>> {
    let height = |l: &Vec<u32>| l.iter().map(|&v| positions[v as usize][1]).sum::<f32>() / l.len() as f32;
    let mut loops = boundary_loops(faces);
    loops.sort_by(|a, b| height(a).total_cmp(&height(b)));
    loops
}

/// The boundary loops of a manifold mesh: each a cycle of vertices following the faces' winding
/// along edges that only one face has. A vertex where two loops touch starts a new loop at its
/// second outgoing edge.
pub fn boundary_loops(faces: &[[u32; 3]]) -> Vec<Vec<u32>> {
    let mut count: std::collections::HashMap<[u32; 2], u32> = std::collections::HashMap::new();
    for &t in faces {
        for (a, b, _) in face_edges(t) {
            *count.entry(sorted(a, b)).or_insert(0) += 1;
        }
    }
    let mut next: std::collections::BTreeMap<u32, Vec<u32>> = std::collections::BTreeMap::new();
    for &t in faces {
        for (a, b, _) in face_edges(t) {
            if count[&sorted(a, b)] == 1 {
                next.entry(a).or_default().push(b);
            }
        }
    }
    let mut loops = Vec::new();
    while let Some((&start, _)) = next.iter().next() {
        let mut cycle = vec![start];
        let mut at = start;
        while let Some(outgoing) = next.get_mut(&at) {
            let to = outgoing.pop().unwrap_or(start);
            if outgoing.is_empty() {
                next.remove(&at);
            }
            if to == start {
                break;
            }
            cycle.push(to);
            at = to;
        }
        loops.push(cycle);
    }
    loops
}

/// The three directed edges of a face with the corner each starts at.
fn face_edges(t: [u32; 3]) -> [(u32, u32, usize); 3] {
    [(t[0], t[1], 0), (t[1], t[2], 1), (t[2], t[0], 2)]
}

fn sorted(a: u32, b: u32) -> [u32; 2] {
    if a < b { [a, b] } else { [b, a] }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_triangles_share_one_edge() {
        let f = [[0, 1, 2], [2, 1, 3]];
        assert_eq!(edges(&f), vec![[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]]);
        assert_eq!(one_rings(4, &f), vec![vec![1, 2], vec![0, 2, 3], vec![0, 1, 3], vec![1, 2]]);
        assert_eq!(face_neighbors(&f), vec![[None, Some(1), None], [Some(0), None, None]]);
    }

    /// A quad strip closed into a ring (a tube of 4 × 1 quads) has two boundary loops of 4,
    /// running in opposite directions around the tube.
    /// A square tube of two rings, vertices 0–3 and 4–7.
    fn tube() -> Vec<[u32; 3]> {
        (0..4u32).flat_map(|a| [[a, (a + 1) % 4, (a + 1) % 4 + 4], [a, (a + 1) % 4 + 4, a + 4]]).collect()
    }

    #[test]
    fn a_tube_has_two_boundary_loops() {
        let f = tube();
        let mut loops = boundary_loops(&f);
        loops.sort();
        assert_eq!(loops.len(), 2);
        assert_eq!(loops[0].len(), 4);
        assert!(loops[0].iter().all(|&v| v < 4) && loops[1].iter().all(|&v| v >= 4));
        assert_eq!(loops[0], vec![0, 1, 2, 3]);
        assert_eq!(loops[1], vec![4, 7, 6, 5]);
    }

    /// The same tube with its ring of vertices 4–7 below the ring 0–3: that ring comes first.
    #[test]
    fn loops_by_height_put_the_lowest_first() {
        let f = tube();
        let positions: Vec<[f32; 3]> =
            (0..8).map(|v| [v as f32, if v < 4 { 1.0 } else { -1.0 }, 0.0]).collect();
        let loops = boundary_loops_by_height(&positions, &f);
        assert_eq!(loops.len(), 2);
        assert!(loops[0].iter().all(|&v| v >= 4) && loops[1].iter().all(|&v| v < 4), "{loops:?}");
    }

    #[test]
    fn non_manifold_edges_have_no_neighbour() {
        let f = [[0, 1, 2], [1, 0, 3], [0, 1, 4]];
        assert!(face_neighbors(&f).iter().all(|n| n[0].is_none()));
    }
}
