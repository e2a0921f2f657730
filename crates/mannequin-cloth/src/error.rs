//! Cloth errors: one line each, naming the field at fault, so a caller can prefix its file name.

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ClothError {
    /// `known`: the material names, listed.
    #[error("material: unknown name {name:?}; the materials are {known}")]
    UnknownMaterial { name: String, known: String },
    #[error("{field}: {reason}")]
    Invalid { field: String, reason: String },
    #[error("{field}[{index}] is not finite")]
    NonFiniteInput { field: &'static str, index: usize },
    #[error("faces[{face}] refers to vertex {index}, but there are {count} vertices")]
    FaceIndex { face: usize, index: u32, count: usize },
    #[error("faces[{face}] is degenerate (zero area)")]
    DegenerateFace { face: usize },
    #[error("faces: edge ({a}, {b}) is shared by {count} triangles; a cloth edge may have at most 2")]
    NonManifoldEdge { a: u32, b: u32, count: usize },
    #[error("pins[{index}] = {vertex} is out of range: the garment has {count} vertices")]
    PinIndex { index: usize, vertex: u32, count: usize },
    /// Self-collision keeps apart what starts apart; a mesh that starts crossed stays crossed.
    #[error(
        "the garment starts crossing itself: {pairs} pairs of triangles intersect, the first faces {first} \
         and {second} near ({x:.3}, {y:.3}, {z:.3}) m; self-collision keeps apart only what starts apart \
         (untangle the mesh, or turn self-collision off)"
    )]
    StartsCrossed { pairs: usize, first: usize, second: usize, x: f32, y: f32, z: f32 },
    #[error(
        "the garment starts crossing the layers under it: {pairs} pairs of triangles intersect, the first \
         its face {face} and their face {layer_face} near ({x:.3}, {y:.3}, {z:.3}) m; self-collision keeps \
         apart only what starts apart (put the garment over them, or turn self-collision off)"
    )]
    StartsCrossingLayers { pairs: usize, face: usize, layer_face: usize, x: f32, y: f32, z: f32 },
    #[error("the simulation blew up: particle {particle} is no longer finite")]
    NonFinite { particle: usize },
}

impl ClothError {
    pub(crate) fn invalid(field: impl Into<String>, reason: impl Into<String>) -> Self {
        Self::Invalid { field: field.into(), reason: reason.into() }
    }
}
