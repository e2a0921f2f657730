//! The picture a user checks a fit by: the photo with the fitted body shaded over it, the
//! detected landmarks (green) joined by their skeleton, and the body's anchors reprojected by
//! the fitted camera (red), each tied to its detection by a thin line.

use mannequin_data::Image;
use mannequin_raster::Raster;

use crate::blazepose::BONES;

const BODY: [f32; 3] = [0.55, 0.72, 0.98];
const BODY_OPACITY: f32 = 0.55;
const DETECTED: [f32; 3] = [0.1, 0.95, 0.2];
const REPROJECTED: [f32; 3] = [1.0, 0.15, 0.1];
/// The face overlay's mesh edges, blended over the photo so the face stays visible.
const EDGE_OPACITY: f32 = 0.3;

/// The overlay for one fit. `confident[i]` says whether landmark i took part.
pub fn overlay(
    photo: &Image,
    body: &Raster,
    detected: &[[f32; 3]],
    confident: &[bool],
    reprojected: &[Option<[f32; 2]>],
) -> Image {
    let mut out = photo.clone();
    for (i, px) in out.pixels.iter_mut().enumerate() {
        if body.mask.values[i] {
            let n = body.normals.normals[i];
            let shade = 0.35 + 0.65 * n[2].abs();
            *px = std::array::from_fn(|c| px[c] * (1.0 - BODY_OPACITY) + BODY[c] * shade * BODY_OPACITY);
        }
    }
    let radius = (photo.width.max(photo.height) as f32 / 250.0).max(2.0);
    for &(a, b) in &BONES {
        if confident[a] && confident[b] {
            line(
                &mut out,
                [detected[a][0], detected[a][1]],
                [detected[b][0], detected[b][1]],
                DETECTED,
                radius / 3.0,
            );
        }
    }
    for (i, p) in detected.iter().enumerate() {
        if !confident[i] {
            continue;
        }
        if let Some(r) = reprojected[i] {
            line(&mut out, [p[0], p[1]], r, REPROJECTED, radius / 4.0);
            disc(&mut out, r, radius, REPROJECTED);
        }
        disc(&mut out, [p[0], p[1]], radius, DETECTED);
    }
    out
}

/// The overlay for a face fit: the fitted head's camera-facing edges (thin, blue), the detected
/// face-mesh points (green) and the model's points reprojected (red).
pub fn face_overlay(
    photo: &Image,
    detected: &[[f32; 3]],
    reprojected: &[[f32; 2]],
    edges: &[[[f32; 2]; 2]],
) -> Image {
    let mut out = photo.clone();
    let mut covered = vec![false; photo.width * photo.height];
    for [a, b] in edges {
        let steps = (b[0] - a[0]).hypot(b[1] - a[1]).ceil().max(1.0) as usize;
        for s in 0..=steps {
            let t = s as f32 / steps as f32;
            let (x, y) = (a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]));
            if x >= 0.0 && y >= 0.0 && (x as usize) < photo.width && (y as usize) < photo.height {
                covered[y as usize * photo.width + x as usize] = true;
            }
        }
    }
    for (px, _) in out.pixels.iter_mut().zip(&covered).filter(|(_, c)| **c) {
        *px = std::array::from_fn(|c| px[c] * (1.0 - EDGE_OPACITY) + BODY[c] * EDGE_OPACITY);
    }
    let radius = (photo.width.max(photo.height) as f32 / 500.0).max(1.0);
    for (d, r) in detected.iter().zip(reprojected) {
        disc(&mut out, [d[0], d[1]], radius, DETECTED);
        disc(&mut out, *r, radius * 0.7, REPROJECTED);
    }
    out
}

fn disc(image: &mut Image, c: [f32; 2], radius: f32, colour: [f32; 3]) {
    let (x0, x1) = ((c[0] - radius).floor().max(0.0) as usize, (c[0] + radius).ceil().max(0.0) as usize);
    let (y0, y1) = ((c[1] - radius).floor().max(0.0) as usize, (c[1] + radius).ceil().max(0.0) as usize);
    for y in y0..y1.min(image.height) {
        for x in x0..x1.min(image.width) {
            let (dx, dy) = (x as f32 + 0.5 - c[0], y as f32 + 0.5 - c[1]);
            if dx * dx + dy * dy <= radius * radius {
                image.pixels[y * image.width + x] = colour;
            }
        }
    }
}

/// A line of half-width `half` as a row of discs one pixel apart.
fn line(image: &mut Image, a: [f32; 2], b: [f32; 2], colour: [f32; 3], half: f32) {
    let len = (b[0] - a[0]).hypot(b[1] - a[1]);
    let steps = len.ceil().max(1.0) as usize;
    for s in 0..=steps {
        let t = s as f32 / steps as f32;
        disc(image, [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])], half.max(0.75), colour);
    }
}
