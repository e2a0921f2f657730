//! Long-range attachments (Kim, Chentanez & Müller 2012): each free particle may be no farther
//! from its nearest attached particle than the shortest path between them over the rest mesh.
//! With one projection per substep, stretch errors travel one edge per pass, so a garment
//! hanging from its waistband stretches under its own weight; a tether reaches from the waist
//! to the hem in one step. It acts only past the rest distance, so it never stiffens folds.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use glam::Vec3;
use rayon::prelude::*;

#[derive(Debug, Clone, Default)]
pub(crate) struct Tethers {
    /// Per particle, its anchor and the rest path length to it (`None` for anchors and for
    /// particles no path reaches).
    links: Vec<Option<(u32, f32)>>,
}

impl Tethers {
    /// Tethers from every one of `n` particles to the nearest of `anchors`, by path length along
    /// `edges` with their rest lengths (Dijkstra from all anchors at once).
    pub fn new(n: usize, edges: &[([u32; 2], f32)], anchors: &[u32]) -> Self {
        let mut neighbours = vec![Vec::new(); n];
        for &([a, b], l) in edges {
            neighbours[a as usize].push((b, l));
            neighbours[b as usize].push((a, l));
        }
        let mut best: Vec<Option<(u32, f32)>> = vec![None; n];
        let mut heap = BinaryHeap::new();
        for &a in anchors {
            best[a as usize] = Some((a, 0.0));
            heap.push((Reverse(0u32), a));
        }
        // f32 path lengths as ordered bits: non-negative floats order like their bit patterns.
        while let Some((Reverse(bits), v)) = heap.pop() {
            let (anchor, d) = best[v as usize].unwrap_or((v, 0.0));
            if bits != d.to_bits() {
                continue;
            }
            for &(u, l) in &neighbours[v as usize] {
                let through = d + l;
                if best[u as usize].is_none_or(|(_, old)| through < old) {
                    best[u as usize] = Some((anchor, through));
                    heap.push((Reverse(through.to_bits()), u));
                }
            }
        }
        for &a in anchors {
            best[a as usize] = None;
        }
        Self { links: best }
    }

    /// Pulls each free particle (inverse mass > 0) back onto the sphere of its tether's length
    /// about its anchor, if it is outside it.
    pub fn project(&self, positions: &mut [[f32; 3]], inverse_mass: &[f32]) {
        let anchors: Vec<Option<Vec3>> =
            self.links.iter().map(|l| l.map(|(a, _)| Vec3::from(positions[a as usize]))).collect();
        positions.par_iter_mut().zip(&self.links).zip(anchors).zip(inverse_mass).for_each(
            |(((p, link), anchor), &w)| {
                let (Some((_, length)), Some(anchor)) = (link, anchor) else { return };
                if w == 0.0 {
                    return;
                }
                let d = Vec3::from(*p) - anchor;
                let distance = d.length();
                if distance > *length {
                    *p = (anchor + d * (*length / distance)).to_array();
                }
            },
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A chain 0–1–2–3 along x (unit edges) bent into an L at 2, anchored at 0: particle 3's tether
    /// is 3 long (the path), not √5 (straight); pulled to x = 10 it comes back to 3 from the anchor,
    /// and a particle within its length is left alone.
    #[test]
    fn tethers_follow_the_path_and_pull_only_past_it() {
        let edges = [([0, 1], 1.0), ([1, 2], 1.0), ([2, 3], 1.0)];
        let tethers = Tethers::new(4, &edges, &[0]);
        assert_eq!(tethers.links[3], Some((0, 3.0)));
        assert_eq!(tethers.links[0], None);
        let mut positions = vec![[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [1.0, 0.0, 0.0], [10.0, 0.0, 0.0]];
        tethers.project(&mut positions, &[0.0, 1.0, 1.0, 1.0]);
        assert_eq!(positions[3], [3.0, 0.0, 0.0]);
        assert_eq!(positions[1], [0.5, 0.0, 0.0]);
    }
}
