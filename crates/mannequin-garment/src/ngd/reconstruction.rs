//! NGD's garment reconstruction loop (seed 002, §2–3): the base garment's static Jacobian field
//! integrated by the Poisson solve, posed by skinning, rendered against each training frame's
//! label map and normal map, and moved by Adam. [`Breakdown`] keeps where the time goes.

use std::time::Instant;

use mannequin_data::Camera;
use mannequin_io::rng::SplitMix64;
use mannequin_mesh::TriMesh;
use mannequin_mesh::manifold::check_manifold;
use serde::Serialize;

use super::dynamic_field::DynamicField;
use super::loss::{LossParts, LossWeights, image_loss};
use super::pose_code::PoseCode;
use super::remesh::{RemeshSchedule, remesh_and_carry, selected_edges};
use super::scene::{FramePose, Scene};
use super::static_field::StaticField;
use super::target::Target;
use crate::error::GarmentError;
use crate::transfer::Dressed;

/// The optimisation's settings; NGD's terms can each be switched off for the ablations.
#[derive(Debug, Clone, Serialize)]
pub struct Settings {
    /// Optimisation steps, one training frame each.
    pub steps: usize,
    /// Adam's step size on the Jacobians.
    pub rate: f64,
    /// λ of the Jacobian regulariser λ Σ ‖M_t − I‖² (0: none).
    pub regulariser: f64,
    /// γ of the vertex noise (Eqs. 11–12), metres (0: none).
    pub noise: f64,
    /// The normal loss's weights against the mask loss: Huber and 1 − SSIM (0, 0: masks only).
    pub normal_weight: f64,
    pub ssim_weight: f64,
    /// The dynamic field J^D (§3.1): the pose code's length and Adam's rate on the network; None
    /// for the static field alone.
    pub dynamic: Option<DynamicSettings>,
    /// Adaptive remeshing (§3.2), or none.
    pub remesh: Option<RemeshSchedule>,
    /// Seeds the frame order and the noise.
    pub seed: u64,
}

#[derive(Debug, Clone, Serialize)]
pub struct DynamicSettings {
    /// k, the principal components of the pose (NGD: 4 for geometry).
    pub components: usize,
    pub rate: f64,
}

impl Default for DynamicSettings {
    fn default() -> Self {
        Self { components: 4, rate: 1e-3 }
    }
}

/// One training frame: its targets, camera and body pose.
pub struct TrainingFrame {
    pub target: Target,
    pub camera: Camera,
    pub pose: FramePose,
}

/// What one step saw: the frame (an index into the training frames), its losses and the mask IoU
/// of the garment it drew (before the step moved it).
#[derive(Debug, Clone, Copy)]
pub struct StepReport {
    pub frame: usize,
    pub losses: LossParts,
    pub mask_iou: f64,
}

/// Seconds spent in each phase, summed over the steps taken.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Breakdown {
    pub jacobian_mlp: f64,
    pub poisson_solve: f64,
    pub skinning: f64,
    pub rasterise: f64,
    pub losses: f64,
    pub backward: f64,
    pub remesh: f64,
}

impl Breakdown {
    fn add(slot: &mut f64, since: Instant) -> Instant {
        let now = Instant::now();
        *slot += (now - since).as_secs_f64();
        now
    }

    /// Milliseconds per step in each phase.
    pub fn per_step_ms(&self, steps: usize) -> Self {
        let k = 1e3 / steps.max(1) as f64;
        Self {
            jacobian_mlp: self.jacobian_mlp * k,
            poisson_solve: self.poisson_solve * k,
            skinning: self.skinning * k,
            rasterise: self.rasterise * k,
            losses: self.losses * k,
            backward: self.backward * k,
            remesh: self.remesh * k,
        }
    }
}

/// The garment being reconstructed on a dressed body.
pub struct Reconstruction<'a> {
    dressed: &'a Dressed<'a>,
    /// The base garment at rest, remeshed as the fit goes.
    base: Vec<[f32; 3]>,
    faces: Vec<[u32; 3]>,
    weights: Vec<f32>,
    field: StaticField,
    /// The dynamic field and the pose code it reads, if the settings ask for one.
    dynamic: Option<(DynamicField, PoseCode)>,
    settings: Settings,
    rng: SplitMix64,
    steps_taken: usize,
    pub breakdown: Breakdown,
}

impl<'a> Reconstruction<'a> {
    /// Starts from the dressed garment at rest, with the pose code (if any) taken over
    /// `training_poses` (72 values each); refuses a base that is not an oriented manifold (the
    /// Poisson solve and the boundaries assume one).
    pub fn new(
        dressed: &'a Dressed<'a>,
        settings: Settings,
        training_poses: &[Vec<f32>],
    ) -> Result<Self, GarmentError> {
        let rest = dressed.rest();
        let faces = dressed.garment().mesh.faces.clone();
        check_manifold(&rest, &faces).map_err(|e| GarmentError::invalid("base garment", e.to_string()))?;
        let field = StaticField::new(&rest, &faces)
            .map_err(|e| GarmentError::invalid("base garment", e.to_string()))?;
        let dynamic = settings.dynamic.as_ref().map(|d| {
            let code = PoseCode::fit(
                &training_poses.iter().map(|p| body_pose(p).to_vec()).collect::<Vec<_>>(),
                d.components,
            );
            (DynamicField::new(code.len(), &rest, &faces, settings.seed), code)
        });
        Ok(Self {
            dressed,
            dynamic,
            base: rest,
            faces,
            weights: dressed.weights.clone(),
            field,
            rng: SplitMix64::new(settings.seed),
            settings,
            steps_taken: 0,
            breakdown: Breakdown::default(),
        })
    }

    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    pub fn steps_taken(&self) -> usize {
        self.steps_taken
    }

    /// The garment at rest on the body, as the static field integrates it.
    pub fn rest(&self) -> Vec<[f32; 3]> {
        to_f32(&self.field.positions())
    }

    /// The garment at rest in the shape it takes in `pose` (the dynamic field's, if any).
    fn rest_for(&self, pose: &FramePose) -> Vec<[f32; 3]> {
        match &self.dynamic {
            Some((network, code)) => {
                to_f32(&self.field.positions_with(&network.forward(&code.encode(body_pose(&pose.pose))).0))
            }
            None => self.rest(),
        }
    }

    pub fn faces(&self) -> &[[u32; 3]] {
        &self.faces
    }

    /// The skinning weights of the current vertices, V × J.
    pub fn weights(&self) -> &[f32] {
        &self.weights
    }

    /// The regulariser's current value.
    pub fn regulariser(&self) -> f64 {
        self.field.regulariser(self.settings.regulariser)
    }

    /// One step on a frame drawn from `frames`.
    pub fn step(&mut self, frames: &[TrainingFrame]) -> Result<StepReport, GarmentError> {
        if frames.is_empty() {
            return Err(GarmentError::invalid("frames", "no training frames"));
        }
        let k = self.rng.below(frames.len());
        let frame = &frames[k];
        let t0 = Instant::now();
        let dynamic = self
            .dynamic
            .as_ref()
            .map(|(network, code)| network.forward(&code.encode(body_pose(&frame.pose.pose))));
        let t0 = Breakdown::add(&mut self.breakdown.jacobian_mlp, t0);
        let rest = match &dynamic {
            Some((m, _)) => to_f32(&self.field.positions_with(m)),
            None => self.rest(),
        };
        let t1 = Breakdown::add(&mut self.breakdown.poisson_solve, t0);
        let scale = self.settings.noise * (1.0 - self.steps_taken as f64 / self.settings.steps.max(1) as f64);
        let rng = &mut self.rng;
        let noise = || -> [f32; 3] {
            if scale > 0.0 { std::array::from_fn(|_| (scale * rng.normal()) as f32) } else { [0.0; 3] }
        };
        let scene =
            Scene::new(self.dressed, &rest, &self.faces, &self.weights, &frame.pose, &frame.camera, noise)?;
        let t2 = Breakdown::add(&mut self.breakdown.skinning, t1);
        let rendered = scene.render(&frame.camera);
        let t3 = Breakdown::add(&mut self.breakdown.rasterise, t2);
        let weights = LossWeights { normal: self.settings.normal_weight, ssim: self.settings.ssim_weight };
        let (parts, grad) = image_loss(&rendered.image, frame.camera.width, &frame.target, weights);
        let t4 = Breakdown::add(&mut self.breakdown.losses, t3);
        let d_rest = scene.backward(&rendered, &grad, &frame.camera);
        let d_field = self.field.step(&d_rest, self.settings.rate, self.settings.regulariser);
        let t5 = Breakdown::add(&mut self.breakdown.backward, t4);
        if let (Some((network, _)), Some((_, activations)), Some(d)) =
            (self.dynamic.as_mut(), dynamic.as_ref(), self.settings.dynamic.as_ref())
        {
            network.step(activations, &d_field, d.rate);
        }
        let t5 = Breakdown::add(&mut self.breakdown.jacobian_mlp, t5);
        self.steps_taken += 1;
        if let Some((alpha, delta)) =
            self.settings.remesh.as_ref().and_then(|r| r.due(self.steps_taken, self.settings.steps))
        {
            self.remesh(alpha, delta)?;
        }
        Breakdown::add(&mut self.breakdown.remesh, t5);
        Ok(StepReport { frame: k, losses: parts, mask_iou: frame.target.iou(&rendered.image) })
    }

    /// Splits the faces that quantile `alpha` and edge length `delta` select (§3.2) and carries
    /// the fit to the new mesh.
    fn remesh(&mut self, alpha: f64, delta: f64) -> Result<(), GarmentError> {
        let norms = self.field.take_gradient_norms();
        let edges = selected_edges(&self.base, &self.faces, &norms, alpha, delta);
        if edges.is_empty() {
            return Ok(());
        }
        let joints = self.dressed.model().num_joints();
        let field = &self.field;
        let carried = remesh_and_carry(
            &self.base,
            &self.faces,
            &edges,
            &field.field,
            [&field.first, &field.second],
            &self.weights,
            joints,
        );
        check_manifold(&carried.positions, &carried.faces)
            .map_err(|e| GarmentError::invalid("remeshing", e.to_string()))?;
        self.field = field
            .remeshed(&carried.positions, &carried.faces, carried.field, carried.first, carried.second)
            .map_err(|e| GarmentError::invalid("remeshing", e.to_string()))?;
        if let Some((network, _)) = self.dynamic.as_mut() {
            network.set_base(&carried.positions, &carried.faces);
        }
        self.base = carried.positions;
        self.faces = carried.faces;
        self.weights = carried.weights;
        Ok(())
    }

    /// The garment's mask IoU against each of `frames`' label maps.
    pub fn mask_iou(&self, frames: &[TrainingFrame]) -> Result<Vec<f64>, GarmentError> {
        frames
            .iter()
            .map(|f| {
                let rest = self.rest_for(&f.pose);
                let scene =
                    Scene::new(self.dressed, &rest, &self.faces, &self.weights, &f.pose, &f.camera, || {
                        [0.0; 3]
                    })?;
                Ok(f.target.iou(&scene.render(&f.camera).image))
            })
            .collect()
    }

    /// The garment posed in `pose`, as a mesh (for evaluation and export).
    pub fn posed(&self, pose: &FramePose) -> Result<TriMesh, GarmentError> {
        let rest = self.rest_for(pose);
        let skinned = self.dressed.skin_with(&rest, &self.weights, &pose.pose, &pose.transl)?;
        Ok(TriMesh::new(skinned.into_iter().map(|(p, _)| p).collect(), self.faces.clone()))
    }
}

fn to_f32(positions: &[[f64; 3]]) -> Vec<[f32; 3]> {
    positions.iter().map(|p| p.map(|x| x as f32)).collect()
}

/// The joints' rotations without the root's: a turn of the whole body does not change how a
/// garment hangs, and in a turning capture it would be the pose's main component.
fn body_pose(pose: &[f32]) -> &[f32] {
    pose.get(3..).unwrap_or(&[])
}
