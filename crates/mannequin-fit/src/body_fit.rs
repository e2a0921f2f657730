//! Fitting the body to one person's landmarks (thesis §2.2.2). Where the thesis regresses the
//! parameters with a network, this solves for them directly, SMPLify-style, minimising:
//!
//! - Eq. 2.12's reprojection term: each BlazePose landmark's anchor on the body (`blazepose.rs`)
//!   projected by the camera, against the detected point, weighted by the landmark's visibility
//!   and made robust (a pseudo-Huber penalty, which behaves like Eq. 2.12's L1 beyond a few
//!   pixels and stays smooth for the solver);
//! - Eq. 2.14's 3D term, on the network's metric world landmarks (hip-centred, camera axes);
//! - a silhouette term: the distance from each of a few hundred body vertices, projected, to the
//!   person's mask (`distance_transform.rs`). It only pulls the body inside the mask, never out
//!   to fill it: clothes widen a silhouette, the body under them does not;
//! - the pose prior of `pose_prior.rs` in place of the adversarial term, a shape prior, and
//!   limbs kept out of each other (`interpenetration.rs`).
//!
//! The camera is OpenCV's, at the world origin, turned half a turn about x so the world is
//! Y-up in front of it; the focal length is given or assumed. The body starts from the prior's
//! relaxed stance, turned onto the world landmarks (`rigid_alignment.rs`), at the distance that
//! best explains the 2D landmarks (a linear solve for the translation, the camera-axes world
//! landmarks supplying the rotation: PnP with the rotation known). Then Levenberg–Marquardt
//! runs in three stages: rotation and translation alone, everything under a strong prior, then
//! under the final prior.

use glam::{DMat3, DQuat, DVec3, Vec3};
use mannequin_body::BodyModel;
use mannequin_body::rodrigues::{axis_angle_quat, quat_axis_angle};
use mannequin_body::smpl_joint::{L_HIP, L_SHOULDER, PELVIS, R_HIP, R_SHOULDER};
use mannequin_data::Camera;

use crate::blazepose::{
    Anchor as LandmarkAnchor, DEFAULT_BODY_VERTICES, LANDMARKS, LEFT_HIP, LEFT_SHOULDER, RIGHT_HIP,
    RIGHT_SHOULDER,
};
use crate::distance_transform::distance_to;
use crate::error::FitError;
use crate::interpenetration;
use crate::landmark_body::{LandmarkBody, PosedLandmarks};
use crate::levenberg_marquardt::{Summary, minimise};
use crate::pose_landmarker::{NUM_LANDMARKS, PoseLandmarks};
use crate::pose_prior;
use crate::rigid_alignment::best_rotation;
use crate::robust::pseudo_huber_scale;

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
/// Per metre that two limbs overlap (a centimetre weighs about as much as a landmark off by 1 %
/// of the crop).
const PENETRATION_WEIGHT: f64 = 100.0;
/// The silhouette term's weight as a whole (each sampled vertex carries 1/√n of it).
const SILHOUETTE_WEIGHT: f64 = 3.0;
/// About this many vertices, evenly spread over the mesh's indices, are held inside the mask.
const SILHOUETTE_SAMPLES: usize = 400;

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

/// A body's pose and placement in one frame, its shape held elsewhere.
#[derive(Debug, Clone, PartialEq)]
pub struct FramePose {
    /// SMPL layout: 24 × axis-angle, global orientation first.
    pub pose: Vec<f32>,
    pub transl: [f32; 3],
}

impl BodyFit {
    pub fn frame_pose(&self) -> FramePose {
        FramePose { pose: self.pose.clone(), transl: self.transl }
    }

    /// The median of the confident landmarks' reprojection errors, in pixels.
    pub fn median_error_px(&self) -> Option<f32> {
        let mut e: Vec<f32> = self.errors_px.iter().flatten().copied().collect();
        e.sort_by(f32::total_cmp);
        e.get(e.len() / 2).copied()
    }
}

/// Each landmark's weight: visibility × presence, zero below [`MIN_CONFIDENCE`].
fn confidence(person: &PoseLandmarks) -> Vec<f64> {
    person
        .visibility
        .iter()
        .zip(&person.presence)
        .map(|(v, p)| {
            let c = v * p;
            if c >= MIN_CONFIDENCE { c as f64 } else { 0.0 }
        })
        .collect()
}

/// The global orientation that turns the body's rest hips and shoulders onto the world
/// landmarks' (camera axes, turned to the world's): where the landmarker says the person faces.
fn torso_orientation(rest: &[Vec3], world: &[DVec3], confidence: &[f64]) -> Option<DQuat> {
    let torso =
        [(LEFT_HIP, L_HIP), (RIGHT_HIP, R_HIP), (LEFT_SHOULDER, L_SHOULDER), (RIGHT_SHOULDER, R_SHOULDER)];
    let a: Vec<DVec3> = torso.iter().map(|&(_, j)| rest[j].as_dvec3()).collect();
    let b: Vec<DVec3> = torso.iter().map(|&(i, _)| flip(world[i])).collect();
    let w: Vec<f64> = torso.iter().map(|&(i, _)| confidence[i].max(1e-3)).collect();
    best_rotation(&a, &b, &w).map(|r| DQuat::from_mat3(&r).normalize())
}

/// The rotation vector taking `from` to `to` the short way (world frame): a difference of
/// orientations that does not jump where axis-angle wraps at half a turn.
pub fn rotation_gap(from: DQuat, to: DQuat) -> DVec3 {
    let mut q = to * from.conjugate();
    if q.w < 0.0 {
        q = -q;
    }
    let s = q.xyz().length();
    if s < 1e-12 { 2.0 * q.xyz() } else { 2.0 * s.atan2(q.w) / s * q.xyz() }
}

fn orientation(p: &[f64]) -> DQuat {
    axis_angle_quat([p[0] as f32, p[1] as f32, p[2] as f32]).as_dquat()
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
    /// Distance (pixels) from each pixel to the person's mask, when there is one.
    outside: Option<Vec<f32>>,
    width: usize,
    height: usize,
}

impl Observed {
    /// The distance to the mask at (u, v), bilinear; zero off the picture, where nothing is known.
    fn outside_at(&self, u: f64, v: f64) -> f64 {
        let Some(d) = &self.outside else { return 0.0 };
        let (x, y) = (u - 0.5, v - 0.5);
        if !(x >= 0.0 && y >= 0.0 && x <= (self.width - 1) as f64 && y <= (self.height - 1) as f64) {
            return 0.0;
        }
        let (i, j) = ((x as usize).min(self.width - 2), (y as usize).min(self.height - 2));
        let (fx, fy) = (x - i as f64, y - j as f64);
        let at = |i: usize, j: usize| d[j * self.width + i] as f64;
        (at(i, j) * (1.0 - fx) + at(i + 1, j) * fx) * (1.0 - fy)
            + (at(i, j + 1) * (1.0 - fx) + at(i + 1, j + 1) * fx) * fy
    }
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
        LandmarkAnchor::Joint(j) => Some(posed.joints[j]),
        LandmarkAnchor::Vertex(_) => vertex_slot[i].map(|s| posed.vertices[s]),
        LandmarkAnchor::Unmapped => None,
    }
}

/// The fit's fixed parts for one body and one camera: reusable over the frames of a video.
pub struct Fitter {
    body: LandmarkBody,
    layout: Layout,
    camera: Camera,
    /// Where each landmark's vertex sits among the tracked ones.
    vertex_slot: Vec<Option<usize>>,
    /// Tracked vertices past this many are silhouette samples.
    landmark_vertices: usize,
    relaxed: Vec<f64>,
}

/// A pull toward earlier parameters (the previous video frame), with its weight per radian and
/// per metre, and optionally toward an orientation the clip's landmarks agree on.
pub struct Anchor<'a> {
    pub at: &'a FramePose,
    pub weight: f64,
    /// Where the body faces, and that pull's weight per radian; the fit starts from it.
    pub facing: Option<(DQuat, f64)>,
}

impl Fitter {
    /// For pictures of `width` × `height` pixels through a camera of focal `focal` pixels.
    pub fn new(model: &BodyModel, width: usize, height: usize, focal: f64) -> Result<Self, FitError> {
        if width < 2 || height < 2 || !(focal.is_finite() && focal > 0.0) {
            return Err(FitError::input(
                "camera",
                format!("a {width}×{height} picture with focal {focal} px"),
            ));
        }
        let mut vertices = Vec::new();
        let mut vertex_slot = vec![None; NUM_LANDMARKS];
        for (i, (_, anchor)) in LANDMARKS.iter().enumerate() {
            if let LandmarkAnchor::Vertex(v) = anchor {
                if *v >= model.num_vertices() {
                    return Err(FitError::input(
                        "body",
                        format!(
                            "the landmark table is made for the default body's {DEFAULT_BODY_VERTICES} vertices; this body has {}",
                            model.num_vertices()
                        ),
                    ));
                }
                vertex_slot[i] = Some(vertices.len());
                vertices.push(*v);
            }
        }
        let landmark_vertices = vertices.len();
        let step = (model.num_vertices() / SILHOUETTE_SAMPLES).max(1);
        vertices.extend((0..model.num_vertices()).step_by(step));
        let body = LandmarkBody::new(model, &vertices);
        let layout = Layout { betas: body.num_betas() };
        Ok(Self {
            body,
            layout,
            camera: picture_camera(width, height, focal),
            vertex_slot,
            landmark_vertices,
            relaxed: pose_prior::relaxed_pose(),
        })
    }

    /// What the fit compares the body with, from one person's landmarks and mask.
    fn observe(&self, person: &PoseLandmarks) -> Result<Observed, FitError> {
        let (width, height) = (self.camera.width, self.camera.height);
        if person.mask.len() != width * height {
            return Err(FitError::input(
                "mask",
                format!("{} values for a {width}×{height} picture", person.mask.len()),
            ));
        }
        if person.points.len() != NUM_LANDMARKS {
            return Err(FitError::input(
                "landmarks",
                format!("{} given, expected {NUM_LANDMARKS}", person.points.len()),
            ));
        }
        let inside = person.person_mask(width, height).values;
        Ok(Observed {
            points: person.points.iter().map(|p| [p[0] as f64, p[1] as f64]).collect(),
            world: person.world.iter().map(|w| DVec3::new(w[0] as f64, w[1] as f64, w[2] as f64)).collect(),
            confidence: confidence(person),
            unit_px: PIXEL_UNIT * person.roi.width as f64,
            outside: inside.iter().any(|&b| b).then(|| distance_to(&inside, width, height)),
            width,
            height,
        })
    }

    /// Fits shape, pose and placement from scratch, in three stages.
    pub fn fit(&self, person: &PoseLandmarks) -> Result<BodyFit, FitError> {
        let observed = self.observe(person)?;
        let mut params = self.initial_parameters(&observed)?;
        let problem = Problem { fitter: self, observed: &observed, anchor: None };
        let layout = &self.layout;
        let global: Vec<usize> = (0..3).chain(layout.transl()..layout.len()).collect();
        let all: Vec<usize> = (0..layout.len()).collect();
        let stages = vec![
            minimise(&|p| problem.residuals(p, REST_WEIGHT), &mut params, &global, 30, 1e-4),
            minimise(&|p| problem.residuals(p, 4.0 * REST_WEIGHT), &mut params, &all, 40, 1e-4),
            minimise(&|p| problem.residuals(p, REST_WEIGHT), &mut params, &all, 60, 1e-4),
        ];
        Ok(self.result(&params, &observed, stages))
    }

    /// Fits pose and placement with the shape held at `betas`, starting from and pulled toward
    /// `anchor` (a video's previous frame).
    pub fn follow(
        &self,
        person: &PoseLandmarks,
        betas: &[f32],
        anchor: &Anchor,
    ) -> Result<BodyFit, FitError> {
        let observed = self.observe(person)?;
        let layout = &self.layout;
        let mut params = self.parameters(anchor.at, betas);
        let pulled: Vec<f64> = params.clone();
        if let Some((q, _)) = anchor.facing {
            let start = quat_axis_angle(q.as_quat());
            params[..3].iter_mut().zip(start).for_each(|(p, v)| *p = v as f64);
        }
        let pull = Pull { params: &pulled, weight: anchor.weight, facing: anchor.facing };
        let problem = Problem { fitter: self, observed: &observed, anchor: Some(pull) };
        let free: Vec<usize> = (0..Layout::POSE).chain(layout.transl()..layout.len()).collect();
        let stages = vec![minimise(&|p| problem.residuals(p, REST_WEIGHT), &mut params, &free, 40, 1e-4)];
        Ok(self.result(&params, &observed, stages))
    }

    /// The parameter vector of a frame's pose and placement with the shape `betas`.
    fn parameters(&self, frame: &FramePose, betas: &[f32]) -> Vec<f64> {
        let layout = &self.layout;
        let mut p = vec![0.0; layout.len()];
        p[..Layout::POSE].iter_mut().zip(&frame.pose).for_each(|(p, &v)| *p = v as f64);
        p[Layout::POSE..layout.transl()].iter_mut().zip(betas).for_each(|(p, &b)| *p = b as f64);
        p[layout.transl()..].iter_mut().zip(frame.transl).for_each(|(p, t)| *p = t as f64);
        p
    }

    /// The fit as it stands at a given shape, pose and placement (nothing is solved): its
    /// reprojections and errors against `person`.
    pub fn at(&self, person: &PoseLandmarks, betas: &[f32], frame: &FramePose) -> Result<BodyFit, FitError> {
        let observed = self.observe(person)?;
        Ok(self.result(&self.parameters(frame, betas), &observed, Vec::new()))
    }

    /// One shape for several frames whose poses and placements are held: Levenberg–Marquardt on
    /// the shape alone, over all the frames' residuals at once, starting from `betas`.
    pub fn fit_shape(
        &self,
        frames: &[(&PoseLandmarks, &FramePose)],
        betas: &[f32],
    ) -> Result<Vec<f32>, FitError> {
        let layout = &self.layout;
        let observed =
            frames.iter().map(|(person, _)| self.observe(person)).collect::<Result<Vec<_>, _>>()?;
        let mut shape: Vec<f64> = betas.iter().map(|&b| b as f64).collect();
        let residuals = |shape: &[f64]| -> Vec<f64> {
            let mut r = Vec::new();
            for (o, (_, frame)) in observed.iter().zip(frames) {
                let problem = Problem { fitter: self, observed: o, anchor: None };
                let mut p = self.parameters(frame, &[]);
                p[Layout::POSE..layout.transl()].copy_from_slice(shape);
                let frame = problem.residuals(&p, REST_WEIGHT);
                // The shape prior is in every frame's residuals; count it once.
                let n = frame.len() - layout.betas;
                r.extend_from_slice(&frame[..n]);
            }
            r.extend(shape.iter().map(|b| SHAPE_WEIGHT * b));
            r
        };
        let all: Vec<usize> = (0..layout.betas).collect();
        minimise(&residuals, &mut shape, &all, 20, 1e-4);
        Ok(shape.iter().map(|&b| b as f32).collect())
    }

    /// Where the landmarker says the person faces: the global orientation that turns the rest
    /// body's hips and shoulders onto the world landmarks. None when they do not fix it.
    pub fn facing(&self, person: &PoseLandmarks) -> Option<DQuat> {
        if person.world.len() != NUM_LANDMARKS || person.visibility.len() != NUM_LANDMARKS {
            return None;
        }
        let rest = self.body.rest_joints(&vec![0.0; self.layout.betas]);
        let world: Vec<DVec3> =
            person.world.iter().map(|w| DVec3::new(w[0] as f64, w[1] as f64, w[2] as f64)).collect();
        torso_orientation(&rest, &world, &confidence(person))
    }

    fn result(&self, params: &[f64], observed: &Observed, stages: Vec<Summary>) -> BodyFit {
        let (pose, betas, transl) = self.layout.unpack(params);
        let posed = self.body.pose(&betas, &pose, transl);
        let camera = &self.camera;
        let reprojected: Vec<Option<[f32; 2]>> = (0..NUM_LANDMARKS)
            .map(|i| {
                anchor_point(&posed, &self.vertex_slot, i).map(|p| {
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
        BodyFit {
            betas,
            pose,
            transl: transl.to_array(),
            camera: camera.clone(),
            reprojected,
            errors_px,
            stages,
        }
    }

    /// The starting parameters: the relaxed stance, turned and placed onto the landmarks.
    fn initial_parameters(&self, observed: &Observed) -> Result<Vec<f64>, FitError> {
        let Self { body, layout, camera, relaxed, .. } = self;
        let mut p = vec![0.0; layout.len()];
        p[3..Layout::POSE].copy_from_slice(relaxed);
        let betas = vec![0.0f32; layout.betas];
        let rest = body.rest_joints(&betas);
        let q = torso_orientation(&rest, &observed.world, &observed.confidence).ok_or_else(|| {
            FitError::input("landmarks", "the hips and shoulders do not fix the body's orientation")
        })?;
        let global = quat_axis_angle(q.as_quat());
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
}

/// A pull toward earlier parameters, per radian and per metre (the orientation's by its
/// geodesic), and toward an orientation.
struct Pull<'a> {
    params: &'a [f64],
    weight: f64,
    facing: Option<(DQuat, f64)>,
}

/// One frame's residuals: the fitter, what it sees, and an optional pull.
struct Problem<'a> {
    fitter: &'a Fitter,
    observed: &'a Observed,
    anchor: Option<Pull<'a>>,
}

impl Problem<'_> {
    /// The residuals at parameters `p`, with the prior's pull to rest weighted `rest`.
    fn residuals(&self, p: &[f64], rest: f64) -> Vec<f64> {
        let Fitter { body, layout, camera, vertex_slot, landmark_vertices, relaxed } = self.fitter;
        let observed = self.observed;
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
            let d = [
                (u - observed.points[i][0]) / observed.unit_px,
                (v - observed.points[i][1]) / observed.unit_px,
            ];
            let scale = pseudo_huber_scale(d[0].hypot(d[1]), ROBUST_DELTA);
            r.push(c.sqrt() * scale * d[0]);
            r.push(c.sqrt() * scale * d[1]);
            let rel = flip(x.as_dvec3()) - hips - observed.world[i];
            let w = WORLD_WEIGHT * c.sqrt() / WORLD_SIGMA;
            r.extend_from_slice(&[w * rel.x, w * rel.y, w * rel.z]);
        }
        let samples = &posed.vertices[*landmark_vertices..];
        let w = SILHOUETTE_WEIGHT / (samples.len() as f64).sqrt() / observed.unit_px;
        for x in samples {
            let [u, v] = camera.project(camera.world_to_camera(x.as_dvec3()));
            r.push(w * observed.outside_at(u, v));
        }
        pose_prior::residuals(&p[3..Layout::POSE], relaxed, LIMIT_WEIGHT, rest, &mut r);
        interpenetration::residuals(&posed.joints, PENETRATION_WEIGHT, &mut r);
        r.extend(p[Layout::POSE..layout.transl()].iter().map(|b| SHAPE_WEIGHT * b));
        if let Some(Pull { params: q, weight: w, facing }) = &self.anchor {
            let turned = orientation(p);
            r.extend((*w * rotation_gap(orientation(q), turned)).to_array());
            let moving = (3..Layout::POSE).chain(layout.transl()..layout.len());
            r.extend(moving.map(|i| w * (p[i] - q[i])));
            if let Some((target, wf)) = facing {
                r.extend((*wf * rotation_gap(*target, turned)).to_array());
            }
        }
        r
    }
}

/// Fits the body to one person's landmarks and mask (`person.mask`, probabilities) in a
/// `width` × `height` picture.
pub fn fit_body(
    model: &BodyModel,
    person: &PoseLandmarks,
    width: usize,
    height: usize,
    focal: f64,
) -> Result<BodyFit, FitError> {
    Fitter::new(model, width, height, focal)?.fit(person)
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

#[cfg(test)]
mod tests {
    use mannequin_raster::{RasterMesh, Shading, rasterize};

    use super::*;
    use crate::crop::RotatedRect;

    /// Landmarks a body in a known pose would give, drawn from the fit's own anchors: a check
    /// of the solver (it must find its way back), not of how well the anchors match BlazePose.
    fn landmarks_of(
        model: &BodyModel,
        betas: &[f32],
        pose: &[f32],
        transl: [f32; 3],
        camera: &Camera,
    ) -> PoseLandmarks {
        let posed = mannequin_body::forward(model, betas, pose, &transl).unwrap();
        let vertex = |v: usize| Vec3::from_slice(&posed.vertices[3 * v..3 * v + 3]);
        let joint = |j: usize| Vec3::from_slice(&posed.joints[3 * j..3 * j + 3]);
        let anchors: Vec<Option<Vec3>> = LANDMARKS
            .iter()
            .map(|(_, a)| match *a {
                LandmarkAnchor::Joint(j) => Some(joint(j)),
                LandmarkAnchor::Vertex(v) => Some(vertex(v)),
                LandmarkAnchor::Unmapped => None,
            })
            .collect();
        let hips = flip((joint(L_HIP) + joint(R_HIP)).as_dvec3() / 2.0);
        let mut mesh = model.template_mesh();
        mesh.positions = posed.vertices.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
        let normals = mannequin_mesh::normals::vertex_normals(&mesh.positions, &mesh.faces);
        let raster = rasterize(
            &RasterMesh {
                positions: &mesh.positions,
                faces: &mesh.faces,
                normals: &normals,
                shading: Shading::Flat([1.0; 3]),
            },
            camera,
            [0.0; 3],
        );
        PoseLandmarks {
            roi: RotatedRect { cx: 256.0, cy: 256.0, width: 500.0, height: 500.0, rotation: 0.0 },
            flag: 1.0,
            points: anchors
                .iter()
                .map(|a| {
                    let [u, v] = a.map_or([0.0; 2], |p| camera.project(camera.world_to_camera(p.as_dvec3())));
                    [u as f32, v as f32, 0.0]
                })
                .collect(),
            visibility: anchors.iter().map(|a| if a.is_some() { 1.0 } else { 0.0 }).collect(),
            presence: vec![1.0; NUM_LANDMARKS],
            world: anchors
                .iter()
                .map(|a| a.map_or([0.0; 3], |p| (flip(p.as_dvec3()) - hips).as_vec3().to_array()))
                .collect(),
            next_roi: RotatedRect { cx: 0.0, cy: 0.0, width: 1.0, height: 1.0, rotation: 0.0 },
            mask: raster.mask.values.iter().map(|&m| m as u8 as f32).collect(),
        }
    }

    #[test]
    fn the_solver_finds_a_known_body_from_its_own_landmarks() {
        let model = BodyModel::default_body();
        let camera = picture_camera(512, 512, 600.0);
        let mut pose = mannequin_body::named_pose("walk").unwrap().to_vec();
        pose[..3].copy_from_slice(&[0.1, 0.5, 0.05]);
        let betas = [0.8, -0.5, 0.3];
        let transl = [0.1, 0.15, -3.2];
        let person = landmarks_of(&model, &betas, &pose, transl, &camera);
        let fit = fit_body(&model, &person, 512, 512, 600.0).unwrap();
        let want = mannequin_body::forward(&model, &betas, &pose, &transl).unwrap();
        let got = mannequin_body::forward(&model, &fit.betas, &fit.pose, &fit.transl).unwrap();
        let joint_error = want
            .joints
            .chunks_exact(3)
            .zip(got.joints.chunks_exact(3))
            .map(|(a, b)| Vec3::from_slice(a).distance(Vec3::from_slice(b)))
            .fold(0.0f32, f32::max);
        let median = fit.median_error_px().unwrap();
        assert!(median < 1.0, "median reprojection error {median} px");
        assert!(joint_error < 0.05, "worst joint {joint_error} m from the truth");
    }
}
