//! Arbitrary bytes through the camera JSON reader: errors are fine, panics are not, and whatever
//! parses is a camera the renderer accepts.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok((camera, _)) = mannequin_splat::parse_camera_json(std::path::Path::new("fuzz.json"), data) {
        assert!(camera.validate().is_ok());
    }
});
