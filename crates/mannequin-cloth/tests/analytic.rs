//! The solver against closed forms: a pendulum's length and period, a hanging triangle's stretch,
//! a hanging sheet's static equilibrium, a bent strip's return to its rest angle, and a strain
//! limit that holds whatever the compliance.

mod common;

use common::{grid, grid_index};
use mannequin_cloth::{Cloth, Material, Settings, Simulator, quality};
use mannequin_mesh::TriMesh;

fn material(density: f32, stretch: f32, bend: f32, damping: f32) -> Material {
    Material {
        name: "test",
        density,
        stretch_compliance: stretch,
        bend_compliance: bend,
        friction: 0.0,
        damping,
        strain_limit: NO_LIMIT,
    }
}

/// A strain limit no test scene reaches: the closed forms are of the compliant solver alone.
const NO_LIMIT: f32 = 1e3;

fn settings(substeps: u32, gravity: [f32; 3]) -> Settings {
    Settings { substeps, gravity, self_collision: false, ..Settings::default() }
}

const G: f32 = 9.81;

/// One triangle with its base a–b pinned on the x axis is a pendulum: the free vertex keeps its
/// distance L from the axis and swings about it with the period 2π√(L/g)·(1 + θ₀²/16).
#[test]
fn a_pendulum_keeps_its_length_and_period() {
    let (length, theta0) = (1.0f32, 0.1f32);
    let mesh = TriMesh::new(
        vec![[-0.5, 0.0, 0.0], [0.5, 0.0, 0.0], [0.0, -length * theta0.cos(), length * theta0.sin()]],
        vec![[0, 1, 2]],
    );
    let cloth = Cloth::new(&mesh, &material(1.0, 0.0, 1.0, 0.0), &[0, 1]).unwrap();
    let mut sim = Simulator::new(cloth, None, Vec::new(), settings(20, [0.0, -G, 0.0])).unwrap();
    let dt = 1.0 / 60.0;
    let mut crossings = Vec::new();
    let mut last_z = sim.positions()[2][2];
    let mut worst_length_error = 0.0f32;
    for frame in 1..=360 {
        sim.step_frame(&[], &[], dt).unwrap();
        let [_, y, z] = sim.positions()[2];
        worst_length_error = worst_length_error.max(((y * y + z * z).sqrt() - length).abs());
        if last_z > 0.0 && z <= 0.0 {
            crossings.push(dt * (frame as f32 - z / (z - last_z)));
        }
        last_z = z;
    }
    assert!(worst_length_error < 1e-3 * length, "length drifted by {worst_length_error} m");
    let periods: Vec<f32> = crossings.windows(2).map(|w| w[1] - w[0]).collect();
    assert!(periods.len() >= 2, "crossings {crossings:?}");
    let expected = std::f32::consts::TAU * (length / G).sqrt() * (1.0 + theta0 * theta0 / 16.0);
    for period in periods {
        assert!((period / expected - 1.0).abs() < 0.01, "period {period} s, expected {expected} s");
    }
}

/// A triangle hanging from its pinned base: at rest each side edge is stretched by α·T, where the
/// tension T holds up the free vertex's weight, 2·T·(depth / l) = m·g. Checked on a soft and a
/// stiff edge (α/Δt² above and below the particle's inverse mass), within 2% of the extension: one
/// constraint pass per substep leaves an O(g·Δt²) bias, here about 1e-5 m.
#[test]
fn a_hanging_triangle_stretches_by_compliance_times_tension() {
    let (half_base, height, density) = (0.1f32, 0.2f32, 0.2f32);
    let mass = density * half_base * height / 3.0;
    let rest = (half_base * half_base + height * height).sqrt();
    for compliance in [1.5f32, 0.05] {
        let mesh = TriMesh::new(
            vec![[-half_base, 0.0, 0.0], [half_base, 0.0, 0.0], [0.0, -height, 0.0]],
            vec![[0, 1, 2]],
        );
        let cloth = Cloth::new(&mesh, &material(density, compliance, 1.0, 4.0), &[0, 1]).unwrap();
        let mut sim = Simulator::new(cloth, None, Vec::new(), settings(20, [0.0, -G, 0.0])).unwrap();
        for _ in 0..600 {
            sim.step_frame(&[], &[], 1.0 / 60.0).unwrap();
        }
        // Solve 2·((l − l₀)/α)·√(l² − a²)/l = m·g for the stretched length l by bisection.
        let imbalance = |l: f64| {
            let a = half_base as f64;
            2.0 * (l - rest as f64) / compliance as f64 * (l * l - a * a).sqrt() / l - (mass * G) as f64
        };
        let (mut lo, mut hi) = (rest as f64, 2.0 * rest as f64);
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if imbalance(mid) > 0.0 { hi = mid } else { lo = mid }
        }
        let expected_depth = (lo * lo - (half_base * half_base) as f64).sqrt();
        let depth = -sim.positions()[2][1] as f64;
        let extension = expected_depth - height as f64;
        assert!(
            (depth - expected_depth).abs() < 0.02 * extension,
            "α = {compliance}: depth {depth}, expected {expected_depth} (extension {extension})"
        );
        let [x, _, z] = sim.positions()[2];
        assert!(x.abs().max(z.abs()) < 0.05 * extension as f32, "off the symmetry plane: {x}, {z}");
    }
}

/// A sheet hanging from its top row settles where its spring energy plus gravity is least:
/// the equilibrium found here by Newton's method on Σ(l − l₀)²/(2α) + Σ m·g·y in f64.
/// One constraint pass per substep leaves a bias that shrinks as Δt²: at 20 substeps per 1/60 s
/// it is within 2.5% of the sag, and doubling the substeps from 10 to 20 divides it by about 4.
#[test]
fn a_hanging_sheet_settles_at_its_static_equilibrium() {
    let (nx, ny, spacing, density, compliance) = (6, 10, 0.05f32, 0.2f32, 0.1f32);
    let mesh = grid(nx, ny, spacing, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]);
    let pins: Vec<u32> = (0..nx).map(|i| grid_index(nx, i, 0)).collect();
    let reference = newton_equilibrium(&mesh, &pins, density as f64, compliance as f64);
    let sag =
        reference.iter().zip(&mesh.positions).map(|(r, p)| (r[1] - p[1] as f64).abs()).fold(0.0, f64::max);
    assert!(sag > 0.01, "the test needs a visible sag, got {sag} m");
    let error = |substeps: u32| {
        let cloth = Cloth::new(&mesh, &material(density, compliance, 1e9, 4.0), &pins).unwrap();
        let mut sim = Simulator::new(cloth, None, Vec::new(), settings(substeps, [0.0, -G, 0.0])).unwrap();
        for _ in 0..900 {
            sim.step_frame(&[], &[], 1.0 / 60.0).unwrap();
        }
        sim.positions()
            .iter()
            .zip(&reference)
            .map(|(p, r)| (0..3).map(|k| (p[k] as f64 - r[k]).powi(2)).sum::<f64>().sqrt())
            .fold(0.0, f64::max)
    };
    let (coarse, fine) = (error(10), error(20));
    assert!(fine < 0.025 * sag, "largest distance from equilibrium {fine} m for a sag of {sag} m");
    assert!(coarse > 3.0 * fine, "the bias should shrink as Δt²: {coarse} m at 10 substeps, {fine} m at 20");
}

/// Minimises the sheet's energy over its free vertices in the sheet's plane (x, y) by Newton's
/// method with a backtracking line search; the Hessian's compressive part is dropped so every
/// step goes downhill.
fn newton_equilibrium(mesh: &TriMesh, pins: &[u32], density: f64, compliance: f64) -> Vec<[f64; 3]> {
    let n = mesh.positions.len();
    let mut mass = vec![0.0f64; n];
    let p64 = |i: u32| mesh.positions[i as usize].map(f64::from);
    for f in &mesh.faces {
        let [a, b, c] = f.map(p64);
        let cross_z = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        for &i in f {
            mass[i as usize] += cross_z.abs() / 6.0 * density;
        }
    }
    let mut edges: Vec<[u32; 2]> = mesh
        .faces
        .iter()
        .flat_map(|f| [[f[0], f[1]], [f[1], f[2]], [f[2], f[0]]])
        .map(|[a, b]| [a.min(b), a.max(b)])
        .collect();
    edges.sort_unstable();
    edges.dedup();
    let rest: Vec<f64> = edges.iter().map(|&[a, b]| dist2(p64(a), p64(b))).collect();
    let free: Vec<usize> = (0..n).filter(|i| !pins.contains(&(*i as u32))).collect();
    let slot: Vec<Option<usize>> = (0..n).map(|i| free.iter().position(|&f| f == i)).collect();
    let mut x: Vec<[f64; 2]> = mesh.positions.iter().map(|p| [p[0] as f64, p[1] as f64]).collect();
    let energy = |x: &[[f64; 2]]| {
        let springs: f64 = edges
            .iter()
            .zip(&rest)
            .map(|(&[a, b], &l0)| (dist2x(x[a as usize], x[b as usize]) - l0).powi(2) / (2.0 * compliance))
            .sum();
        springs + (0..n).map(|i| mass[i] * G as f64 * x[i][1]).sum::<f64>()
    };
    let dof = 2 * free.len();
    for _ in 0..100 {
        let mut grad = vec![0.0; dof];
        let mut hess = vec![0.0; dof * dof];
        for (i, &v) in free.iter().enumerate() {
            grad[2 * i + 1] += mass[v] * G as f64;
        }
        for (&[a, b], &l0) in edges.iter().zip(&rest) {
            let (xa, xb) = (x[a as usize], x[b as usize]);
            let d = [xa[0] - xb[0], xa[1] - xb[1]];
            let l = (d[0] * d[0] + d[1] * d[1]).sqrt();
            let nrm = [d[0] / l, d[1] / l];
            let k = 1.0 / compliance;
            let f = [k * (l - l0) * nrm[0], k * (l - l0) * nrm[1]];
            let tangential = (1.0 - l0 / l).max(0.0);
            let block = |r: usize, c: usize| {
                k * (nrm[r] * nrm[c] + tangential * ((r == c) as u8 as f64 - nrm[r] * nrm[c]))
            };
            for (vertex, sign) in [(a, 1.0), (b, -1.0)] {
                if let Some(i) = slot[vertex as usize] {
                    grad[2 * i] += sign * f[0];
                    grad[2 * i + 1] += sign * f[1];
                }
            }
            for (va, sa) in [(a, 1.0), (b, -1.0)] {
                for (vb, sb) in [(a, 1.0), (b, -1.0)] {
                    if let (Some(i), Some(j)) = (slot[va as usize], slot[vb as usize]) {
                        for r in 0..2 {
                            for c in 0..2 {
                                hess[(2 * i + r) * dof + 2 * j + c] += sa * sb * block(r, c);
                            }
                        }
                    }
                }
            }
        }
        let step = solve(hess, grad.iter().map(|g| -g).collect(), dof);
        let e0 = energy(&x);
        let mut t = 1.0;
        loop {
            let mut trial = x.clone();
            for (i, &v) in free.iter().enumerate() {
                trial[v][0] += t * step[2 * i];
                trial[v][1] += t * step[2 * i + 1];
            }
            if energy(&trial) <= e0 || t < 1e-12 {
                x = trial;
                break;
            }
            t *= 0.5;
        }
        if grad.iter().map(|g| g * g).sum::<f64>().sqrt() < 1e-12 {
            break;
        }
    }
    x.iter().map(|p| [p[0], p[1], 0.0]).collect()
}

fn dist2(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

fn dist2x(a: [f64; 2], b: [f64; 2]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}

/// Dense Gaussian elimination with partial pivoting.
fn solve(mut a: Vec<f64>, mut b: Vec<f64>, n: usize) -> Vec<f64> {
    for col in 0..n {
        let pivot = (col..n).max_by(|&i, &j| a[i * n + col].abs().total_cmp(&a[j * n + col].abs())).unwrap();
        for k in 0..n {
            a.swap(col * n + k, pivot * n + k);
        }
        b.swap(col, pivot);
        for row in col + 1..n {
            let factor = a[row * n + col] / a[col * n + col];
            for k in col..n {
                a[row * n + k] -= factor * a[col * n + k];
            }
            b[row] -= factor * b[col];
        }
    }
    let mut x = vec![0.0; n];
    for row in (0..n).rev() {
        let s: f64 = (row + 1..n).map(|k| a[row * n + k] * x[k]).sum();
        x[row] = (b[row] - s) / a[row * n + row];
    }
    x
}

/// Unsigned angle between the normals of two triangles, by arccos: a different formula from the
/// solver's atan2.
fn fold_angle(p: &[[f32; 3]], t1: [u32; 3], t2: [u32; 3]) -> f64 {
    let normal = |t: [u32; 3]| {
        let [a, b, c] = t.map(|i| p[i as usize].map(f64::from));
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
        let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        n.map(|c| c / l)
    };
    let (n1, n2) = (normal(t1), normal(t2));
    (n1[0] * n2[0] + n1[1] * n2[1] + n1[2] * n2[2]).clamp(-1.0, 1.0).acos()
}

/// A strip whose rest shape is an arc (every cross-hinge folded by the same angle) is flattened
/// and let go without gravity: it curls back to its rest angles, on the same side.
#[test]
fn a_bent_strip_returns_to_its_rest_angle() {
    let (cells, spacing, radius) = (8, 0.02f32, 0.06f32);
    let step = spacing / radius;
    let mut mesh = grid(cells + 1, 2, spacing, [0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    for (k, p) in mesh.positions.iter_mut().enumerate() {
        let angle = (k % (cells + 1)) as f32 * step - 0.5 * cells as f32 * step;
        *p = [radius * angle.sin(), p[1], radius * (1.0 - angle.cos())];
    }
    let rest = mesh.positions.clone();
    let cloth = Cloth::new(&mesh, &material(0.2, 1e-6, 10.0, 2.0), &[]).unwrap();
    let mut sim = Simulator::new(cloth, None, Vec::new(), settings(10, [0.0; 3])).unwrap();
    let flat: Vec<[f32; 3]> = (0..rest.len())
        .map(|k| [(k % (cells + 1)) as f32 * spacing, (k / (cells + 1)) as f32 * spacing, 0.0])
        .collect();
    let mut state = sim.state();
    state.positions = flat.clone();
    sim.restore(state).unwrap();
    let faces = mesh.faces.clone();
    // Across the vertical edge between cells i and i+1: the second triangle of cell i and the
    // first of cell i+1.
    let cross_hinges: Vec<([u32; 3], [u32; 3])> =
        (0..cells - 1).map(|i| (faces[2 * i], faces[2 * i + 2])).collect();
    for &(t1, t2) in &cross_hinges {
        assert!(fold_angle(&flat, t1, t2) < 1e-6);
    }
    for _ in 0..300 {
        sim.step_frame(&[], &[], 1.0 / 60.0).unwrap();
    }
    let p = sim.positions();
    for &(t1, t2) in &cross_hinges {
        let (now, wanted) = (fold_angle(p, t1, t2), fold_angle(&rest, t1, t2));
        assert!((now - wanted).abs() < 1e-3, "hinge angle {now}, rest {wanted}");
    }
    let middle = p[cells / 2][2];
    assert!(p[0][2] > middle + 0.01 && p[cells][2] > middle + 0.01, "curled to the wrong side: {p:?}");
}

/// A sheet far too compliant for its weight hangs stretched by a fifth and more; with a strain
/// limit of 5 % its 99th-percentile edge stretch stays within a tenth of the limit (the solver's
/// few passes per substep leave 5.1 % on this 20-row chain) and its worst edge within twice it,
/// whatever the compliance lets the edges do.
#[test]
fn a_strain_limit_holds_a_compliant_sheet() {
    let (nx, ny) = (10, 20);
    let mesh = grid(nx, ny, 0.02, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]);
    let pins: Vec<u32> = (0..nx).map(|i| grid_index(nx, i, 0)).collect();
    let stretch = |limit: f32| {
        let fabric = Material { strain_limit: limit, ..material(0.3, 0.5, 1e5, 4.0) };
        let cloth = Cloth::new(&mesh, &fabric, &pins).unwrap();
        let mut sim = Simulator::new(cloth, None, Vec::new(), settings(20, [0.0, -G, 0.0])).unwrap();
        for _ in 0..120 {
            sim.step_frame(&[], &[], 1.0 / 60.0).unwrap();
        }
        let p99 = quality::stretch_quantile(&mesh.positions, sim.positions(), &mesh.faces, 0.99);
        let worst = quality::stretch_quantile(&mesh.positions, sim.positions(), &mesh.faces, 1.0);
        (p99, worst)
    };
    let (free, _) = stretch(NO_LIMIT);
    assert!(free > 0.2, "without a limit the sheet should stretch past 20 %, got {free}");
    let (p99, worst) = stretch(0.05);
    assert!(p99 <= 0.055 && worst <= 0.1, "p99 stretch {p99}, worst {worst} against a 5 % limit");
}
