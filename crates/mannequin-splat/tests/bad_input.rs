//! Bad input: non-finite Gaussians are skipped and counted, never drawn; values outside their
//! domain, degenerate cameras and mismatched arrays are errors that say what is wrong.

mod common;

use common::{ColorForm, RotForm, Scene, camera};
use mannequin_splat::{Camera, OutputGrads, RenderOptions, SplatError, backward, render};

fn without(scene: &Scene, i: usize) -> Scene {
    let mut s = scene.clone();
    let cut = |v: &mut Vec<f64>, per: usize| {
        v.drain(per * i..per * (i + 1));
    };
    cut(&mut s.means, 3);
    cut(&mut s.quats, 4);
    cut(&mut s.matrices, 9);
    cut(&mut s.scales, 3);
    cut(&mut s.opacities, 1);
    cut(&mut s.sh, 3 * (s.sh_degree + 1) * (s.sh_degree + 1));
    cut(&mut s.features, s.channels);
    s
}

#[test]
fn non_finite_gaussians_are_skipped_counted_and_leave_the_image_as_without_them() {
    let scene = Scene::random(30, 21, 1, 3);
    let cam = camera(40, 32);
    let opts = RenderOptions::default();
    let reference = {
        let mut s = scene.clone();
        for &i in [17, 9, 4, 2].iter() {
            s = without(&s, i);
        }
        render(&s.cast::<f32>().gaussians(RotForm::Quaternion, ColorForm::Sh(1)), &cam, &opts).unwrap()
    };
    let mut bad = scene.clone();
    bad.means[3 * 2 + 1] = f64::NAN;
    bad.scales[3 * 4] = f64::INFINITY;
    bad.sh[12 * 9 + 5] = f64::NEG_INFINITY;
    bad.opacities[17] = f64::NAN;
    let t = bad.cast::<f32>();
    let g = t.gaussians(RotForm::Quaternion, ColorForm::Sh(1));
    let out = render(&g, &cam, &opts).unwrap();
    assert_eq!(out.skipped, 4);
    assert!(out.image.iter().chain(&out.alpha).chain(&out.depth).all(|v| v.is_finite()));
    for (a, b) in out.image.iter().zip(&reference.image) {
        assert!((a - b).abs() < 1e-6, "{a} vs {b}");
    }
    let d: Vec<f32> = vec![1.0; out.image.len()];
    let grads =
        backward(&g, &cam, &opts, &out, &OutputGrads { image: Some(&d), ..Default::default() }).unwrap();
    for i in [2, 4, 9, 17] {
        assert!(grads.means[3 * i..3 * i + 3].iter().all(|&v| v == 0.0), "Gaussian {i}");
        assert_eq!(grads.opacities[i], 0.0);
    }
    assert!(grads.means.iter().chain(&grads.colors).chain(&grads.scales).all(|v| v.is_finite()));
    assert!(grads.means.iter().any(|&v| v != 0.0));
}

fn error_of(scene: &Scene, cam: &Camera) -> String {
    let t = scene.cast::<f32>();
    render(&t.gaussians(RotForm::Quaternion, ColorForm::Sh(1)), cam, &RenderOptions::default())
        .unwrap_err()
        .to_string()
}

#[test]
fn values_outside_their_domain_are_errors_naming_the_gaussian() {
    let scene = Scene::random(8, 22, 1, 3);
    let cam = camera(16, 16);
    let mut s = scene.clone();
    s.scales[3 * 5 + 2] = 0.0;
    let e = error_of(&s, &cam);
    assert!(e.contains("scale of Gaussian 5") && e.contains("positive"), "{e}");
    let mut s = scene.clone();
    s.scales[3] = -0.1;
    assert!(error_of(&s, &cam).contains("scale of Gaussian 1"));
    let mut s = scene.clone();
    s.opacities[6] = 1.5;
    let e = error_of(&s, &cam);
    assert!(e.contains("opacity of Gaussian 6") && e.contains("[0, 1]"), "{e}");
}

#[test]
fn degenerate_cameras_and_empty_images_are_errors() {
    let scene = Scene::random(4, 23, 1, 3);
    let mut cam = camera(16, 16);
    cam.height = 0;
    assert!(error_of(&scene, &cam).contains("empty"));
    let mut cam = camera(16, 16);
    cam.intrinsic[0][0] = -5.0;
    assert!(error_of(&scene, &cam).contains("focal"));
    let mut cam = camera(16, 16);
    cam.far = cam.near;
    assert!(error_of(&scene, &cam).contains("near < far"));
}

#[test]
fn mismatched_arrays_and_options_are_errors() {
    let scene = Scene::random(4, 24, 1, 3);
    let cam = camera(16, 16);
    let t = scene.cast::<f32>();
    let mut g = t.gaussians(RotForm::Quaternion, ColorForm::Sh(1));
    g.scales = &t.scales[..9];
    let e = render(&g, &cam, &RenderOptions::default()).unwrap_err();
    assert!(matches!(e, SplatError::Shape { field: "scales", expected: 12, found: 9 }), "{e}");
    let g = t.gaussians(RotForm::Quaternion, ColorForm::Sh(1));
    let opts = RenderOptions { background: vec![1.0, 1.0], ..RenderOptions::default() };
    assert!(
        render(&g, &cam, &opts).unwrap_err().to_string().contains("background has 2 values for 3 channels")
    );
    let opts = RenderOptions { max_alpha: 1.0, ..RenderOptions::default() };
    assert!(render(&g, &cam, &opts).unwrap_err().to_string().contains("max_alpha"));
}
