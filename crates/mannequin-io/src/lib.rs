//! File plumbing shared by every Mannequin crate: NumPy arrays and atomic writes.

pub mod atomic;
pub mod error;
pub mod npy;
pub mod npz;

pub use atomic::{write_atomic, write_atomic_with};
pub use error::{IoError, NpyError};
pub use npy::{NpyArray, NpyData};
pub use npz::{Npz, NpzWriter};
