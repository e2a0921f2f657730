//! A skirt: a surface of revolution around the pelvis in the rest pose, hanging from the waist
//! over the hips and legs, skinned to the pelvis and both hips so that it follows the legs on
//! average (the MGN-style garment-as-separate-mesh of the thesis, with blended skinning).

use glam::Vec3;

use crate::clothing::smoothstep;
use crate::subject::Outfit;
use mannequin_body::smpl_joint::{L_HIP, L_KNEE, PELVIS, R_HIP, R_KNEE, SPINE1};
use mannequin_mesh::UvLayout;
use mannequin_mesh::ring_tube::RingLayout;

/// Angular bins for measuring the body's cross-section.
const BINS: usize = 48;

pub struct Skirt {
    /// Rest-pose positions, ring-major from the waist down.
    pub positions: Vec<[f32; 3]>,
    pub faces: Vec<[u32; 3]>,
    pub uv: UvLayout,
    /// Per vertex, `(joint, weight)` pairs summing to one.
    pub weights: Vec<[(usize, f32); 3]>,
    pub layout: RingLayout,
}

/// Waist and hem heights of `outfit`'s skirt on a body with rest `joints`, if it has one: from
/// the lower spine to a hand above the knee (skirt) or below it (dress).
pub fn skirt_span(outfit: Outfit, joints: &[Vec3]) -> Option<(f32, f32)> {
    let knee = joints[L_KNEE].y.min(joints[R_KNEE].y);
    let hem = match outfit {
        Outfit::ShirtSkirt => knee + 0.12,
        Outfit::Dress => knee - 0.1,
        Outfit::TightShirtTrousers | Outfit::LooseShirtTrousers => return None,
    };
    Some((joints[SPINE1].y, hem))
}

/// The rest points a skirt must enclose: those whose strongest skinning joint (`weights` is
/// V × `num_joints`) is the pelvis, a hip, a knee or the lower spine.
pub fn lower_body(points: &[[f32; 3]], weights: &[f32], num_joints: usize) -> Vec<Vec3> {
    let legs = [PELVIS, L_HIP, R_HIP, L_KNEE, R_KNEE, SPINE1];
    points
        .iter()
        .zip(weights.chunks_exact(num_joints))
        .filter(|(_, w)| {
            let strongest = w.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1)).map_or(0, |(j, _)| j);
            legs.contains(&strongest)
        })
        .map(|(p, _)| Vec3::from(*p))
        .collect()
}

/// Builds a skirt from `waist` down to `hem` height around the vertical axis through `centre`,
/// enclosing `body` (the rest vertices considered, e.g. pelvis and legs) with `ease` metres of
/// room and a flare of `flare` metres per metre of length, with its vertices on `layout`.
pub fn build_skirt(
    body: &[Vec3],
    centre: Vec3,
    (waist, hem): (f32, f32),
    (ease, flare): (f32, f32),
    layout: &RingLayout,
) -> Skirt {
    let (length, rings) = (waist - hem, layout.rings.len());
    // Body radius per ring and angle bin, from points at or above the ring (down to the hem),
    // so the skirt never narrows below the widest part it has passed.
    let mut radius = vec![[0.0f32; BINS]; rings];
    for p in body {
        if p.y > waist + 0.02 || p.y < hem - 0.05 {
            continue;
        }
        let d = Vec3::new(p.x - centre.x, 0.0, p.z - centre.z);
        let bin = (((d.z.atan2(d.x) / std::f32::consts::TAU).rem_euclid(1.0)) * BINS as f32) as usize % BINS;
        let ring = layout.ring_at((waist - p.y) / length);
        radius[ring][bin] = radius[ring][bin].max(d.length());
    }
    for r in 1..rings {
        let (above, below) = radius.split_at_mut(r);
        for (b, a) in below[0].iter_mut().zip(&above[r - 1]) {
            *b = b.max(*a);
        }
    }
    let mut positions = Vec::new();
    let mut weights = Vec::new();
    for ((ring, &s), &segments) in radius.iter().zip(&layout.rings).zip(&layout.segments) {
        let y = waist - s * length;
        for k in 0..segments {
            let theta = std::f32::consts::TAU * k as f32 / segments as f32;
            // Smooth the measured profile over neighbouring bins.
            let bin = theta / std::f32::consts::TAU * BINS as f32;
            let rad = (-2..=2)
                .map(|o| ring[((bin as isize + o).rem_euclid(BINS as isize)) as usize])
                .fold(0.0f32, f32::max);
            let rad = rad.max(0.08) + ease + flare * s * length;
            let (sin, cos) = theta.sin_cos();
            positions.push([centre.x + rad * cos, y, centre.z + rad * sin]);
            // Pelvis at the waist, blending into the nearer hip towards the hem.
            let side = smoothstep(-0.08, 0.08, rad * cos);
            let legs = 0.5 * smoothstep(0.0, 1.0, s);
            weights.push([(PELVIS, 1.0 - legs), (L_HIP, legs * side), (R_HIP, legs * (1.0 - side))]);
        }
    }
    let (faces, uv) = layout.tube();
    Skirt { positions, faces, uv, weights, layout: layout.clone() }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn skirt_encloses_the_body() {
        // A body cylinder of radius 0.15 around (0.1, ·, 0.0), from y = 0 to 1.
        let body: Vec<Vec3> = (0..2000)
            .map(|i| {
                let a = i as f32 * 0.37;
                Vec3::new(0.1 + 0.15 * a.cos(), (i % 100) as f32 / 100.0, 0.15 * a.sin())
            })
            .collect();
        // The generator's grid, and rings that gain vertices towards the hem.
        let rings: Vec<f32> = (0..=20).map(|r| r as f32 / 20.0).collect();
        let growing = RingLayout::new(rings, (0..=20).map(|r| 40 + 2 * r).collect());
        for layout in [RingLayout::uniform(64, 28), growing] {
            let s = build_skirt(&body, Vec3::new(0.1, 0.0, 0.0), (0.9, 0.4), (0.01, 0.2), &layout);
            assert_eq!(s.positions.len(), layout.segments.iter().sum::<usize>());
            for p in &s.positions {
                let r = ((p[0] - 0.1).powi(2) + p[2].powi(2)).sqrt();
                assert!(r >= 0.16 - 1e-4, "{p:?} radius {r}");
            }
            for w in &s.weights {
                assert!((w.iter().map(|x| x.1).sum::<f32>() - 1.0).abs() < 1e-6);
            }
        }
    }
}
