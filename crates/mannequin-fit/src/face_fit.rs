//! Fitting the default body's face to one photo (thesis §2.3): the face model's shape α
//! (Eq. 2.18) and expression, the head's rotation and translation, against MediaPipe's 468
//! face-mesh landmarks. Each landmark's point on the head (`face_landmark_table.rs`) moves
//! linearly with α and the expression weights, so the model's landmarks are one matrix product.
//! Levenberg–Marquardt minimises:
//!
//! - the landmarks' reprojection, robust (pseudo-Huber), in 1 % of the inter-ocular distance;
//! - their relative depth against the mesh's z (weak perspective), at a third of that weight;
//! - priors: α is unit normal, expressions are pulled to neutral and kept in [0, 1];
//! - in a video, a pull toward the previous frame's fit.
//!
//! The camera is the body fit's (`picture_camera`): the focal length given or assumed. The fit
//! starts from the neutral face turned and scaled onto the mesh's 3D points (Kabsch), at the
//! distance that scale implies. The photometric term (Eq. 2.20) is not in it yet.

use glam::{DQuat, DVec3};
use mannequin_body::{BodyModel, FaceModel};
use mannequin_data::Camera;

use crate::body_fit::picture_camera;
use crate::body_fit::rotation_gap;
use crate::error::FitError;
use crate::face_landmark_table::FaceLandmarkTable;
use crate::face_landmarker::{FaceLandmarks, NUM_LANDMARKS};
use crate::levenberg_marquardt::{Summary, minimise_with};
use crate::rigid_alignment::best_rotation;
use crate::robust::pseudo_huber_scale;

/// MediaPipe's outer eye corners (the subject's right, then left).
pub const OUTER_EYE_CORNERS: [usize; 2] = [33, 263];
/// Errors are measured in this fraction of the inter-ocular distance.
const UNIT: f64 = 0.01;
const ROBUST_DELTA: f64 = 2.0;
const DEPTH_WEIGHT: f64 = 0.3;
/// Per unit of α (unit normal). Landmarks read by the face mesh network say little about this
/// model's shape: on faces rendered from the model with known α (`benches/face.rs`), the true
/// face's own points lie 5 % of the eyes' distance from the detected ones, and a weak pull lets α
/// chase that (10.8 mm per vertex at 1, against 4.6 mm for the neutral head; 3.6 against 2.9 mm
/// after a similarity). At 16 the fit keeps to what the landmarks clearly say: 4.9 mm, 2.8 mm
/// aligned, and astronaut.png's landmark error rises from 1.8 to 2.5 %.
const SHAPE_WEIGHT: f64 = 16.0;
/// Per unit of expression weight. The 52 units overlap (jawLeft with jawRight, the eyes' looks
/// with their lids), and a weak pull lets them soak up where the generic head differs from the
/// face: at 0.3 they wander by 0.2 between frames that differ by a 4-pixel shift, at 10 they
/// hold, and the landmark error rises from 1.79 to 1.84 % on astronaut.png.
const EXPRESSION_WEIGHT: f64 = 10.0;
/// Per unit an expression weight strays out of [0, 1].
const BOUND_WEIGHT: f64 = 300.0;
/// A video frame's pull toward the previous frame's fit: per radian the head turns, per metre it
/// moves, and per unit an expression weight changes.
const ROTATION_SMOOTHING: f64 = 100.0;
const TRANSLATION_SMOOTHING: f64 = 300.0;
const EXPRESSION_SMOOTHING: f64 = 20.0;
/// A video frame starts at the previous frame's fit and needs few steps: on a 30-frame clip of a
/// moving portrait, 4 give the same landmark error as 10 (1.849 %) with expressions within 0.02.
const TRACK_ITERATIONS: usize = 4;
/// The finite differences' half-width.
const STEP: f64 = 1e-5;

/// One frame's fitting problem: its landmarks, the error unit, and the fit it is pulled toward.
struct Problem<'a> {
    detected: &'a [[f64; 3]],
    /// Pixels per residual unit (a fraction of the inter-ocular distance).
    unit: f64,
    mean_z: f64,
    previous: Option<&'a FaceFit>,
}

/// The fitted face: its coefficients, the head's placement and the landmarks' errors.
#[derive(Debug, Clone)]
pub struct FaceFit {
    pub shape: Vec<f32>,
    pub expression: Vec<f32>,
    /// Camera from head: x_cam = R (x − centre) + t, with x on the default body's rest head.
    pub rotation: DQuat,
    /// R as the solver holds it (a rotation vector): a video's next frame starts from it.
    pub rotation_vector: DVec3,
    pub translation: DVec3,
    pub centre: DVec3,
    pub camera: Camera,
    /// Each landmark's model point projected by the fitted camera.
    pub reprojected: Vec<[f32; 2]>,
    /// Each landmark's reprojection error over the inter-ocular distance.
    pub errors_iod: Vec<f32>,
    pub stages: Vec<Summary>,
}

impl FaceFit {
    pub fn mean_error_iod(&self) -> f32 {
        self.errors_iod.iter().sum::<f32>() / self.errors_iod.len() as f32
    }

    /// A point of the default body's rest head in camera space.
    pub fn to_camera(&self, x: [f32; 3]) -> DVec3 {
        self.rotation * (DVec3::new(x[0] as f64, x[1] as f64, x[2] as f64) - self.centre) + self.translation
    }
}

/// The landmarks' points as linear functions of (α, expression): a base and one column per
/// coefficient, each 3 × 468 values.
pub struct FaceFitter {
    base: Vec<DVec3>,
    columns: Vec<Vec<DVec3>>,
    num_shape: usize,
    centre: DVec3,
    camera: Camera,
}

impl FaceFitter {
    /// For the default body (`body`) and its face model, in pictures of `width` × `height`
    /// through focal `focal`.
    pub fn new(
        body: &BodyModel,
        face: &FaceModel,
        width: usize,
        height: usize,
        focal: f64,
    ) -> Result<Self, FitError> {
        let table = FaceLandmarkTable::default_head();
        let point = |p: [f32; 3]| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
        let base: Vec<DVec3> =
            table.positions(&body.v_template, &body.faces)?.into_iter().map(point).collect();
        let mut slot = vec![None; body.num_vertices()];
        face.vertices.iter().enumerate().for_each(|(i, &v)| slot[v] = Some(i));
        let v = face.vertices.len();
        let column = |basis: &[f32], k: usize| -> Result<Vec<DVec3>, FitError> {
            table
                .triangles
                .iter()
                .zip(&table.barycentrics)
                .map(|(&t, b)| {
                    let mut sum = DVec3::ZERO;
                    for (corner, &w) in body.faces[t].iter().zip(b) {
                        let i = slot[*corner as usize].ok_or_else(|| {
                            FitError::input("face model", "a landmark's triangle leaves the head's vertices")
                        })?;
                        let o = &basis[(k * v + i) * 3..(k * v + i) * 3 + 3];
                        sum += w as f64 * DVec3::new(o[0] as f64, o[1] as f64, o[2] as f64);
                    }
                    Ok(sum)
                })
                .collect()
        };
        let mut columns = Vec::new();
        for k in 0..face.num_shape() {
            columns.push(column(&face.shape_basis, k)?);
        }
        for k in 0..face.num_expressions() {
            columns.push(column(&face.expression_basis, k)?);
        }
        let centre = base.iter().copied().sum::<DVec3>() / base.len() as f64;
        Ok(Self {
            base,
            columns,
            num_shape: face.num_shape(),
            centre,
            camera: picture_camera(width, height, focal),
        })
    }

    /// The landmarks' points on the rest head for coefficients `c` (α then expression).
    fn points(&self, c: &[f64]) -> Vec<DVec3> {
        let mut p = self.base.clone();
        for (col, &w) in self.columns.iter().zip(c).filter(|(_, w)| **w != 0.0) {
            p.iter_mut().zip(col).for_each(|(p, d)| *p += w * *d);
        }
        p
    }

    /// Camera-space points for parameters `p` = (rotation vector, translation, coefficients).
    fn placed(&self, p: &[f64]) -> Vec<DVec3> {
        let r = quat(p);
        let t = DVec3::new(p[3], p[4], p[5]);
        self.points(&p[6..]).into_iter().map(|x| r * (x - self.centre) + t).collect()
    }

    fn project(&self, x: DVec3) -> [f64; 2] {
        self.camera.project(x.with_z(x.z.max(1e-3)))
    }

    /// Fits shape, expression and the head's placement to one face's landmarks.
    pub fn fit(&self, face: &FaceLandmarks) -> Result<FaceFit, FitError> {
        self.solve(face, None, None)
    }

    /// Fits one video frame: the shape held at `shape` (the video's), the expression and the
    /// head's placement started from the previous frame's fit and pulled toward it.
    pub fn track(
        &self,
        face: &FaceLandmarks,
        shape: &[f32],
        previous: Option<&FaceFit>,
    ) -> Result<FaceFit, FitError> {
        if shape.len() != self.num_shape {
            return Err(FitError::input(
                "face shape",
                format!("{} coefficients given, the model has {}", shape.len(), self.num_shape),
            ));
        }
        self.solve(face, Some(shape), previous)
    }

    fn solve(
        &self,
        face: &FaceLandmarks,
        shape: Option<&[f32]>,
        previous: Option<&FaceFit>,
    ) -> Result<FaceFit, FitError> {
        let (detected, iod) = detected(face)?;
        let mean_z = detected.iter().map(|p| p[2]).sum::<f64>() / detected.len() as f64;
        let mut params = vec![0.0; 6 + self.columns.len()];
        match previous {
            Some(prev) => {
                params[..3].copy_from_slice(&prev.rotation_vector.to_array());
                params[3..6].copy_from_slice(&prev.translation.to_array());
                let coefficients = prev.shape.iter().chain(&prev.expression);
                params[6..].iter_mut().zip(coefficients).for_each(|(p, &c)| *p = c as f64);
            }
            None => self.initial_placement(&detected, &mut params)?,
        }
        if let Some(shape) = shape {
            params[6..6 + self.num_shape].iter_mut().zip(shape).for_each(|(p, &a)| *p = a as f64);
        }
        let problem = Problem { detected: &detected, unit: UNIT * iod, mean_z, previous };
        let residuals = |p: &[f64]| self.residuals(&self.placed(p), p, &problem);
        let placement: Vec<usize> = (0..6).collect();
        let expression = 6 + self.num_shape..params.len();
        let free: Vec<usize> = match shape {
            Some(_) => placement.iter().copied().chain(expression).collect(),
            None => (0..params.len()).collect(),
        };
        let problem = &problem;
        let jacobian = |free: &[usize]| {
            let free = free.to_vec();
            move |x: &[f64]| self.jacobian(x, &free, problem)
        };
        let stages = match previous {
            Some(_) => {
                vec![minimise_with(&residuals, &jacobian(&free), &mut params, &free, TRACK_ITERATIONS)]
            }
            None => vec![
                minimise_with(&residuals, &jacobian(&placement), &mut params, &placement, 20),
                minimise_with(&residuals, &jacobian(&free), &mut params, &free, 30),
            ],
        };
        Ok(self.outcome(&params, &detected, iod, stages))
    }

    /// The fit of stored parameters to `face`'s landmarks, without solving (a video's frame
    /// fitted before a resume).
    pub fn at(
        &self,
        face: &FaceLandmarks,
        shape: &[f32],
        expression: &[f32],
        rotation_vector: DVec3,
        translation: DVec3,
    ) -> Result<FaceFit, FitError> {
        let (detected, iod) = detected(face)?;
        if shape.len() != self.num_shape || self.num_shape + expression.len() != self.columns.len() {
            return Err(FitError::input(
                "face fit",
                format!(
                    "{} shape and {} expression coefficients; the model has {} and {}",
                    shape.len(),
                    expression.len(),
                    self.num_shape,
                    self.columns.len() - self.num_shape
                ),
            ));
        }
        let mut params: Vec<f64> =
            rotation_vector.to_array().into_iter().chain(translation.to_array()).collect();
        params.extend(shape.iter().chain(expression).map(|&c| c as f64));
        Ok(self.outcome(&params, &detected, iod, Vec::new()))
    }

    fn outcome(&self, params: &[f64], detected: &[[f64; 3]], iod: f64, stages: Vec<Summary>) -> FaceFit {
        let placed = self.placed(params);
        let reprojected: Vec<[f32; 2]> =
            placed.iter().map(|x| self.project(*x)).map(|[u, v]| [u as f32, v as f32]).collect();
        let errors_iod = reprojected
            .iter()
            .zip(detected)
            .map(|(r, d)| ((r[0] as f64 - d[0]).hypot(r[1] as f64 - d[1]) / iod) as f32)
            .collect();
        let (shape, expression) = params[6..].split_at(self.num_shape);
        FaceFit {
            shape: shape.iter().map(|&v| v as f32).collect(),
            expression: expression.iter().map(|&v| v as f32).collect(),
            rotation: quat(params),
            rotation_vector: DVec3::new(params[0], params[1], params[2]),
            translation: DVec3::new(params[3], params[4], params[5]),
            centre: self.centre,
            camera: self.camera.clone(),
            reprojected,
            errors_iod,
            stages,
        }
    }

    /// The residuals of parameters `p` whose landmarks, placed in the camera, are `placed`.
    fn residuals(&self, placed: &[DVec3], p: &[f64], problem: &Problem) -> Vec<f64> {
        let depth = placed.iter().map(|x| x.z).sum::<f64>() / placed.len() as f64;
        let f = self.camera.intrinsic[0][0];
        let unit = problem.unit;
        let mut r = Vec::with_capacity(3 * NUM_LANDMARKS + self.columns.len() * 3 + 6);
        for (x, d) in placed.iter().zip(problem.detected) {
            let [u, v] = self.project(*x);
            let e = [(u - d[0]) / unit, (v - d[1]) / unit];
            let s = pseudo_huber_scale(e[0].hypot(e[1]), ROBUST_DELTA);
            r.push(s * e[0]);
            r.push(s * e[1]);
            // MediaPipe's z: camera-ward negative, on x's pixel scale, about the face.
            r.push(DEPTH_WEIGHT * (f * (x.z - depth) / depth - (d[2] - problem.mean_z)) / unit);
        }
        let (shape, expression) = p[6..].split_at(self.num_shape);
        r.extend(shape.iter().map(|a| SHAPE_WEIGHT * a));
        r.extend(expression.iter().map(|e| EXPRESSION_WEIGHT * e));
        r.extend(expression.iter().map(|e| BOUND_WEIGHT * (e.min(0.0) + (e - 1.0).max(0.0))));
        if let Some(prev) = problem.previous {
            let turn = rotation_gap(prev.rotation, quat(p));
            let shift = DVec3::new(p[3], p[4], p[5]) - prev.translation;
            r.extend(turn.to_array().map(|c| ROTATION_SMOOTHING * c));
            r.extend(shift.to_array().map(|c| TRANSLATION_SMOOTHING * c));
            r.extend(
                expression.iter().zip(&prev.expression).map(|(e, q)| EXPRESSION_SMOOTHING * (e - *q as f64)),
            );
        }
        r
    }

    /// ∂r/∂p over `free` by central differences. A coefficient moves each landmark along its own
    /// column, so its probes shift the placed points instead of rebuilding them from all
    /// coefficients.
    fn jacobian(&self, x: &[f64], free: &[usize], problem: &Problem) -> Vec<Vec<f64>> {
        let placed = self.placed(x);
        let r = quat(x);
        let mut probe = x.to_vec();
        let mut moved = placed.clone();
        free.iter()
            .map(|&i| {
                let mut side = |sign: f64| {
                    probe[i] = x[i] + sign * STEP;
                    let out = match i.checked_sub(6) {
                        None => self.residuals(&self.placed(&probe), &probe, problem),
                        Some(k) => {
                            for ((m, p), c) in moved.iter_mut().zip(&placed).zip(&self.columns[k]) {
                                *m = *p + sign * STEP * (r * *c);
                            }
                            self.residuals(&moved, &probe, problem)
                        }
                    };
                    probe[i] = x[i];
                    out
                };
                let (plus, minus) = (side(1.0), side(-1.0));
                plus.iter().zip(&minus).map(|(p, q)| (p - q) / (2.0 * STEP)).collect()
            })
            .collect()
    }

    /// The neutral face turned onto the mesh's 3D points (pixels, y down, z away: the camera's
    /// axes), scaled as they are, at the depth that scale implies.
    fn initial_placement(&self, detected: &[[f64; 3]], params: &mut [f64]) -> Result<(), FitError> {
        let model: Vec<DVec3> = self.base.iter().map(|x| *x - self.centre).collect();
        let seen: Vec<DVec3> = detected.iter().map(|d| DVec3::new(d[0], d[1], d[2])).collect();
        let mean = seen.iter().copied().sum::<DVec3>() / seen.len() as f64;
        let seen: Vec<DVec3> = seen.iter().map(|s| *s - mean).collect();
        let w = vec![1.0; model.len()];
        let r = best_rotation(&model, &seen, &w).ok_or_else(|| {
            FitError::Picture("the face landmarks do not fix the head's orientation".into())
        })?;
        let scale = seen.iter().map(|s| s.length_squared()).sum::<f64>().sqrt()
            / model.iter().map(|m| m.length_squared()).sum::<f64>().sqrt();
        let f = self.camera.intrinsic[0][0];
        let (cx, cy) = (self.camera.intrinsic[0][2], self.camera.intrinsic[1][2]);
        let depth = f / scale;
        let t = DVec3::new((mean.x - cx) * depth / f, (mean.y - cy) * depth / f, depth);
        params[..3].copy_from_slice(&DQuat::from_mat3(&r).normalize().to_scaled_axis().to_array());
        params[3..6].copy_from_slice(&t.to_array());
        Ok(())
    }
}

/// A face's landmarks in f64 and its inter-ocular distance, checked.
fn detected(face: &FaceLandmarks) -> Result<(Vec<[f64; 3]>, f64), FitError> {
    if face.points.len() != NUM_LANDMARKS {
        return Err(FitError::input(
            "face landmarks",
            format!("{} given, expected {NUM_LANDMARKS}", face.points.len()),
        ));
    }
    let detected: Vec<[f64; 3]> =
        face.points.iter().map(|p| [p[0] as f64, p[1] as f64, p[2] as f64]).collect();
    let [a, b] = OUTER_EYE_CORNERS.map(|i| detected[i]);
    let iod = (a[0] - b[0]).hypot(a[1] - b[1]);
    if iod.is_nan() || iod <= 1.0 {
        return Err(FitError::Picture("the face's eyes are less than a pixel apart".into()));
    }
    Ok((detected, iod))
}

/// The head's rotation: the parameters' first three, a rotation vector.
fn quat(p: &[f64]) -> DQuat {
    DQuat::from_scaled_axis(DVec3::new(p[0], p[1], p[2]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::crop::RotatedRect;

    /// Landmarks a known face would give, drawn from the fit's own model: a check of the solver
    /// (it must find its way back), not of how well the model matches MediaPipe's mesh.
    #[test]
    fn the_solver_finds_a_known_face_from_its_own_landmarks() {
        let (body, face) = (BodyModel::default_body(), FaceModel::default_face());
        let fitter = FaceFitter::new(&body, &face, 640, 480, 600.0).unwrap();
        let mut p = vec![0.0; 6 + fitter.columns.len()];
        p[..3].copy_from_slice(&[std::f64::consts::PI + 0.1, 0.3, 0.05]);
        p[3..6].copy_from_slice(&[0.03, -0.02, 0.55]);
        p[6] = 0.8;
        p[9] = -0.6;
        p[6 + fitter.num_shape + 24] = 0.5;
        let placed = fitter.placed(&p);
        let depth = placed.iter().map(|x| x.z).sum::<f64>() / placed.len() as f64;
        let points = placed
            .iter()
            .map(|x| {
                let [u, v] = fitter.project(*x);
                [u as f32, v as f32, (600.0 * (x.z - depth) / depth) as f32]
            })
            .collect();
        let square = RotatedRect { cx: 320.0, cy: 240.0, width: 200.0, height: 200.0, rotation: 0.0 };
        let face = FaceLandmarks { roi: square, flag: 1.0, points };
        let fit = fitter.fit(&face).unwrap();
        assert!(fit.mean_error_iod() < 2e-3, "mean error {} of the eyes' distance", fit.mean_error_iod());
        let turn = rotation_gap(quat(&p), fit.rotation).length();
        assert!(turn < 0.03, "the head's rotation is {turn} rad off");
        assert!((fit.translation - DVec3::new(p[3], p[4], p[5])).length() < 0.02, "{}", fit.translation);
    }
}
