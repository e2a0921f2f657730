//! What a shop varies in a garment: the ease (how far it stands off the body) at chest, waist and
//! hips, the hem's height above the floor, and the sleeve's length.

use serde::{Deserialize, Serialize};

use crate::error::GarmentError;

/// A garment's size and cut, in metres except `sleeve`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ease {
    pub ease_chest: f32,
    pub ease_waist: f32,
    pub ease_hips: f32,
    /// The hem's height above the soles at rest; `None` takes the category's.
    pub hem_height: Option<f32>,
    /// The sleeve from shoulder (0) to wrist (1); `None` takes the category's.
    pub sleeve: Option<f32>,
}

/// The names `--size` takes.
pub const SIZE_NAMES: [&str; 4] = ["S", "M", "L", "XL"];

impl Ease {
    /// A size's ease: M stands about 1.5 cm off the chest, each size up adds about 1 cm.
    pub fn size(name: &str) -> Result<Ease, GarmentError> {
        let step = SIZE_NAMES
            .iter()
            .position(|&n| n.eq_ignore_ascii_case(name))
            .ok_or_else(|| GarmentError::UnknownSize { name: name.to_string(), known: &SIZE_NAMES })?
            as f32;
        Ok(Ease {
            ease_chest: 0.005 + 0.01 * step,
            ease_waist: 0.004 + 0.008 * step,
            ease_hips: 0.004 + 0.008 * step,
            hem_height: None,
            sleeve: None,
        })
    }

    pub fn validate(&self) -> Result<(), GarmentError> {
        for (field, value) in
            [("ease_chest", self.ease_chest), ("ease_waist", self.ease_waist), ("ease_hips", self.ease_hips)]
        {
            if !(0.0..=0.2).contains(&value) {
                return Err(GarmentError::invalid(field, format!("{value} m; expected 0 to 0.2 m")));
            }
        }
        if let Some(h) = self.hem_height
            && !(0.0..=2.5).contains(&h)
        {
            return Err(GarmentError::invalid(
                "hem_height",
                format!("{h} m; expected 0 to 2.5 m above the soles"),
            ));
        }
        if let Some(s) = self.sleeve
            && !(0.0..=1.0).contains(&s)
        {
            return Err(GarmentError::invalid(
                "sleeve",
                format!("{s}; expected 0 (none) to 1 (to the wrist)"),
            ));
        }
        Ok(())
    }
}
