//! Fitting the body to one person's landmarks (thesis §2.2.2). Where the thesis regresses the
//! parameters with a network, this solves for them directly, SMPLify-style, minimising:
//!
//! - Eq. 2.12's reprojection term: each BlazePose landmark's anchor on the body (`blazepose.rs`)
//!   projected by the camera, against the detected point, weighted by the landmark's visibility
//!   and made robust (a pseudo-Huber penalty, which behaves like Eq. 2.12's L1 beyond a few
//!   pixels and stays smooth for the solver);
//! - Eq. 2.14's 3D term, on the network's metric world landmarks (hip-centred, camera axes);
//! - the pose prior of `pose_prior.rs` in place of the adversarial term, and a shape prior.
//!
//! The camera is OpenCV's, at the world origin, turned half a turn about x so the world is
//! Y-up in front of it; the focal length is given or assumed. The body starts from a pose with
//! the arms down, turned onto the world landmarks (`rigid_alignment.rs`), at the distance that
//! best explains the 2D landmarks (a linear solve for the translation, the camera-axes world
//! landmarks supplying the rotation: PnP with the rotation known). Then Levenberg–Marquardt
//! runs in three stages: rotation and translation alone, everything under a strong prior, then
//! under the final prior.

use glam::{DMat3, DVec3, Vec3};
use mannequin_body::BodyModel;
use mannequin_body::rodrigues::{axis_angle_quat, quat_axis_angle};
use mannequin_body::smpl_joint::{L_HIP, L_SHOULDER, PELVIS, R_HIP, R_SHOULDER};
use mannequin_data::Camera;

use crate::blazepose::{Anchor, LANDMARKS, LEFT_HIP, LEFT_SHOULDER, RIGHT_HIP, RIGHT_SHOULDER};
use crate::error::FitError;
use crate::landmark_body::{LandmarkBody, PosedLandmarks};
use crate::levenberg_marquardt::{Summary, minimise};
use crate::pose_landmarker::{NUM_LANDMARKS, PoseLandmarks};
use crate::pose_prior;
use crate::rigid_alignment::best_rotation;

/// A landmark counts once its visibility × presence passes this.
const MIN_CONFIDENCE: f32 = 0.3;
/// Reprojection errors are measured in this fraction of the person's crop side (2.5× the
/// hip-to-head span), so weights do not depend on the picture's resolution.
const PIXEL_UNIT: f64 = 0.01;
/// The pseudo-Huber corner, in those units.
const ROBUST_DELTA: f64 = 2.0;
/// World landmarks are trusted to about this many metres.
const WORLD_SIGMA: f64 = 0.05;
const WORLD_WEIGHT: f64 = 0.5;
const LIMIT_WEIGHT: f64 = 30.0;
const REST_WEIGHT: f64 = 0.6;
const SHAPE_WEIGHT: f64 = 1.0;
/// Shoulders turned down by this much (radians) about z: the arms-down start.
const ARMS_DOWN: f32 = 1.2;

/// The fitted body, its camera and how well it explains the landmarks.
#[derive(Debug, Clone)]
pub struct BodyFit {
    pub betas: Vec<f32>,
    /// SMPL layout: 24 × axis-angle, global orientation first.
    pub pose: Vec<f32>,
    pub transl: [f32; 3],
    pub camera: Camera,
    /// Each landmark's anchor projected by the fitted camera (None: not mapped on the body).
    pub reprojected: Vec<Option<[f32; 2]>>,
    /// Each mapped, confident landmark's reprojection error in pixels.
    pub errors_px: Vec<Option<f32>>,
    pub stages: Vec<Summary>,
}

/// The world → camera turn: half a turn about x, so world Y-up and camera y-down agree.
fn flip(p: DVec3) -> DVec3 {
    DVec3::new(p.x, -p.y, -p.z)
}

/// The layout of the parameter vector: global orientation, body pose, shape, translation.
struct Layout {
    betas: usize,
}

impl Layout {
    const POSE: usize = 72;
    fn transl(&self) -> usize {
        Self::POSE + self.betas
    }
    fn len(&self) -> usize {
        self.transl() + 3
    }
    fn unpack(&self, p: &[f64]) -> (Vec<f32>, Vec<f32>, Vec3) {
        let pose = p[..Self::POSE].iter().map(|&v| v as f32).collect();
        let betas = p[Self::POSE..self.transl()].iter().map(|&v| v as f32).collect();
        let t = self.transl();
        (pose, betas, Vec3::new(p[t] as f32, p[t + 1] as f32, p[t + 2] as f32))
    }
}

/// What the fit compares the body with, in pixels and metres.
struct Observed {
    points: Vec<[f64; 2]>,
    world: Vec<DVec3>,
    confidence: Vec<f64>,
    /// Pixels per [`PIXEL_UNIT`] fraction of the crop.
    unit_px: f64,
}

/// The camera for a picture: focal `focal` pixels, principal point at the centre.
pub fn picture_camera(width: usize, height: usize, focal: f64) -> Camera {
    let k = [[focal, 0.0, width as f64 / 2.0], [0.0, focal, height as f64 / 2.0], [0.0, 0.0, 1.0]];
    let e = [[1.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, 0.0], [0.0, 0.0, -1.0, 0.0], [0.0, 0.0, 0.0, 1.0]];
    Camera::new(width, height, k, e)
}

/// A focal length for a picture whose camera is unknown: the long side spans about 53°, between
/// a phone's wide lens and a portrait lens.
pub fn assumed_focal(width: usize, height: usize) -> f64 {
    width.max(height) as f64
}

fn anchor_point(posed: &PosedLandmarks, vertex_slot: &[Option<usize>], i: usize) -> Option<Vec3> {
    match LANDMARKS[i].1 {
        Anchor::Joint(j) => Some(posed.joints[j]),
        Anchor::Vertex(_) => vertex_slot[i].map(|s| posed.vertices[s]),
        Anchor::Unmapped => None,
    }
}

/// Fits the body to one person's landmarks in a `width` × `height` picture.
pub fn fit_body(
    model: &BodyModel,
    person: &PoseLandmarks,
    width: usize,
    height: usize,
    focal: f64,
) -> Result<BodyFit, FitError> {
    if person.points.len() != NUM_LANDMARKS {
        return Err(FitError::input(
            "landmarks",
            format!("{} given, expected {NUM_LANDMARKS}", person.points.len()),
        ));
    }
    let mut vertices = Vec::new();
    let mut vertex_slot = vec![None; NUM_LANDMARKS];
    for (i, (_, anchor)) in LANDMARKS.iter().enumerate() {
        if let Anchor::Vertex(v) = anchor {
            if *v >= model.num_vertices() {
                return Err(FitError::input(
                    "body",
                    format!(
                        "the landmark table is made for the default body's {} vertices; this body has {}",
                        13380,
                        model.num_vertices()
                    ),
                ));
            }
            vertex_slot[i] = Some(vertices.len());
            vertices.push(*v);
        }
    }
    let body = LandmarkBody::new(model, &vertices);
    let layout = Layout { betas: body.num_betas() };
    let camera = picture_camera(width, height, focal);
    let observed = Observed {
        points: person.points.iter().map(|p| [p[0] as f64, p[1] as f64]).collect(),
        world: person.world.iter().map(|w| DVec3::new(w[0] as f64, w[1] as f64, w[2] as f64)).collect(),
        confidence: person
            .visibility
            .iter()
            .zip(&person.presence)
            .map(|(v, p)| {
                let c = v * p;
                if c >= MIN_CONFIDENCE { c as f64 } else { 0.0 }
            })
            .collect(),
        unit_px: PIXEL_UNIT * person.roi.width as f64,
    };
    let mut params = initial_parameters(&body, &layout, &observed, &camera)?;
    let residuals = |rest: f64| {
        let body = &body;
        let layout = &layout;
        let observed = &observed;
        let camera = &camera;
        let vertex_slot = &vertex_slot;
        move |p: &[f64]| -> Vec<f64> { residual_vector(body, layout, observed, camera, vertex_slot, p, rest) }
    };
    let global: Vec<usize> = (0..3).chain(layout.transl()..layout.len()).collect();
    let all: Vec<usize> = (0..layout.len()).collect();
    let stages = vec![
        minimise(&residuals(REST_WEIGHT), &mut params, &global, 30, 1e-4),
        minimise(&residuals(4.0 * REST_WEIGHT), &mut params, &all, 40, 1e-4),
        minimise(&residuals(REST_WEIGHT), &mut params, &all, 60, 1e-4),
    ];
    let (pose, betas, transl) = layout.unpack(&params);
    let posed = body.pose(&betas, &pose, transl);
    let reprojected: Vec<Option<[f32; 2]>> = (0..NUM_LANDMARKS)
        .map(|i| {
            anchor_point(&posed, &vertex_slot, i).map(|p| {
                let [u, v] = camera.project(camera.world_to_camera(p.as_dvec3()));
                [u as f32, v as f32]
            })
        })
        .collect();
    let errors_px = reprojected
        .iter()
        .enumerate()
        .map(|(i, r)| {
            r.filter(|_| observed.confidence[i] > 0.0).map(|[u, v]| {
                ((u as f64 - observed.points[i][0]).hypot(v as f64 - observed.points[i][1])) as f32
            })
        })
        .collect();
    Ok(BodyFit { betas, pose, transl: transl.to_array(), camera, reprojected, errors_px, stages })
}

/// The residuals at parameters `p`, with the prior's pull to rest weighted `rest`.
fn residual_vector(
    body: &LandmarkBody,
    layout: &Layout,
    observed: &Observed,
    camera: &Camera,
    vertex_slot: &[Option<usize>],
    p: &[f64],
    rest: f64,
) -> Vec<f64> {
    let (pose, betas, transl) = layout.unpack(p);
    let posed = body.pose(&betas, &pose, transl);
    let mut r = Vec::with_capacity(6 * NUM_LANDMARKS + 2 * 69 + layout.betas);
    let hips = flip((posed.joints[L_HIP] + posed.joints[R_HIP]).as_dvec3() / 2.0);
    for i in 0..NUM_LANDMARKS {
        let c = observed.confidence[i];
        let Some(x) = anchor_point(&posed, vertex_slot, i).filter(|_| c > 0.0) else {
            r.extend_from_slice(&[0.0; 5]);
            continue;
        };
        let xc = camera.world_to_camera(x.as_dvec3());
        let [u, v] = camera.project(xc.with_z(xc.z.max(1e-3)));
        let d =
            [(u - observed.points[i][0]) / observed.unit_px, (v - observed.points[i][1]) / observed.unit_px];
        let e = d[0].hypot(d[1]);
        // Pseudo-Huber: ρ(e) = 2δ²(√(1 + (e/δ)²) − 1), split along the error's direction.
        let scale = if e > 1e-12 {
            (2.0 * ROBUST_DELTA * ROBUST_DELTA * ((1.0 + (e / ROBUST_DELTA).powi(2)).sqrt() - 1.0)).sqrt() / e
        } else {
            1.0
        };
        r.push(c.sqrt() * scale * d[0]);
        r.push(c.sqrt() * scale * d[1]);
        let rel = flip(x.as_dvec3()) - hips - observed.world[i];
        let w = WORLD_WEIGHT * c.sqrt() / WORLD_SIGMA;
        r.extend_from_slice(&[w * rel.x, w * rel.y, w * rel.z]);
    }
    pose_prior::residuals(&p[3..Layout::POSE], LIMIT_WEIGHT, rest, &mut r);
    r.extend(p[Layout::POSE..layout.transl()].iter().map(|b| SHAPE_WEIGHT * b));
    r
}

/// The starting parameters: arms down, turned and placed onto the landmarks.
fn initial_parameters(
    body: &LandmarkBody,
    layout: &Layout,
    observed: &Observed,
    camera: &Camera,
) -> Result<Vec<f64>, FitError> {
    let mut p = vec![0.0; layout.len()];
    p[3 * L_SHOULDER + 2] = -ARMS_DOWN as f64;
    p[3 * R_SHOULDER + 2] = ARMS_DOWN as f64;
    let betas = vec![0.0f32; layout.betas];
    let rest = body.rest_joints(&betas);
    let torso =
        [(LEFT_HIP, L_HIP), (RIGHT_HIP, R_HIP), (LEFT_SHOULDER, L_SHOULDER), (RIGHT_SHOULDER, R_SHOULDER)];
    let a: Vec<DVec3> = torso.iter().map(|&(_, j)| rest[j].as_dvec3()).collect();
    let b: Vec<DVec3> = torso.iter().map(|&(i, _)| flip(observed.world[i])).collect();
    let w: Vec<f64> = torso.iter().map(|&(i, _)| observed.confidence[i].max(1e-3)).collect();
    let rotation = best_rotation(&a, &b, &w).ok_or_else(|| {
        FitError::input("landmarks", "the hips and shoulders do not fix the body's orientation")
    })?;
    let q = glam::Quat::from_mat3(&DMat3::as_mat3(&rotation)).normalize();
    let global = quat_axis_angle(q);
    p[..3].copy_from_slice(&global.map(|v| v as f64));
    let hips_cam = hip_position(observed, camera)
        .ok_or_else(|| FitError::input("landmarks", "too few confident landmarks to place the body"))?;
    let hips_world = flip(hips_cam);
    let hip_rest = (rest[L_HIP] + rest[R_HIP]).as_dvec3() / 2.0;
    let pelvis = rest[PELVIS].as_dvec3();
    let turned = DMat3::from_quat(axis_angle_quat(global).as_dquat());
    let t = hips_world - pelvis - turned * (hip_rest - pelvis);
    p[layout.transl()..].copy_from_slice(&t.to_array());
    Ok(p)
}

/// The camera-space hip centre that best explains the 2D landmarks, given the world landmarks
/// (hip-centred, camera axes): linear in it, u − cx = f (wₓ + tₓ) / (w_z + t_z) and likewise v.
fn hip_position(observed: &Observed, camera: &Camera) -> Option<DVec3> {
    let (f, cx, cy) = (camera.intrinsic[0][0], camera.intrinsic[0][2], camera.intrinsic[1][2]);
    let mut ata = DMat3::ZERO;
    let mut atb = DVec3::ZERO;
    let mut count = 0;
    for i in 0..NUM_LANDMARKS {
        let c = observed.confidence[i];
        if c <= 0.0 {
            continue;
        }
        count += 1;
        let (w, [u, v]) = (observed.world[i], observed.points[i]);
        for (row, rhs) in [
            (DVec3::new(f, 0.0, -(u - cx)), (u - cx) * w.z - f * w.x),
            (DVec3::new(0.0, f, -(v - cy)), (v - cy) * w.z - f * w.y),
        ] {
            ata += c * outer(row, row);
            atb += c * rhs * row;
        }
    }
    if count < 3 || ata.determinant().abs() < 1e-12 {
        return None;
    }
    let t = ata.inverse() * atb;
    (t.z > 0.0).then_some(t)
}

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}
