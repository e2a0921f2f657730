//! The body as a collider: the triangles of the body mesh, with the adjacency needed to tell inside
//! from outside. The caller supplies the body's vertex positions at the start and the end of every
//! frame; the body is kinematic, so the cloth never moves it.

use glam::Vec3;
use mannequin_mesh::adjacency::face_neighbors;

use crate::error::ClothError;
use crate::layers::Layers;

#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    pub(crate) faces: Vec<[u32; 3]>,
    /// For each face and each k, the face across its edge from corner k to corner k+1.
    neighbours: Vec<[Option<u32>; 3]>,
    /// Faces around each vertex: `vertex_faces[vertex_starts[v]..vertex_starts[v + 1]]`.
    vertex_starts: Vec<u32>,
    vertex_faces: Vec<u32>,
    /// The number of vertices the faces (and the layers) need; frames with fewer are refused.
    pub(crate) vertices_needed: usize,
    /// Cloth worn under the simulated cloth, moving with the body.
    layers: Option<Layers>,
}

impl Body {
    /// A body of these triangles (the body mesh's topology), outward facing.
    pub fn new(faces: Vec<[u32; 3]>) -> Body {
        let vertices_needed = faces.iter().flatten().map(|&i| i as usize + 1).max().unwrap_or(0);
        let mut vertex_starts = vec![0u32; vertices_needed + 1];
        for &i in faces.iter().flatten() {
            vertex_starts[i as usize + 1] += 1;
        }
        for v in 0..vertices_needed {
            vertex_starts[v + 1] += vertex_starts[v];
        }
        let mut next = vertex_starts.clone();
        let mut vertex_faces = vec![0u32; faces.len() * 3];
        for (f, tri) in faces.iter().enumerate() {
            for &i in tri {
                vertex_faces[next[i as usize] as usize] = f as u32;
                next[i as usize] += 1;
            }
        }
        let neighbours = face_neighbors(&faces);
        Body { neighbours, faces, vertex_starts, vertex_faces, vertices_needed, layers: None }
    }

    /// This body worn under cloth `layers`, whose vertices follow the body's in every frame.
    pub fn with_layers(mut self, layers: Layers) -> Result<Body, ClothError> {
        layers.check()?;
        self.vertices_needed = self.vertices_needed.max(layers.first_vertex + layers.rest.len());
        self.layers = Some(layers);
        Ok(self)
    }

    /// The body to push cloth out of, and the layers for the cloth's own contacts to hold it off:
    /// with `self_collision`, the layers go to the contacts; else they join the body's triangles.
    pub(crate) fn colliders(self, self_collision: bool) -> (Body, Option<Layers>) {
        match self.layers {
            Some(layers) if self_collision => (Body { layers: None, ..self }, Some(layers)),
            Some(layers) => {
                let mut faces = self.faces;
                faces.extend(layers.faces_in_body());
                (Body::new(faces), None)
            }
            None => (self, None),
        }
    }

    pub fn faces(&self) -> &[[u32; 3]] {
        &self.faces
    }

    /// The angle-weighted pseudo-normal (Bærentzen & Aanæs 2005) of the feature of face `face`
    /// where the closest point with barycentric coordinates `bary` lies: the face's normal inside
    /// it, the sum of both faces' normals on an edge, the angle-weighted sum around a vertex.
    /// Its dot product with (p − closest point) has the sign of p's side for a closed mesh, even
    /// at sharp edges and corners, where one face's normal would misjudge it.
    pub(crate) fn pseudo_normal(
        &self,
        positions: &[Vec3],
        normals: &[Vec3],
        face: usize,
        bary: [f32; 3],
    ) -> Vec3 {
        let zeros = bary.iter().filter(|&&b| b == 0.0).count();
        match zeros {
            1 => {
                let opposite = bary.iter().position(|&b| b == 0.0).unwrap_or(0);
                let across = self.neighbours[face][(opposite + 1) % 3];
                normals[face] + across.map_or(Vec3::ZERO, |g| normals[g as usize])
            }
            2 => {
                let corner = bary.iter().position(|&b| b != 0.0).unwrap_or(0);
                let vertex = self.faces[face][corner] as usize;
                let around = &self.vertex_faces
                    [self.vertex_starts[vertex] as usize..self.vertex_starts[vertex + 1] as usize];
                around
                    .iter()
                    .map(|&g| corner_angle(positions, self.faces[g as usize], vertex) * normals[g as usize])
                    .sum()
            }
            _ => normals[face],
        }
    }
}

/// The angle of triangle `tri` at its corner `vertex`.
fn corner_angle(positions: &[Vec3], tri: [u32; 3], vertex: usize) -> f32 {
    let k = tri.iter().position(|&i| i as usize == vertex).unwrap_or(0);
    let at = |j: usize| positions[tri[(k + j) % 3] as usize];
    (at(1) - at(0)).angle_between(at(2) - at(0))
}
