//! Draping a sewn panel: the cloth simulator lets it fall from where it was placed onto the
//! resting body, its seam held, until it settles. This is where a skirt's folds come from.

use mannequin_cloth::{Body, Cloth, Material, Settings, Simulator};
use mannequin_mesh::TriMesh;

use crate::error::GarmentError;
use crate::panel::Panel;

/// Frames of 1/30 s to settle: a panel falls its few centimetres and swings out in under a
/// second at the damping below.
const FRAMES: usize = 45;
/// Draping is quasi-static: heavy damping (1/s) settles the swing without changing where the
/// cloth comes to rest.
const DAMPING: f32 = 6.0;

/// The panel's positions at rest in `material` on `body` (rest positions and faces), its seam
/// held in place.
pub fn drape(panel: &Panel, material: &Material, body: &TriMesh) -> Result<Vec<[f32; 3]>, GarmentError> {
    let pins: Vec<u32> = (0..panel.seam as u32).collect();
    let material = Material { damping: material.damping.max(DAMPING), ..*material };
    let cloth = Cloth::sewn(&panel.mesh, &panel.pattern, &material, &pins)?;
    let mut sim =
        Simulator::new(cloth, Some(Body::new(body.faces.clone())), Vec::new(), Settings::default())?;
    for _ in 0..FRAMES {
        sim.step_frame(&body.positions, &body.positions, 1.0 / 30.0)?;
    }
    Ok(sim.positions().to_vec())
}
