//! How a self-contact moves its particles: the gap it keeps (h, or a sliver of it between
//! neighbours along an edge) and the push that shares a correction among up to four particles by
//! their inverse masses, never throwing one farther than the violation.

use glam::Vec3;

/// The share of h kept between elements that are neighbours along an edge. Within one layer, a
/// little compression brings a vertex over its neighbours' triangles with no side to tell apart,
/// and a full h there would throw it out of the layer; the sliver still keeps a tight fold from
/// passing through itself.
const NEIGHBOUR_GAP: f32 = 0.3;

/// How far candidates are looked for, and the gap a contact keeps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Reach {
    pub distance: f32,
    pub thickness: f32,
}

/// Of two elements' distance in the cloth's start shape, the share their gap may keep: elements
/// nearer than h there (a gathered waistband, a tight curve) pushed to h would fight the cloth's
/// own shape and throw it about.
const START_SHARE: f32 = 0.8;

impl Reach {
    /// The gap between two elements `start` apart in the cloth's start shape: h, or a sliver of
    /// it when they are `near` neighbours, and no more than a share of `start`.
    pub fn gap(&self, near: bool, start: f32) -> f32 {
        let gap = if near { NEIGHBOUR_GAP * self.thickness } else { self.thickness };
        gap.min(START_SHARE * start)
    }
}

/// How far each of up to four particles moves, per unit of violation, along the push: `share` is
/// each particle's part of the constraint's gradient. No particle moves farther than the violation
/// itself: where only a corner with a small share is free, the exact projection would throw it by
/// the violation over that share. `None` when nothing can move.
fn push_weights(inverse_mass: [f32; 4], share: [f32; 4]) -> Option<[f32; 4]> {
    let weight: f32 = (0..4).map(|k| inverse_mass[k] * share[k] * share[k]).sum();
    let largest = (0..4).map(|k| inverse_mass[k] * share[k].abs()).fold(0.0, f32::max);
    let denominator = weight.max(largest);
    (denominator > 0.0).then(|| [0, 1, 2, 3].map(|k| inverse_mass[k] * share[k] / denominator))
}

/// Moves four particles along `push` (the full correction, as if the free corners carried it all)
/// in the shares [`push_weights`] gives them.
pub(super) fn push_apart(
    positions: &mut [[f32; 3]],
    particles: [u32; 4],
    inverse_mass: &[f32],
    share: [f32; 4],
    push: Vec3,
) {
    let Some(moves) = push_weights(particles.map(|i| inverse_mass[i as usize]), share) else {
        return;
    };
    for k in 0..4 {
        let p = &mut positions[particles[k] as usize];
        *p = (Vec3::from(*p) + moves[k] * push).to_array();
    }
}

/// The farthest any of `particles` has moved from `previous`: a pair can be no nearer than at
/// the start of the substep less its two sides' farthest moves.
pub(super) fn moved(positions: &[[f32; 3]], previous: &[[f32; 3]], particles: &[u32]) -> f32 {
    particles
        .iter()
        .map(|&i| Vec3::from(positions[i as usize]).distance(Vec3::from(previous[i as usize])))
        .fold(0.0, f32::max)
}
