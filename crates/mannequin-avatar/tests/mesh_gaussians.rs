//! Tavatar's Gaussian derivation (Eqs. 5–11) on triangles whose answers are known by hand, and
//! its gradient with respect to the vertices against central finite differences in f64.

use burn::tensor::{DType, Device, Tensor, TensorData};
use mannequin_avatar::mesh_gaussians::{
    FACE_SCALE, Faces, MeshIndex, NORMAL_SCALE, VERTEX_SCALE, face_gaussians, vertex_gaussians,
    vertex_normals,
};

fn vertices(v: &[[f64; 3]], device: &Device) -> Tensor<2> {
    let flat: Vec<f64> = v.iter().flatten().copied().collect();
    Tensor::from_data(TensorData::new(flat, [v.len(), 3]), (device, DType::F64))
}

fn values<const D: usize>(t: Tensor<D>) -> Vec<f64> {
    t.into_data().convert::<f64>().iter::<f64>().collect()
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

#[test]
fn right_triangle_3_4_5_has_incenter_1_1_and_inradius_1() {
    // Legs 3 and 4 along x and y: the incircle touches both legs, so its centre is (r, r) with
    // r = (3 + 4 − 5) / 2 = 1.
    let device = Device::flex();
    let v = vertices(&[[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [0.0, 4.0, 0.0]], &device);
    let index = MeshIndex::new(3, &[[0, 1, 2]], &device);
    let g = face_gaussians(&Faces::of(&v, &index));
    assert_eq!(values(g.means), vec![1.0, 1.0, 0.0]);
    let s = values(g.scales);
    assert!(close(s[0], FACE_SCALE, 1e-12) && close(s[1], FACE_SCALE, 1e-12), "{s:?}");
    assert!(close(s[2], NORMAL_SCALE, 1e-15));
    // Frame columns: t1 along the first edge (+x), n = +z (counter-clockwise), t2 = n × t1 = +y.
    let r = values(g.frames); // row-major [3, 3], column j = axis j
    let want = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
    for (a, b) in r.iter().zip(want) {
        assert!(close(*a, b, 1e-12), "{r:?}");
    }
}

#[test]
fn equilateral_triangle_incenter_is_centroid_and_inradius_is_side_over_2_sqrt3() {
    let device = Device::flex();
    let h = 3f64.sqrt() / 2.0;
    let v = vertices(&[[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.5, h, 1.0]], &device);
    let index = MeshIndex::new(3, &[[0, 1, 2]], &device);
    let g = face_gaussians(&Faces::of(&v, &index));
    let m = values(g.means);
    assert!(close(m[0], 0.5, 1e-12) && close(m[1], h / 3.0, 1e-12) && close(m[2], 1.0, 1e-12));
    let s = values(g.scales);
    assert!(close(s[0], FACE_SCALE / (2.0 * 3f64.sqrt()), 1e-12), "{s:?}");
}

#[test]
fn pyramid_apex_normal_points_up_and_scale_is_shortest_edge() {
    // A square pyramid: apex (0, 0, 1) over (±1, ±1, 0); by symmetry the area-weighted normal at
    // the apex is +z, and its shortest one-ring edge is √3 (to every base corner).
    let device = Device::flex();
    let pts = [[0.0, 0.0, 1.0], [1.0, 1.0, 0.0], [-1.0, 1.0, 0.0], [-1.0, -1.0, 0.0], [1.0, -1.0, 0.0]];
    let faces = [[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]];
    let v = vertices(&pts, &device);
    let index = MeshIndex::new(5, &faces, &device);
    let n = values(vertex_normals(&Faces::of(&v, &index), &index));
    assert!(close(n[0], 0.0, 1e-12) && close(n[1], 0.0, 1e-12) && close(n[2], 1.0, 1e-12), "{n:?}");
    let g = vertex_gaussians(&v, &Faces::of(&v, &index), &index);
    let s = values(g.scales);
    assert!(close(s[0], VERTEX_SCALE * 3f64.sqrt(), 1e-12), "{s:?}");
    // A base corner's one ring: the apex (√3) and two base neighbours (2): the min is √3.
    assert!(close(s[3], VERTEX_SCALE * 3f64.sqrt(), 1e-12));
    // Every frame is a rotation: orthonormal columns with determinant +1.
    let r = values(g.frames);
    for f in r.chunks_exact(9) {
        let col = |j: usize| [f[j], f[3 + j], f[6 + j]];
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
        };
        for i in 0..3 {
            for j in 0..3 {
                assert!(close(dot(col(i), col(j)), f64::from(u8::from(i == j)), 1e-12));
            }
        }
        assert!(close(dot(cross(col(0), col(1)), col(2)), 1.0, 1e-12));
    }
    // Eq. 10: the reference axis is the one least aligned with n; for the apex (n = z) that is x
    // (first of the tied x, y), so t1 = x × z = −y.
    assert!(close(r[0], 0.0, 1e-12) && close(r[3], -1.0, 1e-12) && close(r[6], 0.0, 1e-12), "{:?}", &r[..9]);
}

/// Σ w · (means, scales, normals, frames) of face and vertex Gaussians, in f64.
fn objective(v: &[[f64; 3]], faces: &[[u32; 3]], device: &Device) -> (Tensor<2>, Tensor<1>) {
    let x = vertices(v, device);
    let x = if x.is_autodiff() { x.require_grad() } else { x };
    let index = MeshIndex::new(v.len(), faces, device);
    let faces = Faces::of(&x, &index);
    let fg = face_gaussians(&faces);
    let vg = vertex_gaussians(&x, &faces, &index);
    let mut total: Option<Tensor<1>> = None;
    let mut k = 0.0;
    let mut add = |t: Tensor<2>| {
        let [r, c] = t.dims();
        let w: Vec<f64> = (0..r * c).map(|i| ((i * 7 + 3) % 11) as f64 / 11.0 - 0.4 + k).collect();
        k += 0.1;
        let term = (t * Tensor::from_data(TensorData::new(w, [r, c]), (device, DType::F64))).sum();
        total = Some(match total.take() {
            Some(s) => s + term,
            None => term,
        });
    };
    for g in [fg, vg] {
        let n = g.frames.dims()[0];
        for t in [g.means, g.scales, g.normals, g.frames.reshape([n, 9])] {
            add(t);
        }
    }
    (x, total.unwrap())
}

#[test]
fn derivation_gradient_matches_finite_differences() {
    let device = Device::flex().autodiff();
    // A bumpy open fan of six triangles whose one-rings have no tied shortest edges (a tie makes
    // the min non-differentiable and finite differences meaningless).
    let pts: Vec<[f64; 3]> = vec![
        [0.0, 0.0, 0.1],
        [1.0, 0.1, 0.0],
        [0.6, 0.9, -0.1],
        [-0.4, 1.1, 0.2],
        [-1.2, 0.25, 0.0],
        [-0.5, -0.9, 0.15],
        [0.7, -1.0, -0.05],
    ];
    let faces = [[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5], [0, 5, 6], [0, 6, 1]];
    let (x, loss) = objective(&pts, &faces, &device);
    let grad = values(x.grad(&loss.backward()).unwrap());
    let plain = Device::flex();
    let f = |p: &[[f64; 3]]| values(objective(p, &faces, &plain).1)[0];
    let h = 1e-6;
    for i in 0..pts.len() {
        for a in 0..3 {
            let (mut up, mut down) = (pts.clone(), pts.clone());
            up[i][a] += h;
            down[i][a] -= h;
            let fd = (f(&up) - f(&down)) / (2.0 * h);
            let g = grad[3 * i + a];
            assert!((g - fd).abs() < 1e-6 * (1.0 + fd.abs()), "vertex {i} axis {a}: {g} vs {fd}");
        }
    }
}
