//! Triangle meshes: the data type, normals, differential operators, and file formats.

pub mod normals;
pub mod tri_mesh;

pub use tri_mesh::{MeshError, TriMesh, UvLayout};
