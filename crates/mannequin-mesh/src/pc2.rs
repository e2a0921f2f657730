//! Point Cache 2 (`.pc2`), the vertex cache Blender's Mesh Cache modifier reads: a 32-byte
//! header (`"POINTCACHE2\0"`, version 1, vertex count, start frame, sampling, frame count), then
//! little-endian f32 x, y, z per vertex per frame.

use std::path::Path;

use crate::MeshFileError;

const MAGIC: &[u8; 12] = b"POINTCACHE2\0";
const HEADER: usize = 32;

/// A vertex cache: `frames` of equally many points, the first at `start` (in frames of the
/// scene), one every `sampling` frames.
#[derive(Debug, Clone, PartialEq)]
pub struct PointCache {
    pub start: f32,
    pub sampling: f32,
    pub frames: Vec<Vec<[f32; 3]>>,
}

impl PointCache {
    /// Writes the cache to `path` atomically.
    pub fn write(&self, path: &Path) -> Result<(), MeshFileError> {
        let vertices = self.frames.first().map_or(0, Vec::len);
        if vertices == 0 {
            return Err(MeshFileError::format(path, "frames", "at least one frame of at least one vertex"));
        }
        if let Some(f) = self.frames.iter().position(|frame| frame.len() != vertices) {
            let expected = format!("{vertices} vertices (as frame 0), found {}", self.frames[f].len());
            return Err(MeshFileError::format(path, format!("frame {f}"), expected));
        }
        if !(self.start.is_finite() && self.sampling.is_finite() && self.sampling > 0.0) {
            let found = format!("found start {} and sampling {}", self.start, self.sampling);
            return Err(MeshFileError::format(
                path,
                "header",
                format!("a finite start and a positive sampling, {found}"),
            ));
        }
        for (f, frame) in self.frames.iter().enumerate() {
            if let Some(v) = frame.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
                return Err(MeshFileError::format(
                    path,
                    format!("frame {f}, vertex {v}"),
                    "finite coordinates",
                ));
            }
        }
        let count = |n: usize, what: &str| {
            i32::try_from(n)
                .map_err(|_| MeshFileError::format(path, what, "at most 2³¹ − 1 (PC2 stores an int32)"))
        };
        let (vertex_count, frame_count) =
            (count(vertices, "vertex count")?, count(self.frames.len(), "frame count")?);
        let mut bytes = Vec::with_capacity(HEADER + 12 * vertices * self.frames.len());
        bytes.extend_from_slice(MAGIC);
        bytes.extend_from_slice(&1i32.to_le_bytes());
        bytes.extend_from_slice(&vertex_count.to_le_bytes());
        bytes.extend_from_slice(&self.start.to_le_bytes());
        bytes.extend_from_slice(&self.sampling.to_le_bytes());
        bytes.extend_from_slice(&frame_count.to_le_bytes());
        bytes.extend(self.frames.iter().flatten().flatten().flat_map(|c| c.to_le_bytes()));
        mannequin_io::write_atomic(path, &bytes).map_err(|e| MeshFileError::io(path, e))
    }

    /// Reads a cache, checking the header against the file's length.
    pub fn read(path: &Path) -> Result<Self, MeshFileError> {
        let bytes = std::fs::read(path).map_err(|e| MeshFileError::io(path, e))?;
        Self::parse(path, &bytes)
    }

    /// Parses the bytes of a cache read from `path` (named in errors).
    pub fn parse(path: &Path, bytes: &[u8]) -> Result<Self, MeshFileError> {
        let fail = |at: &str, expected: String| MeshFileError::format(path, at, expected);
        if bytes.len() < HEADER || &bytes[..12] != MAGIC {
            return Err(fail("header", "a 32-byte header starting \"POINTCACHE2\\0\"".into()));
        }
        let word = |o: usize| -> [u8; 4] { bytes[o..o + 4].try_into().expect("4 bytes inside the header") };
        let version = i32::from_le_bytes(word(12));
        if version != 1 {
            return Err(fail("version", format!("1, found {version}")));
        }
        let (vertices, frames) = (i32::from_le_bytes(word(16)), i32::from_le_bytes(word(28)));
        let (start, sampling) = (f32::from_le_bytes(word(20)), f32::from_le_bytes(word(24)));
        let (Ok(v @ 1..), Ok(f)) = (usize::try_from(vertices), usize::try_from(frames)) else {
            let found = format!("found {vertices} vertices, {frames} frames");
            return Err(fail("counts", format!("at least one vertex and no negative count, {found}")));
        };
        let body = v.checked_mul(f).and_then(|n| n.checked_mul(12));
        if body != Some(bytes.len() - HEADER) {
            let found = bytes.len() - HEADER;
            return Err(fail("data", format!("{v} vertices × {f} frames × 12 bytes, found {found} bytes")));
        }
        let points: Vec<[f32; 3]> = bytes[HEADER..]
            .chunks_exact(12)
            .map(|p| {
                std::array::from_fn(|d| f32::from_le_bytes(p[4 * d..4 * d + 4].try_into().expect("4 bytes")))
            })
            .collect();
        let frames = points.chunks(v).map(<[_]>::to_vec).collect();
        Ok(Self { start, sampling, frames })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The header bytes written by hand from the format's description, then the points.
    #[test]
    fn writes_the_documented_layout() {
        let path = std::env::temp_dir().join(format!("mq-pc2-{}.pc2", std::process::id()));
        let cache = PointCache {
            start: 1.0,
            sampling: 0.5,
            frames: vec![vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]], vec![[7.0, 8.0, 9.0], [10.0, 11.0, 12.0]]],
        };
        cache.write(&path).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let mut want = b"POINTCACHE2\0".to_vec();
        want.extend([1, 0, 0, 0, 2, 0, 0, 0]); // version 1, 2 vertices
        want.extend([0x00, 0x00, 0x80, 0x3f, 0x00, 0x00, 0x00, 0x3f]); // 1.0f, 0.5f
        want.extend([2, 0, 0, 0]); // 2 frames
        want.extend([0x00, 0x00, 0x80, 0x3f]); // frame 0, vertex 0, x = 1.0f
        assert_eq!(&bytes[..36], &want[..]);
        assert_eq!(bytes.len(), 32 + 2 * 2 * 12);
        assert_eq!(PointCache::read(&path).unwrap(), cache);
        std::fs::write(&path, &bytes[..bytes.len() - 4]).unwrap();
        let e = PointCache::read(&path).unwrap_err().to_string();
        assert!(e.contains("2 vertices × 2 frames × 12 bytes, found 44 bytes"), "{e}");
        // No vertices and 2³¹ − 1 frames would be an empty body with a huge list to make.
        let mut empty = bytes[..32].to_vec();
        empty[16..20].copy_from_slice(&0i32.to_le_bytes());
        empty[28..32].copy_from_slice(&i32::MAX.to_le_bytes());
        std::fs::write(&path, &empty).unwrap();
        let e = PointCache::read(&path).unwrap_err().to_string();
        assert!(e.contains("at least one vertex"), "{e}");
        std::fs::remove_file(&path).unwrap();
    }

    #[test]
    fn non_finite_numbers_are_not_written() {
        let path = std::env::temp_dir().join(format!("mq-pc2-nan-{}.pc2", std::process::id()));
        let mut cache = PointCache { start: 0.0, sampling: 1.0, frames: vec![vec![[0.0; 3]; 2]; 3] };
        cache.frames[2][1][0] = f32::NAN;
        let e = cache.write(&path).unwrap_err().to_string();
        assert_eq!(e, format!("{}: frame 2, vertex 1: finite coordinates", path.display()));
        cache.frames[2][1][0] = 0.0;
        cache.sampling = f32::INFINITY;
        let e = cache.write(&path).unwrap_err().to_string();
        assert!(
            e.ends_with("header: a finite start and a positive sampling, found start 0 and sampling inf"),
            "{e}"
        );
        assert!(!path.exists());
    }
}
