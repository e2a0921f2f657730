//! The differentiable rasteriser against finite differences (its gradients) and against a closed
//! form (the antialiased coverage of a square is its area).

use mannequin_data::Camera;
use mannequin_io::rng::SplitMix64;
use mannequin_raster::differentiable::render;

fn camera(w: usize, h: usize) -> Camera {
    Camera::new(
        w,
        h,
        [[90.0, 0.0, 33.3], [0.0, 80.0, 27.1], [0.0, 0.0, 1.0]],
        [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]],
    )
}

/// A closed sphere (rings of quads between two poles), counter-clockwise seen from outside.
fn sphere(centre: [f32; 3], r: f32, rings: usize, segments: usize) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let mut positions = vec![[centre[0], centre[1] + r, centre[2]]];
    for i in 1..rings {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        for j in 0..segments {
            let phi = std::f32::consts::TAU * j as f32 / segments as f32;
            positions.push([
                centre[0] + r * theta.sin() * phi.cos(),
                centre[1] + r * theta.cos(),
                centre[2] + r * theta.sin() * phi.sin(),
            ]);
        }
    }
    positions.push([centre[0], centre[1] - r, centre[2]]);
    let ring = |i: usize, j: usize| (1 + (i - 1) * segments + j % segments) as u32;
    let bottom = positions.len() as u32 - 1;
    let mut faces = Vec::new();
    for j in 0..segments {
        faces.push([0, ring(1, j + 1), ring(1, j)]);
        faces.push([bottom, ring(rings - 1, j), ring(rings - 1, j + 1)]);
    }
    for i in 1..rings - 1 {
        for j in 0..segments {
            faces.push([ring(i, j), ring(i, j + 1), ring(i + 1, j)]);
            faces.push([ring(i, j + 1), ring(i + 1, j + 1), ring(i + 1, j)]);
        }
    }
    (positions, faces)
}

/// L = Σ weights · image for random weights: the analytic gradients of the positions and the
/// attributes against central differences. The image is piecewise smooth (a pixel changes
/// triangle where an edge crosses its centre), so a difference that straddles such an event
/// jumps: one in twenty may miss (measured: 3 of 186, all at one vertex).
#[test]
fn gradients_match_finite_differences() {
    let cam = camera(64, 56);
    let (positions, faces) = sphere([-0.05, 0.02, 2.0], 0.45, 7, 10);
    let mut rng = SplitMix64::new(7);
    let attributes: Vec<[f64; 2]> = positions.iter().map(|_| [1.0, rng.uniform()]).collect();
    let weights: Vec<[f64; 2]> = (0..64 * 56).map(|_| [rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)]).collect();
    let loss = |positions: &[[f32; 3]], attributes: &[[f64; 2]]| -> f64 {
        let out = render(positions, &faces, attributes, &cam, [0.0, 0.25]);
        out.image.iter().zip(&weights).map(|(p, w)| p[0] * w[0] + p[1] * w[1]).sum()
    };
    let rendered = render(&positions, &faces, &attributes, &cam, [0.0, 0.25]);
    let grads = rendered.backward(&weights, &faces, &attributes, &cam);

    let (mut checked, mut off) = (0, Vec::new());
    let h = 2e-5f32;
    for v in 0..positions.len() {
        for axis in 0..3 {
            let mut plus = positions.clone();
            let mut minus = positions.clone();
            plus[v][axis] += h;
            minus[v][axis] -= h;
            let fd = (loss(&plus, &attributes) - loss(&minus, &attributes)) / (2.0 * h as f64);
            let analytic = grads.positions[v][axis];
            checked += 1;
            if (fd - analytic).abs() > 0.02 * fd.abs().max(analytic.abs()).max(1.0) {
                off.push((v, axis, analytic, fd));
            }
        }
    }
    println!("{checked} position derivatives, {} off: {:?}", off.len(), &off[..off.len().min(8)]);
    assert!(off.len() * 20 <= checked, "{} of {checked} position derivatives off: {off:?}", off.len());
    let moving: f64 = grads.positions.iter().flatten().map(|g| g.abs()).sum();
    assert!(moving > 1.0, "the positions barely matter: {moving}");

    for v in (0..attributes.len()).step_by(3) {
        for c in 0..2 {
            let mut plus = attributes.clone();
            let mut minus = attributes.clone();
            plus[v][c] += 1e-3;
            minus[v][c] -= 1e-3;
            let fd = (loss(&positions, &plus) - loss(&positions, &minus)) / 2e-3;
            assert!(
                (fd - grads.attributes[v][c]).abs() < 1e-6 * fd.abs().max(1.0),
                "attribute {v}.{c}: {fd} vs {}",
                grads.attributes[v][c]
            );
        }
    }
}

/// A fronto-parallel square with its sides between pixel centres: the antialiased coverage sums
/// to its projected area, where the hard raster counts whole pixels.
#[test]
fn antialiased_coverage_is_the_area() {
    let cam = camera(64, 56);
    // Corners at x ∈ [−0.2, 0.25], y ∈ [−0.15, 0.2], depth 2: fx 90, fy 80.
    let (x0, x1, y0, y1, z) = (-0.2f32, 0.25f32, -0.15f32, 0.2f32, 2.0f32);
    let positions = [[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]];
    // Counter-clockwise seen from the camera (at the origin, looking along +z with y down).
    let faces = [[0u32, 3, 2], [0, 2, 1]];
    let attributes = [[1.0f64]; 4];
    let out = render(&positions, &faces, &attributes, &cam, [0.0]);
    let area = (90.0 * (x1 - x0) as f64 / z as f64) * (80.0 * (y1 - y0) as f64 / z as f64);
    let soft: f64 = out.image.iter().map(|p| p[0]).sum();
    let hard = out.raster.face_id.iter().filter(|&&f| f != mannequin_raster::NO_FACE).count() as f64;
    println!("area {area:.3} px², antialiased {soft:.3}, hard {hard}");
    assert!((soft - area).abs() < 0.02 * area, "antialiased coverage {soft} vs area {area}");
    assert!((soft - area).abs() < (hard - area).abs(), "antialiasing should beat the hard count");
}
