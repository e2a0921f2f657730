//! Arbitrary bytes through the mesh `.ply` reader: errors are fine, panics are not, and whatever
//! parses is a valid mesh.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(ply) = mannequin_mesh::ply::parse(std::path::Path::new("fuzz.ply"), data) {
        assert!(ply.mesh.validate().is_ok());
    }
});
