//! The embedded default body: a SMPL-compatible skeleton in SMPL's T-pose convention, weights that
//! sum to one, a shape space, UVs, and named poses that put joints where a person's would be.

use glam::Vec3;
use mannequin_body::{BodyModel, ModelFamily, forward, named_pose, shape_body};

fn joints_of(model: &BodyModel, pose: &str, shape: &[f32]) -> Vec<Vec3> {
    let out = forward(model, shape, &named_pose(pose).unwrap(), &[0.0; 3]).unwrap();
    out.frame_joints(0).chunks_exact(3).map(Vec3::from_slice).collect()
}

fn height(model: &BodyModel, shape: &[f32]) -> f32 {
    let v = shape_body(model, shape).unwrap().vertices;
    let ys = v.chunks_exact(3).map(|p| p[1]);
    ys.clone().fold(f32::MIN, f32::max) - ys.fold(f32::MAX, f32::min)
}

fn levels() -> [BodyModel; 2] {
    [BodyModel::default_body(), BodyModel::default_body_lod1()]
}

#[test]
fn is_smpl_compatible_with_uvs_and_shape_space() {
    let [full, lod1] = levels();
    assert!(full.num_vertices() > 10_000, "{}", full.num_vertices());
    assert!((500..2000).contains(&lod1.num_vertices()), "{}", lod1.num_vertices());
    for m in [&full, &lod1] {
        assert_eq!(m.family, ModelFamily::Smpl);
        assert!(m.num_betas() >= 10);
        let uv = m.uv.as_ref().expect("UVs");
        assert_eq!(uv.faces.len(), m.faces.len());
        assert!(uv.coords.iter().flatten().all(|&c| (-0.01..=1.01).contains(&c)));
        for (v, row) in m.weights().chunks_exact(24).enumerate() {
            let s: f32 = row.iter().sum();
            assert!((s - 1.0).abs() < 1e-4, "vertex {v} weights sum to {s}");
        }
        // Every vertex is on the surface: no helper geometry left over.
        let mut used = vec![false; m.num_vertices()];
        m.faces.iter().flatten().for_each(|&i| used[i as usize] = true);
        assert!(used.iter().all(|&u| u));
    }
}

#[test]
fn average_adult_height_and_plausible_shapes() {
    let m = BodyModel::default_body_lod1();
    let h0 = height(&m, &[]);
    assert!((1.55..1.85).contains(&h0), "β = 0 height {h0}");
    for k in 0..m.num_betas().min(10) {
        for s in [-2.0, 2.0] {
            let mut b = vec![0.0; k + 1];
            b[k] = s;
            let h = height(&m, &b);
            assert!((1.35..2.05).contains(&h), "β{k} = {s}: height {h}");
        }
    }
}

/// (parent, child, expected direction) in SMPL's rest pose: Y up, facing +Z, left = +X.
const BONES: &[(usize, usize, [f32; 3], f32)] = &[
    (1, 4, [0.0, -1.0, 0.0], 0.95),
    (2, 5, [0.0, -1.0, 0.0], 0.95),
    (4, 7, [0.0, -1.0, 0.0], 0.95),
    (5, 8, [0.0, -1.0, 0.0], 0.95),
    // SMPL's own pelvis->spine1 leans back (cos 0.96); MakeHuman's leans a little more.
    (0, 3, [0.0, 1.0, 0.0], 0.85),
    (3, 6, [0.0, 1.0, 0.0], 0.9),
    (6, 9, [0.0, 1.0, 0.0], 0.9),
    (12, 15, [0.0, 1.0, 0.0], 0.8),
    (16, 18, [1.0, 0.0, 0.0], 0.95),
    (18, 20, [1.0, 0.0, 0.0], 0.95),
    (20, 22, [1.0, 0.0, 0.0], 0.9),
    (17, 19, [-1.0, 0.0, 0.0], 0.95),
    (19, 21, [-1.0, 0.0, 0.0], 0.95),
    (21, 23, [-1.0, 0.0, 0.0], 0.9),
    (13, 16, [1.0, 0.0, 0.0], 0.7),
    (14, 17, [-1.0, 0.0, 0.0], 0.7),
];

#[test]
fn rest_bones_follow_the_smpl_convention() {
    for m in levels() {
        let j = shape_body(&m, &[]).unwrap().joints;
        for &(a, b, dir, min_cos) in BONES {
            let d = (j[b] - j[a]).normalize();
            let cos = d.dot(Vec3::from(dir));
            assert!(cos > min_cos, "bone {a}->{b} direction {d} (cos {cos} to {dir:?})");
        }
        // Feet point forward: the ball of the foot is in front of the ankle.
        for (ankle, foot) in [(7, 10), (8, 11)] {
            assert!(j[foot].z - j[ankle].z > 0.05, "foot {foot} not in front of ankle");
        }
        assert!(j[1].x > 0.0 && j[2].x < 0.0, "left hip must be at +X");
    }
}

#[test]
fn named_poses_put_joints_where_a_person_would() {
    let m = BodyModel::default_body_lod1();
    let rest = joints_of(&m, "t-pose", &[]);
    let (head, l_wrist, r_wrist) = (15, 20, 21);

    let up = joints_of(&m, "arms-raised", &[]);
    assert!(up[l_wrist].y > up[head].y + 0.1 && up[r_wrist].y > up[head].y + 0.1, "wrists above the head");

    let a = joints_of(&m, "a-pose", &[]);
    assert!(a[l_wrist].y < a[16].y - 0.2 && a[l_wrist].x > 0.3, "A-pose left wrist down and out");

    let squat = joints_of(&m, "squat", &[]);
    for (hip, knee, ankle) in [(1, 4, 7), (2, 5, 8)] {
        assert!(squat[knee].z > squat[hip].z + 0.25, "knees forward of hips in a squat");
        assert!(squat[ankle].y < squat[knee].y - 0.2, "shins point down");
    }
    let drop = (rest[0].y - rest[7].y) - (squat[0].y - squat[7].y);
    assert!(drop > 0.25, "pelvis-to-ankle height drops by {drop} m");

    let walk = joints_of(&m, "walk", &[]);
    assert!(walk[7].z > walk[8].z + 0.2, "left foot leads in the walk frame");
    assert!(walk[l_wrist].y < walk[16].y, "arms hang while walking");

    let crossed = joints_of(&m, "arms-crossed", &[]);
    assert!(crossed[l_wrist].x < 0.15 && crossed[r_wrist].x > -0.15, "wrists cross the midline region");
    assert!(crossed[l_wrist].z > crossed[9].z, "forearms in front of the chest");
}
