//! File names of the dataset layout (PeopleSnapshot preprocessed, extended with optional
//! ground-truth folders). `docs/dataset-format.md` describes it for users.

use std::path::{Path, PathBuf};

pub const CAMERAS: &str = "cameras.npz";
pub const SPLITS: &str = "splits.json";
/// Where the poses came from (`crate::origin`).
pub const ORIGIN: &str = "origin.json";
pub const IMAGES: &str = "images";
pub const MASKS: &str = "masks";
pub const NORMALS: &str = "normals";
pub const DEPTH: &str = "depth";
pub const MESHES: &str = "meshes";
pub const POSES: &str = "poses";
pub const LABELS: &str = "labels";
pub const HANDS: &str = "hands";
/// All frames' SMPL parameters, sliced by each split's range when no per-split file exists.
pub const ALL_POSES: &str = "poses.npz";

/// Extensions an image frame may have, the written one (PNG) first.
pub const IMAGE_EXTENSIONS: [&str; 3] = ["png", "jpg", "jpeg"];

/// The image of `frame` as Mannequin writes it (PNG).
pub fn image(root: &Path, frame: usize) -> PathBuf {
    image_file(root, frame, IMAGE_EXTENSIONS[0])
}

pub fn image_file(root: &Path, frame: usize, ext: &str) -> PathBuf {
    root.join(IMAGES).join(format!("image_{frame:04}.{ext}"))
}

pub fn mask(root: &Path, frame: usize) -> PathBuf {
    root.join(MASKS).join(format!("mask_{frame:04}.npy"))
}

pub fn normal(root: &Path, frame: usize) -> PathBuf {
    root.join(NORMALS).join(format!("normal_{frame:04}.png"))
}

pub fn depth(root: &Path, frame: usize) -> PathBuf {
    root.join(DEPTH).join(format!("depth_{frame:04}.npy"))
}

pub fn mesh(root: &Path, frame: usize) -> PathBuf {
    root.join(MESHES).join(format!("mesh_{frame:04}.ply"))
}

/// Frame `frame`'s label map (synthetic subjects).
pub fn label(root: &Path, frame: usize) -> PathBuf {
    root.join(LABELS).join(format!("label_{frame:04}.png"))
}

/// Frame `frame`'s hand mask: the pixels where a hand shows (synthetic subjects).
pub fn hand_mask(root: &Path, frame: usize) -> PathBuf {
    root.join(HANDS).join(format!("hand_{frame:04}.npy"))
}

/// Frame `frame`'s ground-truth mesh of the garment `name` (synthetic subjects).
pub fn garment_mesh(root: &Path, name: &str, frame: usize) -> PathBuf {
    root.join(MESHES).join(format!("garment_{name}_{frame:04}.ply"))
}

pub fn split_poses(root: &Path, split: &str) -> PathBuf {
    root.join(POSES).join(format!("anim_nerf_{split}.npz"))
}

/// The frame number in a file name `<prefix>_<digits>.<ext>`, if it has that form.
pub fn frame_number(name: &str, prefix: &str, ext: &str) -> Option<usize> {
    let digits = name.strip_prefix(prefix)?.strip_prefix('_')?.strip_suffix(ext)?.strip_suffix('.')?;
    (!digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit())).then(|| digits.parse().ok()).flatten()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_numbers_parse_only_the_expected_form() {
        assert_eq!(frame_number("image_0042.png", "image", "png"), Some(42));
        assert_eq!(frame_number("image_12345.png", "image", "png"), Some(12345));
        assert_eq!(frame_number("image_00a1.png", "image", "png"), None);
        assert_eq!(frame_number("mask_0001.npy", "image", "png"), None);
        assert_eq!(frame_number("image_.png", "image", "png"), None);
        assert_eq!(image(Path::new("d"), 7), Path::new("d/images/image_0007.png"));
    }
}
