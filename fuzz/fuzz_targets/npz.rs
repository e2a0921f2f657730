//! Arbitrary bytes through the `.npz` reader and the body-model parser: errors are fine, panics
//! are not.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mannequin_io::Npz;

fuzz_target!(|data: &[u8]| {
    if let Ok(npz) = Npz::from_bytes("fuzz.npz".into(), data) {
        let _ = mannequin_body::parse_model(&npz, None);
    }
});
