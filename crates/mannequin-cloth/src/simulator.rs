//! The XPBD time loop with small steps (Eqs. 3.13–3.15, 3.26–3.35): each frame is split into
//! substeps; each substep predicts positions from velocities and gravity, projects every constraint
//! once with fresh multipliers λ, and takes the velocities from the positions' change.

use std::time::Instant;

use glam::Vec3;

use crate::attachment::{Attachment, check_attachments};
use crate::body::Body;
use crate::body_contacts::BodyCollider;
use crate::cloth::Cloth;
use crate::error::ClothError;
use crate::layers::Layers;
use crate::phase_times::PhaseTimes;
use crate::self_contacts::SelfContacts;
use crate::settings::Settings;
use crate::state::ClothState;
use crate::tethers::Tethers;

pub struct Simulator {
    cloth: Cloth,
    settings: Settings,
    /// The cloth's inverse masses, with attached particles made kinematic (0).
    inverse_mass: Vec<f32>,
    body: Option<BodyCollider>,
    attachments: Vec<Attachment>,
    /// Long-range attachments to the attached particles (none without attachments).
    tethers: Tethers,
    /// Present when self-collision is on.
    contacts: Option<SelfContacts>,
    /// Cloth under this one that the contacts hold it off (with self-collision): its particles
    /// follow the cloth's, kinematic, moved with the body.
    layers: Option<Layers>,
    /// The triangles the contacts keep apart: the cloth's, then the layers'.
    contact_faces: Vec<[u32; 3]>,
    /// The cloth's particles, then the layers'.
    positions: Vec<[f32; 3]>,
    velocities: Vec<[f32; 3]>,
    /// Positions at the start of the current substep.
    previous: Vec<[f32; 3]>,
    stretch_lambda: Vec<f32>,
    bending_lambda: Vec<f32>,
    times: PhaseTimes,
}

impl Simulator {
    /// A simulator starting from the cloth's start positions at rest, colliding with `body` if given
    /// (and the layers it wears, held off by the contacts with self-collision), with `attachments`
    /// (which need a body, and refer to its own triangles) following it.
    pub fn new(
        cloth: Cloth,
        body: Option<Body>,
        attachments: Vec<Attachment>,
        settings: Settings,
    ) -> Result<Self, ClothError> {
        settings.validate()?;
        let n = cloth.particle_count();
        let (body, layers) = match body.map(|b| b.colliders(settings.self_collision)) {
            Some((body, layers)) => (Some(body), layers),
            None => (None, None),
        };
        check_attachments(&attachments, n, body.as_ref())?;
        let mut inverse_mass = cloth.inverse_mass.clone();
        for a in &attachments {
            inverse_mass[a.particle as usize] = 0.0;
        }
        let mut positions = cloth.start.clone();
        let mut contact_faces = cloth.faces.clone();
        let mut edges = cloth.edges();
        if let Some(layers) = &layers {
            // The layers' particles follow the cloth's.
            let past = |i: u32| i + n as u32;
            positions.extend_from_slice(&layers.rest);
            contact_faces.extend(layers.faces.iter().map(|f| f.map(past)));
            edges.extend(mannequin_mesh::adjacency::edges(&layers.faces).into_iter().map(|e| e.map(past)));
            inverse_mass.resize(positions.len(), 0.0);
        }
        if settings.self_collision {
            check_uncrossed(&positions, &contact_faces, cloth.faces.len())?;
        }
        let anchors: Vec<u32> = attachments.iter().map(|a| a.particle).collect();
        let tethers = if anchors.is_empty() {
            Tethers::default()
        } else {
            Tethers::new(n, &cloth.stretch.edges, &anchors)
        };
        Ok(Self {
            tethers,
            inverse_mass,
            body: body.map(BodyCollider::new),
            attachments,
            contacts: settings
                .self_collision
                .then(|| SelfContacts::new(settings.thickness, edges, positions.clone(), n as u32)),
            layers,
            contact_faces,
            velocities: vec![[0.0; 3]; positions.len()],
            previous: positions.clone(),
            positions,
            stretch_lambda: vec![0.0; cloth.stretch.len()],
            bending_lambda: vec![0.0; cloth.bending.len()],
            cloth,
            settings,
            times: PhaseTimes::default(),
        })
    }

    /// Advances the cloth by one frame of `frame_dt` seconds, while the body moves from the
    /// vertex positions `body_start` to `body_end` (both empty when there is no body).
    pub fn step_frame(
        &mut self,
        body_start: &[[f32; 3]],
        body_end: &[[f32; 3]],
        frame_dt: f32,
    ) -> Result<(), ClothError> {
        if !(frame_dt.is_finite() && frame_dt > 0.0) {
            return Err(ClothError::invalid("frame_dt", format!("{frame_dt} is not a positive duration")));
        }
        let substeps = match &mut self.body {
            Some(body) => {
                body.begin_frame(body_start, body_end, self.settings.substeps, self.settings.body_margin)?
            }
            None if body_start.is_empty() && body_end.is_empty() => self.settings.substeps,
            None => {
                return Err(ClothError::invalid(
                    "body_start",
                    "body positions given, but the simulator has no body",
                ));
            }
        };
        if let Some(layers) = &self.layers {
            // Where the caller says, moving at the frame's pace: a resumed run starts as this one.
            let (n, first) = (self.cloth.particle_count(), layers.first_vertex);
            let moves = body_start[first..].iter().zip(&body_end[first..]);
            for ((x, v), (start, end)) in
                self.positions[n..].iter_mut().zip(&mut self.velocities[n..]).zip(moves)
            {
                *x = *start;
                *v = ((Vec3::from(*end) - Vec3::from(*start)) / frame_dt).to_array();
            }
        }
        if let Some(contacts) = &mut self.contacts {
            contacts.begin_frame();
        }
        let dt = frame_dt / substeps as f32;
        for k in 0..substeps {
            self.substep(k, dt, (substeps - k) as f32 * dt);
        }
        match self.positions.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            Some(particle) => Err(ClothError::NonFinite { particle }),
            None => Ok(()),
        }
    }

    /// Substep `k` of `dt`, `remaining` of the frame left (its own included).
    fn substep(&mut self, k: u32, dt: f32, remaining: f32) {
        if let Some(body) = &mut self.body {
            let t = Instant::now();
            body.advance(k);
            self.times.body_contacts += t.elapsed();
            let t = Instant::now();
            if body.rebuild_if_due(k) {
                self.times.hashing += t.elapsed();
            }
        }
        // Before the prediction, which stills the attached particles' velocities.
        if let Some(contacts) = &mut self.contacts {
            let t = Instant::now();
            contacts.begin_substep(&self.positions, &self.velocities, (dt, remaining), &self.contact_faces);
            self.times.hashing += t.elapsed();
        }
        let t = Instant::now();
        self.predict(dt);
        self.times.prediction += t.elapsed();
        self.stretch_lambda.fill(0.0);
        self.bending_lambda.fill(0.0);
        let w = &self.inverse_mass;
        for _ in 0..self.settings.iterations {
            let t = Instant::now();
            self.cloth.stretch.project(&mut self.positions, w, &mut self.stretch_lambda, dt);
            self.tethers.project(&mut self.positions, w);
            // Before the body and the contacts, which have the last word on where cloth may be.
            let limit = self.cloth.material.strain_limit;
            self.cloth.stretch.limit_strain(&mut self.positions, w, limit, &mut self.stretch_lambda);
            self.times.stretch += t.elapsed();
            let t = Instant::now();
            self.cloth.bending.project(&mut self.positions, w, &mut self.bending_lambda, dt);
            self.times.bending += t.elapsed();
            if let Some(body) = &self.body {
                let t = Instant::now();
                let (margin, friction) = (self.settings.body_margin, self.cloth.material.friction);
                body.project(&mut self.positions, &self.previous, w, margin, friction);
                self.times.body_contacts += t.elapsed();
            }
            // Last, so the body's push does not undo them: what they leave undone the safe step holds.
            if let Some(contacts) = &self.contacts {
                let t = Instant::now();
                contacts.project(&mut self.positions, &self.previous, w, &self.contact_faces);
                self.times.self_contacts += t.elapsed();
            }
        }
        if let Some(contacts) = &mut self.contacts {
            let t = Instant::now();
            contacts.find_candidates(&self.positions, &self.previous, &self.contact_faces);
            self.times.hashing += t.elapsed();
            let t = Instant::now();
            contacts.hold(&mut self.positions, &self.previous, &self.inverse_mass, &self.contact_faces);
            self.times.self_contacts += t.elapsed();
        }
        let t = Instant::now();
        self.update_velocities(dt);
        self.times.prediction += t.elapsed();
    }

    /// Eq. 3.13 before the constraints: v ← (v + Δt·g)·e^(−damping·Δt), x ← x + Δt·v; attached
    /// particles go to their body points, and the layers' where the body has them.
    fn predict(&mut self, dt: f32) {
        let g = Vec3::from(self.settings.gravity);
        let keep = (-self.cloth.material.damping * dt).exp();
        let w = &self.inverse_mass;
        // A few nanoseconds a particle: on one thread, as the pool's hand-off costs more.
        for (((x, v), previous), &w) in
            self.positions.iter_mut().zip(&mut self.velocities).zip(&mut self.previous).zip(w)
        {
            *previous = *x;
            if w == 0.0 {
                *v = [0.0; 3];
                continue;
            }
            let velocity = (Vec3::from(*v) + dt * g) * keep;
            *v = velocity.to_array();
            *x = (Vec3::from(*x) + dt * velocity).to_array();
        }
        if let Some(body) = &self.body {
            for a in &self.attachments {
                let target = a.target(&body.now, &body.body.faces, &body.normals);
                self.positions[a.particle as usize] = target.to_array();
            }
            if let Some(layers) = &self.layers {
                let now = &body.now[layers.first_vertex..];
                let n = self.cloth.particle_count();
                for (x, p) in self.positions[n..].iter_mut().zip(now) {
                    *x = p.to_array();
                }
            }
        }
    }

    /// Eq. 3.14: the velocity is the substep's displacement over Δt.
    fn update_velocities(&mut self, dt: f32) {
        for ((v, x), previous) in self.velocities.iter_mut().zip(&self.positions).zip(&self.previous) {
            *v = ((Vec3::from(*x) - Vec3::from(*previous)) / dt).to_array();
        }
    }

    /// The cloth's positions.
    pub fn positions(&self) -> &[[f32; 3]] {
        &self.positions[..self.cloth.particle_count()]
    }

    pub fn cloth(&self) -> &Cloth {
        &self.cloth
    }

    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Cumulative wall time per phase over every frame stepped.
    pub fn phase_times(&self) -> PhaseTimes {
        self.times
    }

    /// The cloth's positions and velocities (the layers' come with the body's every frame).
    pub fn state(&self) -> ClothState {
        let n = self.cloth.particle_count();
        ClothState { positions: self.positions[..n].to_vec(), velocities: self.velocities[..n].to_vec() }
    }

    /// Continues from `state`, as saved by [`Simulator::state`] from a simulator of the same cloth.
    pub fn restore(&mut self, state: ClothState) -> Result<(), ClothError> {
        let n = self.cloth.particle_count();
        state.check(n)?;
        self.positions[..n].copy_from_slice(&state.positions);
        self.velocities[..n].copy_from_slice(&state.velocities);
        Ok(())
    }
}

/// Refuses a start where the cloth (the first `cloth_faces` of `faces`) crosses itself or the
/// layers under it (the rest), with the count and the place of the first crossing: the safe step
/// would hold such a pair crossed for ever. The layers crossing themselves are not the cloth's
/// to mend.
fn check_uncrossed(positions: &[[f32; 3]], faces: &[[u32; 3]], cloth_faces: usize) -> Result<(), ClothError> {
    let crossed: Vec<[usize; 2]> = crate::quality::self_intersections(positions, faces)
        .into_iter()
        .filter(|&[first, _]| first < cloth_faces)
        .collect();
    let (itself, layers): (Vec<[usize; 2]>, _) =
        crossed.into_iter().partition(|&[_, second]| second < cloth_faces);
    let place = |pair| crate::quality::pair_place(positions, faces, pair);
    if let Some(&pair) = itself.first() {
        let [x, y, z] = place(pair);
        let [first, second] = pair;
        return Err(ClothError::StartsCrossed { pairs: itself.len(), first, second, x, y, z });
    }
    match layers.first() {
        Some(&pair) => {
            let [x, y, z] = place(pair);
            let (face, layer_face) = (pair[0], pair[1] - cloth_faces);
            Err(ClothError::StartsCrossingLayers { pairs: layers.len(), face, layer_face, x, y, z })
        }
        None => Ok(()),
    }
}
