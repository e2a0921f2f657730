//! Tavatar §4.2: Gaussians whose centre, frame and scale are analytic functions of the posed
//! mesh, so every geometric attribute follows the surface and carries gradients back to the
//! vertices (and from there to the offset field E_s).

use std::sync::Arc;

use burn::tensor::{Device, IndexingUpdateOp, Int, Tensor, TensorData};

use crate::one_ring_mesh::OneRingMesh;

/// In-plane scale factor of face Gaussians, β in Eq. 8.
pub const FACE_SCALE: f64 = 0.5;
/// In-plane scale factor of vertex Gaussians, γ in Eq. 11.
pub const VERTEX_SCALE: f64 = 0.5;
/// Out-of-plane scale ε of Eqs. 8 and 11: flat disks.
pub const NORMAL_SCALE: f64 = 1e-3;

/// Keeps norms differentiable at zero-length vectors (degenerate faces).
pub(crate) const NORM_EPS: f64 = 1e-20;

/// Gaussian geometry on a device: centres [G, 3], frames [G, 3, 3] whose columns are
/// (t1, t2, n), scales [G, 3], and the unit normal [G, 3] (the third column, kept for normal
/// rendering).
#[derive(Clone, Debug)]
pub struct GaussianGeometry {
    pub means: Tensor<2>,
    pub frames: Tensor<3>,
    pub scales: Tensor<2>,
    pub normals: Tensor<2>,
}

impl GaussianGeometry {
    /// Both sets as one, face Gaussians first.
    pub fn cat(a: Self, b: Self) -> Self {
        Self {
            means: Tensor::cat(vec![a.means, b.means], 0),
            frames: Tensor::cat(vec![a.frames, b.frames], 0),
            scales: Tensor::cat(vec![a.scales, b.scales], 0),
            normals: Tensor::cat(vec![a.normals, b.normals], 0),
        }
    }

    pub fn len(&self) -> usize {
        self.means.dims()[0]
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Index tensors of a fixed-topology mesh: the three corners of every face, and each vertex's
/// one-ring padded to the largest valence (padding marked in `ring_pad`); and the same on the
/// host for the fused binding.
#[derive(Clone, Debug)]
pub struct MeshIndex {
    pub corners: [Tensor<1, Int>; 3],
    /// [V · valence] neighbour indices, row-major; padding repeats the vertex itself.
    pub ring: Tensor<1, Int>,
    /// [V, valence], 1 where `ring` is padding.
    pub ring_pad: Tensor<2>,
    pub valence: usize,
    pub mesh: Arc<OneRingMesh>,
}

impl MeshIndex {
    /// Builds the index tensors; faces must already be validated against `num_vertices`.
    pub fn new(num_vertices: usize, faces: &[[u32; 3]], device: &Device) -> Self {
        let corner = |k: usize| {
            let idx: Vec<i64> = faces.iter().map(|f| f[k] as i64).collect();
            Tensor::<1, Int>::from_data(TensorData::new(idx, [faces.len()]), device)
        };
        let mesh = OneRingMesh::new(num_vertices, faces);
        let valence = mesh.valence();
        let mut ring = Vec::with_capacity(num_vertices * valence);
        let mut pad = Vec::with_capacity(num_vertices * valence);
        for v in 0..num_vertices {
            let r = mesh.ring(v);
            for k in 0..valence {
                ring.push(r.get(k).map_or(v as i64, |&n| n as i64));
                pad.push(if k < r.len() { 0.0f32 } else { 1.0 });
            }
        }
        Self {
            corners: [corner(0), corner(1), corner(2)],
            ring: Tensor::from_data(TensorData::new(ring, [num_vertices * valence]), device),
            ring_pad: Tensor::from_data(TensorData::new(pad, [num_vertices, valence]), device),
            valence,
            mesh: Arc::new(mesh),
        }
    }
}

/// ‖x‖ per row, [N, 1].
fn row_norm(x: Tensor<2>) -> Tensor<2> {
    (x.square().sum_dim(1) + NORM_EPS).sqrt()
}

/// Unit rows.
pub(crate) fn normalise(x: Tensor<2>) -> Tensor<2> {
    x.clone() / row_norm(x)
}

/// A frame with columns (t1, t2, n), [N, 3, 3].
fn frame(t1: Tensor<2>, t2: Tensor<2>, n: Tensor<2>) -> Tensor<3> {
    Tensor::stack(vec![t1, t2, n], 2)
}

/// Disk scales (s, s, ε) from an in-plane scale [N, 1].
fn disk_scales(in_plane: Tensor<2>) -> Tensor<2> {
    let eps = in_plane.zeros_like() + NORMAL_SCALE;
    Tensor::cat(vec![in_plane.clone(), in_plane, eps], 1)
}

/// What both bindings read of each face of a posed mesh, computed once: the corners, the edges
/// a→b and a→c, and the unnormalised normal (b − a) × (c − a) = 2A·n.
#[derive(Clone, Debug)]
pub struct Faces {
    pub corners: [Tensor<2>; 3],
    pub edge_ab: Tensor<2>,
    pub edge_ac: Tensor<2>,
    pub cross: Tensor<2>,
}

impl Faces {
    /// The faces of posed vertices [V, 3], each quantity [F, 3].
    pub fn of(vertices: &Tensor<2>, index: &MeshIndex) -> Self {
        let [a, b, c] = index.corners.clone().map(|c| vertices.clone().select(0, c));
        let (edge_ab, edge_ac) = (b.clone() - a.clone(), c.clone() - a.clone());
        let cross = edge_ab.clone().cross(edge_ac.clone(), 1);
        Self { corners: [a, b, c], edge_ab, edge_ac, cross }
    }
}

/// Face Gaussians (Eqs. 5–8) of a posed mesh's faces.
pub fn face_gaussians(faces: &Faces) -> GaussianGeometry {
    let [a, b, c] = faces.corners.clone();
    // Edge lengths opposite each corner.
    let la = row_norm(b.clone() - c.clone());
    let lb = row_norm(faces.edge_ac.clone());
    let lc = row_norm(faces.edge_ab.clone());
    let perimeter = la.clone() + lb.clone() + lc.clone();
    // Eq. 5: the incenter weights each corner by the length of the opposite edge.
    let means = (a * la + b * lb + c * lc.clone()) / perimeter.clone();
    let double_area = row_norm(faces.cross.clone());
    // Eqs. 6–7.
    let n = faces.cross.clone() / double_area.clone();
    let t1 = faces.edge_ab.clone() / lc;
    let t2 = n.clone().cross(t1.clone(), 1);
    // Eq. 8: inradius r = A / s with s the semi-perimeter, so r = 2A / perimeter.
    let inradius = double_area / perimeter;
    GaussianGeometry {
        means,
        frames: frame(t1, t2, n.clone()),
        scales: disk_scales(inradius * FACE_SCALE),
        normals: n,
    }
}

/// Area-weighted vertex normals (Eq. 9), [V, 3]: the sum of the adjacent faces' unnormalised
/// cross products (each 2 A_f n_f), normalised.
pub fn vertex_normals(faces: &Faces, index: &MeshIndex) -> Tensor<2> {
    let cross = &faces.cross;
    let mut sum = Tensor::zeros([index.mesh.num_vertices, 3], (&cross.device(), cross.dtype()));
    for corner in &index.corners {
        sum = sum.select_assign(0, corner.clone(), cross.clone(), IndexingUpdateOp::Add);
    }
    normalise(sum)
}

/// Vertex Gaussians (Eqs. 9–11) of posed vertices [V, 3] and their faces.
pub fn vertex_gaussians(vertices: &Tensor<2>, faces: &Faces, index: &MeshIndex) -> GaussianGeometry {
    let n = vertex_normals(faces, index);
    // Eq. 10: the reference axis is the coordinate axis least aligned with the normal; the
    // choice is piecewise constant, so it carries no gradient.
    let axis = n.clone().detach().abs().argmin(1).reshape([index.mesh.num_vertices]);
    let r: Tensor<2> = axis.one_hot::<2>(3).float().cast(n.dtype());
    let t1 = normalise(r.cross(n.clone(), 1));
    let t2 = n.clone().cross(t1.clone(), 1);
    // Eq. 11: γ times the shortest one-ring edge. The nearest neighbour is found on detached
    // values (padding lifted out of the min), then that one edge is measured again with a plain
    // gather, so the gradient reaches exactly the two vertices of the shortest edge.
    let v = index.mesh.num_vertices;
    let neighbours = vertices.clone().detach().select(0, index.ring.clone()).reshape([v, index.valence, 3]);
    let offsets = neighbours - vertices.clone().detach().unsqueeze_dim::<3>(1);
    let lengths = offsets.square().sum_dim(2).reshape([v, index.valence]);
    let padded = lengths + index.ring_pad.clone().cast(n.dtype()) * 1e6;
    let slot = padded.argmin(1).reshape([v]);
    let rows = Tensor::<1, Int>::arange(0..v as i64, &vertices.device()) * index.valence as i64;
    let nearest = index.ring.clone().select(0, rows + slot);
    let shortest = row_norm(vertices.clone().select(0, nearest) - vertices.clone());
    GaussianGeometry {
        means: vertices.clone(),
        frames: frame(t1, t2, n.clone()),
        scales: disk_scales(shortest * VERTEX_SCALE),
        normals: n,
    }
}
