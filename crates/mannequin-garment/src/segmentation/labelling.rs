//! A frame's labels: each pixel of the person scored per class by the prior its body pixel
//! carries (the part's, later the clip's vote on that spot of the body) plus the class's colour
//! model, then smoothed by mean-field inference over a 4-neighbour Potts model whose links weaken
//! across colour edges (a dense-CRF step, Krähenbühl & Koltun, 2011, on the pixel grid), so a
//! label boundary follows the image's edges.

use mannequin_raster::hard::NO_FACE;

use super::class::{CLASSES, Scores};
use super::colour_model::ColourModel;
use super::frame_view::{FrameView, NO_SOURCE, neighbours};

/// Mean-field iterations.
const ITERATIONS: usize = 5;
/// Strength of agreement between neighbours (per neighbour, in log units).
const SMOOTHNESS: f32 = 1.2;
/// Colour distance (RGB in [0, 1]) over which a neighbour's link fades.
const EDGE_SIGMA: f32 = 0.08;

/// Per pixel of the person, the posterior over the classes; `None` off the person.
pub struct Posterior {
    pub scores: Vec<Option<Scores>>,
}

/// Labels `view` with `vertex_prior` (a log prior per body vertex) and the classes' colour models.
pub fn label(
    view: &FrameView,
    faces: &[[u32; 3]],
    vertex_prior: &[Scores],
    colours: &[ColourModel],
) -> Posterior {
    let n = view.width * view.height;
    let mut unary: Vec<Option<Scores>> = vec![None; n];
    for (i, u) in unary.iter_mut().enumerate() {
        let s = view.source[i];
        if !view.mask.values[i] || s == NO_SOURCE {
            continue;
        }
        let s = s as usize;
        let f = view.face[s];
        debug_assert_ne!(f, NO_FACE);
        let b = view.barycentrics[s];
        let tri = faces[f as usize];
        let rgb = view.image.pixels[i];
        let mut score = [0.0; CLASSES];
        for (c, sc) in score.iter_mut().enumerate() {
            let prior: f32 = (0..3).map(|k| b[k] * vertex_prior[tri[k] as usize][c]).sum();
            *sc = prior + colours[c].log_likelihood(rgb);
        }
        *u = Some(score);
    }
    Posterior { scores: mean_field(view, &unary) }
}

fn mean_field(view: &FrameView, unary: &[Option<Scores>]) -> Vec<Option<Scores>> {
    let (w, h) = (view.width, view.height);
    let weight = |a: usize, b: usize| {
        let (p, q) = (view.image.pixels[a], view.image.pixels[b]);
        let d2: f32 = (0..3).map(|c| (p[c] - q[c]) * (p[c] - q[c])).sum();
        SMOOTHNESS * (-d2 / (2.0 * EDGE_SIGMA * EDGE_SIGMA)).exp()
    };
    let mut q: Vec<Option<Scores>> = unary.iter().map(|u| u.map(softmax)).collect();
    for _ in 0..ITERATIONS {
        let next: Vec<Option<Scores>> = (0..w * h)
            .map(|i| {
                let mut s = unary[i]?;
                for j in neighbours(i, w, h).into_iter().flatten() {
                    if let Some(qj) = q[j] {
                        let wij = weight(i, j);
                        s.iter_mut().zip(qj).for_each(|(a, b)| *a += wij * b);
                    }
                }
                Some(softmax(s))
            })
            .collect();
        q = next;
    }
    q
}

pub fn softmax(s: Scores) -> Scores {
    let m = s.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    let e = s.map(|v| (v - m).exp());
    let z: f32 = e.iter().sum();
    e.map(|v| v / z)
}

/// The class of highest score.
pub fn argmax(s: &Scores) -> usize {
    (0..CLASSES).max_by(|&a, &b| s[a].total_cmp(&s[b])).unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn softmax_sums_to_one_and_keeps_the_order() {
        let p = softmax([1.0, 3.0, 2.0, -5.0, 0.0]);
        assert!((p.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        assert_eq!(argmax(&p), 1);
        assert!(p[2] > p[0] && p[0] > p[4] && p[4] > p[3]);
    }
}
