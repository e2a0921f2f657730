//! glTF has one index per vertex for every attribute, while OBJ and MakeHuman index UVs per
//! corner. A vertex on a UV seam is therefore written once per distinct UV it carries.

use crate::TriMesh;

/// The mesh re-indexed so that every output vertex has a single UV.
pub(crate) struct SeamSplit {
    /// For each output vertex, the mesh vertex it copies.
    pub source: Vec<u32>,
    /// For each output vertex, its UV (OBJ convention, v up), when the mesh has UVs.
    pub uv: Option<Vec<[f32; 2]>>,
    pub faces: Vec<[u32; 3]>,
}

/// Splits vertices per distinct (vertex, UV value) corner pair. Vertices no face uses are dropped,
/// because glTF viewers would draw them nowhere and their normals are undefined.
pub(crate) fn split_uv_seams(mesh: &TriMesh) -> SeamSplit {
    // A corner's key: its vertex and the bits of its UV (zero without UVs).
    let key = |f: usize, k: usize| -> (u32, u32, u32) {
        let v = mesh.faces[f][k];
        match &mesh.uv {
            Some(uv) => {
                let t = uv.coords[uv.faces[f][k] as usize];
                (v, t[0].to_bits(), t[1].to_bits())
            }
            None => (v, 0, 0),
        }
    };
    let mut keys: Vec<(u32, u32, u32)> =
        (0..mesh.faces.len()).flat_map(|f| (0..3).map(move |k| (f, k))).map(|(f, k)| key(f, k)).collect();
    keys.sort_unstable();
    keys.dedup();
    let index = |k: (u32, u32, u32)| keys.binary_search(&k).expect("every corner's key was collected") as u32;
    let faces = (0..mesh.faces.len()).map(|f| [0, 1, 2].map(|k| index(key(f, k)))).collect();
    SeamSplit {
        source: keys.iter().map(|k| k.0).collect(),
        uv: mesh
            .uv
            .as_ref()
            .map(|_| keys.iter().map(|k| [f32::from_bits(k.1), f32::from_bits(k.2)]).collect()),
        faces,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::UvLayout;

    #[test]
    fn seam_vertices_are_duplicated_and_unused_ones_dropped() {
        let mut mesh = TriMesh::new(
            vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [9.0; 3]],
            vec![[0, 1, 2], [2, 1, 3]],
        );
        // Vertex 2 carries UV 2 in the first face and UV 3 in the second: a seam.
        mesh.uv = Some(UvLayout {
            coords: vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.5, 0.5], [1.0, 1.0]],
            faces: vec![[0, 1, 2], [3, 1, 4]],
        });
        let s = split_uv_seams(&mesh);
        assert_eq!(s.source, vec![0, 1, 2, 2, 3]);
        let uv = s.uv.unwrap();
        for (f, tri) in s.faces.iter().enumerate() {
            for k in 0..3 {
                assert_eq!(s.source[tri[k] as usize], mesh.faces[f][k]);
                let layout = mesh.uv.as_ref().unwrap();
                assert_eq!(uv[tri[k] as usize], layout.coords[layout.faces[f][k] as usize]);
            }
        }
        mesh.uv = None;
        assert_eq!(split_uv_seams(&mesh).source, vec![0, 1, 2, 3]);
    }
}
