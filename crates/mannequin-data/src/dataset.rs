//! Reading a dataset folder in the PeopleSnapshot preprocessed layout (see
//! `docs/dataset-format.md`). Opening checks the structure (cameras, frame numbering, masks,
//! pose counts); frames are loaded on demand, downscaled if asked.

use std::path::{Path, PathBuf};

use mannequin_io::Npz;
use mannequin_mesh::ply::{self, PlyMesh};

use crate::Camera;
use crate::error::DataError;
use crate::frame_files::{ImageFiles, list_frame_files};
use crate::image::{Image, Mask};
use crate::layout;
use crate::maps::{DepthMap, NormalMap, read_mask_npy};
use crate::origin::Origin;
use crate::poses::Poses;
use crate::splits::{SplitRange, Splits, read_splits_json, standard_splits};

/// One camera for the whole capture (PeopleSnapshot), or one per frame (novel-view sets).
#[allow(clippy::large_enum_variant)] // one per dataset: boxing the single camera would buy nothing
#[derive(Debug, Clone, PartialEq)]
pub enum Cameras {
    Static(Camera),
    PerFrame(Vec<Camera>),
}

impl Cameras {
    pub fn get(&self, frame: usize) -> &Camera {
        match self {
            Self::Static(c) => c,
            Self::PerFrame(v) => &v[frame],
        }
    }

    pub fn downscale(&self, factor: usize) -> Self {
        match self {
            Self::Static(c) => Self::Static(c.downscale(factor)),
            Self::PerFrame(v) => Self::PerFrame(v.iter().map(|c| c.downscale(factor)).collect()),
        }
    }

    /// Reads `intrinsic (3,3)|(N,3,3)`, `extrinsic (4,4)|(N,4,4)`, and scalar `height`, `width`.
    pub fn read(path: &Path) -> Result<Self, DataError> {
        let npz = Npz::read(path)?;
        let scalar = |key: &str| -> Result<usize, DataError> {
            let a = npz.require(key)?;
            match a.to_f64().as_deref() {
                Some(&[v]) if v >= 1.0 && v.fract() == 0.0 => Ok(v as usize),
                _ => Err(npz
                    .field_error(
                        key,
                        format!("expected one positive whole number, found shape {:?}", a.shape),
                    )
                    .into()),
            }
        };
        let (height, width) = (scalar("height")?, scalar("width")?);
        let k_shape = npz.require("intrinsic")?.shape.clone();
        let e_shape = npz.require("extrinsic")?.shape.clone();
        let (_, k) = npz.f64_with_shape("intrinsic", &vec![None; k_shape.len()])?;
        let (_, e) = npz.f64_with_shape("extrinsic", &vec![None; e_shape.len()])?;
        let camera = |k: &[f64], e: &[f64]| {
            Camera::new(
                width,
                height,
                std::array::from_fn(|r| std::array::from_fn(|c| k[3 * r + c])),
                std::array::from_fn(|r| std::array::from_fn(|c| e[4 * r + c])),
            )
        };
        let cameras = match (k_shape.as_slice(), e_shape.as_slice()) {
            ([3, 3], [4, 4]) => Self::Static(camera(&k, &e)),
            ([n, 3, 3], [m, 4, 4]) if n == m => {
                Self::PerFrame(k.chunks_exact(9).zip(e.chunks_exact(16)).map(|(k, e)| camera(k, e)).collect())
            }
            ([3, 3], [_, 4, 4]) => Self::PerFrame(e.chunks_exact(16).map(|e| camera(&k, e)).collect()),
            _ => {
                return Err(DataError::file(
                    path,
                    format!(
                        "expected intrinsic (3,3) or (N,3,3) and extrinsic (4,4) or (N,4,4), found {k_shape:?} and {e_shape:?}"
                    ),
                ));
            }
        };
        let all = match &cameras {
            Self::Static(c) => std::slice::from_ref(c),
            Self::PerFrame(v) => v.as_slice(),
        };
        for (i, c) in all.iter().enumerate() {
            c.validate().map_err(|e| {
                let which = if all.len() > 1 { format!("camera {i}: ") } else { String::new() };
                DataError::file(path, format!("{which}{e}"))
            })?;
        }
        Ok(cameras)
    }
}

/// Everything stored for one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    pub index: usize,
    pub image: Image,
    pub mask: Mask,
    pub normals: Option<NormalMap>,
    pub depth: Option<DepthMap>,
}

/// A split's frame numbers and the SMPL parameters of each.
#[derive(Debug, Clone, PartialEq)]
pub struct Split {
    pub name: String,
    pub frames: Vec<usize>,
    pub poses: Poses,
}

#[derive(Debug, Clone)]
pub struct Dataset {
    pub root: PathBuf,
    /// Cameras at the loaded resolution.
    pub cameras: Cameras,
    /// Images on disk are `frame_count` files numbered 0..frame_count.
    pub frame_count: usize,
    pub splits: Splits,
    pub downscale: usize,
    pub has_normals: bool,
    pub has_depth: bool,
    pub has_meshes: bool,
    /// Where the poses came from, where the dataset says (`origin.json`).
    pub origin: Option<Origin>,
    native: Camera,
    /// The extension the images share (`png`, `jpg` or `jpeg`).
    image_ext: &'static str,
}

/// The first number missing from `0..` in a sorted list, if the list is not exactly `0..len`.
fn first_gap(frames: &[usize]) -> Option<usize> {
    frames.iter().enumerate().find(|&(i, &f)| i != f).map(|(i, _)| i)
}

impl Dataset {
    /// Opens `root`, checking its structure. `downscale` ≥ 1 divides the image size (2 turns
    /// PeopleSnapshot's 1080² into 540²) and scales the intrinsics with it.
    pub fn open(root: impl AsRef<Path>, downscale: usize) -> Result<Self, DataError> {
        let root = root.as_ref().to_path_buf();
        if downscale == 0 {
            return Err(DataError::Invalid("the downscale factor must be at least 1".into()));
        }
        let cameras_path = root.join(layout::CAMERAS);
        let cameras = Cameras::read(&cameras_path)?;
        let images = ImageFiles::list(&root)?;
        if images.frames.is_empty() {
            return Err(DataError::file(
                root.join(layout::IMAGES),
                format!("no image_NNNN.{} files", layout::IMAGE_EXTENSIONS.join("|")),
            ));
        }
        if let Some(gap) = first_gap(&images.frames) {
            return Err(DataError::file(
                images.path(&root, gap),
                format!(
                    "missing frame: images must be numbered 0..{} without gaps",
                    images.frames.last().unwrap_or(&0)
                ),
            ));
        }
        let frame_count = images.frames.len();
        let masks: Vec<usize> =
            list_frame_files(&root, layout::MASKS, "mask", &["npy"])?.into_iter().map(|(n, _)| n).collect();
        if let Some(gap) = first_gap(&masks).or((masks.len() < frame_count).then_some(masks.len())) {
            return Err(DataError::file(layout::mask(&root, gap), format!("missing mask for image {gap}")));
        }
        if masks.len() != frame_count {
            return Err(DataError::file(
                root.join(layout::MASKS),
                format!(
                    "{} masks for {frame_count} images (extra: {})",
                    masks.len(),
                    layout::mask(&root, frame_count).display()
                ),
            ));
        }
        if let Cameras::PerFrame(v) = &cameras
            && v.len() != frame_count
        {
            return Err(DataError::file(
                cameras_path,
                format!("{} per-frame cameras for {frame_count} images", v.len()),
            ));
        }
        let splits_path = root.join(layout::SPLITS);
        let splits = if splits_path.exists() {
            read_splits_json(&splits_path)?
        } else {
            let subject = root.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
            standard_splits(&subject).unwrap_or_else(|| {
                // Without a split table, every split file covers all frames in order.
                let all = SplitRange::new(0, frame_count - 1, 1);
                ["train", "val", "test"]
                    .into_iter()
                    .filter(|s| layout::split_poses(&root, s).exists())
                    .map(|s| (s.to_string(), all))
                    .collect()
            })
        };
        for (name, range) in &splits {
            if let Some(last) = Some(range.last()).filter(|&f| f >= frame_count) {
                return Err(DataError::file(
                    images.path(&root, last),
                    format!(
                        "missing frame: split '{name}' needs frames up to {last}, found {frame_count} images"
                    ),
                ));
            }
        }
        let native = cameras.get(0).clone();
        Ok(Self {
            cameras: if downscale > 1 { cameras.downscale(downscale) } else { cameras },
            frame_count,
            splits,
            downscale,
            has_normals: root.join(layout::NORMALS).is_dir(),
            has_depth: root.join(layout::DEPTH).is_dir(),
            has_meshes: root.join(layout::MESHES).is_dir(),
            origin: Origin::read(&root)?,
            native,
            image_ext: images.ext,
            root,
        })
    }

    /// The image file of `frame`.
    pub fn image_path(&self, frame: usize) -> PathBuf {
        layout::image_file(&self.root, frame, self.image_ext)
    }

    pub fn camera(&self, frame: usize) -> &Camera {
        self.cameras.get(frame)
    }

    /// The split's frames and poses, from `poses/anim_nerf_<name>.npz` or else `poses.npz`
    /// sliced by the split's range. Counts must agree.
    pub fn split(&self, name: &str) -> Result<Split, DataError> {
        let range = self.splits.get(name).ok_or_else(|| {
            let known: Vec<&str> = self.splits.keys().map(String::as_str).collect();
            DataError::file(&self.root, format!("no split '{name}' (known: {})", known.join(", ")))
        })?;
        let frames = range.frames();
        let per_split = layout::split_poses(&self.root, name);
        let all = self.root.join(layout::ALL_POSES);
        let (path, poses) = if per_split.exists() {
            (per_split.clone(), Poses::read(&per_split)?)
        } else if all.exists() {
            let poses = Poses::read(&all)?;
            if poses.len() != self.frame_count {
                return Err(DataError::file(
                    &all,
                    format!("{} poses for {} images", poses.len(), self.frame_count),
                ));
            }
            (all.clone(), poses.select(&frames))
        } else {
            return Err(DataError::file(
                per_split,
                format!("missing poses for split '{name}' (nor is there {})", all.display()),
            ));
        };
        if poses.len() != frames.len() {
            return Err(DataError::file(
                path,
                format!(
                    "{} poses, but split '{name}' ({}–{} step {}) has {} frames",
                    poses.len(),
                    range.start,
                    range.end,
                    range.step,
                    frames.len()
                ),
            ));
        }
        Ok(Split { name: name.to_string(), frames, poses })
    }

    /// Loads one frame at the dataset's resolution, checking every size against the camera.
    pub fn frame(&self, index: usize) -> Result<Frame, DataError> {
        if index >= self.frame_count {
            return Err(DataError::file(
                self.image_path(index),
                format!("missing frame: there are {} images", self.frame_count),
            ));
        }
        let (w, h) = (self.native.width, self.native.height);
        let size_error = |path: PathBuf, what: &str, fw: usize, fh: usize| {
            DataError::file(path, format!("{what} is {fw}×{fh} but cameras.npz says {w}×{h}"))
        };
        let image_path = self.image_path(index);
        let image = Image::read(&image_path)?;
        if (image.width, image.height) != (w, h) {
            return Err(size_error(image_path, "image", image.width, image.height));
        }
        let mask_path = layout::mask(&self.root, index);
        let mask = read_mask_npy(&mask_path)?;
        if (mask.width, mask.height) != (w, h) {
            return Err(size_error(mask_path, "mask", mask.width, mask.height));
        }
        let normals = if self.has_normals {
            let path = layout::normal(&self.root, index);
            let n = NormalMap::read_png(&path)?;
            if (n.width, n.height) != (w, h) {
                return Err(size_error(path, "normal map", n.width, n.height));
            }
            Some(n)
        } else {
            None
        };
        let depth = if self.has_depth {
            let path = layout::depth(&self.root, index);
            let d = DepthMap::read_npy(&path)?;
            if (d.width, d.height) != (w, h) {
                return Err(size_error(path, "depth map", d.width, d.height));
            }
            Some(d)
        } else {
            None
        };
        let f = self.downscale;
        if f == 1 {
            return Ok(Frame { index, image, mask, normals, depth });
        }
        Ok(Frame {
            index,
            image: image.downscale(f),
            mask: mask.downscale(f),
            normals: normals.map(|n| n.downscale(f)),
            depth: depth.map(|d| d.downscale(f)),
        })
    }

    /// The ground-truth mesh of a frame, in world coordinates, where the dataset has one.
    pub fn mesh(&self, index: usize) -> Result<Option<PlyMesh>, DataError> {
        if !self.has_meshes {
            return Ok(None);
        }
        Ok(Some(ply::read(layout::mesh(&self.root, index))?))
    }
}
