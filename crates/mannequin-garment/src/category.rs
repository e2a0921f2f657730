//! Garment categories (the thesis's MGN templates, §3.2) and where each one covers the body.

use mannequin_cloth::Material;
use serde::{Deserialize, Serialize};

use crate::error::GarmentError;

/// A garment category: the thesis's Pants, ShortPants, ShirtNoCoat, TShirtNoCoat and LongCoat,
/// and the Skirt and Dress of the synthetic subjects.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Category {
    Pants,
    ShortPants,
    Shirt,
    Tshirt,
    LongCoat,
    Skirt,
    Dress,
}

/// The names `garment make --category` takes.
pub const CATEGORY_NAMES: [&str; 7] =
    ["pants", "short-pants", "shirt", "tshirt", "long-coat", "skirt", "dress"];

impl Category {
    pub const ALL: [Category; 7] = [
        Category::Pants,
        Category::ShortPants,
        Category::Shirt,
        Category::Tshirt,
        Category::LongCoat,
        Category::Skirt,
        Category::Dress,
    ];

    pub fn named(name: &str) -> Result<Category, GarmentError> {
        CATEGORY_NAMES
            .iter()
            .position(|&n| n == name)
            .map(|i| Category::ALL[i])
            .ok_or_else(|| GarmentError::UnknownCategory { name: name.to_string(), known: &CATEGORY_NAMES })
    }

    pub fn name(self) -> &'static str {
        CATEGORY_NAMES[Category::ALL.iter().position(|&c| c == self).unwrap_or(0)]
    }

    /// The cloth it is made of unless told otherwise.
    pub fn default_material(self) -> Material {
        match self {
            Category::Pants | Category::LongCoat => Material::DENIM,
            Category::ShortPants | Category::Shirt | Category::Skirt => Material::COTTON,
            Category::Tshirt => Material::JERSEY,
            Category::Dress => Material::SILK,
        }
    }

    /// Worn on the legs: held up at the waist, and under a top when both are worn.
    pub fn is_lower_body(self) -> bool {
        matches!(self, Category::Pants | Category::ShortPants | Category::Skirt)
    }

    /// How much wider its hem is than the seat line, as a share of the seat line's girth, for the
    /// categories that hang free of the body below it (a sewn, draped panel); `None` for those
    /// that follow the body all the way.
    pub fn flare(self) -> Option<f32> {
        match self {
            Category::Skirt => Some(0.4),
            Category::Dress => Some(0.6),
            Category::LongCoat => Some(0.2),
            Category::Pants | Category::ShortPants | Category::Shirt | Category::Tshirt => None,
        }
    }

    /// The colour it renders in, linear RGB.
    pub fn colour(self) -> [f32; 3] {
        match self {
            Category::Pants => [0.12, 0.2, 0.42],
            Category::ShortPants => [0.45, 0.38, 0.25],
            Category::Shirt => [0.85, 0.85, 0.8],
            Category::Tshirt => [0.7, 0.15, 0.12],
            Category::LongCoat => [0.3, 0.22, 0.15],
            Category::Skirt => [0.2, 0.45, 0.3],
            Category::Dress => [0.55, 0.25, 0.55],
        }
    }
}
