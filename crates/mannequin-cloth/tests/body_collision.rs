//! Collisions with a kinematic body: sheets dropped on a sphere and over a box edge never get
//! nearer than the margin (measured with the shapes' own distance formulas, not the solver's),
//! Coulomb friction on an incline sticks or slides as μ says, and a sleeve on a fast swinging arm
//! stays outside it.

mod common;

use common::{box_distance, box_mesh, distance, grid, icosphere, inscribed_radius};
use mannequin_cloth::{Attachment, Body, Cloth, Material, Settings, Simulator};
use mannequin_mesh::TriMesh;

const MARGIN: f32 = 0.005;
/// Positions are f32 near 1 m; a push-out lands on the margin to within a few ulps.
const TOLERANCE: f32 = 1e-5;

fn settings(substeps: u32) -> Settings {
    Settings { substeps, body_margin: MARGIN, self_collision: false, ..Settings::default() }
}

fn cotton() -> Material {
    Material::named("cotton").unwrap()
}

/// Steps `frames` frames of a still body, calling `check` after each.
fn run_still(sim: &mut Simulator, body: &TriMesh, frames: usize, mut check: impl FnMut(&[[f32; 3]])) {
    for _ in 0..frames {
        sim.step_frame(&body.positions, &body.positions, 1.0 / 60.0).unwrap();
        check(sim.positions());
    }
}

#[test]
fn a_sheet_dropped_on_a_sphere_never_comes_within_the_margin() {
    let (centre, radius) = ([0.0, 0.0, 0.0], 0.15);
    let sphere = icosphere(centre, radius, 3);
    let inner = inscribed_radius(&sphere, centre);
    let sheet = grid(41, 41, 0.01, [-0.2, radius + 0.05, -0.2], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
    let cloth = Cloth::new(&sheet, &cotton(), &[]).unwrap();
    let mut sim =
        Simulator::new(cloth, Some(Body::new(sphere.faces.clone())), Vec::new(), settings(10)).unwrap();
    let mut closest = f32::INFINITY;
    run_still(&mut sim, &sphere, 120, |p| {
        closest = p.iter().map(|&x| distance(x, centre) - inner).fold(closest, f32::min);
    });
    assert!(closest >= MARGIN - TOLERANCE, "a particle came within {closest} m of the sphere");
    let top = sim.positions()[20 * 41 + 20];
    assert!((top[1] - (radius + MARGIN)).abs() < 0.003, "the sheet's centre should rest on top: {top:?}");
}

#[test]
fn a_sheet_dropped_over_a_box_edge_never_comes_within_the_margin() {
    let (min, max) = ([-0.3, -0.3, -0.3], [0.0, 0.0, 0.3]);
    let block = box_mesh(min, max);
    let sheet = grid(31, 31, 0.01, [-0.15, 0.03, -0.15], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
    let cloth = Cloth::new(&sheet, &cotton(), &[]).unwrap();
    let mut sim =
        Simulator::new(cloth, Some(Body::new(block.faces.clone())), Vec::new(), settings(10)).unwrap();
    let mut closest = f32::INFINITY;
    let mut draped = false;
    run_still(&mut sim, &block, 90, |p| {
        closest = p.iter().map(|&x| box_distance(x, min, max)).fold(closest, f32::min);
        draped |= p.iter().any(|x| x[0] > 0.0 && x[1] < -0.05);
    });
    assert!(closest >= MARGIN - TOLERANCE, "a particle came within {closest} m of the box");
    assert!(draped, "the free half should hang down past the edge");
}

/// A small sheet resting on a plane tilted by 20°: with μ = 0.5 > tan 20° it stays put; with
/// μ = 0.1 it slides down with the acceleration g·(sin θ − μ·cos θ).
#[test]
fn friction_on_an_incline_sticks_or_slides_as_coulomb_says() {
    let angle = 20f32.to_radians();
    let (down, normal) = ([angle.cos(), -angle.sin(), 0.0], [angle.sin(), angle.cos(), 0.0]);
    let plane = TriMesh::new(
        [[-2.0, -2.0], [2.0, -2.0], [2.0, 2.0], [-2.0, 2.0]]
            .iter()
            .map(|&[s, z]| [s * down[0], s * down[1], z])
            .collect(),
        vec![[0, 2, 1], [0, 3, 2]],
    );
    let origin = [0, 1, 2].map(|k| MARGIN * normal[k] - 0.02 * down[k]);
    let sheet = grid(5, 5, 0.01, origin, down, [0.0, 0.0, 1.0]);
    let slide = |mu: f32| {
        let material = Material { friction: mu, damping: 0.0, ..cotton() };
        let cloth = Cloth::new(&sheet, &material, &[]).unwrap();
        let mut sim =
            Simulator::new(cloth, Some(Body::new(plane.faces.clone())), Vec::new(), settings(20)).unwrap();
        run_still(&mut sim, &plane, 60, |_| {});
        let moved: f32 = (0..3).map(|k| (sim.positions()[12][k] - sheet.positions[12][k]) * down[k]).sum();
        moved
    };
    let stuck = slide(0.5);
    assert!(stuck.abs() < 1e-3, "μ = 0.5 should hold the sheet, it moved {stuck} m");
    let g = 9.81f32;
    let expected = 0.5 * g * (angle.sin() - 0.1 * angle.cos());
    let slid = slide(0.1);
    assert!((slid / expected - 1.0).abs() < 0.05, "μ = 0.1: slid {slid} m in 1 s, expected {expected} m");
}

/// A cloth tube around a box arm, its top ring attached to the arm, while the arm swings about
/// the shoulder with its tip at up to `tip_speed` m/s for 2 s at 30 fps, 10 substeps a frame (or
/// more), with or without `self_collision`: the closest any particle came to the arm, and the
/// sleeve's top speed.
fn swing_sleeve(tip_speed: f32, self_collision: bool) -> (f32, f32) {
    let (length, half) = (0.6f32, 0.04f32);
    let (min, max) = ([0.0, -half, -half], [length, half, half]);
    let arm = box_mesh(min, max);
    let (rings, segments, radius) = (22usize, 24usize, 0.07f32);
    let mut positions = Vec::new();
    for r in 0..rings {
        for s in 0..segments {
            let a = s as f32 / segments as f32 * std::f32::consts::TAU;
            positions.push([0.15 + 0.4 * r as f32 / (rings - 1) as f32, radius * a.cos(), radius * a.sin()]);
        }
    }
    let mut faces = Vec::new();
    for r in 0..rings as u32 - 1 {
        for s in 0..segments as u32 {
            let at = |r: u32, s: u32| r * segments as u32 + s % segments as u32;
            faces.push([at(r, s), at(r + 1, s), at(r + 1, s + 1)]);
            faces.push([at(r, s), at(r + 1, s + 1), at(r, s + 1)]);
        }
    }
    let sleeve = TriMesh::new(positions, faces);
    let attachments: Vec<Attachment> = (0..segments as u32)
        .map(|v| Attachment::bind(&arm.positions, &arm.faces, v, sleeve.positions[v as usize]))
        .collect();
    let cloth = Cloth::new(&sleeve, &cotton(), &[]).unwrap();
    let mut sim = Simulator::new(
        cloth,
        Some(Body::new(arm.faces.clone())),
        attachments,
        Settings { self_collision, ..settings(10) },
    )
    .unwrap();
    // θ(t) = A·sin(ωt) about the z axis: the tip's top speed is length·A·ω.
    let (amplitude, omega, fps) = (1.0f32, tip_speed / length, 30.0);
    let angle = |frame: usize| amplitude * (omega * frame as f32 / fps).sin();
    let posed = |theta: f32| -> Vec<[f32; 3]> {
        let (s, c) = theta.sin_cos();
        arm.positions.iter().map(|p| [c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]]).collect()
    };
    let mut closest = f32::INFINITY;
    let mut fastest = 0.0f32;
    let mut last = sim.positions().to_vec();
    for frame in 0..60 {
        sim.step_frame(&posed(angle(frame)), &posed(angle(frame + 1)), 1.0 / fps).unwrap();
        let (s, c) = angle(frame + 1).sin_cos();
        for (p, q) in sim.positions().iter().zip(&last) {
            let local = [c * p[0] + s * p[1], -s * p[0] + c * p[1], p[2]];
            closest = closest.min(box_distance(local, min, max));
            fastest = fastest.max(distance(*p, *q) * fps);
        }
        last = sim.positions().to_vec();
    }
    (closest, fastest)
}

/// With and without the cloth contacts, which have the last word: in 10 substeps the arm's tip
/// moves 17 mm in one, 3 times the margin, and the contacts held a particle 2.6 mm inside the arm;
/// the frame takes more substeps, so none gets in.
#[test]
fn a_sleeve_on_a_fast_swinging_arm_does_not_tunnel() {
    for self_collision in [false, true] {
        let (closest, fastest) = swing_sleeve(5.0, self_collision);
        assert!(fastest > 3.0, "the sleeve should move fast, its top speed was {fastest} m/s");
        assert!(closest >= MARGIN - 1e-4, "a particle came within {closest} m of the arm ({self_collision})");
    }
}
