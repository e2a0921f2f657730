//! Triangle meshes: the data type, normals, differential operators, and file formats.

pub mod adjacency;
pub mod area;
pub mod barycentric;
pub mod clip;
pub mod closest_point;
pub mod file_error;
pub mod gltf;
pub mod gradient;
pub mod jacobian_field;
pub mod kdtree;
pub mod laplacian;
pub mod manifold;
pub mod mass;
pub mod mesh_file;
pub mod normals;
pub mod obj;
pub mod pc2;
pub mod ply;
pub mod poisson;
pub mod remesh;
pub mod ring_tube;
pub mod subdivide;
pub mod tri_mesh;
pub mod uv_ellipsoid;

pub use area::double_areas;
pub use closest_point::{ClosestPoint, SurfacePoint};
pub use file_error::MeshFileError;
pub use gltf::{
    BlendShapeAnimation, BlendShapeMesh, MorphSequence, SkeletalAnimation, Skeleton, SkinnedLayer,
    SkinnedMesh, write_blend_shape_glb, write_glb, write_layered_glb, write_scene_glb,
};
pub use gradient::gradient_operator;
pub use laplacian::cotan_laplacian;
pub use mass::{MassKind, mass_matrix, vertex_areas};
pub use mesh_file::{MeshWriteError, write_mesh};
pub use obj::{Obj, ObjGroup, read_obj, write_obj};
pub use pc2::PointCache;
pub use tri_mesh::{MeshError, TriMesh, UvLayout, points};
pub use uv_ellipsoid::uv_ellipsoid;
