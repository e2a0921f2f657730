//! Writing a dataset folder in the layout that [`crate::dataset::Dataset`] reads. Every file is
//! written atomically.

use std::path::{Path, PathBuf};

use mannequin_io::{NpyArray, NpzWriter};
use mannequin_mesh::TriMesh;

use crate::dataset::{Cameras, Frame};
use crate::error::DataError;
use crate::image::Mask;
use crate::labels::LabelMap;
use crate::layout;
use crate::maps::write_mask_npy;
use crate::origin::{Origin, PoseOrigin};
use crate::poses::Poses;
use crate::splits::{Splits, write_splits_json};

pub struct DatasetWriter {
    pub root: PathBuf,
}

impl DatasetWriter {
    pub fn new(root: impl AsRef<Path>) -> Self {
        Self { root: root.as_ref().to_path_buf() }
    }

    pub fn write_cameras(&self, cameras: &Cameras) -> Result<(), DataError> {
        let list = match cameras {
            Cameras::Static(c) => std::slice::from_ref(c),
            Cameras::PerFrame(v) => v.as_slice(),
        };
        let path = self.root.join(layout::CAMERAS);
        let Some(first) = list.first() else {
            return Err(DataError::file(path, "no cameras to write"));
        };
        if list.iter().any(|c| (c.width, c.height) != (first.width, first.height)) {
            return Err(DataError::file(path, "all cameras of a dataset must share one image size"));
        }
        let k: Vec<f64> = list.iter().flat_map(|c| c.intrinsic.iter().flatten().copied()).collect();
        let e: Vec<f64> = list.iter().flat_map(|c| c.extrinsic.iter().flatten().copied()).collect();
        let (k_shape, e_shape) = match cameras {
            Cameras::Static(_) => (vec![3, 3], vec![4, 4]),
            Cameras::PerFrame(v) => (vec![v.len(), 3, 3], vec![v.len(), 4, 4]),
        };
        let mut w = NpzWriter::new();
        w.add("intrinsic", NpyArray::f64(k_shape, k));
        w.add("extrinsic", NpyArray::f64(e_shape, e));
        w.add("height", NpyArray::i64(vec![], vec![first.height as i64]));
        w.add("width", NpyArray::i64(vec![], vec![first.width as i64]));
        Ok(w.write(path)?)
    }

    pub fn write_splits(&self, splits: &Splits) -> Result<(), DataError> {
        write_splits_json(&self.root.join(layout::SPLITS), splits)
    }

    /// Records where the dataset's poses came from (`origin.json`).
    pub fn write_origin(&self, poses: PoseOrigin, by: &str) -> Result<(), DataError> {
        Origin { poses, by: by.to_string() }.write(&self.root)
    }

    pub fn write_poses(&self, split: &str, poses: &Poses) -> Result<(), DataError> {
        poses.write(&layout::split_poses(&self.root, split))
    }

    /// Writes the image, mask, and (where present) normal and depth maps of `frame`.
    pub fn write_frame(&self, frame: &Frame) -> Result<(), DataError> {
        let i = frame.index;
        frame.image.write_png(&layout::image(&self.root, i))?;
        write_mask_npy(&layout::mask(&self.root, i), &frame.mask)?;
        if let Some(n) = &frame.normals {
            n.write_png(&layout::normal(&self.root, i))?;
        }
        if let Some(d) = &frame.depth {
            d.write_npy(&layout::depth(&self.root, i))?;
        }
        Ok(())
    }

    /// Writes a frame's ground-truth mesh (world coordinates) as binary PLY.
    pub fn write_mesh(&self, index: usize, mesh: &TriMesh) -> Result<(), DataError> {
        Ok(mannequin_mesh::ply::write(layout::mesh(&self.root, index), mesh, None)?)
    }

    /// Writes a frame's ground-truth mesh of the garment `name` (world coordinates).
    pub fn write_garment_mesh(&self, index: usize, name: &str, mesh: &TriMesh) -> Result<(), DataError> {
        Ok(mannequin_mesh::ply::write(layout::garment_mesh(&self.root, name, index), mesh, None)?)
    }

    /// Writes a frame's label map and hand mask.
    pub fn write_labels(&self, index: usize, labels: &LabelMap, hands: &Mask) -> Result<(), DataError> {
        labels.write_png(&layout::label(&self.root, index))?;
        write_mask_npy(&layout::hand_mask(&self.root, index), hands)
    }
}
