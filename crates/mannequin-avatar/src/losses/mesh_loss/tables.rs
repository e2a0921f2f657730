//! A mesh's index tables on one GPU device, uploaded on first use and kept while the mesh lives:
//! the one-rings (the Laplacian's gathers), the faces and hinges, and per vertex the corner slots
//! of the faces and hinges it belongs to (the backward's gathers, which need no atomics).

use std::sync::{Arc, Mutex};

use burn::backend::ops::IntTensorOps;
use burn::backend::wgpu::{CubeBackend, CubeTensor};
use burn::tensor::TensorData;
use burn_cubecl::CubeDevice;

use super::HostMesh;
use crate::mesh_tables::{TableCache, cached, csr};

/// Index tables as `i32` `[n]` tensors.
pub(super) struct Tables {
    /// Ring `i` is `rings[ring_start[i] .. ring_start[i + 1]]`.
    pub ring_start: CubeTensor,
    pub rings: CubeTensor,
    /// `[F·3]` corners, `[H·4]` hinge vertices `a, b, c, d`.
    pub faces: CubeTensor,
    pub hinges: CubeTensor,
    /// Vertex `i`'s face corner slots (`3f + k`) are `face_slots[face_start[i] .. face_start[i + 1]]`;
    /// likewise its hinge slots (`4h + k`).
    pub face_start: CubeTensor,
    pub face_slots: CubeTensor,
    pub hinge_start: CubeTensor,
    pub hinge_slots: CubeTensor,
}

static CACHE: TableCache<HostMesh, Arc<Tables>> = Mutex::new(Vec::new());

/// The tables of `mesh` on `device`, uploaded on first use.
pub(super) fn tables(mesh: &Arc<HostMesh>, device: &CubeDevice) -> Arc<Tables> {
    cached(&CACHE, mesh, device, || Arc::new(upload(mesh, device)))
}

fn upload(mesh: &HostMesh, device: &CubeDevice) -> Tables {
    let rings = &mesh.rings;
    let n = rings.num_vertices;
    let (ring_start, ring_entries) = csr(n, (0..n).flat_map(|i| rings.ring(i).iter().map(move |&j| (i, j))));
    let faces: Vec<u32> = rings.faces.iter().flatten().copied().collect();
    let hinges: Vec<u32> = mesh.hinges.iter().flatten().copied().collect();
    let slots = |corners: &[u32]| csr(n, corners.iter().enumerate().map(|(s, &v)| (v as usize, s as u32)));
    let (face_start, face_slots) = slots(&faces);
    let (hinge_start, hinge_slots) = slots(&hinges);
    let up = |v: &[u32]| {
        // At least one entry: a mesh without hinges still gets a (never read) buffer.
        let v: Vec<i32> = if v.is_empty() {
            vec![0]
        } else {
            v.iter().map(|&x| i32::try_from(x).expect("mesh indices fit i32")).collect()
        };
        let len = v.len();
        CubeBackend::int_from_data(TensorData::new(v, [len]), device)
    };
    Tables {
        ring_start: up(&ring_start),
        rings: up(&ring_entries),
        faces: up(&faces),
        hinges: up(&hinges),
        face_start: up(&face_start),
        face_slots: up(&face_slots),
        hinge_start: up(&hinge_start),
        hinge_slots: up(&hinge_slots),
    }
}
