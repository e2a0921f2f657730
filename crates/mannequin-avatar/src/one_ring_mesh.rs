//! A fixed triangle mesh with every vertex's one-ring, flat on the host: what the fused host ops
//! (Tavatar's binding, the mesh regularisers) walk, and what the binding's ring tensors pad.

use mannequin_mesh::adjacency::one_rings;

/// A fixed triangle mesh's faces and every vertex's one-ring (each ring sorted, as `MeshIndex`
/// pads them).
#[derive(Debug)]
pub struct OneRingMesh {
    pub num_vertices: usize,
    pub faces: Vec<[u32; 3]>,
    ring_start: Vec<usize>,
    rings: Vec<u32>,
}

impl OneRingMesh {
    /// Faces must already be validated against `num_vertices`.
    pub fn new(num_vertices: usize, faces: &[[u32; 3]]) -> Self {
        let rings = one_rings(num_vertices, faces);
        let ring_start = std::iter::once(0)
            .chain(rings.iter().scan(0, |end, r| {
                *end += r.len();
                Some(*end)
            }))
            .collect();
        Self { num_vertices, faces: faces.to_vec(), ring_start, rings: rings.concat() }
    }

    /// Vertex `i`'s neighbours, ascending.
    pub fn ring(&self, i: usize) -> &[u32] {
        &self.rings[self.ring_start[i]..self.ring_start[i + 1]]
    }

    /// The largest valence (at least 1).
    pub fn valence(&self) -> usize {
        (0..self.num_vertices).map(|i| self.ring(i).len()).max().unwrap_or(0).max(1)
    }
}
