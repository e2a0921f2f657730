//! The one layout of scores that every `mannequin eval` writes: one entry per test set, named
//! for what the set tests, and the geometry over all of them.

use serde::Serialize;

use std::collections::BTreeMap;

use crate::evaluation::{EvalSummary, FrameScores, garment_means, mean_of};
use crate::metrics::geometry::GeometryMetrics;

/// What a test set holds, named for what it tests.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum TestSet {
    /// Cameras that no training frame used.
    #[value(name = "novel_view")]
    NovelView,
    /// Poses from motions that no training frame used.
    #[value(name = "novel_pose")]
    NovelPose,
    /// Held-out frames of the training camera (PeopleSnapshot's test split).
    Test,
}

impl TestSet {
    pub fn name(self) -> &'static str {
        match self {
            Self::NovelView => "novel_view",
            Self::NovelPose => "novel_pose",
            Self::Test => "test",
        }
    }
}

/// Geometry over every scored frame with a ground-truth mesh or normal map, whatever its set.
#[derive(Debug, Clone, Serialize)]
pub struct GeometryScores {
    pub chamfer_cm: Option<f64>,
    pub p2s_cm: Option<f64>,
    pub normal_consistency: Option<f64>,
    pub normal_angle_deg: Option<f64>,
    pub normal_mse_x1e3: Option<f64>,
    /// Per garment, over every frame with its meshes.
    pub garments: BTreeMap<String, GeometryMetrics>,
}

/// Each test set's summary (`None` where the dataset has no such set), and the geometry.
#[derive(Debug, Clone, Serialize)]
pub struct Scores {
    pub novel_view: Option<EvalSummary>,
    pub novel_pose: Option<EvalSummary>,
    pub test: Option<EvalSummary>,
    pub geometry: GeometryScores,
}

impl Scores {
    /// Gathers the sets' summaries; a set given twice keeps the last.
    pub fn new(sets: Vec<(TestSet, EvalSummary)>) -> Self {
        let all: Vec<FrameScores> = sets.iter().flat_map(|(_, s)| s.per_frame.iter().cloned()).collect();
        let geometry = GeometryScores {
            chamfer_cm: mean_of(&all, |s| s.chamfer_cm),
            p2s_cm: mean_of(&all, |s| s.p2s_cm),
            normal_consistency: mean_of(&all, |s| s.normal_consistency),
            normal_angle_deg: mean_of(&all, |s| s.normal_angle_deg),
            normal_mse_x1e3: mean_of(&all, |s| s.normal_mse_x1e3),
            garments: garment_means(&all),
        };
        let mut scores = Self { novel_view: None, novel_pose: None, test: None, geometry };
        for (set, summary) in sets {
            *scores.set_mut(set) = Some(summary);
        }
        scores
    }

    fn set_mut(&mut self, set: TestSet) -> &mut Option<EvalSummary> {
        match set {
            TestSet::NovelView => &mut self.novel_view,
            TestSet::NovelPose => &mut self.novel_pose,
            TestSet::Test => &mut self.test,
        }
    }

    /// The sets present, in the layout's order.
    pub fn sets(&self) -> impl Iterator<Item = (TestSet, &EvalSummary)> {
        [
            (TestSet::NovelView, &self.novel_view),
            (TestSet::NovelPose, &self.novel_pose),
            (TestSet::Test, &self.test),
        ]
        .into_iter()
        .filter_map(|(set, s)| s.as_ref().map(|s| (set, s)))
    }
}
