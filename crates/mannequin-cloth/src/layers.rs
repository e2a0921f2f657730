//! Cloth worn under the simulated cloth (a garment's inner layers), moved by the caller along
//! with the body. With self-collision on, their triangles join the cloth's own contacts as
//! kinematic particles, so the safe step keeps the cloth from passing through them as it keeps it
//! from passing through itself; without it, they are part of the body, pushed out of by normal,
//! which cannot tell the sides of an open sheet once a vertex is past it.

use crate::error::ClothError;

/// The layers' triangles over their own vertices, which follow the body's in the positions the
/// caller gives every frame, and where those vertices are at rest.
#[derive(Debug, Clone, PartialEq)]
pub struct Layers {
    /// Where the layers' vertices start in each frame's body positions.
    pub first_vertex: usize,
    /// Triangles over the layers' vertices (0 is the one at `first_vertex`).
    pub faces: Vec<[u32; 3]>,
    /// The layers' vertices at rest, where the cloth starts.
    pub rest: Vec<[f32; 3]>,
}

impl Layers {
    /// Refuses faces beyond the vertices at rest, and rest positions that are not finite.
    pub(crate) fn check(&self) -> Result<(), ClothError> {
        let count = self.rest.len();
        for (k, face) in self.faces.iter().enumerate() {
            if let Some(&index) = face.iter().find(|&&i| i as usize >= count) {
                let reason =
                    format!("refers to vertex {index}, but the layers have {count} vertices at rest");
                return Err(ClothError::invalid(format!("layers.faces[{k}]"), reason));
            }
        }
        match self.rest.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            Some(index) => Err(ClothError::NonFiniteInput { field: "layers.rest", index }),
            None => Ok(()),
        }
    }

    /// The layers' triangles over the body's vertex positions.
    pub(crate) fn faces_in_body(&self) -> impl Iterator<Item = [u32; 3]> + '_ {
        self.faces.iter().map(|f| f.map(|i| i + self.first_vertex as u32))
    }
}
