//! What generating a subject reports as it goes: its cloth simulation takes minutes before the
//! first frame is written, so a progress display counts simulated frames too.

/// One report of [`crate::generate`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    /// This many more steps are to come (announced as each part of the work is known).
    Planned(usize),
    /// One garment simulated through one frame.
    Simulated,
    /// One frame rendered and written.
    Written,
}
