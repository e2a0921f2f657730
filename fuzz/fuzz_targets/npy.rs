//! Arbitrary bytes through the `.npy` reader directly (inside an archive, checksums would stop
//! most of them before the header parser): errors are fine, panics are not.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(array) = mannequin_io::npy::parse_npy(data) {
        assert_eq!(array.len(), array.to_f64().map_or(array.len(), |v| v.len()));
    }
});
