//! The mesh regularisers of one fixed mesh, built once from its faces: the index tensors their
//! gathers and scatters use (edges, one-rings, face pairs), so each loss evaluation is a handful
//! of tensor ops, and the same mesh on the host for the fused op. The terms themselves live in
//! their own files ([`super::laplacian`], [`super::normal_consistency`], [`super::equilateral`]).

use std::sync::Arc;

use burn::tensor::{Device, Int, Tensor, TensorData};

use super::mesh_loss::{HostMesh, HostTerm, MeshLoss, mesh_loss};
use crate::AvatarError;
use crate::one_ring_mesh::OneRingMesh;

/// The regularisers of a triangle mesh: its edges, one-rings and face pairs as index tensors
/// on one device.
#[derive(Debug, Clone)]
pub struct MeshRegularisers {
    pub(super) num_vertices: usize,
    pub(super) device: Device,
    /// Corner `k` of every face, `[F]` for k = 0, 1, 2.
    pub(super) corners: [Tensor<1, Int>; 3],
    /// Both directions of every undirected edge, `[2E]`: vertex `neighbour_to[i]` has
    /// neighbour `neighbour_from[i]`.
    pub(super) neighbour_from: Tensor<1, Int>,
    pub(super) neighbour_to: Tensor<1, Int>,
    /// One-ring size per vertex as a float `[V, 1]` (1 for isolated vertices, whose neighbour sum
    /// is 0), and 1 or 0 as the vertex has neighbours or not.
    pub(super) degree: Tensor<2>,
    pub(super) connected: Tensor<2>,
    pub(super) num_connected: usize,
    /// Every pair of faces sharing an edge `(a, b)`, as `[a, b, c, d]` with `c` and `d` the
    /// vertices opposite the edge in the two faces, `[H]` each; `None` when no edge is shared.
    pub(super) hinges: Option<[Tensor<1, Int>; 4]>,
    num_edges: usize,
    num_hinges: usize,
    /// The same mesh for the fused host op.
    host: Arc<HostMesh>,
}

fn indices(v: Vec<i64>, device: &Device) -> Tensor<1, Int> {
    let n = v.len();
    Tensor::from_data(TensorData::new(v, [n]), device)
}

impl MeshRegularisers {
    /// Connectivity of `faces` over `num_vertices` vertices, with tensors on `device`. Faces must
    /// name three distinct vertices below `num_vertices`.
    pub fn new(num_vertices: usize, faces: &[[u32; 3]], device: &Device) -> Result<Self, AvatarError> {
        if faces.is_empty() {
            return Err(AvatarError::Invalid("a mesh topology needs at least one face".into()));
        }
        for (i, f) in faces.iter().enumerate() {
            if let Some(&v) = f.iter().find(|&&v| v as usize >= num_vertices) {
                return Err(AvatarError::Invalid(format!(
                    "face {i} {f:?} names vertex {v}, but the mesh has {num_vertices} vertices"
                )));
            }
            if f[0] == f[1] || f[1] == f[2] || f[2] == f[0] {
                return Err(AvatarError::Invalid(format!("face {i} {f:?} repeats a vertex")));
            }
        }
        // (low, high, opposite vertex) for each face's three edges, grouped by edge.
        let mut sides: Vec<(u32, u32, u32)> = faces
            .iter()
            .flat_map(|&[a, b, c]| [(a, b, c), (b, c, a), (c, a, b)])
            .map(|(a, b, opposite)| (a.min(b), a.max(b), opposite))
            .collect();
        sides.sort_unstable();
        let (mut from, mut to, mut hinge) = (Vec::new(), Vec::new(), [(); 4].map(|_| Vec::new()));
        let mut degree = vec![0u32; num_vertices];
        for group in sides.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
            let (a, b) = (group[0].0, group[0].1);
            from.extend([i64::from(b), i64::from(a)]);
            to.extend([i64::from(a), i64::from(b)]);
            degree[a as usize] += 1;
            degree[b as usize] += 1;
            for (i, s) in group.iter().enumerate() {
                for t in &group[i + 1..] {
                    for (list, v) in hinge.iter_mut().zip([a, b, s.2, t.2]) {
                        list.push(i64::from(v));
                    }
                }
            }
        }
        let column = |f: fn(u32) -> f32| {
            let v: Vec<f32> = degree.iter().map(|&d| f(d)).collect();
            Tensor::from_data(TensorData::new(v, [num_vertices, 1]), device)
        };
        let (num_edges, num_hinges) = (from.len() / 2, hinge[0].len());
        let num_connected = degree.iter().filter(|&&d| d > 0).count();
        let host = Arc::new(HostMesh {
            rings: Arc::new(OneRingMesh::new(num_vertices, faces)),
            hinges: (0..num_hinges).map(|k| hinge.each_ref().map(|h| h[k] as u32)).collect(),
            num_connected,
        });
        Ok(Self {
            num_vertices,
            device: device.clone(),
            corners: [0, 1, 2].map(|k| indices(faces.iter().map(|f| i64::from(f[k])).collect(), device)),
            neighbour_from: indices(from, device),
            neighbour_to: indices(to, device),
            degree: column(|d| d.max(1) as f32),
            connected: column(|d| if d > 0 { 1.0 } else { 0.0 }),
            num_connected,
            hinges: (num_hinges > 0).then(|| hinge.map(|h| indices(h, device))),
            num_edges,
            num_hinges,
            host,
        })
    }

    pub fn num_vertices(&self) -> usize {
        self.num_vertices
    }

    pub fn num_faces(&self) -> usize {
        self.corners[0].dims()[0]
    }

    /// Undirected edges.
    pub fn num_edges(&self) -> usize {
        self.num_edges
    }

    /// Pairs of faces that share an edge (one per interior edge of a manifold mesh).
    pub fn num_hinges(&self) -> usize {
        self.num_hinges
    }

    /// Checks that `vertices` is `[V, 3]` for this mesh and lives on its device.
    pub(super) fn check(&self, vertices: &Tensor<2>) -> Result<(), AvatarError> {
        let dims = vertices.dims();
        if dims != [self.num_vertices, 3] {
            return Err(AvatarError::Invalid(format!(
                "mesh regulariser: vertices are {dims:?}, the topology expects [{}, 3]",
                self.num_vertices
            )));
        }
        if vertices.device() != self.device {
            return Err(AvatarError::Invalid(format!(
                "mesh regulariser: vertices are on {:?}, the topology on {:?}",
                vertices.device(),
                self.device
            )));
        }
        Ok(())
    }

    /// The term by the fused host op where the device runs it, else by `tensors`.
    pub(super) fn fused_or(
        &self,
        term: HostTerm,
        vertices: Tensor<2>,
        tensors: impl FnOnce(Tensor<2>) -> Result<Tensor<1>, AvatarError>,
    ) -> Result<Tensor<1>, AvatarError> {
        if !crate::host_ops::supported(&self.device) {
            return tensors(vertices);
        }
        self.check(&vertices)?;
        Ok(mesh_loss(vertices, MeshLoss { term, mesh: self.host.clone() }))
    }

    /// The three corners of every face, `[F, 3]` each.
    pub(super) fn face_corners(&self, vertices: &Tensor<2>) -> [Tensor<2>; 3] {
        self.corners.clone().map(|idx| vertices.clone().select(0, idx))
    }
}
