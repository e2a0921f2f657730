//! Training (Tavatar §4.3, iHuman supplement §1.3): one view per iteration, the losses of
//! Eq. 16 plus a mask term, Adam, checkpoints that resume bit for bit.

use std::path::Path;
use std::time::{Duration, Instant};

use burn::tensor::{Gradients, Tensor};
use mannequin_io::rng::SplitMix64;
use mannequin_io::{NpyArray, NpzWriter};

use crate::adam::Adam;
use crate::avatar::Avatar;
use crate::checkpoint::Checkpoint;
use crate::config::Method;
use crate::error::AvatarError;
use crate::losses::MeshRegularisers;
use crate::options::TrainOptions;
use crate::pose_refinement::{PoseRefinement, START_SHARE};
use crate::run::TrainingRun;
use crate::view_loss::view_loss;
use crate::views::View;

/// Wall time of each phase of one iteration, for the benchmark's breakdown.
#[derive(Debug, Clone, Default)]
pub struct Timings {
    pub skinning: Duration,
    pub derivation: Duration,
    pub render: Duration,
    pub losses: Duration,
    pub backward: Duration,
    pub optimiser: Duration,
}

/// The phases of one iteration, in order, as [`Trainer::on_phase`] names them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    Skinning,
    Derivation,
    Render,
    Losses,
    Backward,
    Optimiser,
}

impl Phase {
    pub const ALL: [Phase; 6] =
        [Phase::Skinning, Phase::Derivation, Phase::Render, Phase::Losses, Phase::Backward, Phase::Optimiser];
}

#[derive(Debug, Clone)]
pub struct StepStats {
    /// Iterations done, this one included.
    pub iteration: usize,
    pub loss: f64,
    /// PSNR of the colour inside the view's crop.
    pub psnr: f64,
    pub timings: Timings,
}

pub struct Trainer {
    pub avatar: Avatar,
    pub options: TrainOptions,
    pub iteration: usize,
    adam: Adam,
    views: Vec<View>,
    /// `views` at half resolution, for the first iterations (see `half_resolution_share`).
    halved: Vec<View>,
    regularisers: MeshRegularisers,
    /// 1 / (mean canonical edge length)²: makes the Laplacian term unit-free, so λ_m weighs it
    /// like the (unit-free) normal consistency whatever the mesh resolution.
    laplacian_scale: f64,
    /// Each parameter's learning rate at iteration 0.
    base_lr: Vec<f64>,
    /// Each training view's pose as a parameter, where the run refines them.
    refinement: Option<PoseRefinement>,
    /// Wait for the device at each phase boundary, so that [`Timings`] charges each phase its
    /// own work on a GPU, whose launches return before the work is done (costs throughput).
    pub profile: bool,
    /// Called after each phase has finished on the device (with [`Trainer::profile`] set), so a
    /// benchmark can attribute what the device logged (kernel launches) to the phase. `None`
    /// names the work queued before the iteration's first phase.
    pub on_phase: Option<Box<dyn Fn(Option<Phase>) + Send + Sync>>,
}

/// Mean edge length of the canonical mesh (each edge counted once per face side).
fn mean_edge_length(c: &crate::canonical::Canonical) -> f64 {
    let mut sum = 0.0;
    for f in &c.faces {
        for k in 0..3 {
            let (a, b) = (c.vertices[f[k] as usize], c.vertices[f[(k + 1) % 3] as usize]);
            sum += ((0..3).map(|i| (a[i] - b[i]) as f64 * (a[i] - b[i]) as f64).sum::<f64>()).sqrt();
        }
    }
    sum / (3 * c.faces.len()).max(1) as f64
}

/// View order of one epoch: a seeded Fisher–Yates shuffle, a pure function of (seed, epoch) so
/// a resumed run visits the same views.
fn epoch_order(seed: u64, epoch: usize, n: usize) -> Vec<usize> {
    let mut rng = SplitMix64::new(seed ^ (epoch as u64).wrapping_mul(0xD1B5_4A32_D192_ED03));
    let mut order: Vec<usize> = (0..n).collect();
    for i in (1..n).rev() {
        order.swap(i, (rng.next_u64() % (i as u64 + 1)) as usize);
    }
    order
}

impl Trainer {
    pub fn new(avatar: Avatar, views: Vec<View>, options: TrainOptions) -> Result<Self, AvatarError> {
        if views.is_empty() {
            return Err(AvatarError::Invalid("no training views".into()));
        }
        let regularisers =
            MeshRegularisers::new(avatar.canonical.num_vertices(), &avatar.canonical.faces, avatar.device())?;
        let mut avatar = avatar;
        let colours = crate::colour_init::observed_colours(&avatar, &views)?;
        avatar.set_sh_dc(crate::colour_init::dc_coefficients(&colours))?;
        let adam = Adam::new(&avatar.params);
        let laplacian_scale = mean_edge_length(&avatar.canonical).max(1e-6).powi(-2);
        let base_lr = avatar.params.iter().map(|p| p.lr).collect();
        let halved = if options.half_resolution_share > 0.0 {
            views.iter().map(|v| v.halved().unwrap_or_else(|| v.clone())).collect()
        } else {
            Vec::new()
        };
        let refinement = options.refine_poses.then(|| PoseRefinement::new(&views, avatar.device()));
        Ok(Self {
            refinement,
            avatar,
            options,
            iteration: 0,
            adam,
            views,
            halved,
            regularisers,
            laplacian_scale,
            base_lr,
            profile: false,
            on_phase: None,
        })
    }

    pub fn num_views(&self) -> usize {
        self.views.len()
    }

    pub fn has_normals(&self) -> bool {
        self.views.iter().all(|v| v.has_normals())
    }

    /// iHuman's three stages (supplement §1.3) over 20 "epochs" spread across the run: the
    /// displacement encoder learns fastest in stage 2, joints freeze in stage 3.
    fn apply_schedule(&mut self) {
        if self.avatar.config.method != Method::Ihuman {
            let factor = self.lr_factor();
            for (p, base) in self.avatar.params.iter_mut().zip(&self.base_lr) {
                p.lr = base * factor;
            }
            return;
        }
        let epoch = 20.0 * self.iteration as f64 / self.options.iterations.max(1) as f64;
        let stage = if epoch < 4.0 {
            1
        } else if epoch < 10.0 {
            2
        } else {
            3
        };
        for p in &mut self.avatar.params {
            p.lr = match p.name.split('/').next().unwrap_or("") {
                "offsets" => {
                    if stage == 2 {
                        8e-4
                    } else {
                        1e-4
                    }
                }
                "joints" => {
                    if stage == 3 {
                        0.0
                    } else {
                        5e-4
                    }
                }
                "colour" => 5e-4,
                _ => 5e-3,
            };
        }
    }

    /// Tavatar's learning rates, and the refined poses', decay exponentially to
    /// `final_lr_factor` of their start over the run.
    fn lr_factor(&self) -> f64 {
        let t = self.iteration as f64 / self.options.iterations.max(1) as f64;
        self.options.final_lr_factor.powf(t)
    }

    /// Whether this iteration moves the poses (refinement starts after `START_SHARE`).
    fn refining(&self) -> bool {
        self.refinement.is_some() && self.iteration as f64 >= START_SHARE * self.options.iterations as f64
    }

    /// One iteration on the next view.
    pub fn step(&mut self) -> Result<StepStats, AvatarError> {
        self.apply_schedule();
        let (grads, value, psnr, k, mut t) = self.loss_and_gradients()?;
        let clock = Instant::now();
        self.adam.update(&mut self.avatar.params, &grads);
        let factor = self.lr_factor();
        if let Some(r) = &mut self.refinement {
            r.update(&grads, factor, k)?;
        }
        t.optimiser = self.lap(clock, Some(Phase::Optimiser))?;
        self.iteration += 1;
        Ok(StepStats { iteration: self.iteration, loss: value, psnr, timings: t })
    }

    /// Time since `clock`, after the device has finished its work when profiling.
    fn lap(&self, clock: Instant, phase: Option<Phase>) -> Result<Duration, AvatarError> {
        if self.profile {
            self.avatar
                .device()
                .sync()
                .map_err(|e| AvatarError::Invalid(format!("the device failed: {e:?}")))?;
            if let Some(f) = &self.on_phase {
                f(phase);
            }
        }
        Ok(clock.elapsed())
    }

    /// This iteration's gradients, loss, PSNR and view. Every forward tensor is dropped on
    /// return, so the optimiser finds the parameters' buffers unshared and updates them in place.
    fn loss_and_gradients(&self) -> Result<(Gradients, f64, f64, usize, Timings), AvatarError> {
        let n = self.views.len();
        let (epoch, k) = (self.iteration / n, self.iteration % n);
        let coarse =
            (self.iteration as f64) < self.options.half_resolution_share * self.options.iterations as f64;
        let views = if coarse { &self.halved } else { &self.views };
        let k = epoch_order(self.options.seed, epoch, n)[k];
        let view = &views[k];
        let o = &self.options;
        let refining = self.refining();
        let mut t = Timings::default();

        self.lap(Instant::now(), None)?;
        let clock = Instant::now();
        let offsets = self.avatar.offsets()?;
        let personalised = self.avatar.personalised(offsets.clone());
        let vertices = match &self.refinement {
            Some(r) => {
                let (pose, transl) = r.pose(k, refining);
                self.avatar.skin_tensor(personalised.clone(), pose, transl)
            }
            None => self.avatar.skin(personalised.clone(), &view.pose, view.transl)?,
        };
        t.skinning = self.lap(clock, Some(Phase::Skinning))?;
        let clock = Instant::now();
        let gaussians = self.avatar.bind(&vertices);
        t.derivation = self.lap(clock, Some(Phase::Derivation))?;
        let clock = Instant::now();
        let posed = crate::avatar::Posed { personalised: personalised.clone(), vertices, gaussians };
        // Only the crop is rendered: the losses look nowhere else.
        let r = self.avatar.render(&posed, &view.crop_camera())?;
        t.render = self.lap(clock, Some(Phase::Render))?;

        let clock = Instant::now();
        let (mut loss, mse) = view_loss(&r, view, o)?;
        // Laplacian smoothness of the offset field and normal consistency of V_s (Eq. 15).
        let mesh = self.regularisers.laplacian(offsets)? * self.laplacian_scale
            + self.regularisers.normal_consistency(personalised.clone())?;
        loss = loss + mesh * o.lambda_mesh;
        if o.lambda_equilateral > 0.0 {
            loss = loss + self.regularisers.equilateral(personalised)? * o.lambda_equilateral;
        }
        if let Some(r) = self.refinement.as_ref().filter(|_| refining) {
            loss = loss + r.prior(k);
        }
        let value = loss.clone().into_scalar::<f64>();
        t.losses = self.lap(clock, Some(Phase::Losses))?;
        if !value.is_finite() {
            return Err(AvatarError::NonFiniteLoss {
                iteration: self.iteration + 1,
                value,
                checkpoint: String::new(),
            });
        }
        let psnr = -10.0 * mse.into_scalar::<f64>().max(1e-20).log10();

        let clock = Instant::now();
        let grads = loss.backward();
        t.backward = self.lap(clock, Some(Phase::Backward))?;
        Ok((grads, value, psnr, k, t))
    }

    /// The refined training poses with the dataset's `betas`, where the run refines them.
    pub fn refined_poses(&self, betas: &[f32]) -> Option<mannequin_data::Poses> {
        self.refinement.as_ref().map(|r| r.poses(betas))
    }

    /// Mean wall time of the splatting backward alone (Gaussians as leaves) on the first view,
    /// so the benchmark can split the backward pass.
    pub fn render_backward_time(&self, repeats: usize) -> Result<Duration, AvatarError> {
        let view = &self.views[0];
        let posed = self.avatar.pose(&view.pose, view.transl)?;
        let g = posed.gaussians;
        let leaf = |t: Tensor<2>| t.detach().require_grad();
        let gaussians = crate::mesh_gaussians::GaussianGeometry {
            means: leaf(g.means),
            frames: g.frames.detach().require_grad(),
            scales: leaf(g.scales),
            normals: leaf(g.normals),
        };
        let posed = crate::avatar::Posed { gaussians, ..posed };
        let mut total = Duration::ZERO;
        for _ in 0..repeats.max(1) {
            let r = self.avatar.render(&posed, &view.crop_camera())?;
            let loss = r.image().sum() + r.alpha().sum();
            let clock = Instant::now();
            let _ = loss.backward();
            total += clock.elapsed();
        }
        Ok(total / repeats.max(1) as u32)
    }

    /// Writes parameters, optimiser moments, the iteration count and `run`, the record of what
    /// this trainer was built from, in one atomic file.
    pub fn save_checkpoint(&self, path: &Path, run: &TrainingRun) -> Result<(), AvatarError> {
        let mut w = NpzWriter::uncompressed();
        w.add("iteration", NpyArray::i64(vec![1], vec![self.iteration as i64]));
        run.write(&mut w);
        for p in &self.avatar.params {
            p.save(&mut w, "param/");
        }
        self.adam.save(&self.avatar.params, &mut w, "");
        if let Some(r) = &self.refinement {
            r.save(&mut w);
        }
        w.write(path)?;
        Ok(())
    }

    /// Continues from a checkpoint written by [`Trainer::save_checkpoint`], refusing one whose
    /// record differs from `run` in any setting, or whose arrays do not fit this avatar.
    pub fn resume(&mut self, checkpoint: &Checkpoint, run: &TrainingRun) -> Result<(), AvatarError> {
        let npz = &checkpoint.npz;
        run.check(npz, &[])?;
        self.avatar.load_params(npz, "param/")?;
        self.adam = Adam::load(&self.avatar.params, npz, checkpoint.iteration, "")?;
        if let Some(r) = &mut self.refinement {
            r.load(npz, checkpoint.iteration)?;
        }
        self.iteration = checkpoint.iteration;
        Ok(())
    }
}
