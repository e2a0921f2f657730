//! Garments worn over the body as meshes of their own (NGD's layered avatar): each garment's
//! vertices and faces are appended to the canonical mesh, so its Gaussians bind to it with the
//! avatar's binding and the clothed avatar renders in one splatting pass. Every vertex keeps the
//! index of the layer it belongs to, so exports and evaluation can take the layers apart again.

use glam::Vec3;
use mannequin_mesh::TriMesh;
use mannequin_mesh::adjacency::boundary_loops;
use mannequin_mesh::closest_point::ClosestPoint;

use crate::canonical::Canonical;
use crate::error::AvatarError;

/// Cell size of the closest-point index over a garment (m): about the body's distance from it.
const CELL: f32 = 0.03;

/// A garment at rest on the canonical body, in its rest frame.
#[derive(Debug, Clone, PartialEq)]
pub struct GarmentLayer {
    /// The layer's name: the garment's category (`tshirt`, `dress`, `skirt` …).
    pub name: String,
    pub positions: Vec<[f32; 3]>,
    pub faces: Vec<[u32; 3]>,
    /// Skinning weights, V × J row-major, in the body's joints.
    pub weights: Vec<f32>,
}

impl GarmentLayer {
    /// Per rest point of `body`, how much of its offset it keeps: none where the garment covers
    /// it (the point is on the garment's inner side, and its closest garment triangle does not
    /// touch an opening), all of it elsewhere. No view sees the body under a garment, and left
    /// free its offsets would push it through the garment to fit the garment's silhouette.
    pub fn offset_gate(&self, body: &[[f32; 3]]) -> Vec<f32> {
        let openings: std::collections::HashSet<u32> =
            boundary_loops(&self.faces).into_iter().flatten().collect();
        let index = ClosestPoint::new(&self.positions, &self.faces, CELL);
        let corner = |i: u32| Vec3::from(self.positions[i as usize]);
        body.iter()
            .map(|&p| {
                let p = Vec3::from(p);
                let Some((at, q)) = index.query(p) else { return 1.0 };
                let tri = self.faces[at.face as usize];
                let normal = (corner(tri[1]) - corner(tri[0])).cross(corner(tri[2]) - corner(tri[0]));
                let inside = (p - q).dot(normal) < 0.0;
                let at_opening = tri.iter().any(|i| openings.contains(i));
                if inside && !at_opening { 0.0 } else { 1.0 }
            })
            .collect()
    }
}

/// One layer of a canonical mesh as a mesh of its own: the whole mesh's vertices it keeps, in
/// order, and its faces renumbered to index them.
#[derive(Debug, Clone, PartialEq)]
pub struct LayerPart {
    pub vertices: Vec<usize>,
    pub faces: Vec<[u32; 3]>,
}

impl LayerPart {
    /// This part of `whole` (the canonical mesh's faces, in any pose, with any colours).
    pub fn mesh(&self, whole: &TriMesh) -> TriMesh {
        let mut part =
            TriMesh::new(self.vertices.iter().map(|&i| whole.positions[i]).collect(), self.faces.clone());
        part.colors = whole.colors.as_ref().map(|c| self.vertices.iter().map(|&i| c[i]).collect());
        part
    }

    /// This part's rows of a per-vertex table `width` values wide (skinning weights, say).
    pub fn rows(&self, table: &[f32], width: usize) -> Vec<f32> {
        self.vertices.iter().flat_map(|&v| table[v * width..(v + 1) * width].iter().copied()).collect()
    }
}

impl Canonical {
    /// The mesh with `layer` appended as a layer of its own (no pose correctives on it), the
    /// body's offsets gated by `body_gate` (one value per vertex of the mesh so far; the lesser
    /// of it and the current gate holds). The layer's own vertices take the offset field fully.
    pub fn with_garment(mut self, layer: &GarmentLayer, body_gate: &[f32]) -> Result<Self, AvatarError> {
        let (v, j) = (self.num_vertices(), self.num_joints());
        let added = layer.positions.len();
        if layer.weights.len() != added * j || body_gate.len() != v {
            return Err(AvatarError::Invalid(format!(
                "garment layer {}: {} weights and {} gates, expected {} ({added} vertices × {j} joints) and {v}",
                layer.name,
                layer.weights.len(),
                body_gate.len(),
                added * j
            )));
        }
        if let Some(f) = layer.faces.iter().position(|f| f.iter().any(|&i| i as usize >= added)) {
            return Err(AvatarError::Invalid(format!(
                "garment layer {}: face {f} indexes past its {added} vertices",
                layer.name
            )));
        }
        for (gate, g) in self.offset_gate.iter_mut().zip(body_gate) {
            *gate = gate.min(*g);
        }
        self.offset_gate.extend(std::iter::repeat_n(1.0, added));
        if !self.posedirs.is_empty() {
            self.posedirs = self
                .posedirs
                .chunks_exact(3 * v)
                .flat_map(|row| row.iter().copied().chain(std::iter::repeat_n(0.0, 3 * added)))
                .collect();
        }
        let index = self.layer_names.len() as u8;
        self.layer_names.push(layer.name.clone());
        self.layer.extend(std::iter::repeat_n(index, added));
        self.vertices.extend_from_slice(&layer.positions);
        self.faces.extend(layer.faces.iter().map(|f| f.map(|i| i + v as u32)));
        self.weights.extend_from_slice(&layer.weights);
        Ok(self)
    }

    /// The garment layers' names (every layer but the body), in order.
    pub fn garment_names(&self) -> &[String] {
        &self.layer_names[1..]
    }

    /// Layer `name` as a mesh of its own; `None` when there is no such layer.
    pub fn layer_part(&self, name: &str) -> Option<LayerPart> {
        let index = self.layer_names.iter().position(|n| n == name)? as u8;
        let mut renumbered = vec![u32::MAX; self.num_vertices()];
        let mut vertices = Vec::new();
        for i in (0..self.num_vertices()).filter(|&i| self.layer[i] == index) {
            renumbered[i] = vertices.len() as u32;
            vertices.push(i);
        }
        let faces = self
            .faces
            .iter()
            .filter(|f| self.layer[f[0] as usize] == index)
            .map(|f| f.map(|i| renumbered[i as usize]))
            .collect();
        Some(LayerPart { vertices, faces })
    }

    /// Layer `name`'s part of `mesh` (this mesh's faces, in any pose, with any colours).
    pub fn layer_mesh(&self, name: &str, mesh: &TriMesh) -> Option<TriMesh> {
        Some(self.layer_part(name)?.mesh(mesh))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::canonical::BODY;

    /// An open cylinder of radius `r` around the y axis from y = 0 to 1, outward-facing.
    fn tube(r: f32, segments: usize, rings: usize) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
        let mut positions = Vec::new();
        for k in 0..rings {
            for s in 0..segments {
                let a = std::f32::consts::TAU * s as f32 / segments as f32;
                positions.push([r * a.cos(), k as f32 / (rings - 1) as f32, r * a.sin()]);
            }
        }
        let mut faces = Vec::new();
        let at = |k: usize, s: usize| (k * segments + s % segments) as u32;
        for k in 0..rings - 1 {
            for s in 0..segments {
                faces.push([at(k, s), at(k + 1, s), at(k, s + 1)]);
                faces.push([at(k, s + 1), at(k + 1, s), at(k + 1, s + 1)]);
            }
        }
        (positions, faces)
    }

    fn layer(name: &str, positions: Vec<[f32; 3]>, faces: Vec<[u32; 3]>, joints: usize) -> GarmentLayer {
        let weights =
            positions.iter().flat_map(|_| (0..joints).map(|j| f32::from(u8::from(j == 0)))).collect();
        GarmentLayer { name: name.into(), positions, faces, weights }
    }

    #[test]
    fn the_body_is_covered_inside_the_garment_and_away_from_its_openings() {
        let (positions, faces) = tube(0.3, 32, 21);
        let garment = layer("skirt", positions, faces, 1);
        // Inside at mid-height, outside at mid-height, inside but beside the lower opening,
        // beyond the top opening.
        let body = [[0.1, 0.5, 0.0], [0.5, 0.5, 0.0], [0.28, 0.01, 0.0], [0.0, 1.3, 0.0]];
        assert_eq!(garment.offset_gate(&body), vec![0.0, 1.0, 1.0, 1.0]);
    }

    #[test]
    fn a_layer_comes_apart_as_it_went_in() {
        let (body_positions, body_faces) = tube(0.2, 8, 3);
        let mut body = Canonical {
            vertices: body_positions.clone(),
            faces: body_faces.clone(),
            weights: vec![1.0; body_positions.len()],
            joints: vec![[0.0; 3]],
            parents: vec![None],
            posedirs: Vec::new(),
            offset_gate: vec![1.0; body_positions.len()],
            layer: vec![0; body_positions.len()],
            layer_names: vec![BODY.into()],
        };
        let (positions, faces) = tube(0.3, 6, 4);
        let garment = layer("dress", positions.clone(), faces.clone(), 1);
        let mut gate = vec![1.0; body.num_vertices()];
        gate[3] = 0.0;
        body = body.with_garment(&garment, &gate).unwrap();
        assert_eq!(body.garment_names(), ["dress"]);
        assert_eq!(body.offset_gate[3], 0.0);
        assert_eq!(body.offset_gate.iter().filter(|&&g| g == 0.0).count(), 1);
        let whole = TriMesh::new(body.vertices.clone(), body.faces.clone());
        assert_eq!(body.layer_mesh("dress", &whole), Some(TriMesh::new(positions, faces)));
        assert_eq!(body.layer_mesh(BODY, &whole), Some(TriMesh::new(body_positions, body_faces)));
        assert_eq!(body.layer_mesh("cape", &whole), None);
        // Subdivision keeps every new vertex in its edge's layer (24 + 24 ring, 18 vertical and
        // 18 diagonal edges' midpoints).
        let fine = body.subdivided();
        let part =
            fine.layer_mesh("dress", &TriMesh::new(fine.vertices.clone(), fine.faces.clone())).unwrap();
        let (p, f) = (part.positions, part.faces);
        assert_eq!((p.len(), f.len()), (24 + 60, 4 * 36));
        assert!(p.iter().all(|q| ((q[0] * q[0] + q[2] * q[2]).sqrt() - 0.3).abs() < 0.05));
        // Weights of the wrong length are refused, naming the layer.
        let bad = GarmentLayer { weights: vec![], ..garment };
        let gate = vec![1.0; fine.num_vertices()];
        let e = fine.with_garment(&bad, &gate).unwrap_err().to_string();
        assert!(e.contains("garment layer dress"), "{e}");
    }
}
