//! What every Mannequin crate shares, at the bottom of the house: NumPy arrays (in `.npy`, `.npz`,
//! or pickled), PLY headers and values, atomic writes and staged outputs, the limits on what any
//! reader accepts, checkpoint run records, progress bars, the seeded RNG, content fingerprints
//! and video encoding through `ffmpeg`.

pub mod atomic;
pub mod error;
pub mod fingerprint;
pub mod limits;
pub mod npy;
pub mod npz;
pub mod pickle;
pub mod pickle_arrays;
pub mod ply_body;
pub mod ply_header;
pub mod progress;
pub mod rng;
pub mod run_record;
pub mod staging;
pub mod video;

pub use atomic::{write_atomic, write_atomic_with};
pub use error::{IoError, NpyError, PickleError};
pub use npy::{NpyArray, NpyData};
pub use npz::{Npz, NpzWriter};
pub use ply_body::{PlyValueError, PlyValues};
pub use ply_header::{PlyHeader, PlyHeaderError};
pub use video::{VideoError, write_video};
