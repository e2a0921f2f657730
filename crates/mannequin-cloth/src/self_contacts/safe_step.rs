//! A substep's moves made safe, pair by pair, in place of continuous collision detection (after
//! the conservative bounds of Chen et al. 2025, "Offset Geometric Contact", measured per pair).
//!
//! Moving every particle of a pair by a common vector leaves the pair's distance unchanged, and a
//! vertex–triangle or edge–edge distance is 1-Lipschitz in each side, so along the straight move
//! from the start of the substep the distance falls by at most 2·max |mₖ − m̄| over the pair's
//! four moves mₖ and their mean m̄. A pair whose moves spread less than its start distance allows
//! (`SHARE`) cannot pass through itself, however far it travels: cloth carried by a swinging leg,
//! and the layers on it, move freely together. Where a pair's moves spread too far, its free
//! particles are drawn to the pair's mean move, or to the move of the layer in the pair where it
//! has one, as a layer under the cloth does not yield (several rounds, as neighbouring pairs
//! share particles), each kept within its room (the box around its own move, so that pairs left
//! out of the candidates stay apart); what still spreads too far after that is carried once with
//! its pair's layer, then stopped where it started the substep, and so on until nothing does,
//! which stopping everything free achieves. Stopped outright, cloth in a layer's way is run
//! through by it: a T-shirt's hem pressed against a skirt's waist by a jogger's hands.
//!
//! The spread bounds how far a pair can close, not whether it does: a pair pushed apart spreads
//! as much as one driven through. So a pair also passes whose elements' projections on the line
//! between their closest points at the start stay apart by the same share at the end ([`Apart`]):
//! they are apart all the way, and a pair squeezed close can always be pushed apart again.

use glam::Vec3;
use rayon::prelude::*;

use super::apart::Apart;
use crate::box_hash::Aabb;

/// Of a pair's start distance, the most its moves may close it by in one substep.
const SHARE: f32 = 0.8;
/// Rounds of drawing the moves of pairs that spread too far to their pairs' means.
const ROUNDS: usize = 8;

/// One pair: its four particles, `particles[..split]` the first element's (a triangle's corners,
/// or an edge's ends) and the rest the second's (a vertex, or the other edge's ends), and how far
/// apart they are at the start of the substep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Closing {
    pub particles: [u32; 4],
    pub split: usize,
    pub apart: Apart,
}

impl Closing {
    /// True when the moves `moves` of the pair's particles from `previous` could bring it nearer
    /// than [`SHARE`] allows: they spread more than that, and the pair's projections on its
    /// axis end nearer than the rest of the start distance.
    fn spreads(&self, previous: &[[f32; 3]], moves: &[Vec3]) -> bool {
        let m = self.particles.map(|p| moves[p as usize]);
        if closing(m) < SHARE * self.apart.distance {
            return false;
        }
        let ends = [0, 1, 2, 3].map(|k| Vec3::from(previous[self.particles[k] as usize]) + m[k]);
        let gap = self.apart.along_axis(ends, self.split);
        !(gap > 0.0 && gap >= (1.0 - SHARE) * self.apart.distance)
    }
}

/// What making a substep safe did.
#[derive(Debug, Default, Clone, Copy, PartialEq)]
pub(super) struct Held {
    /// Particles whose moves were drawn to their pairs' means.
    pub drawn: usize,
    /// Particles stopped where they started the substep.
    pub stopped: usize,
}

/// The moves of one substep, held pair by pair.
#[derive(Debug, Default)]
pub(super) struct SafeStep {
    moves: Vec<Vec3>,
    sums: Vec<(Vec3, u32)>,
    /// `incident[starts[p]..starts[p + 1]]` are the pairs with particle p.
    starts: Vec<u32>,
    incident: Vec<u32>,
    /// The round in which each pair was last queued, so it is queued once a round.
    queued: Vec<usize>,
    /// Particles already stopped once, carried with a layer: a second stop is where they started.
    carried: Vec<bool>,
}

impl SafeStep {
    /// Pulls the moves from `previous` to `positions` back until no pair of `pairs` can close
    /// by more than [`SHARE`] of its start distance; kinematic particles (inverse mass 0) keep
    /// their moves, and every free particle ends within its `room`, which holds its start. After
    /// one pass over every pair, only the pairs of particles a round moved are looked at again.
    pub fn hold(
        &mut self,
        positions: &mut [[f32; 3]],
        previous: &[[f32; 3]],
        inverse_mass: &[f32],
        pairs: &[Closing],
        room: &[Aabb],
    ) -> Held {
        self.moves.clear();
        self.moves.par_extend(
            (&*positions, previous).into_par_iter().map(|(x, p)| Vec3::from(*x) - Vec3::from(*p)),
        );
        let free = |p: u32| inverse_mass[p as usize] > 0.0;
        let spreads = |moves: &[Vec3], pair: &Closing| {
            pair.particles.iter().any(|&p| free(p)) && pair.spreads(previous, moves)
        };
        let mut spreading: Vec<u32> = (0..pairs.len() as u32)
            .into_par_iter()
            .filter(|&k| spreads(&self.moves, &pairs[k as usize]))
            .collect();
        let mut held = Held::default();
        if spreading.is_empty() {
            return held;
        }
        self.index_incident(pairs, previous.len());
        for round in 1..=ROUNDS {
            self.sums.clear();
            self.sums.resize(self.moves.len(), (Vec3::ZERO, 0));
            for &k in &spreading {
                let particles = pairs[k as usize].particles;
                let mean = carrier(particles, &self.moves, free)
                    .unwrap_or_else(|| particles.iter().map(|&p| self.moves[p as usize]).sum::<Vec3>() / 4.0);
                for p in particles.into_iter().filter(|&p| free(p)) {
                    let sum = &mut self.sums[p as usize];
                    *sum = (sum.0 + mean, sum.1 + 1);
                }
            }
            let mut moved = Vec::new();
            for (p, (m, &(sum, count))) in self.moves.iter_mut().zip(&self.sums).enumerate() {
                if count > 0 {
                    let start = Vec3::from(previous[p]);
                    *m = (start + sum / count as f32).clamp(room[p].min, room[p].max) - start;
                    moved.push(p as u32);
                }
            }
            held.drawn += moved.len();
            spreading = self.incident_to(&moved, round);
            spreading.retain(|&k| spreads(&self.moves, &pairs[k as usize]));
            if spreading.is_empty() {
                break;
            }
        }
        // What still spreads is stopped: carried with the layer in the pair, once, where the
        // pair has one (a particle stopped where it started is run through by a layer that moves
        // on), and where it started after that. Stopping a pair's free particles may make its
        // neighbours spread: follow them until none does.
        self.carried.clear();
        self.carried.resize(self.moves.len(), false);
        let mut round = ROUNDS + 1;
        while !spreading.is_empty() {
            let mut stopped = Vec::new();
            for &k in &spreading {
                let particles = pairs[k as usize].particles;
                let layer = carrier(particles, &self.moves, free);
                for p in particles.into_iter().filter(|&p| free(p)) {
                    let p = p as usize;
                    let start = Vec3::from(previous[p]);
                    let stop = match layer {
                        Some(m) if !self.carried[p] => (start + m).clamp(room[p].min, room[p].max) - start,
                        _ => Vec3::ZERO,
                    };
                    self.carried[p] = true;
                    if self.moves[p] != stop {
                        self.moves[p] = stop;
                        stopped.push(p as u32);
                    }
                }
            }
            held.stopped += stopped.len();
            round += 1;
            spreading = self.incident_to(&stopped, round);
            spreading.retain(|&k| spreads(&self.moves, &pairs[k as usize]));
        }
        (positions, previous, &self.moves).into_par_iter().for_each(|(x, p, m)| {
            *x = (Vec3::from(*p) + *m).to_array();
        });
        held
    }

    /// Lists each particle's pairs.
    fn index_incident(&mut self, pairs: &[Closing], particles: usize) {
        self.starts.clear();
        self.starts.resize(particles + 1, 0);
        for &p in pairs.iter().flat_map(|pair| &pair.particles) {
            self.starts[p as usize + 1] += 1;
        }
        for p in 0..particles {
            self.starts[p + 1] += self.starts[p];
        }
        let mut next = self.starts[..particles].to_vec();
        self.incident.clear();
        self.incident.resize(self.starts[particles] as usize, 0);
        for (k, pair) in pairs.iter().enumerate() {
            for &p in &pair.particles {
                self.incident[next[p as usize] as usize] = k as u32;
                next[p as usize] += 1;
            }
        }
        self.queued.clear();
        self.queued.resize(pairs.len(), 0);
    }

    /// The pairs with any of `particles`, each once, marked as queued in `round`.
    fn incident_to(&mut self, particles: &[u32], round: usize) -> Vec<u32> {
        let mut out = Vec::new();
        for &p in particles {
            for &k in &self.incident[self.starts[p as usize] as usize..self.starts[p as usize + 1] as usize] {
                if self.queued[k as usize] != round {
                    self.queued[k as usize] = round;
                    out.push(k);
                }
            }
        }
        out
    }
}

/// The mean move of a pair's kinematic particles (a layer under the cloth), if it has any: the
/// move its free particles are drawn to, as the layer does not yield.
fn carrier(particles: [u32; 4], moves: &[Vec3], free: impl Fn(u32) -> bool) -> Option<Vec3> {
    let (sum, count) = particles
        .iter()
        .filter(|&&p| !free(p))
        .fold((Vec3::ZERO, 0), |(sum, count), &p| (sum + moves[p as usize], count + 1));
    (count > 0).then(|| sum / count as f32)
}

/// The most a pair's distance can fall along its four moves: twice their farthest from their mean.
pub(super) fn closing(moves: [Vec3; 4]) -> f32 {
    let mean = moves.iter().sum::<Vec3>() / 4.0;
    2.0 * moves.iter().map(|m| m.distance(mean)).fold(0.0, f32::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A vertex 1 cm over a triangle, driven 3 cm down through it: the move is cut so the vertex
    /// stays above, and the same pair carried 3 cm sideways together is left alone.
    #[test]
    fn a_vertex_driven_through_a_triangle_is_held_and_one_carried_with_it_is_not() {
        let previous = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.2, 0.2, 0.01]];
        let inverse_mass = [1.0; 4];
        let apart = Apart::between(Vec3::new(0.2, 0.2, 0.0), Vec3::from(previous[3]));
        let pairs = [Closing { particles: [0, 1, 2, 3], split: 3, apart }];
        let mut step = SafeStep::default();
        let mut through = previous;
        through[3][2] = -0.02;
        let room = [Aabb { min: Vec3::splat(-1.0), max: Vec3::splat(2.0) }; 4];
        let held = step.hold(&mut through, &previous, &inverse_mass, &pairs, &room);
        assert!(held.drawn > 0 || held.stopped > 0, "{held:?}");
        let height = through[3][2] - (through[0][2] + through[1][2] + through[2][2]) / 3.0;
        assert!(height > 0.0, "the vertex stays above: {through:?}");
        let mut carried = previous.map(|[x, y, z]| [x + 0.03, y, z]);
        let held = step.hold(&mut carried, &previous, &inverse_mass, &pairs, &room);
        assert_eq!(held, Held::default());
        assert_eq!(carried[3], [previous[3][0] + 0.03, 0.2, 0.01]);
    }

    /// A vertex squeezed to 0.1 mm over a triangle and pushed 1 mm away from it: its moves spread
    /// ten times what the start distance allows, but it moves away, so it keeps its move; pushed
    /// 1 mm through instead, it is held above.
    #[test]
    fn a_vertex_pushed_away_from_a_triangle_keeps_its_move() {
        let previous = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.2, 0.2, 1e-4]];
        let apart = Apart::between(Vec3::new(0.2, 0.2, 0.0), Vec3::from(previous[3]));
        let pairs = [Closing { particles: [0, 1, 2, 3], split: 3, apart }];
        let room = [Aabb { min: Vec3::splat(-1.0), max: Vec3::splat(2.0) }; 4];
        let mut step = SafeStep::default();
        let mut away = previous;
        away[3][2] = 1.1e-3;
        let held = step.hold(&mut away, &previous, &[1.0; 4], &pairs, &room);
        assert_eq!(held, Held::default());
        assert_eq!(away[3], [0.2, 0.2, 1.1e-3]);
        let mut through = previous;
        through[3][2] = -0.9e-3;
        step.hold(&mut through, &previous, &[1.0; 4], &pairs, &room);
        let height = through[3][2] - (through[0][2] + through[1][2] + through[2][2]) / 3.0;
        assert!(height > 0.0, "the vertex stays above: {through:?}");
    }
}
