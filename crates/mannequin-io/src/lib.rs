//! File plumbing shared by every Mannequin crate: NumPy arrays, PLY headers and values, and
//! atomic writes.

pub mod atomic;
pub mod error;
pub mod npy;
pub mod npz;
pub mod ply_body;
pub mod ply_header;

pub use atomic::{write_atomic, write_atomic_with};
pub use error::{IoError, NpyError};
pub use npy::{NpyArray, NpyData};
pub use npz::{Npz, NpzWriter};
pub use ply_body::{PlyValueError, PlyValues};
pub use ply_header::{PlyHeader, PlyHeaderError};
