//! Wall time spent in each phase of the solver, summed over every frame stepped, so a benchmark can
//! say where the next speed-up lies.

use std::time::Duration;

#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PhaseTimes {
    /// Gravity, damping, the displacement bound, attachments and the velocity update.
    pub prediction: Duration,
    /// Spatial hashes: cloth triangles for self-collision, body triangles for body collision.
    pub hashing: Duration,
    pub stretch: Duration,
    pub bending: Duration,
    pub self_contacts: Duration,
    pub body_contacts: Duration,
}

impl PhaseTimes {
    pub fn total(&self) -> Duration {
        self.prediction + self.hashing + self.stretch + self.bending + self.self_contacts + self.body_contacts
    }

    /// The phases with their names, in solver order.
    pub fn named(&self) -> [(&'static str, Duration); 6] {
        [
            ("prediction", self.prediction),
            ("hashing", self.hashing),
            ("stretch", self.stretch),
            ("bending", self.bending),
            ("self contacts", self.self_contacts),
            ("body contacts", self.body_contacts),
        ]
    }
}
