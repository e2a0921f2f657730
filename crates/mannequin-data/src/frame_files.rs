//! The numbered files of a dataset or prediction folder (`<folder>/<prefix>_NNNN.<ext>`), and
//! its images in particular: `images/image_NNNN.<ext>` with `ext` one of
//! [`layout::IMAGE_EXTENSIONS`]. A folder keeps to one image extension, so a frame number names
//! one file; the file's content, not its extension, decides how it is decoded.

use std::path::{Path, PathBuf};

use crate::error::DataError;
use crate::layout;

/// `(frame, extension)` of every `<root>/<folder>/<prefix>_NNNN.<ext>` with `ext` in `exts`,
/// sorted; other files are ignored.
pub fn list_frame_files(
    root: &Path,
    folder: &str,
    prefix: &str,
    exts: &[&'static str],
) -> Result<Vec<(usize, &'static str)>, DataError> {
    let dir = root.join(folder);
    let mut found = Vec::new();
    for entry in std::fs::read_dir(&dir).map_err(|e| DataError::os(&dir, e))? {
        let name = entry.map_err(|e| DataError::os(&dir, e))?.file_name();
        let name = name.to_string_lossy();
        found.extend(exts.iter().find_map(|&ext| layout::frame_number(&name, prefix, ext).map(|n| (n, ext))));
    }
    found.sort_unstable();
    Ok(found)
}

/// A folder's image frame numbers, sorted, and the extension they share.
#[derive(Debug, Clone, PartialEq)]
pub struct ImageFiles {
    pub ext: &'static str,
    pub frames: Vec<usize>,
}

impl ImageFiles {
    /// Lists `<root>/images`; mixed extensions are an error naming one file of each.
    pub fn list(root: &Path) -> Result<Self, DataError> {
        let found = list_frame_files(root, layout::IMAGES, "image", &layout::IMAGE_EXTENSIONS)?;
        let ext = found.first().map_or(layout::IMAGE_EXTENSIONS[0], |&(_, ext)| ext);
        if let Some(&(other, other_ext)) = found.iter().find(|&&(_, e)| e != ext) {
            let name = |frame, ext| layout::image_file(Path::new(""), frame, ext).display().to_string();
            return Err(DataError::file(
                root.join(layout::IMAGES),
                format!(
                    "holds both {} and {}: a folder's images must share one extension",
                    name(found[0].0, ext),
                    name(other, other_ext)
                ),
            ));
        }
        Ok(Self { ext, frames: found.into_iter().map(|(n, _)| n).collect() })
    }

    /// The file of `frame` under `root`.
    pub fn path(&self, root: &Path, frame: usize) -> PathBuf {
        layout::image_file(root, frame, self.ext)
    }
}
