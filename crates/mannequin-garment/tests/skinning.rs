//! Eq. 3.3 against the body's own skinning: a "garment" that is the body surface itself (each
//! vertex bound to its body vertex, no offset) must take the body's weights exactly through the
//! GRBF transfer, and then pose exactly as the body does through `pose_frames`, the path checked
//! against smplx; with betas, the transfer (Eq. 3.2) must follow the shape too.

use mannequin_body::{BodyModel, Motion, forward};
use mannequin_garment::{Category, Dressed, Ease, Garment, Recipe};
use mannequin_mesh::SurfacePoint;

#[test]
fn the_body_as_a_garment_poses_as_the_body() {
    let model = BodyModel::default_body_lod1();
    let body = model.template_mesh();
    let mut binding = vec![SurfacePoint { face: 0, bary: [0.0; 3] }; body.vertex_count()];
    for (f, tri) in body.faces.iter().enumerate() {
        for (k, &v) in tri.iter().enumerate() {
            let mut bary = [0.0; 3];
            bary[k] = 1.0;
            binding[v as usize] = SurfacePoint { face: f as u32, bary };
        }
    }
    let recipe = Recipe {
        category: Category::Tshirt,
        fit: Ease::size("M").unwrap(),
        edge_length: 0.015,
        material: mannequin_cloth::Material::COTTON,
        body: "default-lod1".into(),
        betas: vec![],
        body_vertices: model.num_vertices(),
        body_faces: body.faces.len(),
    };
    let garment =
        Garment { recipe, mesh: body.clone(), binding, offsets: vec![[0.0; 3]; body.vertex_count()] };
    let betas = [1.5, -1.0, 0.5];
    let dressed = Dressed::new(&garment, &model, &betas).unwrap();

    // The weights: rows sum to one and equal the body's rows (no two body vertices coincide).
    let j = model.num_joints();
    for (v, (row, body_row)) in
        dressed.weights.chunks_exact(j).zip(model.weights().chunks_exact(j)).enumerate()
    {
        assert!((row.iter().sum::<f32>() - 1.0).abs() < 1e-5, "vertex {v}: sum {}", row.iter().sum::<f32>());
        for (a, b) in row.iter().zip(body_row) {
            assert!((a - b).abs() < 1e-6, "vertex {v}: {row:?} vs {body_row:?}");
        }
    }

    let motion = Motion::walk_cycle(0.5, 10.0);
    let poses = motion.poses_for(&model).unwrap();
    let frames = forward(&model, &betas, &poses, &motion.trans).unwrap();
    let pl = model.pose_len();
    for f in 0..motion.num_frames() {
        let posed = dressed.posed(&poses[f * pl..(f + 1) * pl], &motion.trans[3 * f..3 * f + 3]).unwrap();
        let expected = frames.frame_vertices(f);
        let worst = posed.iter().flatten().zip(expected).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
        assert!(worst < 1e-5, "frame {f}: {worst} m from the body's own LBS");
    }
}
