//! Self-collision: cloth that falls onto itself ends, and stays at every frame, with no two
//! triangles intersecting, as counted by the exact test in `quality`. Each scenario also runs with
//! self-collision off, where it must tangle, so the scenario does test something.

mod common;

use common::{box_distance, box_mesh, grid};
use mannequin_cloth::{Body, Cloth, Material, Settings, Simulator, quality};
use mannequin_mesh::TriMesh;

const FLOOR_MIN: [f32; 3] = [-1.0, -0.2, -1.0];
const FLOOR_MAX: [f32; 3] = [1.0, 0.0, 1.0];

/// Runs `frames` frames of `substeps` substeps over a still floor; returns the most intersecting pairs seen in a frame
/// (every frame is counted with self-collision on; with it off, where the count only has to show
/// a tangle, the last frame alone), the pairs at the end, and the nearest any particle came to
/// the floor.
fn drop_on_floor(sheet: &TriMesh, self_collision: bool, substeps: u32, frames: usize) -> (usize, usize, f32) {
    let floor = box_mesh(FLOOR_MIN, FLOOR_MAX);
    let cloth = Cloth::new(sheet, &Material::named("cotton").unwrap(), &[]).unwrap();
    let settings = Settings { self_collision, substeps, ..Settings::default() };
    let mut sim = Simulator::new(cloth, Some(Body::new(floor.faces.clone())), Vec::new(), settings).unwrap();
    let (mut worst, mut nearest) = (0, f32::INFINITY);
    for _ in 0..frames {
        sim.step_frame(&floor.positions, &floor.positions, 1.0 / 60.0).unwrap();
        if self_collision {
            worst = worst.max(quality::self_intersecting_pairs(sim.positions(), &sheet.faces));
        }
        nearest =
            sim.positions().iter().map(|&p| box_distance(p, FLOOR_MIN, FLOOR_MAX)).fold(nearest, f32::min);
    }
    let last = quality::self_intersecting_pairs(sim.positions(), &sheet.faces);
    (worst.max(last), last, nearest)
}

/// A long strip held upright, tilted a little, and let go: it piles up on the floor in folds. At
/// `mannequin cloth simulate`'s 20 substeps per 1/60 s; at 10, 3 pairs cross for a moment as
/// the pile forms (and none at the end).
#[test]
fn a_strip_dropped_on_the_floor_piles_up_without_intersecting() {
    let tilt = 0.15f32;
    let strip = grid(20, 80, 0.01, [-0.1, 0.02, 0.0], [1.0, 0.0, 0.0], [0.0, tilt.cos(), tilt.sin()]);
    let (worst, last, nearest) = drop_on_floor(&strip, true, 20, 150);
    assert_eq!((worst, last), (0, 0), "intersecting pairs: at worst {worst}, at the end {last}");
    // Contacts are projected after the floor, so a pile may press into the 5 mm margin (to 2.2 mm
    // from the floor here); never through it.
    assert!(nearest > 0.002, "a particle came within {nearest} m of the floor");
    let (tangled, _, _) = drop_on_floor(&strip, false, 20, 150);
    assert!(tangled > 0, "without self-collision the pile should tangle");
}

/// A sheet standing up from the floor along a crease falls over onto its own lying half.
#[test]
fn a_sheet_folding_over_onto_itself_stays_in_two_layers() {
    let (n, spacing) = (30usize, 0.01f32);
    let mut sheet = grid(n, 2 * n, spacing, [-0.15, 0.0051, -0.3], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
    for p in &mut sheet.positions {
        // Past the crease at z = 0 the sheet rises, leaning a little towards the lying half.
        if p[2] > 0.0 {
            let up = p[2];
            *p = [p[0], 0.0051 + up * 0.98, -up * 0.2];
        }
    }
    let (worst, last, _) = drop_on_floor(&sheet, true, 10, 120);
    assert_eq!((worst, last), (0, 0), "intersecting pairs: at worst {worst}, at the end {last}");
    let (tangled, _, _) = drop_on_floor(&sheet, false, 10, 120);
    assert!(tangled > 0, "without self-collision the fold should pass through itself");
}

/// Two sheets crossing at the start: self-collision would hold them crossed, so the simulator
/// refuses them, counting the crossing pairs and saying where; without self-collision it runs.
#[test]
fn a_cloth_that_starts_crossed_is_refused_with_the_place() {
    let flat = grid(6, 6, 0.02, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
    let upright = grid(6, 6, 0.02, [0.05, -0.05, 0.05], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    let n = flat.positions.len() as u32;
    let mut positions = flat.positions.clone();
    positions.extend_from_slice(&upright.positions);
    let mut faces = flat.faces.clone();
    faces.extend(upright.faces.iter().map(|f| f.map(|v| v + n)));
    let sheets = TriMesh::new(positions, faces);
    let crossing = quality::self_intersecting_pairs(&sheets.positions, &sheets.faces);
    assert!(crossing > 0);
    let cloth = Cloth::new(&sheets, &Material::named("cotton").unwrap(), &[]).unwrap();
    let refused = Simulator::new(cloth.clone(), None, Vec::new(), Settings::default()).err().unwrap();
    let message = refused.to_string();
    assert!(message.contains(&format!("{crossing} pairs")) && message.contains("near ("), "{message}");
    let off = Settings { self_collision: false, ..Settings::default() };
    assert!(Simulator::new(cloth, None, Vec::new(), off).is_ok());
}
