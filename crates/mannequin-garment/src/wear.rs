//! Wearing garments through a motion: each layer, inner first, simulated by XPBD from its
//! transferred rest shape (Eq. 3.2) through the pose schedule, colliding with the body and with
//! every layer under it. Skinning (Eq. 3.3) says where the layer goes; the simulator resolves
//! what skinning cannot, gravity on loose parts and the body pushing through.

use mannequin_body::Settling;
use mannequin_cloth::{Attachment, Body, Cloth, Material, PhaseTimes, Settings, Simulator};
use mannequin_mesh::TriMesh;
use mannequin_mesh::adjacency::boundary_loops_by_height;

use crate::collider::Collider;
use crate::error::GarmentError;
use crate::transfer::Dressed;

/// A layer under the one being simulated: its triangles, and its positions at every frame of
/// the schedule.
pub(crate) type Layer<'a> = (&'a [[u32; 3]], &'a [Vec<[f32; 3]>]);

/// The body the layers are worn on: its triangles, and its vertices at every frame of
/// `schedule`, which plays at `fps`.
pub struct Wearer<'a> {
    pub faces: &'a [[u32; 3]],
    pub frames: &'a [Vec<[f32; 3]>],
    pub schedule: &'a Settling,
    pub fps: f32,
}

/// One layer simulated: its positions at every frame of the schedule, and where the time went.
pub struct WornLayer {
    pub frames: Vec<Vec<[f32; 3]>>,
    pub phases: PhaseTimes,
}

/// Simulates `layers` (named, inner first) on `wearer` with the solver's `settings`;
/// `on_frame(layer)` is called after each simulated frame.
pub fn wear(
    layers: &[(&str, &Dressed)],
    wearer: &Wearer,
    settings: Settings,
    on_frame: &(dyn Fn(usize) + Sync),
) -> Result<Vec<WornLayer>, GarmentError> {
    let mut worn: Vec<WornLayer> = Vec::with_capacity(layers.len());
    for (i, (name, dressed)) in layers.iter().enumerate() {
        let inner: Vec<Layer> = layers
            .iter()
            .zip(&worn)
            .map(|((_, d), w)| (d.garment().mesh.faces.as_slice(), w.frames.as_slice()))
            .collect();
        let layer = simulate_layer(name, dressed, &inner, wearer, settings, &|| on_frame(i))?;
        worn.push(layer);
    }
    Ok(worn)
}

/// One layer through the whole schedule (settling included). Lower-body garments are held at
/// the waist (the loop of their boundary that is highest at rest), as an elastic waistband
/// holds them.
fn simulate_layer(
    name: &str,
    dressed: &Dressed,
    inner: &[Layer],
    wearer: &Wearer,
    settings: Settings,
    on_frame: &dyn Fn(),
) -> Result<WornLayer, GarmentError> {
    let garment = dressed.garment();
    let rest = dressed.rest();
    let mut mesh = garment.mesh.clone();
    mesh.positions = rest.clone();
    let material = Material::named(&garment.recipe.material)?;
    let failed =
        |when: String| move |source| GarmentError::Simulation { garment: name.to_string(), when, source };
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
    let faces = collider.faces.clone();
    let at_rest = collider.at(0);
    let attachments: Vec<Attachment> = if garment.recipe.category.is_lower_body() {
        waist_loop(&mesh)
            .into_iter()
            .map(|v| Attachment::bind(&at_rest, &faces, v, mesh.positions[v as usize]))
            .collect()
    } else {
        Vec::new()
    };
    let mut sim = Simulator::new(cloth, Some(Body::new(faces)), attachments, settings)
        .map_err(failed("at rest".into()))?;
    let settle = wearer.schedule.settle;
    let mut frames = vec![rest];
    let mut previous = at_rest;
    for k in 1..wearer.frames.len() {
        let next = collider.at(k);
        sim.step_frame(&previous, &next, 1.0 / wearer.fps).map_err(failed(if k < settle {
            "while settling".into()
        } else {
            format!("at motion frame {}", k - settle)
        }))?;
        frames.push(sim.positions().to_vec());
        previous = next;
        on_frame();
    }
    Ok(WornLayer { frames, phases: sim.phase_times() })
}

/// The vertices of the boundary loop whose mean height at rest is greatest.
fn waist_loop(mesh: &TriMesh) -> Vec<u32> {
    boundary_loops_by_height(&mesh.positions, &mesh.faces).pop().unwrap_or_default()
}
