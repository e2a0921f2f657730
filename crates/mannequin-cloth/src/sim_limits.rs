//! Limits on what a simulating command (`cloth simulate`, `dress`) is asked to do, checked when
//! its flags are parsed or before anything is allocated for them (issue 42: `--settle inf` once
//! grew to 24 GB).

use mannequin_body::settling::MAX_SETTLE_SECONDS;
use mannequin_mesh::gltf::MAX_MORPH_FRAMES;

use crate::settings::SUBSTEPS;
use crate::simulate_error::SimulateError;

/// Most solver substeps per frame: the default is [`SUBSTEPS`], and past 100 a frame costs seconds
/// without draping differently.
pub const MAX_SUBSTEPS: u32 = 100;
const _: () = assert!(SUBSTEPS <= MAX_SUBSTEPS);

/// Most vertex positions a run holds over all its frames (frames × vertices, of the body and
/// of every garment it keeps): 10 million positions are 120 MB a copy, and writing the outputs
/// takes a few copies.
pub const MAX_KEPT_POSITIONS: usize = 10_000_000;

/// `--settle`: seconds, finite, from 0 to [`MAX_SETTLE_SECONDS`].
pub fn parse_settle(text: &str) -> Result<f32, String> {
    let seconds: f32 = text.parse().map_err(|e| format!("{e}"))?;
    if (0.0..=MAX_SETTLE_SECONDS).contains(&seconds) {
        Ok(seconds)
    } else {
        Err(format!("{seconds}: expected 0 to {MAX_SETTLE_SECONDS} seconds"))
    }
}

/// Refuses a run that would hold `frames` frames of `vertices` positions past
/// [`MAX_KEPT_POSITIONS`], or play more frames than a `.glb` point cache holds
/// ([`MAX_MORPH_FRAMES`]), naming the motion and how to shorten it: before any simulating, not
/// when the scene is written after it.
pub fn check_kept_positions(
    motion: &std::path::Path,
    frames: usize,
    vertices: usize,
) -> Result<(), SimulateError> {
    if frames > MAX_MORPH_FRAMES {
        return Err(SimulateError::invalid(
            motion.display().to_string(),
            format!(
                "{frames} frames; the scene's point cache holds at most {MAX_MORPH_FRAMES}: \
                 shorten the clip with --max-frames or --settle"
            ),
        ));
    }
    let kept = frames.saturating_mul(vertices);
    if kept > MAX_KEPT_POSITIONS {
        return Err(SimulateError::invalid(
            motion.display().to_string(),
            format!(
                "{frames} frames of {vertices} vertices are {kept} positions to keep; \
                 expected at most {MAX_KEPT_POSITIONS}: shorten the clip with --max-frames or --settle"
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settle_is_finite_and_bounded() {
        assert_eq!(parse_settle("0.5"), Ok(0.5));
        assert_eq!(parse_settle("10"), Ok(10.0));
        for bad in ["inf", "NaN", "-1", "1e5", "10.5"] {
            assert!(parse_settle(bad).unwrap_err().contains("expected 0 to 10 seconds"), "{bad}");
        }
        assert!(parse_settle("x").is_err());
    }

    #[test]
    fn a_run_is_held_to_the_positions_it_keeps_and_the_frames_a_scene_holds() {
        let walk = std::path::Path::new("walk.npz");
        assert!(check_kept_positions(walk, MAX_MORPH_FRAMES, 100).is_ok());
        let e = check_kept_positions(walk, MAX_MORPH_FRAMES + 1, 1).unwrap_err().to_string();
        assert!(e.starts_with("walk.npz: 4097 frames") && e.contains("--max-frames"), "{e}");
        let e = check_kept_positions(walk, 1000, 20_000).unwrap_err().to_string();
        assert!(e.contains("20000000 positions"), "{e}");
    }
}
