//! A dataset's fingerprint: what a training checkpoint records so that resuming on changed data
//! is refused. Every file of the layout is listed with its size; the cameras and the split's
//! poses, which change the result without changing any size, are hashed by value (not by file
//! bytes, which hold zip timestamps). Images are not read: the check must come before the slow
//! loading, so an image rewritten in place at the same size goes unnoticed.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::dataset::{Cameras, Dataset, Split};
use crate::error::DataError;
use crate::layout;

#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Fingerprint {
    /// Files of the layout (images, masks, normals, depth, meshes, poses, cameras, splits).
    pub files: usize,
    /// Their total size.
    pub bytes: u64,
    /// Hash of every such file's path (relative to the dataset) and size.
    pub listing: String,
    /// Hash of every camera's size, intrinsics and extrinsics, at the stored resolution.
    pub cameras: String,
    /// Hash of the split's frame numbers, shape and poses.
    pub poses: String,
}

/// 64-bit FNV-1a: a stable hash (the same on every run and platform, unlike std's `Hasher`s),
/// ample for telling changed inputs apart.
struct Fnv(u64);

impl Fnv {
    fn new() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }

    fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }

    fn u64(&mut self, x: u64) {
        self.bytes(&x.to_le_bytes());
    }

    fn f64s(&mut self, values: impl IntoIterator<Item = f64>) {
        for x in values {
            self.u64(x.to_bits());
        }
    }

    fn hex(&self) -> String {
        format!("{:016x}", self.0)
    }
}

/// The FNV-1a hash of `bytes` as 16 hex digits: how a checkpoint tells an edited input file from
/// the one its run read.
pub fn hash_bytes(bytes: &[u8]) -> String {
    let mut h = Fnv::new();
    h.bytes(bytes);
    h.hex()
}

/// Every file under `dir` (recursively) as (path relative to `root` with `/` separators, size),
/// appended to `out`. A missing `dir` adds nothing.
fn list_files(root: &Path, dir: &Path, out: &mut Vec<(String, u64)>) -> Result<(), DataError> {
    if !dir.exists() {
        return Ok(());
    }
    let meta = std::fs::metadata(dir).map_err(|e| DataError::os(dir, e))?;
    if meta.is_file() {
        let relative = dir.strip_prefix(root).unwrap_or(dir);
        let name: Vec<_> = relative.components().map(|c| c.as_os_str().to_string_lossy()).collect();
        out.push((name.join("/"), meta.len()));
        return Ok(());
    }
    for entry in std::fs::read_dir(dir).map_err(|e| DataError::os(dir, e))? {
        list_files(root, &entry.map_err(|e| DataError::os(dir, e))?.path(), out)?;
    }
    Ok(())
}

impl Fingerprint {
    /// The fingerprint of `dataset` trained on `split`.
    pub fn of(dataset: &Dataset, split: &Split) -> Result<Self, DataError> {
        let root = &dataset.root;
        let mut files = Vec::new();
        for name in [
            layout::CAMERAS,
            layout::SPLITS,
            layout::ALL_POSES,
            layout::IMAGES,
            layout::MASKS,
            layout::NORMALS,
            layout::DEPTH,
            layout::MESHES,
            layout::POSES,
        ] {
            list_files(root, &root.join(name), &mut files)?;
        }
        files.sort();
        let mut listing = Fnv::new();
        for (name, size) in &files {
            listing.u64(name.len() as u64);
            listing.bytes(name.as_bytes());
            listing.u64(*size);
        }

        // As stored: the downscale factor is a setting of its own.
        let native = Cameras::read(&root.join(layout::CAMERAS))?;
        let mut cameras = Fnv::new();
        let all = match &native {
            Cameras::Static(c) => std::slice::from_ref(c),
            Cameras::PerFrame(v) => v.as_slice(),
        };
        cameras.u64(all.len() as u64);
        for c in all {
            cameras.u64(c.width as u64);
            cameras.u64(c.height as u64);
            cameras.f64s(c.intrinsic.iter().flatten().copied());
            cameras.f64s(c.extrinsic.iter().flatten().copied());
        }

        let mut poses = Fnv::new();
        let p = &split.poses;
        for part in [split.frames.len(), p.betas.len(), p.len()] {
            poses.u64(part as u64);
        }
        for &f in &split.frames {
            poses.u64(f as u64);
        }
        let values = p.betas.iter().chain(p.global_orient.iter().flatten());
        poses.f64s(values.chain(&p.body_pose).chain(p.transl.iter().flatten()).map(|&x| x as f64));

        Ok(Self {
            files: files.len(),
            bytes: files.iter().map(|(_, size)| size).sum(),
            listing: listing.hex(),
            cameras: cameras.hex(),
            poses: poses.hex(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv_matches_the_published_test_vectors() {
        let hash = |s: &str| {
            let mut h = Fnv::new();
            h.bytes(s.as_bytes());
            h.hex()
        };
        assert_eq!(hash(""), "cbf29ce484222325");
        assert_eq!(hash("a"), "af63dc4c8601ec8c");
        assert_eq!(hash("foobar"), "85944171f73967e8");
    }
}
