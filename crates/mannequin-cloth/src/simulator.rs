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
    positions: Vec<[f32; 3]>,
    velocities: Vec<[f32; 3]>,
    /// Positions at the start of the current substep.
    previous: Vec<[f32; 3]>,
    stretch_lambda: Vec<f32>,
    bending_lambda: Vec<f32>,
    times: PhaseTimes,
}

impl Simulator {
    /// A simulator starting from the cloth's start positions at rest, colliding with `body` if given,
    /// with `attachments` (which need a body) following it.
    pub fn new(
        cloth: Cloth,
        body: Option<Body>,
        attachments: Vec<Attachment>,
        settings: Settings,
    ) -> Result<Self, ClothError> {
        settings.validate()?;
        let n = cloth.particle_count();
        check_attachments(&attachments, n, body.as_ref())?;
        let mut inverse_mass = cloth.inverse_mass.clone();
        for a in &attachments {
            inverse_mass[a.particle as usize] = 0.0;
        }
        if settings.self_collision {
            check_uncrossed(&cloth.start, &cloth.faces)?;
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
                .then(|| SelfContacts::new(settings.thickness, cloth.edges(), cloth.start.clone())),
            positions: cloth.start.clone(),
            velocities: vec![[0.0; 3]; n],
            previous: cloth.start.clone(),
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
        let substeps = self.settings.substeps;
        match &mut self.body {
            Some(body) => body.begin_frame(body_start, body_end, substeps, self.settings.body_margin)?,
            None if body_start.is_empty() && body_end.is_empty() => {}
            None => {
                return Err(ClothError::invalid(
                    "body_start",
                    "body positions given, but the simulator has no body",
                ));
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
            contacts.begin_substep(&self.positions, &self.velocities, (dt, remaining), &self.cloth.faces);
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
                contacts.project(&mut self.positions, &self.previous, w, &self.cloth.faces);
                self.times.self_contacts += t.elapsed();
            }
        }
        if let Some(contacts) = &mut self.contacts {
            let t = Instant::now();
            contacts.find_candidates(&self.positions, &self.previous, &self.cloth.faces);
            self.times.hashing += t.elapsed();
            let t = Instant::now();
            contacts.hold(&mut self.positions, &self.previous, &self.inverse_mass, &self.cloth.faces);
            self.times.self_contacts += t.elapsed();
        }
        let t = Instant::now();
        self.update_velocities(dt);
        self.times.prediction += t.elapsed();
    }

    /// Eq. 3.13 before the constraints: v ← (v + Δt·g)·e^(−damping·Δt), x ← x + Δt·v; attached
    /// particles go to their body points.
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
        }
    }

    /// Eq. 3.14: the velocity is the substep's displacement over Δt.
    fn update_velocities(&mut self, dt: f32) {
        for ((v, x), previous) in self.velocities.iter_mut().zip(&self.positions).zip(&self.previous) {
            *v = ((Vec3::from(*x) - Vec3::from(*previous)) / dt).to_array();
        }
    }

    pub fn positions(&self) -> &[[f32; 3]] {
        &self.positions
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

    pub fn state(&self) -> ClothState {
        ClothState { positions: self.positions.clone(), velocities: self.velocities.clone() }
    }

    /// Continues from `state`, as saved by [`Simulator::state`] from a simulator of the same cloth.
    pub fn restore(&mut self, state: ClothState) -> Result<(), ClothError> {
        state.check(self.positions.len())?;
        self.positions = state.positions;
        self.velocities = state.velocities;
        Ok(())
    }
}

/// Refuses a start where the cloth crosses itself, with the count and the place of the first
/// crossing: the safe step would hold such a pair crossed for ever.
fn check_uncrossed(positions: &[[f32; 3]], faces: &[[u32; 3]]) -> Result<(), ClothError> {
    let crossed = crate::quality::self_intersections(positions, faces);
    let Some(&[first, second]) = crossed.first() else {
        return Ok(());
    };
    let corners = faces[first].iter().chain(&faces[second]).map(|&v| Vec3::from(positions[v as usize]));
    let [x, y, z] = (corners.sum::<Vec3>() / 6.0).to_array();
    Err(ClothError::StartsCrossed { pairs: crossed.len(), first, second, x, y, z })
}
