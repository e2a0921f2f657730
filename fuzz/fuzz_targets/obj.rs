//! Arbitrary bytes through the Wavefront `.obj` reader: errors are fine, panics are not, and
//! whatever parses is a valid mesh.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mannequin_mesh::Obj;

fuzz_target!(|data: &[u8]| {
    if let Ok(obj) = Obj::parse(std::path::Path::new("fuzz.obj"), data) {
        assert!(obj.mesh.validate().is_ok());
    }
});
