//! The steps a manifest row can ask for, in the only order they can run, and the verb each one
//! runs: a batch task is the CLI that exists, one verb (or one per garment) a step.

use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Step {
    Capture,
    Train,
    Garments,
    Export,
    Eval,
}

impl Step {
    /// Every step, in the order a row must list them.
    pub const ALL: [Step; 5] = [Step::Capture, Step::Train, Step::Garments, Step::Export, Step::Eval];

    pub fn name(self) -> &'static str {
        match self {
            Step::Capture => "capture",
            Step::Train => "train",
            Step::Garments => "garments",
            Step::Export => "export",
            Step::Eval => "eval",
        }
    }

    pub fn named(name: &str) -> Option<Step> {
        Step::ALL.into_iter().find(|s| s.name() == name)
    }

    /// The verb's path under `mannequin` (`garment fit` runs once per garment of the legend).
    pub fn verb(self) -> &'static [&'static str] {
        match self {
            Step::Capture => &["capture"],
            Step::Train => &["train"],
            Step::Garments => &["garment", "fit"],
            Step::Export => &["export"],
            Step::Eval => &["eval"],
        }
    }

    /// The flags the batch sets itself (where a person's files go, and what a re-run does with
    /// them), which a manifest's `<step>.<flag>` column may not set.
    pub fn owned_flags(self) -> &'static [&'static str] {
        match self {
            Step::Capture => &["video", "frames", "out", "restart"],
            Step::Train => &["data", "out", "restart"],
            Step::Garments => &["data", "category", "out"],
            Step::Export => &["avatar", "output", "gaussians"],
            Step::Eval => &["avatar", "data", "json", "truth", "pred", "gt"],
        }
    }

    /// What the step needs run before it in the same row, if anything.
    pub fn needs_train(self) -> bool {
        matches!(self, Step::Export | Step::Eval)
    }
}
