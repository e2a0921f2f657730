//! Against a peer: NVIDIA Newton's XPBD solver (an implementation nobody here wrote) and this one on
//! the same grid, material and drop: a 1.6 m sheet of 10 cm cells hung by its four corners, and by
//! two diagonally opposite ones (`tools/oracles/cloth_newton.py fixture`, which explains the
//! scenes). Both must come to the same rest: the static equilibrium of the edge constraints'
//! compliance under gravity.

mod common;

use common::{distance, grid};
use mannequin_cloth::{Cloth, Material, Settings, Simulator};
use mannequin_io::Npz;

fn fixture(scene: &str) -> Npz {
    let path = format!("{}/tests/fixtures/newton_{scene}.npz", env!("CARGO_MANIFEST_DIR"));
    Npz::read(&path).unwrap()
}

fn numbers(npz: &Npz, key: &str) -> Vec<f64> {
    npz.require(key).unwrap().to_f64().unwrap()
}

fn number(npz: &Npz, key: &str) -> f64 {
    numbers(npz, key)[0]
}

fn points(npz: &Npz, key: &str) -> Vec<[f32; 3]> {
    npz.require(key).unwrap().to_f32().unwrap().chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect()
}

fn fixture_pins(npz: &Npz) -> Vec<u32> {
    npz.require("pins").unwrap().to_i64().unwrap().iter().map(|&p| p as u32).collect()
}

/// Mannequin's rest after the fixture's frames, with `pins` fixed and the fixture's material and
/// settings as `change` leaves them, and the largest particle speed at the end.
fn rest(npz: &Npz, pins: &[u32], change: impl Fn(&mut Material, &mut Settings)) -> (Vec<[f32; 3]>, f32) {
    let size: Vec<usize> =
        npz.require("grid").unwrap().to_i64().unwrap().iter().map(|&n| n as usize).collect();
    let origin = numbers(npz, "origin");
    let origin = [0, 1, 2].map(|k| origin[k] as f32);
    let sheet =
        grid(size[0], size[1], number(npz, "spacing") as f32, origin, [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
    let initial = points(npz, "initial");
    assert_eq!(sheet.positions.len(), initial.len());
    for (ours, theirs) in sheet.positions.iter().zip(&initial) {
        assert!(distance(*ours, *theirs) < 1e-6, "the grids differ: {ours:?} vs {theirs:?}");
    }
    let faces = npz.require("faces").unwrap().to_i64().unwrap();
    assert!(
        sheet.faces.iter().flatten().zip(&faces).all(|(&a, &b)| i64::from(a) == b),
        "the triangles differ"
    );
    let mut material = Material {
        name: "newton-scene",
        density: number(npz, "density") as f32,
        stretch_compliance: number(npz, "stretch_compliance") as f32,
        bend_compliance: number(npz, "bend_compliance") as f32,
        friction: 0.5,
        damping: number(npz, "damping") as f32,
        // Newton has no strain limiting: none that the scene reaches.
        strain_limit: 1e3,
    };
    let mut settings = Settings {
        substeps: number(npz, "substeps") as u32,
        gravity: [0.0, number(npz, "gravity") as f32, 0.0],
        self_collision: false,
        ..Settings::default()
    };
    change(&mut material, &mut settings);
    let cloth = Cloth::new(&sheet, &material, pins).unwrap();
    let mut sim = Simulator::new(cloth, None, Vec::new(), settings).unwrap();
    for _ in 0..number(npz, "frames") as usize {
        sim.step_frame(&[], &[], (1.0 / number(npz, "fps")) as f32).unwrap();
    }
    let speed = sim.state().velocities.iter().map(|&v| distance(v, [0.0; 3])).fold(0.0, f32::max);
    (sim.positions().to_vec(), speed)
}

/// Largest and root-mean-square distance between matching particles.
fn gaps(a: &[[f32; 3]], b: &[[f32; 3]]) -> (f32, f32) {
    let d: Vec<f32> = a.iter().zip(b).map(|(p, q)| distance(*p, *q)).collect();
    let rms = (d.iter().map(|x| x * x).sum::<f32>() / d.len() as f32).sqrt();
    (d.iter().copied().fold(0.0, f32::max), rms)
}

/// Largest and root-mean-square height difference between matching particles, and the
/// difference of the mean heights (the centre of mass, which sets the potential energy).
fn height_gaps(a: &[[f32; 3]], b: &[[f32; 3]]) -> (f32, f32, f32) {
    let d: Vec<f32> = a.iter().zip(b).map(|(p, q)| (p[1] - q[1]).abs()).collect();
    let rms = (d.iter().map(|x| x * x).sum::<f32>() / d.len() as f32).sqrt();
    let mean = |p: &[[f32; 3]]| p.iter().map(|q| q[1]).sum::<f32>() / p.len() as f32;
    (d.iter().copied().fold(0.0, f32::max), rms, (mean(a) - mean(b)).abs())
}

/// Hung by its four corners the sheet has one rest, every edge in tension and nothing free to
/// fold, so whole positions are compared. Both solvers project the same constraint
/// (|xᵢ − xⱼ| − l₀, α/Δt²) on the same masses with one pass per substep, and that pass stops short
/// of the static equilibrium by a bias that shrinks as Δt² (see `analytic.rs`): the fixture's
/// `equilibrium`, the energy minimum found in f64 by the script, lies 1.23 cm from Newton's rest
/// at worst (0.97 cm RMS), since Newton sums each particle's corrections (Jacobi), and 0.58 cm
/// (0.44 cm RMS) from Mannequin's coloured Gauss–Seidel sweep, both below it. So the two may rest
/// up to about the larger bias apart, on a sag of 55 cm; the particles' last motion (under 1 cm/s
/// after 10 s) adds millimetres at most. Tolerances: 1.5 cm at worst and 1 cm RMS (0.9 % and
/// 0.6 % of the 1.6 m sheet), which a Mannequin at the exact equilibrium would also pass.
/// Measured: 0.69 cm and 0.54 cm.
#[test]
fn a_sheet_hung_by_four_corners_rests_where_newton_puts_it() {
    let npz = fixture("four_corners");
    let pins = fixture_pins(&npz);
    let (theirs, equilibrium) = (points(&npz, "rest"), points(&npz, "equilibrium"));
    let lowest = theirs.iter().map(|p| p[1]).fold(f32::MAX, f32::min);
    let sag = points(&npz, "initial")[0][1] - lowest;
    assert!(sag > 0.5, "the scene needs a visible sag: {sag} m");
    let agrees = |(worst, rms): (f32, f32)| worst <= 0.015 && rms <= 0.01;

    let (ours, speed) = rest(&npz, &pins, |_, _| {});
    assert!(speed < 0.01, "not at rest: a particle still moves at {speed} m/s");
    let (worst, rms) = gaps(&ours, &theirs);
    let (from_equilibrium, _) = gaps(&ours, &equilibrium);
    assert!(
        agrees((worst, rms)),
        "against Newton's rest: worst {worst} m, RMS {rms} m (ours is {from_equilibrium} m from the equilibrium)"
    );

    // The comparison can fail: with edges 20 % softer (a stiffness that does not map) the sheet
    // rests 3.1 cm from Newton's at worst, 2.3 cm RMS, twice the tolerances; gravity 10 % weaker
    // gives 2.7 and 2.1 cm. (10 % softer edges, 1.3 and 0.9 cm, would pass: below what the
    // one-pass bias lets this comparison resolve.)
    let (softer, _) = rest(&npz, &pins, |m, _| m.stretch_compliance *= 1.2);
    let (worst, rms) = gaps(&softer, &theirs);
    assert!(!agrees((worst, rms)), "20 % softer edges should not match Newton: worst {worst} m, RMS {rms} m");
}

/// Heights are compared, not whole positions: with no bending stiffness the hanging halves can
/// fold out of the diagonal's vertical plane at no cost, so where they bulge sideways depends on
/// each solver's path (measured: up to 12 cm sideways between the two), while the heights follow
/// from the equilibrium of stretch and gravity. (Matching bending instead fails: Newton 1.8's
/// XPBD bending moves a hinge's wing vertices along |e| times the unit normals, not along the
/// angle's gradient |e|·n/|n|², so on 10 cm cells (|n| = 2·area = 0.01 m²) its pushes are about
/// 1/100 of what the same compliance gives here; at compliance 1 Mannequin's sheet turns stiff
/// where Newton's barely changes.) Tolerances, on a sheet whose centre of mass
/// hangs 70 cm below the pins, about 30 cm of that from stretch: mean height within 1.5 cm (5 %
/// of the stretch: the equilibrium is the same, so this is what the one-pass bias of each solver
/// and the motion left after 6 s may leave), and per-particle heights within 1.5 cm RMS and 5 cm
/// at worst (the folds move particles up and down a little as they bulge). Measured: 0.74 cm,
/// 0.99 cm and 3.4 cm.
#[test]
fn a_sheet_hung_by_two_corners_rests_where_newton_puts_it() {
    let npz = fixture("diagonal_hang");
    let pins = fixture_pins(&npz);
    let theirs = points(&npz, "rest");
    let (worst, rms, mean) = height_gaps(&rest(&npz, &pins, |_, _| {}).0, &theirs);
    assert!(
        mean <= 0.015 && rms <= 0.015 && worst <= 0.05,
        "heights against Newton's: mean {mean} m, RMS {rms} m, worst {worst} m"
    );

    // The comparison can fail: hung by two adjacent corners, the same sheet rests with its mean
    // height 36 cm from Newton's.
    let (_, _, mean) = height_gaps(&rest(&npz, &[0, 16], |_, _| {}).0, &theirs);
    assert!(mean > 0.2, "another pin layout should not match Newton's rest: mean height {mean} m apart");
}
