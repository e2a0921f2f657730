//! Sewing a skirt panel onto a garment's seat line: the lowest boundary loop of the part cut
//! from the body becomes the panel's top seam, the panel is draped, and the two become one mesh.

use glam::Vec3;
use mannequin_cloth::Material;
use mannequin_mesh::TriMesh;
use mannequin_mesh::adjacency::boundary_loops_by_height;

use crate::drape::drape;
use crate::error::GarmentError;
use crate::panel::hang_panel;

/// How far outside the body the panel is placed before it drapes (m).
const CLEARANCE: f32 = 0.01;

/// `top` with a panel `depth` metres long and `flare` wider at the hem sewn to its lowest
/// boundary loop, draped in `material` on the rest `body`.
pub fn sew_skirt(
    top: &TriMesh,
    depth: f32,
    flare: f32,
    edge: f32,
    material: &Material,
    body: &TriMesh,
) -> Result<TriMesh, GarmentError> {
    let mut seam =
        boundary_loops_by_height(&top.positions, &top.faces).into_iter().next().ok_or_else(|| {
            GarmentError::invalid("fit", "the part above the seat has no hem to sew a panel to")
        })?;
    // Ordered from +x towards +z about the vertical through the loop's centre, starting at
    // centre back (−z), as the panel expects.
    let mut loop_points: Vec<Vec3> = seam.iter().map(|&v| Vec3::from(top.positions[v as usize])).collect();
    let centre = loop_points.iter().copied().sum::<Vec3>() / seam.len() as f32;
    let around = |p: Vec3| Vec3::new(p.x - centre.x, 0.0, p.z - centre.z);
    let turning: f32 = (0..seam.len())
        .map(|i| {
            let (a, b) = (around(loop_points[i]), around(loop_points[(i + 1) % seam.len()]));
            a.x * b.z - a.z * b.x
        })
        .sum();
    if turning < 0.0 {
        seam.reverse();
        loop_points.reverse();
    }
    let towards_back = |p: &Vec3| -around(*p).normalize_or_zero().z;
    let back = (0..seam.len())
        .max_by(|&i, &j| towards_back(&loop_points[i]).total_cmp(&towards_back(&loop_points[j])))
        .unwrap_or(0);
    seam.rotate_left(back);
    loop_points.rotate_left(back);
    let body_points: Vec<Vec3> = body.positions.iter().map(|&p| Vec3::from(p)).collect();
    let panel = hang_panel(&loop_points, depth, flare, edge, &body_points, CLEARANCE);
    let draped = drape(&panel, material, body)?;
    let n = top.positions.len() as u32;
    let sewn = |v: u32| if (v as usize) < panel.seam { seam[v as usize] } else { v - panel.seam as u32 + n };
    let mut positions = top.positions.clone();
    positions.extend_from_slice(&draped[panel.seam..]);
    let mut faces = top.faces.clone();
    faces.extend(panel.mesh.faces.iter().map(|t| t.map(sewn)));
    Ok(TriMesh::new(positions, faces))
}
