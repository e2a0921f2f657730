//! Datasets and their metrics: the PeopleSnapshot-layout reader and writer, the images and maps
//! a dataset holds, and the metrics the papers report.

pub mod dataset;
pub mod error;
pub mod evaluation;
pub mod fingerprint;
pub mod frame_files;
pub mod image;
pub mod image_decode;
pub mod labels;
pub mod layout;
pub mod maps;
pub mod metrics;
pub mod origin;
pub mod poses;
pub mod scores;
pub mod splits;
pub mod writer;

pub use dataset::{Cameras, Dataset, Frame, Split};
pub use error::DataError;
pub use evaluation::TestPoses;
pub use image::{Image, Mask};
/// The one camera type of the project, shared with the renderer.
pub use mannequin_splat::Camera;
pub use maps::{DepthMap, NormalMap};
pub use origin::{Origin, PoseOrigin};
pub use poses::Poses;
pub use scores::{Scores, TestSet};
pub use splits::{SplitRange, Splits, standard_splits};
pub use writer::DatasetWriter;
