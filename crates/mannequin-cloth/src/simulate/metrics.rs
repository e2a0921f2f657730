//! How well each simulated frame of `cloth simulate` went: vertices inside the body, the
//! cloth crossing itself, edge strain and stretch, and the time it took.

use serde::{Deserialize, Serialize};

use crate::quality;

/// Per-frame quality of the simulated garment.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(super) struct FrameMetrics {
    pub frame: usize,
    pub vertices_inside_body: usize,
    pub self_intersecting_pairs: usize,
    pub max_edge_strain: f32,
    pub mean_edge_strain: f32,
    /// The 99th percentile of the edges' stretch past their rest length, held to the material's
    /// strain limit.
    pub p99_edge_stretch: f32,
    pub simulation_ms: f64,
}

impl FrameMetrics {
    /// Motion frame `frame`'s metrics: the cloth at `positions` (rest shape `rest`, triangles
    /// `faces`) on the body at `body` (triangles `body_faces`), simulated in `ms`.
    pub fn measure(
        frame: usize,
        positions: &[[f32; 3]],
        (rest, faces): (&[[f32; 3]], &[[u32; 3]]),
        (body, body_faces): (&[[f32; 3]], &[[u32; 3]]),
        ms: f64,
    ) -> Self {
        let (max_edge_strain, mean_edge_strain) = quality::edge_strain(rest, positions, faces);
        FrameMetrics {
            frame,
            vertices_inside_body: quality::vertices_inside_body(positions, body, body_faces),
            self_intersecting_pairs: quality::self_intersecting_pairs(positions, faces),
            max_edge_strain,
            mean_edge_strain,
            p99_edge_stretch: quality::stretch_quantile(rest, positions, faces, 0.99),
            simulation_ms: ms,
        }
    }

    /// Whether these are motion frame `frame`'s, every measure finite and non-negative.
    pub fn is_frame(&self, frame: usize) -> bool {
        let measures = [self.max_edge_strain, self.mean_edge_strain, self.p99_edge_stretch].map(f64::from);
        self.frame == frame
            && measures.into_iter().chain([self.simulation_ms]).all(|x| x.is_finite() && x >= 0.0)
    }
}
