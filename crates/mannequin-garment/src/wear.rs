//! Wearing garments through a motion: each layer, inner first, simulated by XPBD from its
//! transferred rest shape (Eq. 3.2) through the pose schedule, colliding with the body and with
//! every layer under it. Skinning (Eq. 3.3) says where the layer goes; the simulator resolves
//! what skinning cannot, gravity on loose parts and the body pushing through. A wear reports
//! each frame with what a checkpoint needs, and resumes from such a checkpoint bit for bit.

use mannequin_body::Settling;
use mannequin_cloth::{Attachment, Cloth, ClothState, PhaseTimes, Settings, Simulator};

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

/// How far a wear has got: every frame of the layers finished (inner first), and of the layer
/// under way with the simulator's state after its last frame. What a checkpoint holds.
#[derive(Debug, Clone, Default)]
pub struct WearProgress {
    pub finished: Vec<Vec<Vec<[f32; 3]>>>,
    pub current: Option<LayerProgress>,
}

/// The layer under way: its frames so far (from the schedule's first) and the cloth's state.
#[derive(Debug, Clone)]
pub struct LayerProgress {
    pub frames: Vec<Vec<[f32; 3]>>,
    pub state: ClothState,
}

/// What a wear reports after each simulated frame.
pub struct WearStep<'a> {
    /// The layer just stepped (inner first).
    pub layer: usize,
    finished: &'a [WornLayer],
    frames: &'a [Vec<[f32; 3]>],
    sim: &'a Simulator,
}

impl WearStep<'_> {
    /// Frames simulated so far over all layers, settling included (each layer's first frame is
    /// its rest shape and is not simulated).
    pub fn frames_done(&self) -> usize {
        self.finished.iter().map(|l| l.frames.len() - 1).sum::<usize>() + self.frames.len() - 1
    }

    /// A copy of the progress so far, to save as a checkpoint.
    pub fn progress(&self) -> WearProgress {
        WearProgress {
            finished: self.finished.iter().map(|l| l.frames.clone()).collect(),
            current: Some(LayerProgress { frames: self.frames.to_vec(), state: self.sim.state() }),
        }
    }
}

/// Simulates `layers` (named, inner first) on `wearer` with the solver's `settings`, going on
/// from `resume` (a default one starts afresh); `on_frame` is called after each simulated frame
/// (to save a checkpoint, say) and its error stops the wear.
pub fn wear<E: From<GarmentError>>(
    layers: &[(&str, &Dressed)],
    wearer: &Wearer,
    settings: Settings,
    resume: WearProgress,
    on_frame: &mut dyn FnMut(&WearStep) -> Result<(), E>,
) -> Result<Vec<WornLayer>, E> {
    resume.check(layers, wearer.frames.len())?;
    let mut worn: Vec<WornLayer> = resume
        .finished
        .into_iter()
        .map(|frames| WornLayer { frames, phases: PhaseTimes::default() })
        .collect();
    let mut current = resume.current;
    for (i, (name, dressed)) in layers.iter().enumerate().skip(worn.len()) {
        let inner: Vec<Layer> = layers
            .iter()
            .zip(&worn)
            .map(|((_, d), w)| (d.garment().mesh.faces.as_slice(), w.frames.as_slice()))
            .collect();
        let mut report = |frames: &[Vec<[f32; 3]>], sim: &Simulator| {
            on_frame(&WearStep { layer: i, finished: &worn, frames, sim })
        };
        let layer = simulate_layer(name, dressed, &inner, wearer, settings, current.take(), &mut report)?;
        worn.push(layer);
    }
    Ok(worn)
}

impl WearProgress {
    /// Refuses progress that is not of `layers` on a schedule of `schedule` frames, naming the
    /// field at fault: too many layers, a layer's frame or vertex count, or a cloth state out of
    /// its bounds.
    pub fn check(&self, layers: &[(&str, &Dressed)], schedule: usize) -> Result<(), GarmentError> {
        let under_way = usize::from(self.current.is_some());
        if self.finished.len() + under_way > layers.len() {
            return Err(GarmentError::invalid(
                "progress.finished",
                format!(
                    "{} layers finished and {under_way} under way, but {} are worn",
                    self.finished.len(),
                    layers.len()
                ),
            ));
        }
        let current = self.current.iter().map(|c| ("current", &c.frames, 1..schedule));
        let finished = self.finished.iter().map(|f| ("finished", f, schedule..schedule + 1));
        for ((field, frames, expected), (_, dressed)) in finished.chain(current).zip(layers) {
            let vertices = dressed.garment().vertex_count();
            if !expected.contains(&frames.len()) || frames.iter().any(|f| f.len() != vertices) {
                return Err(GarmentError::invalid(
                    format!("progress.{field}"),
                    format!(
                        "expected {expected:?} frames of {vertices} vertices ({}), found {} frames",
                        dressed.garment().recipe.category.name(),
                        frames.len()
                    ),
                ));
            }
        }
        if let (Some(current), Some((_, dressed))) = (&self.current, layers.get(self.finished.len())) {
            current
                .state
                .check(dressed.garment().vertex_count())
                .map_err(|e| GarmentError::invalid("progress.current", e.to_string()))?;
        }
        Ok(())
    }
}

/// Called after each frame of a layer with its frames so far and the simulator.
type LayerReport<'a, E> = dyn FnMut(&[Vec<[f32; 3]>], &Simulator) -> Result<(), E> + 'a;

/// One layer through the whole schedule (settling included), or its rest from `resume`, held
/// where [`Dressed::held`] says.
fn simulate_layer<E: From<GarmentError>>(
    name: &str,
    dressed: &Dressed,
    inner: &[Layer],
    wearer: &Wearer,
    settings: Settings,
    resume: Option<LayerProgress>,
    on_frame: &mut LayerReport<E>,
) -> Result<WornLayer, E> {
    let garment = dressed.garment();
    let rest = dressed.rest();
    let mut mesh = garment.mesh.clone();
    mesh.positions = rest.clone();
    let material = garment.recipe.material;
    let failed =
        |when: String| move |error| GarmentError::Simulation { garment: name.to_string(), when, error };
    let cloth = Cloth::new(&mesh, &material, &[]).map_err(failed("at rest".into()))?;

    // The layer skinned (Eq. 3.3) every few frames says which part of the body it can meet.
    let skinned: Vec<(usize, Vec<[f32; 3]>)> = (0..wearer.frames.len())
        .step_by(5)
        .map(|k| {
            let (pose, trans) = wearer.schedule.pose(k);
            Ok((k, dressed.posed(pose, trans)?))
        })
        .collect::<Result<_, GarmentError>>()?;
    let collider = Collider::new(wearer.frames, wearer.faces, inner, &skinned);
    let at_rest = collider.at(0);
    // Held to the body itself, under the layers.
    let attachments: Vec<Attachment> = dressed
        .held()
        .into_iter()
        .map(|v| Attachment::bind(&at_rest, &collider.faces, v, mesh.positions[v as usize]))
        .collect();
    let body = collider.body().map_err(failed("at rest".into()))?;
    let mut sim =
        Simulator::new(cloth, Some(body), attachments, settings).map_err(failed("at rest".into()))?;
    let settle = wearer.schedule.settle;
    let mut frames = match resume {
        Some(progress) => {
            sim.restore(progress.state).map_err(failed("resuming".into()))?;
            progress.frames
        }
        None => vec![rest],
    };
    let mut previous = collider.at(frames.len() - 1);
    for k in frames.len()..wearer.frames.len() {
        let next = collider.at(k);
        sim.step_frame(&previous, &next, 1.0 / wearer.fps).map_err(failed(if k < settle {
            "while settling".into()
        } else {
            format!("at motion frame {}", k - settle)
        }))?;
        frames.push(sim.positions().to_vec());
        previous = next;
        on_frame(&frames, &sim)?;
    }
    Ok(WornLayer { frames, phases: sim.phase_times() })
}
