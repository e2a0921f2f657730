//! A sewing-pattern panel (thesis §3.2: garments that leave the body are sewn from flat panels
//! and draped, as in Marvelous Designer). The panel is a flared skirt: its top edge is sewn to a
//! loop of the garment above it (a yoke's or a bodice's seat line) and its two sides to each
//! other at centre back. Widening linearly from the loop's girth to the hem's makes the flat
//! pattern a sector of an annulus, the development of a cone, so the pattern is what a tailor
//! would cut.

use glam::Vec3;
use mannequin_mesh::ring_tube::RingLayout;
use mannequin_mesh::{TriMesh, UvLayout};

/// Angular bins for the body's girth about the panel's axis.
const BINS: usize = 64;

pub struct Panel {
    /// The panel placed around the body: the loop's vertices first, then ring by ring to the hem.
    pub mesh: TriMesh,
    /// Per face, its corners on the flat pattern, in metres.
    pub pattern: UvLayout,
    /// How many vertices (the first) are the loop's.
    pub seam: usize,
}

/// A panel sewn to `seam` (a closed loop, ordered from +x towards +z about the vertical and
/// starting at centre back), hanging `depth` metres below it and `flare` × its girth wider at
/// the hem, with edges of about `edge`, placed at least `clearance` outside the `body` points.
pub fn hang_panel(seam: &[Vec3], depth: f32, flare: f32, edge: f32, body: &[Vec3], clearance: f32) -> Panel {
    let n = seam.len();
    let mut along = vec![0.0f32; n + 1];
    for i in 0..n {
        along[i + 1] = along[i] + seam[i].distance(seam[(i + 1) % n]);
    }
    let girth = along[n];
    let rows = ((depth / (edge * 0.866)).round() as usize).max(1);
    let width = |fraction: f32| girth * (1.0 + flare * fraction);
    let fractions: Vec<f32> = (0..=rows).map(|r| r as f32 / rows as f32).collect();
    let segments: Vec<usize> = fractions
        .iter()
        .enumerate()
        .map(|(r, &s)| if r == 0 { n } else { ((width(s) / edge).round() as usize).max(3) })
        .collect();
    let layout = RingLayout::new(fractions, segments);
    let (faces, mut pattern) = layout.tube();
    // The tube's layout has u round the ring and v = 1 − fraction; on the pattern, the loop's
    // vertices sit at their own arc lengths, not evenly.
    let sector = Sector { girth, depth, flare };
    for (k, c) in pattern.coords.iter_mut().enumerate() {
        let u = if k <= n { along[k] / girth } else { c[0] };
        *c = sector.point(u, (1.0 - c[1]) * depth);
    }
    let centre = seam.iter().copied().sum::<Vec3>() / n as f32;
    let top = seam.iter().map(|p| p.y).fold(f32::MIN, f32::max);
    let girths = BodyGirth::new(body, centre, top, depth, &layout);
    let mut positions: Vec<[f32; 3]> = seam.iter().map(|p| p.to_array()).collect();
    for (r, (&s, &count)) in layout.rings.iter().zip(&layout.segments).enumerate().skip(1) {
        let spread = (width(s) - girth) / std::f32::consts::TAU;
        for k in 0..count {
            let base = on_loop(seam, &along, girth * k as f32 / count as f32);
            let out = Vec3::new(base.x - centre.x, 0.0, base.z - centre.z);
            let (radius, direction) = (out.length(), out.normalize_or_zero());
            let angle = direction.z.atan2(direction.x);
            let radius = (radius + spread).max(girths.at(r, angle) + clearance);
            let p = Vec3::new(centre.x, base.y - s * depth, centre.z) + direction * radius;
            positions.push(p.to_array());
        }
    }
    Panel { mesh: TriMesh::new(positions, faces), pattern, seam: n }
}

/// The flat pattern: an annular sector with an inner arc of the loop's girth and an outer arc
/// `flare` × that wider, `depth` apart (a rectangle without flare).
struct Sector {
    girth: f32,
    depth: f32,
    flare: f32,
}

impl Sector {
    /// The pattern point a share `u` along the top edge and `d` metres down.
    fn point(&self, u: f32, d: f32) -> [f32; 2] {
        let angle = self.flare * self.girth / self.depth;
        if angle < 1e-4 {
            return [(u - 0.5) * self.girth, -d];
        }
        let inner = self.girth / angle;
        let (sin, cos) = (angle * (u - 0.5)).sin_cos();
        [(inner + d) * sin, inner - (inner + d) * cos]
    }
}

/// The point `s` metres along the closed polyline `loop_points`, whose cumulative lengths are
/// `along`.
fn on_loop(loop_points: &[Vec3], along: &[f32], s: f32) -> Vec3 {
    let n = loop_points.len();
    let i = along.partition_point(|&a| a <= s).clamp(1, n) - 1;
    let span = (along[i + 1] - along[i]).max(f32::MIN_POSITIVE);
    loop_points[i].lerp(loop_points[(i + 1) % n], ((s - along[i]) / span).clamp(0.0, 1.0))
}

/// How far the body reaches from the panel's axis, per ring and direction, counting every point
/// between the top and the ring: a panel ring must clear all it has passed over.
struct BodyGirth {
    radius: Vec<[f32; BINS]>,
}

impl BodyGirth {
    fn new(body: &[Vec3], centre: Vec3, top: f32, depth: f32, layout: &RingLayout) -> Self {
        let mut radius = vec![[0.0f32; BINS]; layout.rings.len()];
        for p in body {
            if p.y > top || p.y < top - depth - 0.05 {
                continue;
            }
            let d = Vec3::new(p.x - centre.x, 0.0, p.z - centre.z);
            let ring = layout.ring_at((top - p.y) / depth);
            let bin = Self::bin(d.z.atan2(d.x));
            radius[ring][bin] = radius[ring][bin].max(d.length());
        }
        for r in 1..radius.len() {
            let above = radius[r - 1];
            for (b, a) in radius[r].iter_mut().zip(above) {
                *b = b.max(a);
            }
        }
        Self { radius }
    }

    fn bin(angle: f32) -> usize {
        ((angle / std::f32::consts::TAU).rem_euclid(1.0) * BINS as f32) as usize % BINS
    }

    /// The reach at ring `ring` towards `angle`, the largest over the two bins either side.
    fn at(&self, ring: usize, angle: f32) -> f32 {
        let bin = Self::bin(angle) as isize;
        (-2..=2).map(|o| self.radius[ring][(bin + o).rem_euclid(BINS as isize) as usize]).fold(0.0, f32::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 12-sided loop of radius 0.15 about a body cylinder of radius 0.2 below it: the panel
    /// clears the cylinder, and its pattern's top edge is the loop's girth and its hem
    /// (1 + flare) × that (within 0.1 %: the pattern's edges are chords of the sector's arcs).
    #[test]
    fn the_pattern_is_the_flared_sector_and_the_panel_clears_the_body() {
        let seam: Vec<Vec3> = (0..12)
            .map(|k| {
                let a = std::f32::consts::TAU * k as f32 / 12.0 - std::f32::consts::FRAC_PI_2;
                Vec3::new(0.15 * a.cos(), 1.0, 0.15 * a.sin())
            })
            .collect();
        let body: Vec<Vec3> = (0..4000)
            .map(|i| {
                let a = i as f32 * 0.37;
                Vec3::new(0.2 * a.cos(), 0.99 - (i % 100) as f32 * 0.006, 0.2 * a.sin())
            })
            .collect();
        let panel = hang_panel(&seam, 0.5, 0.5, 0.04, &body, 0.01);
        let positions = &panel.mesh.positions;
        assert_eq!(panel.seam, 12);
        assert!(positions[..12].iter().zip(&seam).all(|(p, q)| *p == q.to_array()));
        for p in &positions[12..] {
            let r = (p[0] * p[0] + p[2] * p[2]).sqrt();
            assert!(r >= 0.21 - 1e-4 && p[1] < 1.0, "{p:?} at radius {r}");
        }
        let girth: f32 = (0..12).map(|k| seam[k].distance(seam[(k + 1) % 12])).sum();
        let (mut top, mut hem) = (0.0, 0.0);
        for (tri, corners) in panel.mesh.faces.iter().zip(&panel.pattern.faces) {
            for k in 0..3 {
                let (a, b) = (tri[k] as usize, tri[(k + 1) % 3] as usize);
                let [p, q] = [corners[k], corners[(k + 1) % 3]]
                    .map(|c| glam::Vec2::from(panel.pattern.coords[c as usize]));
                if a < 12 && b < 12 {
                    top += p.distance(q);
                }
                if positions[a][1] < 0.501 && positions[b][1] < 0.501 {
                    hem += p.distance(q);
                }
            }
        }
        assert!((top - girth).abs() < 1e-3 * girth, "top {top}, girth {girth}");
        assert!((hem - 1.5 * girth).abs() < 1e-3 * girth, "hem {hem}, girth {girth}");
    }
}
