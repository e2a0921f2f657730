//! The triangle mesh every Mannequin crate exchanges.

/// Texture coordinates with their own per-corner indexing, as OBJ and MakeHuman store them:
/// a seam vertex has one position but several UVs.
#[derive(Debug, Clone, PartialEq)]
pub struct UvLayout {
    /// UV coordinates, (u, v) with v up, as in OBJ.
    pub coords: Vec<[f32; 2]>,
    /// For each triangle, the indices of its three corners into `coords`.
    pub faces: Vec<[u32; 3]>,
}

/// An indexed triangle mesh in metres.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TriMesh {
    pub positions: Vec<[f32; 3]>,
    pub faces: Vec<[u32; 3]>,
    /// Optional texture coordinates, one corner triple per face.
    pub uv: Option<UvLayout>,
    /// Optional per-vertex colour in [0, 1].
    pub colors: Option<Vec<[f32; 3]>>,
}

#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    #[error("face {face} refers to vertex {index}, but the mesh has {count} vertices")]
    FaceIndex { face: usize, index: u32, count: usize },
    #[error("the UV layout has {uv_faces} faces but the mesh has {faces}")]
    UvFaceCount { uv_faces: usize, faces: usize },
    #[error("UV face {face} refers to coordinate {index}, but there are {count}")]
    UvIndex { face: usize, index: u32, count: usize },
    #[error("{count} colours for {vertices} vertices")]
    ColorCount { count: usize, vertices: usize },
    #[error("vertex {vertex} is not finite")]
    NonFinite { vertex: usize },
    #[error("the colour of vertex {vertex} is not finite")]
    NonFiniteColor { vertex: usize },
    #[error("UV coordinate {coord} is not finite")]
    NonFiniteUv { coord: usize },
    #[error("vertex {pinned} pinned, but the mesh has {count} vertices")]
    PinnedVertex { pinned: usize, count: usize },
    #[error(
        "the Poisson system cannot be factored ({0}): the mesh has degenerate faces or parts not connected to the pinned vertex"
    )]
    Poisson(String),
    #[error("not a manifold mesh: {0}")]
    NotManifold(String),
}

impl TriMesh {
    pub fn new(positions: Vec<[f32; 3]>, faces: Vec<[u32; 3]>) -> Self {
        Self { positions, faces, uv: None, colors: None }
    }

    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    pub fn face_count(&self) -> usize {
        self.faces.len()
    }

    /// The mesh made of the listed faces and only the vertices they use, kept in their original
    /// order, with the index each kept vertex had here: how one garment or body part is cut out of a
    /// file that holds several.
    pub fn submesh(&self, faces: &[usize]) -> (TriMesh, Vec<u32>) {
        let (kept_vertices, vertex_map) = compact(faces.iter().map(|&f| self.faces[f]), self.positions.len());
        let pick = |i: &u32| self.positions[*i as usize];
        let mut mesh = TriMesh::new(
            kept_vertices.iter().map(pick).collect(),
            faces.iter().map(|&f| self.faces[f].map(|i| vertex_map[i as usize])).collect(),
        );
        mesh.colors = self.colors.as_ref().map(|c| kept_vertices.iter().map(|&i| c[i as usize]).collect());
        mesh.uv = self.uv.as_ref().map(|uv| {
            let (kept, map) = compact(faces.iter().map(|&f| uv.faces[f]), uv.coords.len());
            UvLayout {
                coords: kept.iter().map(|&i| uv.coords[i as usize]).collect(),
                faces: faces.iter().map(|&f| uv.faces[f].map(|i| map[i as usize])).collect(),
            }
        });
        (mesh, kept_vertices)
    }

    /// Checks that every index is in range and every position, UV and colour is finite.
    pub fn validate(&self) -> Result<(), MeshError> {
        let n = self.positions.len();
        for (face, tri) in self.faces.iter().enumerate() {
            if let Some(&index) = tri.iter().find(|&&i| i as usize >= n) {
                return Err(MeshError::FaceIndex { face, index, count: n });
            }
        }
        if let Some(vertex) = self.positions.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
            return Err(MeshError::NonFinite { vertex });
        }
        if let Some(uv) = &self.uv {
            if uv.faces.len() != self.faces.len() {
                return Err(MeshError::UvFaceCount { uv_faces: uv.faces.len(), faces: self.faces.len() });
            }
            let m = uv.coords.len();
            for (face, tri) in uv.faces.iter().enumerate() {
                if let Some(&index) = tri.iter().find(|&&i| i as usize >= m) {
                    return Err(MeshError::UvIndex { face, index, count: m });
                }
            }
            if let Some(coord) = uv.coords.iter().position(|t| t.iter().any(|c| !c.is_finite())) {
                return Err(MeshError::NonFiniteUv { coord });
            }
        }
        if let Some(c) = &self.colors {
            if c.len() != n {
                return Err(MeshError::ColorCount { count: c.len(), vertices: n });
            }
            if let Some(vertex) = c.iter().position(|rgb| rgb.iter().any(|x| !x.is_finite())) {
                return Err(MeshError::NonFiniteColor { vertex });
            }
        }
        Ok(())
    }
}

/// Flat xyz values (3 per point, as body models and `.npy` arrays store them) as points.
pub fn points(flat: &[f32]) -> Vec<[f32; 3]> {
    flat.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect()
}

/// The indices (ascending) that `tris` use out of `0..count`, and the map from old index to new.
fn compact(tris: impl Iterator<Item = [u32; 3]>, count: usize) -> (Vec<u32>, Vec<u32>) {
    let mut used = vec![false; count];
    for t in tris {
        for i in t {
            used[i as usize] = true;
        }
    }
    let kept: Vec<u32> = (0..count as u32).filter(|&i| used[i as usize]).collect();
    let mut map = vec![u32::MAX; count];
    for (new, &old) in kept.iter().enumerate() {
        map[old as usize] = new as u32;
    }
    (kept, map)
}
