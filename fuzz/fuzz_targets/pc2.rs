//! Arbitrary bytes through the PC2 vertex-cache reader: errors are fine, panics are not, and
//! whatever parses has frames of equal length.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mannequin_mesh::PointCache;

fuzz_target!(|data: &[u8]| {
    if let Ok(cache) = PointCache::parse(std::path::Path::new("fuzz.pc2"), data) {
        let v = cache.frames.first().map_or(0, Vec::len);
        assert!(cache.frames.iter().all(|f| f.len() == v));
    }
});
