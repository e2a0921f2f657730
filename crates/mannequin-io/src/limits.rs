//! The largest inputs Mannequin accepts, in one place (listed with their reasons in
//! `docs/limits.md`). A size read from a file header or a flag is checked against these before
//! anything is allocated for it, so a few bytes claiming gigabytes are refused rather than
//! obeyed (issue 42: peak memory within 1 GB for any input under 10 MB).

/// Elements in one array of an `.npz` archive. SMPL-X's pose blend shapes, the largest array a
/// real model file holds, have 15.3 million.
pub const MAX_ARRAY_ELEMENTS: usize = 1 << 25;

/// Elements in all the arrays of one `.npz` archive together (SMPL-X holds about 29 million).
pub const MAX_ARCHIVE_ELEMENTS: usize = 1 << 26;

/// Pixels in one image, camera or render: 4096² (a 16-megapixel photo; a 4K video frame has
/// 8.3 million). Each pixel costs tens of bytes in the renderers' buffers.
pub const MAX_IMAGE_PIXELS: usize = 4096 * 4096;

/// Longest image or camera side, in pixels (a panorama's width within [`MAX_IMAGE_PIXELS`]).
pub const MAX_IMAGE_SIDE: usize = 16384;

/// Refuses an image or camera size past [`MAX_IMAGE_SIDE`] or [`MAX_IMAGE_PIXELS`], in the words
/// every reader of a size uses.
pub fn check_image_size(width: usize, height: usize) -> Result<(), String> {
    if width.max(height) > MAX_IMAGE_SIDE || width.saturating_mul(height) > MAX_IMAGE_PIXELS {
        return Err(format!(
            "image size {width}×{height}: expected at most {MAX_IMAGE_SIDE} a side and {MAX_IMAGE_PIXELS} pixels"
        ));
    }
    Ok(())
}

/// Frames in one motion file: 100,000 is 55 minutes at 30 fps (AMASS's longest takes are a few
/// minutes at 120 fps).
pub const MAX_MOTION_FRAMES: usize = 100_000;

/// Largest shape coefficient, in standard deviations of the body model's shape space. SMPL's
/// shapes stay human within ±3; beyond ±10 a body is not a person.
pub const MAX_BETA: f64 = 10.0;

/// Focal length range in pixels, as a multiple of the image's longer side: 0.01 sees nearly a
/// hemisphere, 1000 a field of view of 0.06°.
pub const FOCAL_RANGE_PER_SIDE: (f64, f64) = (0.01, 1000.0);

/// Farthest a principal point may lie from the image, in image sides (a crop moves it off
/// centre, but not by kilometres of pixels).
pub const MAX_PRINCIPAL_OFFSET_SIDES: f64 = 4.0;

/// Largest translation, in metres, of a body or a camera from the world origin: a capture
/// happens in a room, not in orbit.
pub const MAX_DISTANCE: f64 = 1000.0;

/// Every value a float32 holds: an array read as float64 and computed in float32 is held to
/// this, so nothing overflows to an infinity on the way in.
pub const FLOAT32: std::ops::RangeInclusive<f64> = -(f32::MAX as f64)..=f32::MAX as f64;

/// Surface samples per mesh for the geometry metrics (`eval --samples`): a million points and
/// their k-d trees stay well under a gigabyte, and Chamfer distances settle to 0.01 cm long
/// before.
pub const MAX_SURFACE_SAMPLES: usize = 1_000_000;
