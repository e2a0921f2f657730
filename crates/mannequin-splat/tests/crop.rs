//! A cropped camera renders the window of the full image, as the avatar trainer uses it: the
//! window holds every projected mean with a margin (the subject's mask box + 16 px). Outside
//! such a window the Jacobian's frustum clamp (1.3× the image, as gsplat) would differ.

mod common;

use common::{ColorForm, RotForm, Scene, camera};
use mannequin_splat::{RenderOptions, project_gaussians, render};

const MARGIN: f64 = 16.0;

/// Largest and mean absolute difference, over colour and alpha, between the render through the
/// camera cropped to the projected means' box (+ margin, its corner moved down to a multiple
/// of `align`) and the same window of the full render.
fn window_difference(align: usize) -> (f64, f64) {
    let scene = Scene::random(200, 11, 1, 3).cast::<f64>();
    let g = scene.gaussians(RotForm::Quaternion, ColorForm::Sh(1));
    let opts = RenderOptions::default();
    let full_cam = camera(320, 288);
    let m = project_gaussians(&g, &full_cam, &opts).unwrap().means2d;
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    for p in m.chunks_exact(2) {
        for k in 0..2 {
            (lo[k], hi[k]) = (lo[k].min(p[k] - MARGIN), hi[k].max(p[k] + MARGIN));
        }
    }
    let (x, y) = (lo[0].max(0.0) as usize / align * align, lo[1].max(0.0) as usize / align * align);
    let (w, h) = (hi[0].ceil() as usize - x, hi[1].ceil() as usize - y);
    assert!(x > 0 && y > 0 && x + w < 320 && y + h < 288, "the window must be inside the image");
    let full = render(&g, &full_cam, &opts).unwrap();
    let part = render(&g, &full_cam.crop(x, y, w, h), &opts).unwrap();
    assert_eq!((part.width, part.height), (w, h));
    let (fw, fh) = (full.width, full.height);
    let (mut worst, mut total) = (0.0f64, 0.0);
    for r in 0..h {
        for c in 0..w {
            let (p, q) = ((y + r) * fw + x + c, r * w + c);
            let mut pairs = vec![(part.alpha[q], full.alpha[p])];
            pairs.extend((0..3).map(|k| (part.image[k * w * h + q], full.image[k * fw * fh + p])));
            for (a, b) in pairs {
                worst = worst.max((a - b).abs());
                total += (a - b).abs();
            }
        }
    }
    (worst, total / (4 * w * h) as f64)
}

#[test]
fn a_tile_aligned_crop_renders_exactly_the_window() {
    let (worst, _) = window_difference(16);
    assert!(worst < 1e-12, "{worst}");
}

/// Off the tile grid a Gaussian's whole-tile footprint (its 3.33σ box rounded out to tiles) covers
/// other pixels, so terms below the 1/255 alpha cutoff come and go at the footprint's edge.
#[test]
fn an_unaligned_crop_differs_only_below_the_alpha_cutoff() {
    let (worst, mean) = window_difference(1);
    assert!(worst < 1.0 / 255.0 && mean < 1e-4, "largest {worst}, mean {mean}");
}
