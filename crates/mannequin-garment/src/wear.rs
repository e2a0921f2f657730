//! Wearing garments through a motion: each layer simulated by XPBD from its transferred rest
//! shape (Eq. 3.2) through the pose schedule, colliding with the body and with every layer under
//! it. Skinning (Eq. 3.3) says where the layer goes; the simulator resolves what skinning cannot,
//! gravity on loose parts and the body pushing through.
//!
//! A layer meets those under it only where they are at the same frame, so the layers go as a
//! wavefront: each step, every layer whose inner neighbour is ahead of it simulates its next
//! frame, all at once, on their own cores. Each layer's frames are those of a run that simulates
//! the layers one after another, bit for bit. A wear reports each step with what a checkpoint
//! needs, and resumes from such a checkpoint bit for bit.

use mannequin_body::Settling;
use mannequin_cloth::{Attachment, Cloth, ClothError, ClothState, PhaseTimes, Settings, Simulator};
use rayon::prelude::*;

use crate::collider::{Collider, Layer};
use crate::error::GarmentError;
use crate::transfer::Dressed;

/// The body the layers are worn on: its triangles, and its vertices at every frame of
/// `schedule`, which plays at `fps`.
pub struct Wearer<'a> {
    pub faces: &'a [[u32; 3]],
    pub frames: &'a [Vec<[f32; 3]>],
    pub schedule: &'a Settling,
    pub fps: f32,
}

/// One layer simulated: its positions at every frame of the schedule, and where the time went
/// (since the wear resumed, for a resumed layer).
pub struct WornLayer {
    pub frames: Vec<Vec<[f32; 3]>>,
    pub phases: PhaseTimes,
}

/// How far a wear has got: per layer (inner first), its frames so far and the cloth's state
/// after the last. No layer is ahead of the one under it. What a checkpoint holds; an empty one
/// starts afresh.
#[derive(Debug, Clone, Default)]
pub struct WearProgress {
    pub layers: Vec<LayerProgress>,
}

/// One layer's frames so far (from the schedule's first, its rest shape) and the cloth's state.
#[derive(Debug, Clone)]
pub struct LayerProgress {
    pub frames: Vec<Vec<[f32; 3]>>,
    pub state: ClothState,
}

/// What a wear reports after each step of the wavefront.
pub struct WearStep<'a> {
    /// How many frames this step simulated (one per layer that moved on).
    pub stepped: usize,
    layers: &'a [LayerRun<'a>],
}

impl WearStep<'_> {
    /// Frames simulated so far over all layers, settling included (each layer's first frame is
    /// its rest shape and is not simulated).
    pub fn frames_done(&self) -> usize {
        self.layers.iter().map(|l| l.frames.len() - 1).sum()
    }

    /// A copy of the progress so far, to save as a checkpoint.
    pub fn progress(&self) -> WearProgress {
        let layers =
            self.layers.iter().map(|l| LayerProgress { frames: l.frames.clone(), state: l.sim.state() });
        WearProgress { layers: layers.collect() }
    }
}

/// Simulates `layers` (named, inner first) on `wearer` with the solver's `settings`, going on
/// from `resume` (a default one starts afresh); `on_step` is called after each step of the
/// wavefront (to save a checkpoint, say) and its error stops the wear.
pub fn wear<E: From<GarmentError>>(
    layers: &[(&str, &Dressed)],
    wearer: &Wearer,
    settings: Settings,
    resume: WearProgress,
    on_step: &mut dyn FnMut(&WearStep) -> Result<(), E>,
) -> Result<Vec<WornLayer>, E> {
    resume.check(layers, wearer.frames.len())?;
    let mut resumed = resume.layers.into_iter();
    let mut runs: Vec<LayerRun> = Vec::with_capacity(layers.len());
    for (name, dressed) in layers {
        let run = LayerRun::new(name, dressed, &inner_of(&runs), wearer, settings, resumed.next())?;
        runs.push(run);
    }
    let schedule = wearer.frames.len();
    loop {
        // The frame each layer would simulate next, where the layer under it has reached it.
        let due: Vec<Option<Vec<[f32; 3]>>> = (0..runs.len())
            .map(|i| {
                let k = runs[i].frames.len();
                let ready = k < schedule && (i == 0 || runs[i - 1].frames.len() > k);
                ready.then(|| runs[i].collider.at(k, &inner_of(&runs[..i])))
            })
            .collect();
        let stepped = due.iter().flatten().count();
        if stepped == 0 {
            break;
        }
        let outcomes: Vec<Result<(), GarmentError>> = runs
            .par_iter_mut()
            .zip(due)
            .map(|(run, next)| next.map_or(Ok(()), |next| run.step(next, wearer)))
            .collect();
        outcomes.into_iter().collect::<Result<(), GarmentError>>()?;
        on_step(&WearStep { stepped, layers: &runs })?;
    }
    Ok(runs.into_iter().map(|r| WornLayer { phases: r.sim.phase_times(), frames: r.frames }).collect())
}

/// The layers under the next one, as its collider reads them.
fn inner_of<'r>(runs: &'r [LayerRun]) -> Vec<Layer<'r>> {
    runs.iter().map(|r| (r.faces, r.frames.as_slice())).collect()
}

impl WearProgress {
    /// Refuses progress that is not of `layers` on a schedule of `schedule` frames, naming the
    /// field at fault: another number of layers, a layer's frame or vertex count, a layer ahead
    /// of the one under it, or a cloth state out of its bounds.
    pub fn check(&self, layers: &[(&str, &Dressed)], schedule: usize) -> Result<(), GarmentError> {
        if !self.layers.is_empty() && self.layers.len() != layers.len() {
            return Err(GarmentError::invalid(
                "progress.layers",
                format!("progress of {} layers, but {} are worn", self.layers.len(), layers.len()),
            ));
        }
        let mut under = schedule;
        for (i, (progress, (_, dressed))) in self.layers.iter().zip(layers).enumerate() {
            let (frames, vertices) = (&progress.frames, dressed.garment().vertex_count());
            let field = format!("progress.layers[{i}]");
            let category = dressed.garment().recipe.category.name();
            if !(1..=under).contains(&frames.len()) || frames.iter().any(|f| f.len() != vertices) {
                return Err(GarmentError::invalid(
                    field,
                    format!(
                        "expected 1 to {under} frames of {vertices} vertices ({category}), found {} \
                         frames",
                        frames.len()
                    ),
                ));
            }
            progress.state.check(vertices).map_err(|e| GarmentError::invalid(field, e.to_string()))?;
            under = frames.len();
        }
        Ok(())
    }
}

/// One layer under way: its simulator, what it collides with, and its frames so far.
struct LayerRun<'a> {
    name: &'a str,
    /// The garment's triangles.
    faces: &'a [[u32; 3]],
    sim: Simulator,
    collider: Collider<'a>,
    frames: Vec<Vec<[f32; 3]>>,
    /// The collider's vertices at the last frame.
    previous: Vec<[f32; 3]>,
}

/// What turns the simulator's error into the layer `name`'s, `when` it happened.
fn failed(name: &str, when: impl Into<String>) -> impl FnOnce(ClothError) -> GarmentError {
    let (garment, when) = (name.to_string(), when.into());
    move |error| GarmentError::Simulation { garment, when, error }
}

impl<'a> LayerRun<'a> {
    /// A layer worn over `inner`, from its rest shape or from `resume`, held where
    /// [`Dressed::held`] says.
    fn new(
        name: &'a str,
        dressed: &'a Dressed,
        inner: &[Layer],
        wearer: &Wearer<'a>,
        settings: Settings,
        resume: Option<LayerProgress>,
    ) -> Result<Self, GarmentError> {
        let garment = dressed.garment();
        let rest = dressed.rest();
        let mut mesh = garment.mesh.clone();
        mesh.positions = rest.clone();
        let material = garment.recipe.material;
        let cloth = Cloth::new(&mesh, &material, &[]).map_err(failed(name, "at rest"))?;

        // The layer skinned (Eq. 3.3) every few frames says which part of the body it can meet.
        let skinned: Vec<(usize, Vec<[f32; 3]>)> = (0..wearer.frames.len())
            .step_by(5)
            .map(|k| {
                let (pose, trans) = wearer.schedule.pose(k);
                Ok((k, dressed.posed(pose, trans)?))
            })
            .collect::<Result<_, GarmentError>>()?;
        let collider = Collider::new(wearer.frames, wearer.faces, inner, &skinned);
        let at_rest = collider.at(0, inner);
        // Held to the body itself, under the layers.
        let attachments: Vec<Attachment> = dressed
            .held()
            .into_iter()
            .map(|v| Attachment::bind(&at_rest, &collider.faces, v, mesh.positions[v as usize]))
            .collect();
        let body = collider.body(inner).map_err(failed(name, "at rest"))?;
        let mut sim =
            Simulator::new(cloth, Some(body), attachments, settings).map_err(failed(name, "at rest"))?;
        let frames = match resume {
            Some(progress) => {
                sim.restore(progress.state).map_err(failed(name, "resuming"))?;
                progress.frames
            }
            None => vec![rest],
        };
        let previous = collider.at(frames.len() - 1, inner);
        let faces = garment.mesh.faces.as_slice();
        Ok(Self { name, faces, sim, collider, frames, previous })
    }

    /// Simulates the next frame, the collider moving to `next`.
    fn step(&mut self, next: Vec<[f32; 3]>, wearer: &Wearer) -> Result<(), GarmentError> {
        let (k, settle) = (self.frames.len(), wearer.schedule.settle);
        let when = match k < settle {
            true => "while settling".to_string(),
            false => format!("at motion frame {}", k - settle),
        };
        self.sim.step_frame(&self.previous, &next, 1.0 / wearer.fps).map_err(failed(self.name, when))?;
        self.frames.push(self.sim.positions().to_vec());
        self.previous = next;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Category, Ease, make_garment};
    use mannequin_body::BodyModel;

    /// Progress with each layer at most as far as the one under it passes; a T-shirt a frame
    /// ahead of the pants under it, or progress of one layer for two, is refused naming the field.
    #[test]
    fn progress_keeps_each_layer_behind_the_one_under_it() {
        let model = BodyModel::default_body_lod1();
        let make = |c: Category| {
            make_garment(c, Ease::size("M").unwrap(), 0.06, c.default_material(), &model, "default", &[])
                .unwrap()
        };
        let (pants, tshirt) = (make(Category::Pants), make(Category::Tshirt));
        let dressed = [&pants, &tshirt].map(|g| Dressed::new(g, &model, &[]).unwrap());
        let layers = [("pants", &dressed[0]), ("tshirt", &dressed[1])];
        let at = |d: &Dressed, frames: usize| {
            let rest = d.rest();
            let state = ClothState { positions: rest.clone(), velocities: vec![[0.0; 3]; rest.len()] };
            LayerProgress { frames: vec![rest; frames], state }
        };
        let progress = |pants: usize, tshirt: usize| WearProgress {
            layers: vec![at(&dressed[0], pants), at(&dressed[1], tshirt)],
        };
        assert!(progress(4, 3).check(&layers, 10).is_ok());
        assert!(progress(10, 10).check(&layers, 10).is_ok());
        let refused = |p: WearProgress| p.check(&layers, 10).unwrap_err().to_string();
        let ahead = refused(progress(3, 4));
        assert!(ahead.contains("progress.layers[1]") && ahead.contains("1 to 3 frames"), "{ahead}");
        let past = refused(progress(11, 1));
        assert!(past.contains("progress.layers[0]") && past.contains("1 to 10 frames"), "{past}");
        let one = refused(WearProgress { layers: vec![at(&dressed[0], 2)] });
        assert!(one.contains("progress of 1 layers, but 2 are worn"), "{one}");
    }
}
