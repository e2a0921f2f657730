//! The procedural jog, the faster motion the cloth is held to, keeps the body out of itself no
//! worse than the walk: a body part inside another leaves the cloth between them nowhere to be.

use mannequin_body::Motion;
use mannequin_body::lbs::{pose_frames, shape_body};
use mannequin_body::model::BodyModel;
use mannequin_cloth::quality::self_intersecting_pairs;

#[test]
fn the_jog_crosses_the_body_no_more_than_the_walk() {
    let model = BodyModel::from_spec("default", None).unwrap();
    let faces = model.template_mesh().faces;
    let (walk, jog) = (Motion::walk_cycle(1.0, 30.0), Motion::jog_cycle(1.0, 30.0));
    // The jog moves twice as far a second as the walk, at a faster cadence.
    assert!(jog.trans[3 * 29 + 2] > 2.0 * walk.trans[3 * 29 + 2]);
    // The default shape and the one the walk folds least, every other frame (for time).
    for betas in [[0.0f32, 0.0], [0.0, -2.0]] {
        let shaped = shape_body(&model, &betas).unwrap();
        let worst = |motion: &Motion| {
            (0..motion.num_frames())
                .step_by(2)
                .map(|f| {
                    let pose = &motion.poses[72 * f..72 * (f + 1)];
                    let posed = pose_frames(&model, &shaped, pose, &[0.0; 3]).unwrap();
                    let v: Vec<[f32; 3]> =
                        posed.frame_vertices(0).chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
                    self_intersecting_pairs(&v, &faces)
                })
                .max()
                .unwrap()
        };
        // A wider arm swing (0.55 rad) made 21 more pairs in the armpits than the walk's 100.
        let (w, j) = (worst(&walk), worst(&jog));
        assert!(j <= w, "betas {betas:?}: the jog crosses the body in {j} pairs, the walk in {w}");
    }
}
