//! The shop's question, per garment and body region: how far the garment stands off the body
//! (its ease) and where it is stretched past its material's limit: too tight here, too loose there.

use glam::Vec3;
use mannequin_body::smpl_joint::*;
use mannequin_mesh::ClosestPoint;
use serde::Serialize;

/// Below this ease (m) a region hugs the body; above the loose one it hangs off it.
const TIGHT: f32 = 0.003;
const LOOSE: f32 = 0.05;
/// A region is too tight when more than this share of it is stretched past the material's
/// limit: a few vertices always are, where skinning pinches (the armpits).
const TOO_TIGHT_SHARE: f32 = 0.05;

/// Body regions by the joint that moves them most.
fn region(joint: usize) -> &'static str {
    match joint {
        SPINE2 | SPINE3 | L_COLLAR | R_COLLAR | NECK => "chest",
        SPINE1 => "waist",
        PELVIS | L_HIP | R_HIP => "hips and thighs",
        L_KNEE | R_KNEE | L_ANKLE | R_ANKLE | L_FOOT | R_FOOT => "lower legs",
        L_SHOULDER | R_SHOULDER => "upper arms",
        _ => "forearms",
    }
}

#[derive(Debug, Clone, Serialize)]
pub struct RegionFit {
    pub region: &'static str,
    pub vertices: usize,
    pub min_ease_cm: f32,
    pub mean_ease_cm: f32,
    /// The share of its vertices with an edge stretched past the material's limit.
    pub share_over_limit: f32,
    pub verdict: String,
}

/// The report for one garment at one frame: `positions` on the body `body`/`body_faces`,
/// `rest` its unstretched shape, `weights` its skinning weights (N × `joints`).
#[allow(clippy::too_many_arguments)]
pub(super) fn fit_report(
    positions: &[[f32; 3]],
    rest: &[[f32; 3]],
    faces: &[[u32; 3]],
    weights: &[f32],
    joints: usize,
    body: &[[f32; 3]],
    body_faces: &[[u32; 3]],
    strain_limit: f32,
) -> Vec<RegionFit> {
    let index = ClosestPoint::new(body, body_faces, 0.03);
    let names: Vec<&'static str> = weights
        .chunks_exact(joints)
        .map(|w| region((0..joints).max_by(|&a, &b| w[a].total_cmp(&w[b])).unwrap_or(0)))
        .collect();
    let ease: Vec<f32> = positions
        .iter()
        .map(|&p| index.query(Vec3::from(p)).map_or(0.0, |(_, q)| q.distance(Vec3::from(p))))
        .collect();
    // Each vertex's largest stretch over its edges (compression left out: cloth buckles).
    let mut stretch = vec![0.0f32; positions.len()];
    for [a, b] in mannequin_mesh::adjacency::edges(faces) {
        let length = |p: &[[f32; 3]]| Vec3::from(p[a as usize]).distance(Vec3::from(p[b as usize]));
        let s = (length(positions) / length(rest).max(1e-9) - 1.0).max(0.0);
        stretch[a as usize] = stretch[a as usize].max(s);
        stretch[b as usize] = stretch[b as usize].max(s);
    }
    let mut order: Vec<&'static str> = names.clone();
    order.sort_unstable();
    order.dedup();
    order
        .into_iter()
        .map(|name| {
            let members: Vec<usize> = (0..positions.len()).filter(|&v| names[v] == name).collect();
            let n = members.len() as f32;
            let min_ease = members.iter().map(|&v| ease[v]).fold(f32::INFINITY, f32::min);
            let mean_ease = members.iter().map(|&v| ease[v]).sum::<f32>() / n;
            let share_over_limit = members.iter().filter(|&&v| stretch[v] > strain_limit).count() as f32 / n;
            let mut verdict = Vec::new();
            if share_over_limit > TOO_TIGHT_SHARE {
                verdict.push(format!(
                    "too tight: {:.0} % of it stretched past the material's {:.0} %",
                    100.0 * share_over_limit,
                    100.0 * strain_limit
                ));
            } else if min_ease < TIGHT {
                verdict.push("tight: touches the body".to_string());
            }
            if mean_ease > LOOSE {
                verdict.push(format!("loose: {:.0} cm off the body on average", 100.0 * mean_ease));
            }
            RegionFit {
                region: name,
                vertices: members.len(),
                min_ease_cm: 100.0 * min_ease,
                mean_ease_cm: 100.0 * mean_ease,
                share_over_limit,
                verdict: if verdict.is_empty() { "fits".into() } else { verdict.join("; ") },
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 3×3-vertex patch hanging 1 cm over a flat "body", all of it moved by spine1 (the waist):
    /// its ease is 1 cm everywhere and it fits; pulling one corner 5 cm out stretches its three
    /// edges past a 5 % limit, so 4 of 9 vertices are over it: too tight.
    #[test]
    fn a_pulled_corner_makes_the_region_too_tight() {
        let grid = |z: f32| -> Vec<[f32; 3]> {
            (0..9).map(|i| [(i % 3) as f32 * 0.1, (i / 3) as f32 * 0.1, z]).collect()
        };
        let faces: Vec<[u32; 3]> =
            [0u32, 1, 3, 4].iter().flat_map(|&c| [[c, c + 1, c + 4], [c, c + 4, c + 3]]).collect();
        let body = grid(0.0);
        let rest = grid(0.01);
        let joints = 24;
        let mut weights = vec![0.0; 9 * joints];
        for v in 0..9 {
            weights[v * joints + SPINE1] = 1.0;
        }
        let report = fit_report(&rest, &rest, &faces, &weights, joints, &body, &faces, 0.05);
        assert_eq!(report.len(), 1);
        assert_eq!(report[0].region, "waist");
        assert!((report[0].min_ease_cm - 1.0).abs() < 1e-4 && (report[0].mean_ease_cm - 1.0).abs() < 1e-4);
        assert_eq!(report[0].verdict, "fits");

        let mut pulled = rest.clone();
        pulled[0] = [-0.05, 0.0, 0.01];
        let report = fit_report(&pulled, &rest, &faces, &weights, joints, &body, &faces, 0.05);
        // Vertex 0's edges: to 1 (0.1 → 0.15), to 3 (0.1 → √(0.05² + 0.1²)), to 4 (diagonal).
        assert!((report[0].share_over_limit - 4.0 / 9.0).abs() < 1e-6, "{}", report[0].share_over_limit);
        assert!(report[0].verdict.starts_with("too tight: 44 %"), "{}", report[0].verdict);
    }
}
