//! The shop's question, per garment and body region: how far the garment stands off the body
//! (its ease) and where it is stretched past its material's limit: too tight here, too loose there.

use glam::Vec3;
use mannequin_body::smpl_joint::*;
use mannequin_mesh::ClosestPoint;
use serde::Serialize;

/// Below this ease (m) a region hugs the body; above the loose one it hangs off it.
const TIGHT: f32 = 0.003;
const LOOSE: f32 = 0.05;

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
    pub max_strain: f32,
    pub verdict: String,
}

/// The report for one garment at one frame: `positions` on the body `body`/`body_faces`,
/// `rest` its unstretched shape, `weights` its skinning weights (N × `joints`).
#[allow(clippy::too_many_arguments)]
pub fn fit_report(
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
    let mut strain = vec![0.0f32; positions.len()];
    for [a, b] in mannequin_mesh::adjacency::edges(faces) {
        let length = |p: &[[f32; 3]]| Vec3::from(p[a as usize]).distance(Vec3::from(p[b as usize]));
        let s = (length(positions) / length(rest).max(1e-9) - 1.0).abs();
        strain[a as usize] = strain[a as usize].max(s);
        strain[b as usize] = strain[b as usize].max(s);
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
            let max_strain = members.iter().map(|&v| strain[v]).fold(0.0, f32::max);
            let mut verdict = Vec::new();
            if max_strain > strain_limit {
                verdict.push(format!(
                    "too tight: stretched {:.0} % (the material gives {:.0} %)",
                    100.0 * max_strain,
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
                max_strain,
                verdict: if verdict.is_empty() { "fits".into() } else { verdict.join("; ") },
            }
        })
        .collect()
}
