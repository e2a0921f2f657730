//! Arbitrary bytes through the 3DGS `.ply` reader: errors are fine, panics are not, and whatever
//! parses has array lengths the renderer accepts.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mannequin_splat::SplatScene;

fuzz_target!(|data: &[u8]| {
    if let Ok(scene) = SplatScene::from_ply_bytes(std::path::Path::new("fuzz.ply"), data) {
        assert!(scene.gaussians().validate_shapes().is_ok());
    }
});
