//! An open tube of vertex rings, for garments that hang around the body (skirts, dresses): the
//! rings can hold different numbers of vertices, so a flared tube keeps its triangles one size
//! from its narrow top to its wide bottom.

use crate::tri_mesh::UvLayout;

/// Where a tube's vertices sit: rings at fractions of the length from the top (0) to the bottom
/// (1), increasing, each with its own number of vertices; ring-major vertex order.
#[derive(Debug, Clone, PartialEq)]
pub struct RingLayout {
    pub rings: Vec<f32>,
    /// Vertices around each ring.
    pub segments: Vec<usize>,
    /// Index of each ring's first vertex.
    starts: Vec<usize>,
}

impl RingLayout {
    /// Rings at `rings` with `segments[r]` vertices each (at least 3).
    pub fn new(rings: Vec<f32>, segments: Vec<usize>) -> Self {
        assert_eq!(rings.len(), segments.len(), "one segment count per ring");
        assert!(segments.iter().all(|&n| n >= 3), "a ring has at least 3 vertices");
        let starts = segments.iter().scan(0, |next, &n| Some(std::mem::replace(next, *next + n))).collect();
        Self { rings, segments, starts }
    }

    /// `rings + 1` evenly spaced rings of `segments` vertices each.
    pub fn uniform(segments: usize, rings: usize) -> Self {
        Self::new((0..=rings).map(|r| r as f32 / rings as f32).collect(), vec![segments; rings + 1])
    }

    pub fn vertex_count(&self) -> usize {
        self.segments.iter().sum()
    }

    /// The last ring at or above `fraction` of the length from the top.
    pub fn ring_at(&self, fraction: f32) -> usize {
        self.rings.partition_point(|&s| s <= fraction).saturating_sub(1).min(self.rings.len() - 1)
    }

    /// Index of vertex `segment` (taken around the ring) of ring `ring`.
    pub fn vertex(&self, ring: usize, segment: usize) -> usize {
        self.starts[ring] + segment % self.segments[ring]
    }

    /// The vertex of ring `ring` nearest the angle `turn` (in turns, 0 to 1).
    pub fn nearest(&self, ring: usize, turn: f32) -> usize {
        self.vertex(ring, (turn.rem_euclid(1.0) * self.segments[ring] as f32).round() as usize)
    }

    /// The ring of each vertex, in vertex order.
    pub fn ring_of_vertices(&self) -> impl Iterator<Item = usize> + '_ {
        self.segments.iter().enumerate().flat_map(|(r, &n)| std::iter::repeat_n(r, n))
    }

    /// The tube's triangles, and UVs with u around the ring (a seam column at u = 1) and v from 1
    /// at the top to 0 at the bottom. With vertex k of a ring at angle 2πk/n from +x towards +z
    /// and the top ring highest, the faces point outward.
    pub fn tube(&self) -> (Vec<[u32; 3]>, UvLayout) {
        let mut coords = Vec::new();
        for (&s, &n) in self.rings.iter().zip(&self.segments) {
            coords.extend((0..=n).map(|k| [k as f32 / n as f32, 1.0 - s]));
        }
        // Between two rings, walk round both and step whichever ring's next vertex comes first
        // (the lower ring on ties, which on equal rings gives each quad the diagonal from upper k
        // to lower k + 1).
        let mut faces = Vec::new();
        let mut uv_faces = Vec::new();
        let mut uv_start = 0;
        for r in 0..self.rings.len().saturating_sub(1) {
            let (n_up, n_down) = (self.segments[r], self.segments[r + 1]);
            let up = |k: usize| self.vertex(r, k) as u32;
            let down = |k: usize| self.vertex(r + 1, k) as u32;
            let t_up = |k: usize| (uv_start + k) as u32;
            let t_down = |k: usize| (uv_start + n_up + 1 + k) as u32;
            let (mut i, mut j) = (0, 0);
            while i < n_up || j < n_down {
                let step_down = j < n_down && (i == n_up || (j + 1) * n_up <= (i + 1) * n_down);
                if step_down {
                    faces.push([up(i), down(j + 1), down(j)]);
                    uv_faces.push([t_up(i), t_down(j + 1), t_down(j)]);
                    j += 1;
                } else {
                    faces.push([up(i), up(i + 1), down(j)]);
                    uv_faces.push([t_up(i), t_up(i + 1), t_down(j)]);
                    i += 1;
                }
            }
            uv_start += n_up + 1;
        }
        (faces, UvLayout { coords, faces: uv_faces })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    /// A tube is an open cylinder: every edge has two faces except the top and bottom rings',
    /// V − E + F = 0, and the faces point away from the axis.
    #[test]
    fn tube_is_an_open_outward_cylinder() {
        let rings: Vec<f32> = (0..=20).map(|r| r as f32 / 20.0).collect();
        let growing = RingLayout::new(rings.clone(), (0..=20).map(|r| 40 + 2 * r).collect());
        for layout in [RingLayout::uniform(64, 28), growing] {
            let positions: Vec<[f32; 3]> = layout
                .ring_of_vertices()
                .enumerate()
                .map(|(v, r)| {
                    let k = v - layout.vertex(r, 0);
                    let a = std::f32::consts::TAU * k as f32 / layout.segments[r] as f32;
                    [a.cos(), -layout.rings[r], a.sin()]
                })
                .collect();
            let (faces, uv) = layout.tube();
            let mut edges = HashMap::new();
            for f in &faces {
                for k in 0..3 {
                    let (a, b) = (f[k].min(f[(k + 1) % 3]), f[k].max(f[(k + 1) % 3]));
                    *edges.entry((a, b)).or_insert(0) += 1;
                }
            }
            let boundary = edges.values().filter(|&&c| c == 1).count();
            assert_eq!(boundary, layout.segments[0] + layout.segments[layout.segments.len() - 1]);
            assert!(edges.values().all(|&c| c <= 2));
            assert_eq!(layout.vertex_count() + faces.len(), edges.len());
            assert_eq!(uv.faces.len(), faces.len());
            for f in &faces {
                let [a, b, c] = f.map(|i| glam::Vec3::from(positions[i as usize]));
                let centre = (a + b + c) / 3.0;
                let outward = glam::Vec3::new(centre.x, 0.0, centre.z).normalize();
                assert!((b - a).cross(c - a).normalize().dot(outward) > 0.5, "{f:?}");
            }
        }
    }
}
