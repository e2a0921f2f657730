//! The forward pass against golden outputs of the `smplx` package (tools/oracles/body_smplx.py)
//! on full-size random SMPL, SMPL-H and SMPL-X models: vertices and joints within 1e-5 m.

mod common;

use mannequin_body::{BodyModel, ModelFamily, forward, parse_model};
use mannequin_io::Npz;

fn fixture(name: &str) -> Npz {
    Npz::read(format!("{}/tests/fixtures/smplx_{name}.npz", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

fn f32s(npz: &Npz, key: &str) -> Vec<f32> {
    npz.require(key).unwrap().to_f32().unwrap()
}

fn check_family(name: &str, family: ModelFamily, grid: (usize, usize)) {
    let fx = fixture(name);
    let joints = fx.require("joint_count").unwrap().to_i64().unwrap()[0] as usize;
    let components = fx.require("components").unwrap().to_i64().unwrap()[0] as usize;
    let bytes = common::random_model::random_model_npz(joints, components, grid.0, grid.1);
    let model: BodyModel =
        parse_model(&Npz::from_bytes("random.npz".into(), &bytes).unwrap(), Some(10)).unwrap();
    assert_eq!(model.family, family);

    let betas = f32s(&fx, "betas");
    let expression = f32s(&fx, "expression");
    let poses = f32s(&fx, "pose");
    let transl = f32s(&fx, "transl");
    let ids = fx.require("vertex_ids").unwrap().to_i64().unwrap();
    let want_v = fx.require("vertices").unwrap().to_f64().unwrap();
    let want_j = fx.require("joints").unwrap().to_f64().unwrap();
    let frames = transl.len() / 3;
    let (mut worst_v, mut worst_j) = (0.0f64, 0.0f64);
    for f in 0..frames {
        // Shape vector: 10 betas, then expressions (zero past the 10 the oracle drives).
        let mut shape = betas[f * 10..(f + 1) * 10].to_vec();
        if model.num_expression() > 0 {
            let mut e = vec![0.0; model.num_expression()];
            e[..10].copy_from_slice(&expression[f * 10..(f + 1) * 10]);
            shape.extend(e);
        }
        let pose = &poses[f * 3 * joints..(f + 1) * 3 * joints];
        let out = forward(&model, &shape, pose, &transl[3 * f..3 * f + 3]).unwrap();
        let verts = out.frame_vertices(0);
        for (i, &id) in ids.iter().enumerate() {
            for c in 0..3 {
                let want = want_v[(f * ids.len() + i) * 3 + c];
                worst_v = worst_v.max((verts[id as usize * 3 + c] as f64 - want).abs());
            }
        }
        for (k, got) in out.frame_joints(0).iter().enumerate() {
            worst_j = worst_j.max((*got as f64 - want_j[f * joints * 3 + k]).abs());
        }
    }
    assert!(worst_v < 1e-5, "{name}: worst vertex error {worst_v} m");
    assert!(worst_j < 1e-5, "{name}: worst joint error {worst_j} m");
}

#[test]
fn smpl_matches_smplx() {
    check_family("smpl", ModelFamily::Smpl, (65, 106));
}

#[test]
fn smplh_matches_smplx() {
    check_family("smplh", ModelFamily::SmplH, (65, 106));
}

#[test]
fn smplx_matches_smplx() {
    check_family("smplx", ModelFamily::SmplX, (25, 419));
}
