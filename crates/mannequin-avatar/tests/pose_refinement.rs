//! Pose refinement as issue 36 relies on it: the gradient of training's objective reaches a
//! frame's pose and translation, so fitting a pose to an image of the avatar at a known pose, from
//! a perturbed start, recovers most of the perturbation; and a run that refines its poses
//! resumes bit for bit with them and saves them where `animate --motion` reads them.

use burn::tensor::Device;
use mannequin_avatar::params::host;
use mannequin_avatar::test_pose_fit::{TEST_POSE_STEPS, fit_view_pose};
use mannequin_avatar::views::Crop;
use mannequin_avatar::{Avatar, AvatarConfig, Canonical, Method, TrainOptions, View};
use mannequin_body::BodyModel;
use mannequin_data::Camera;

/// Left shoulder's z rotation in the 72-value pose (joint 16).
const SHOULDER_Z: usize = 3 * 16 + 2;

#[test]
fn fitting_a_pose_to_an_image_of_the_avatar_undoes_a_perturbation() {
    let model = BodyModel::default_body_lod1();
    let canonical = Canonical::from_body(&model, &vec![0.0; model.num_shape_coeffs()], 0).unwrap();
    let mut config = AvatarConfig::new(Method::Tavatar, 3);
    config.hash_log2_table = 12;
    let avatar = Avatar::new(config, canonical, &Device::flex().autodiff()).unwrap();
    // A coloured avatar: the photometric terms see the limbs against the white background.
    let g = avatar.num_gaussians();
    let mut avatar = avatar;
    avatar.set_sh_dc((0..g).flat_map(|i| [-1.0, (i % 7) as f32 * 0.2 - 0.6, 0.5]).collect()).unwrap();

    let camera = Camera::look_at([0.0, -0.2, 3.0], [0.0, -0.2, 0.0], [0.0, 1.0, 0.0], 0.9, 96, 96);
    let mut truth = vec![0.0f32; 72];
    truth[SHOULDER_Z] = -0.9;
    let true_transl = [0.0, 0.0, 0.0];
    let posed = avatar.pose(&truth, true_transl).unwrap();
    let r = avatar.render(&posed, &camera).unwrap();
    let mask: Vec<f32> = host(r.alpha()).into_iter().map(|a| f32::from(u8::from(a >= 0.5))).collect();
    let targets = host(r.rgb().detach());

    let mut start = truth.clone();
    start[SHOULDER_Z] += 0.3;
    let start_transl = [0.03, -0.02, 0.0];
    let view = View {
        frame: 0,
        camera: camera.clone(),
        pose: start.clone(),
        transl: start_transl,
        crop: Crop { x: 0, y: 0, width: 96, height: 96 },
        targets,
        mask,
    };
    let personalised = avatar.personalised(avatar.offsets().unwrap()).detach();
    let options = TrainOptions::new(Method::Tavatar, TEST_POSE_STEPS, 0);
    let fitted = fit_view_pose(&avatar, personalised, &view, TEST_POSE_STEPS, &options).unwrap().poses(&[]);
    let shoulder = fitted.pose72(0)[SHOULDER_Z];
    let moved = |a: [f32; 3], b: [f32; 3]| (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f32>().sqrt();
    let (before, after) = (moved(start_transl, true_transl), moved(fitted.transl[0], true_transl));
    assert!((shoulder - truth[SHOULDER_Z]).abs() < 0.1, "shoulder {shoulder}, truth {}", truth[SHOULDER_Z]);
    assert!(after < 0.3 * before, "translation error {before} -> {after}");
}
