//! The canonical mesh a subject trains on: the shaped body, a skirt layer where the masks call
//! for one ([`crate::skirt_layer`]), the garments worn as layers of their own
//! ([`crate::garment_layer`]), then subdivided. It sits above the three, which know only the
//! mesh they extend.

use mannequin_body::BodyModel;

use crate::canonical::{Canonical, check_subdivisions};
use crate::error::AvatarError;
use crate::garment_layer::GarmentLayer;
use crate::skirt_layer::{SkirtLayer, SkirtMode, fit_skirt};
use crate::views::View;

impl Canonical {
    /// The subject's mesh: the shaped body, plus a skirt layer where `mode` and the views' masks
    /// call for one (returned too, for reporting), plus `garments` as layers of their own, then
    /// subdivided.
    pub fn for_subject(
        model: &BodyModel,
        betas: &[f32],
        subdivisions: usize,
        views: &[View],
        mode: SkirtMode,
        garments: &[GarmentLayer],
    ) -> Result<(Self, Option<SkirtLayer>), AvatarError> {
        check_subdivisions(subdivisions)?;
        let body = Self::from_body(model, betas, 0)?;
        let layer = fit_skirt(&body, views, mode)?;
        let mut c = match &layer {
            Some(l) => body.with_layer(l)?,
            None => body,
        };
        for garment in garments {
            let gate = garment.offset_gate(&c.vertices);
            c = c.with_garment(garment, &gate)?;
        }
        for _ in 0..subdivisions {
            c = c.subdivided();
        }
        Ok((c, layer))
    }
}
