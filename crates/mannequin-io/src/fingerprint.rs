//! Stable hashes of inputs, so a checkpoint can refuse to resume on changed data: the FNV-1a
//! hash, and the fingerprint of a dataset that a training checkpoint records (what it holds is
//! computed where datasets are read, in `mannequin-data`).

use serde::{Deserialize, Serialize};

/// What a training checkpoint records of its dataset. Every file of the layout is listed with its
/// size; the cameras and the split's poses, which change the result without changing any size,
/// are hashed by value.
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
pub struct Fnv(u64);

impl Default for Fnv {
    fn default() -> Self {
        Self::new()
    }
}

impl Fnv {
    pub fn new() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }

    pub fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }

    /// `x` as its 8 little-endian bytes.
    pub fn u64(&mut self, x: u64) {
        self.bytes(&x.to_le_bytes());
    }

    /// Each value's bits, as [`Fnv::u64`].
    pub fn f64s(&mut self, values: impl IntoIterator<Item = f64>) {
        for x in values {
            self.u64(x.to_bits());
        }
    }

    /// The hash so far as 16 hex digits.
    pub fn hex(&self) -> String {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv_matches_the_published_test_vectors() {
        assert_eq!(hash_bytes(b""), "cbf29ce484222325");
        assert_eq!(hash_bytes(b"a"), "af63dc4c8601ec8c");
        assert_eq!(hash_bytes(b"foobar"), "85944171f73967e8");
    }

    /// The serialised form is stored in training checkpoints: its field names must not change.
    #[test]
    fn serialises_under_the_names_checkpoints_hold() {
        let f =
            Fingerprint { files: 3, bytes: 42, listing: "a".into(), cameras: "b".into(), poses: "c".into() };
        let json = serde_json::to_string(&f).unwrap();
        assert_eq!(json, r#"{"files":3,"bytes":42,"listing":"a","cameras":"b","poses":"c"}"#);
    }
}
