//! NGD's optimisation chain end to end on a case with a known answer: a per-face Jacobian field
//! M, integrated by the Poisson solve, rendered as a mask by the differentiable rasteriser, and
//! fitted by Adam to the mask of the same sheet stretched by 1.3 across and 0.8 down. Only the
//! silhouette carries gradient (the mask is 1 inside), so this is the path a garment's mask
//! loss takes to its Jacobians.

use mannequin_data::Camera;
use mannequin_mesh::jacobian_field::{deform, deform_backward, rest_jacobians};
use mannequin_mesh::poisson::{Jacobian, PoissonSolve};
use mannequin_raster::differentiable::render;

const SIDE: usize = 64;

fn camera() -> Camera {
    Camera::new(
        SIDE,
        SIDE,
        [[100.0, 0.0, 32.0], [0.0, 100.0, 32.0], [0.0, 0.0, 1.0]],
        [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]],
    )
}

/// A 9×9 sheet, 0.5 m square, 2 m in front of the camera, counter-clockwise seen from it.
fn sheet(scale: [f32; 2]) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let n = 9;
    let positions = (0..n * n)
        .map(|k| {
            let (i, j) = ((k % n) as f32, (k / n) as f32);
            [scale[0] * (i / 8.0 - 0.5) * 0.5, scale[1] * (j / 8.0 - 0.5) * 0.5, 2.0]
        })
        .collect();
    let mut faces = Vec::new();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let v = (j * n + i) as u32;
            faces.push([v, v + n as u32, v + 1]);
            faces.push([v + 1, v + n as u32, v + n as u32 + 1]);
        }
    }
    (positions, faces)
}

fn mask(positions: &[[f32; 3]], faces: &[[u32; 3]]) -> Vec<[f64; 1]> {
    render(positions, faces, &vec![[1.0]; positions.len()], &camera(), [0.0]).image
}

fn iou(a: &[[f64; 1]], b: &[[f64; 1]]) -> f64 {
    let (mut inter, mut union) = (0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        let (x, y) = (x[0] > 0.5, y[0] > 0.5);
        inter += f64::from(u8::from(x && y));
        union += f64::from(u8::from(x || y));
    }
    inter / union
}

#[test]
fn a_jacobian_field_learns_a_stretch_from_masks() {
    let (rest, faces) = sheet([1.0, 1.0]);
    let target = mask(&sheet([1.3, 0.8]).0, &faces);
    let solve = PoissonSolve::new(&rest, &faces, 40).unwrap();
    let jacobians = rest_jacobians(&rest, &faces);
    let identity: Jacobian = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let mut field = vec![identity; faces.len()];
    let (mut m, mut v) = (vec![[[0.0; 3]; 3]; faces.len()], vec![[[0.0; 3]; 3]; faces.len()]);
    let (lr, b1, b2, regulariser) = (0.01, 0.9, 0.999, 1e-2);
    let pin = rest[40].map(f64::from);
    let positions_of = |field: &[Jacobian]| -> Vec<[f32; 3]> {
        solve.solve(&deform(field, &jacobians), pin).iter().map(|p| p.map(|x| x as f32)).collect()
    };
    let start = iou(&mask(&positions_of(&field), &faces), &target);
    for step in 1..=150 {
        let positions = positions_of(&field);
        let rendered = render(&positions, &faces, &vec![[1.0]; positions.len()], &camera(), [0.0]);
        let grad: Vec<[f64; 1]> =
            rendered.image.iter().zip(&target).map(|(r, t)| [2.0 * (r[0] - t[0])]).collect();
        let d_positions =
            rendered.backward(&grad, &faces, &vec![[1.0]; positions.len()], &camera()).positions;
        let d_field = deform_backward(&solve.backward(&d_positions), &jacobians);
        for f in 0..faces.len() {
            for i in 0..3 {
                for k in 0..3 {
                    let g = d_field[f][i][k] + 2.0 * regulariser * (field[f][i][k] - identity[i][k]);
                    m[f][i][k] = b1 * m[f][i][k] + (1.0 - b1) * g;
                    v[f][i][k] = b2 * v[f][i][k] + (1.0 - b2) * g * g;
                    let (mh, vh) = (m[f][i][k] / (1.0 - b1.powi(step)), v[f][i][k] / (1.0 - b2.powi(step)));
                    field[f][i][k] -= lr * mh / (vh.sqrt() + 1e-8);
                }
            }
        }
    }
    let fitted = positions_of(&field);
    let end = iou(&mask(&fitted, &faces), &target);
    let span = |axis: usize| {
        let (lo, hi) = fitted
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(l, h), p| (l.min(p[axis]), h.max(p[axis])));
        hi - lo
    };
    println!(
        "mask IoU {start:.3} → {end:.3}; the sheet spans {:.3} × {:.3} m (target 0.650 × 0.400)",
        span(0),
        span(1)
    );
    assert!(start < 0.8 && end > 0.95, "mask IoU {start} → {end}");
    assert!(
        (span(0) - 0.65).abs() < 0.02 && (span(1) - 0.40).abs() < 0.02,
        "spans {} × {}",
        span(0),
        span(1)
    );
}
