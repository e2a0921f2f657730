//! Where to look again for a person the whole-picture detector missed, as a person would look:
//! closer, at overlapping square parts of the picture (the pose detector sees the whole picture
//! letterboxed to 224², where someone small in a landscape or a large picture is a few pixels
//! across), and from a face to the body below it (the detector wants a whole body; an upper-body
//! portrait shows a face and shoulders). Pure geometry; [`crate::person_models`] runs the
//! networks on what it proposes, and the landmarker confirms.

use crate::crop::RotatedRect;
use crate::ssd_detector::Detection;

/// Window sides tried, as fractions of the picture's short side: two or three scales.
const WINDOW_SCALES: [f32; 3] = [1.0, 0.5, 0.25];
/// Windows smaller than this many pixels would only enlarge what the detector already saw.
const MIN_WINDOW: f32 = 128.0;
/// Neighbouring windows overlap by this fraction of their side, so someone cut by one window's
/// edge is whole in the next.
const WINDOW_OVERLAP: f32 = 0.5;

/// A face's box side to the body's proportions, in face-box sides: the hip centre lies about
/// this far below the face's centre (an adult is about ten face boxes tall, the hips near the
/// middle) ...
const HIP_BELOW_FACE: f32 = 4.0;
/// ... and the circle about the hips that holds the whole body, MediaPipe's scale point, this
/// far (hip to the top of the head).
const BODY_RADIUS: f32 = 4.7;
/// Body sizes tried per face, relative to an adult's proportions: children and foreshortened
/// bodies are smaller, faces seen from a distance in a crowd shot vary.
const BODY_SIZES: [f32; 3] = [1.0, 0.8, 1.25];

/// The overlapping square windows to search a `width` × `height` picture in, largest first, left
/// to right and top to bottom. The whole picture's own letterbox (which the detector has already
/// read) is left out.
pub fn windows(width: usize, height: usize) -> Vec<RotatedRect> {
    let (w, h) = (width as f32, height as f32);
    let short = w.min(h);
    let mut out = Vec::new();
    for scale in WINDOW_SCALES {
        let side = short * scale;
        if side < MIN_WINDOW || (scale == 1.0 && width == height) {
            continue;
        }
        for cy in centres(h, side) {
            for cx in centres(w, side) {
                out.push(RotatedRect { cx, cy, width: side, height: side, rotation: 0.0 });
            }
        }
    }
    out
}

/// Evenly spaced centres of windows of `side` covering [0, `length`], neighbours overlapping by
/// at least [`WINDOW_OVERLAP`].
fn centres(length: f32, side: f32) -> Vec<f32> {
    if side >= length {
        return vec![length / 2.0];
    }
    let step = side * (1.0 - WINDOW_OVERLAP);
    let gaps = ((length - side) / step).ceil() as usize;
    (0..=gaps).map(|i| side / 2.0 + i as f32 * (length - side) / gaps as f32).collect()
}

/// Body regions to read the landmarks in for a face BlazeFace found, most likely first: the
/// pose detector's own keypoints (hip centre, scale point) as a body of each of [`BODY_SIZES`]
/// below the face would have them, "down" taken from the face (eyes above the mouth) and
/// snapped to the picture's nearest axis, so a photo turned on its side still works.
pub fn body_seeds(face: &Detection) -> Vec<[[f32; 2]; 2]> {
    let [x0, y0, x1, y1] = face.bbox;
    let centre = [(x0 + x1) / 2.0, (y0 + y1) / 2.0];
    let up = face_up(face);
    let side = face.side();
    BODY_SIZES
        .iter()
        .map(|size| {
            let hip = [
                centre[0] - up[0] * HIP_BELOW_FACE * side * size,
                centre[1] - up[1] * HIP_BELOW_FACE * side * size,
            ];
            let scale =
                [hip[0] + up[0] * BODY_RADIUS * side * size, hip[1] + up[1] * BODY_RADIUS * side * size];
            [hip, scale]
        })
        .collect()
}

/// The face's up direction (mouth to eyes, BlazeFace keypoints 0, 1 and 3), snapped to the
/// nearest of the picture's axes; straight up when the keypoints say nothing.
fn face_up(face: &Detection) -> [f32; 2] {
    let k = &face.keypoints;
    let (dx, dy) = if k.len() >= 4 {
        ((k[0][0] + k[1][0]) / 2.0 - k[3][0], (k[0][1] + k[1][1]) / 2.0 - k[3][1])
    } else {
        (0.0, -1.0)
    };
    match (dx.abs() > dy.abs(), dx > 0.0, dy > 0.0) {
        (true, true, _) => [1.0, 0.0],
        (true, false, _) => [-1.0, 0.0],
        (false, _, true) => [0.0, 1.0],
        _ => [0.0, -1.0],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_cover_a_landscape_picture_with_overlap() {
        let w = windows(1600, 400);
        // Short side 400: windows of 400 (7 across, 200 apart) and 200 (15 × 3); 100 is too small.
        assert_eq!(w.len(), 7 + 15 * 3);
        assert_eq!((w[0].cx, w[0].cy, w[0].width), (200.0, 200.0, 400.0));
        assert_eq!(w[6].cx, 1400.0);
        let last = w.last().unwrap();
        assert_eq!((last.cx, last.cy, last.width), (1500.0, 300.0, 200.0));
    }

    #[test]
    fn a_square_picture_is_not_searched_whole_again() {
        let w = windows(512, 512);
        assert!(w.iter().all(|r| r.width < 512.0));
        assert_eq!(w.len(), 9 + 49);
    }

    #[test]
    fn the_body_hangs_below_an_upright_face_and_beside_a_turned_one() {
        let upright = Detection {
            score: 0.9,
            bbox: [90.0, 90.0, 110.0, 110.0],
            keypoints: vec![[95.0, 96.0], [105.0, 96.0], [100.0, 100.0], [100.0, 105.0]],
        };
        let [hip, scale] = body_seeds(&upright)[0];
        assert_eq!(hip, [100.0, 100.0 + HIP_BELOW_FACE * 20.0]);
        assert!(scale[1] < 100.0, "the scale point lies above the face: {scale:?}");
        // On its side: the eyes to the right of the mouth, the body to the left.
        let turned = Detection {
            keypoints: vec![[104.0, 95.0], [104.0, 105.0], [100.0, 100.0], [95.0, 100.0]],
            ..upright
        };
        let [hip, _] = body_seeds(&turned)[0];
        assert_eq!(hip, [100.0 - HIP_BELOW_FACE * 20.0, 100.0]);
    }
}
