//! The body and camera settings every fitting command shares (`fit`, `capture`, `face fit`,
//! `face track`): which body model, and the camera's focal length.

use mannequin_body::BodyModel;
use mannequin_io::limits::FOCAL_RANGE_PER_SIDE;

use crate::body_fit::assumed_focal;
use crate::error::FitError;

/// The body model and the camera's focal length.
#[derive(Clone, Debug, PartialEq, clap::Args, serde::Serialize, serde::Deserialize)]
pub struct FitSettings {
    /// The body model (the landmark table is made for the embedded default).
    #[arg(long, default_value_t = FitSettings::default().body)]
    pub body: String,
    /// Focal length in pixels; by default the picture's long side (a 53° view across it).
    #[arg(long)]
    pub focal: Option<f64>,
}

impl Default for FitSettings {
    fn default() -> Self {
        Self { body: "default".into(), focal: None }
    }
}

impl FitSettings {
    /// Refuses a focal length that is no length.
    pub fn check(&self) -> Result<(), FitError> {
        if let Some(f) = self.focal.filter(|f| !(f.is_finite() && *f > 0.0)) {
            return Err(FitError::Setting(format!(
                "--focal: expected a positive number of pixels, found {f}"
            )));
        }
        Ok(())
    }

    /// [`check`](Self::check), and refuses a body the face model is not made for.
    pub fn check_face_body(&self) -> Result<(), FitError> {
        self.check()?;
        if !self.is_default_body() {
            return Err(FitError::Setting(format!(
                "--body {}: the face model is the embedded default body's; use --body default",
                self.body
            )));
        }
        Ok(())
    }

    /// The body model, loaded.
    pub fn body_model(&self) -> Result<BodyModel, FitError> {
        BodyModel::from_spec(&self.body, None)
            .map_err(|e| FitError::within(format!("loading body model '{}'", self.body), e))
    }

    /// Whether the body is the embedded default, the one the face model is made for.
    pub fn is_default_body(&self) -> bool {
        self.body == FitSettings::default().body
    }

    /// The focal length for pictures of `width` × `height` pixels, within
    /// [`FOCAL_RANGE_PER_SIDE`] of their longer side (`--focal 1e30` once put the body 1.5e27 m
    /// away).
    pub fn focal(&self, width: usize, height: usize) -> Result<f64, FitError> {
        let Some(f) = self.focal else { return Ok(assumed_focal(width, height)) };
        let side = width.max(height) as f64;
        let (lo, hi) = FOCAL_RANGE_PER_SIDE;
        if f < lo * side || f > hi * side {
            return Err(FitError::Setting(format!(
                "--focal: {f} pixels for a {width}×{height} picture: expected {lo}–{hi} times its longer side ({}–{} px)",
                lo * side,
                hi * side
            )));
        }
        Ok(f)
    }
}
