//! A dataset's fingerprint ([`Fingerprint`], hashed with `mannequin_io`'s FNV-1a): what a
//! training checkpoint records so that resuming on changed data is refused. Every file of the
//! layout is listed with its size; the cameras and the split's poses, which change the result
//! without changing any size, are hashed by value (not by file bytes, which hold zip timestamps).
//! Images are not read: the check must come before the slow loading, so an image rewritten in
//! place at the same size goes unnoticed.

use std::path::Path;

use mannequin_io::fingerprint::{Fingerprint, Fnv};

use crate::dataset::{Cameras, Dataset, Split};
use crate::error::DataError;
use crate::layout;

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

impl Dataset {
    /// The fingerprint of this dataset trained on `split`.
    pub fn fingerprint(&self, split: &Split) -> Result<Fingerprint, DataError> {
        let root = &self.root;
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

        Ok(Fingerprint {
            files: files.len(),
            bytes: files.iter().map(|(_, size)| size).sum(),
            listing: listing.hex(),
            cameras: cameras.hex(),
            poses: poses.hex(),
        })
    }
}
