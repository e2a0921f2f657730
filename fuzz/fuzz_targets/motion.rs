//! Arbitrary bytes through the motion reader (AMASS or PeopleSnapshot `.npz`) and what every
//! caller does next, resampling and posing: errors are fine, panics are not.
#![no_main]

use libfuzzer_sys::fuzz_target;
use mannequin_body::Motion;
use mannequin_io::Npz;

fuzz_target!(|data: &[u8]| {
    let Ok(npz) = Npz::from_bytes("fuzz.npz".into(), data) else { return };
    if let Ok(motion) = Motion::from_npz(&npz) {
        let _ = motion.resample(30.0);
        let _ = motion.frame_pose(0, 24);
    }
});
