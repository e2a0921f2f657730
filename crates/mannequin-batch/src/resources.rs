//! What one person's task asks the scheduler for: each step's CPUs, memory and time on one
//! node, from the per-step times and peaks measured at the default settings (docs/scale.md:
//! 46 s, 177 s, 0.2 s and 125 s for capture, train, export and eval, 855 MiB at most; garments
//! from docs/ngd.md's 10 minutes per 100 frames), with room to spare; a task asks for the most
//! CPUs and memory of its steps and the sum of their times.

use serde::{Deserialize, Serialize};

use super::step::Step;

/// One step's needs.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Needs {
    pub cpus: u32,
    pub memory_gib: u32,
    pub minutes: u32,
}

impl Needs {
    /// A step's needs at the default settings on a 2-core node.
    pub fn of(step: Step) -> Needs {
        let (cpus, memory_gib, minutes) = match step {
            Step::Capture => (2, 2, 5),
            Step::Train => (2, 2, 10),
            Step::Garments => (2, 2, 20),
            Step::Export => (1, 1, 2),
            Step::Eval => (2, 2, 8),
        };
        Needs { cpus, memory_gib, minutes }
    }

    /// A task running `steps` one after the other.
    pub fn of_steps(steps: impl IntoIterator<Item = Step>) -> Needs {
        steps.into_iter().map(Needs::of).fold(Needs { cpus: 1, memory_gib: 1, minutes: 0 }, |a, b| Needs {
            cpus: a.cpus.max(b.cpus),
            memory_gib: a.memory_gib.max(b.memory_gib),
            minutes: a.minutes + b.minutes,
        })
    }

    /// The larger of two tasks' needs: every array task asks for the same.
    pub fn max(self, other: Needs) -> Needs {
        Needs {
            cpus: self.cpus.max(other.cpus),
            memory_gib: self.memory_gib.max(other.memory_gib),
            minutes: self.minutes.max(other.minutes),
        }
    }
}
