//! One person of a run: the manifest row as the plan keeps it, the folder that holds everything
//! of theirs (no two tasks write the same file), and each step's command line in it.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::step::Step;

/// What a row's `input` names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum InputKind {
    /// A video file, for `capture --video`.
    Video,
    /// A folder of frames, for `capture --frames`.
    Frames,
    /// A dataset folder (`cameras.npz` and `images/`): trained on as it is, or its images
    /// captured as plain frames and its truth used to score the result.
    Dataset,
}

impl InputKind {
    /// The kind of an existing `path`.
    pub fn of(path: &Path) -> InputKind {
        if path.is_file() {
            InputKind::Video
        } else if path.join("cameras.npz").is_file() && path.join("images").is_dir() {
            InputKind::Dataset
        } else {
            InputKind::Frames
        }
    }
}

/// A step as planned: which one, and the flags the manifest's columns add to its verb.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlannedStep {
    pub step: Step,
    pub flags: Vec<String>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Person {
    pub id: String,
    /// The manifest line it came from.
    pub line: usize,
    /// Absolute path of the input.
    pub input: PathBuf,
    pub kind: InputKind,
    pub steps: Vec<PlannedStep>,
}

impl Person {
    pub fn runs(&self, step: Step) -> bool {
        self.steps.iter().any(|s| s.step == step)
    }

    /// The folder of this person's files under the run folder.
    pub fn dir(&self, run: &Path) -> PathBuf {
        run.join("people").join(&self.id)
    }

    /// The dataset `train`, `garments` and `eval` read: the captured one where the row captures,
    /// else the input itself.
    pub fn dataset(&self, run: &Path) -> PathBuf {
        if self.runs(Step::Capture) { self.dir(run).join("captured") } else { self.input.clone() }
    }

    /// The command line (without the binary's name) of `step`; `garment` names the garment of a
    /// `garments` step, which runs once for each.
    pub fn argv(&self, run: &Path, step: &PlannedStep, garment: Option<&str>) -> Vec<String> {
        let dir = self.dir(run);
        let data = self.dataset(run);
        let text = |p: &Path| p.to_string_lossy().into_owned();
        let mut argv: Vec<String> = step.step.verb().iter().map(|s| s.to_string()).collect();
        let mut add = |words: &[&str]| argv.extend(words.iter().map(|w| w.to_string()));
        match step.step {
            Step::Capture => {
                let (flag, source) = match self.kind {
                    InputKind::Video => ("--video", self.input.clone()),
                    InputKind::Frames => ("--frames", self.input.clone()),
                    InputKind::Dataset => ("--frames", self.input.join("images")),
                };
                add(&[flag, &text(&source), "--out", &text(&data)]);
            }
            Step::Train => add(&["--data", &text(&data), "--out", &text(&dir.join("avatar"))]),
            Step::Garments => {
                let garment = garment.unwrap_or("tshirt");
                let out = dir.join("garments").join(garment);
                add(&["--data", &text(&data), "--category", garment, "--out", &text(&out)]);
            }
            Step::Export => {
                let export = dir.join("export");
                let (glb, ply) = (export.join("avatar.glb"), export.join("avatar_gaussians.ply"));
                add(&["--avatar", &text(&dir.join("avatar")), "-o", &text(&glb), "--gaussians", &text(&ply)]);
            }
            Step::Eval => {
                add(&["--avatar", &text(&dir.join("avatar")), "--data", &text(&data)]);
                add(&["--json", &text(&dir.join("eval.json"))]);
                // A dataset captured as plain frames is scored against its own truth.
                if self.kind == InputKind::Dataset && self.runs(Step::Capture) {
                    add(&["--truth", &text(&self.input)]);
                }
            }
        }
        argv.extend(step.flags.iter().cloned());
        argv
    }
}
