//! Garment categories (the thesis's MGN templates, §3.2) and where each one covers the body.

use serde::{Deserialize, Serialize};

use crate::error::GarmentError;

/// A garment category; the thesis's Pants, ShortPants, ShirtNoCoat and TShirtNoCoat.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Category {
    Pants,
    ShortPants,
    Shirt,
    Tshirt,
}

/// The names `garment make --category` takes.
pub const CATEGORY_NAMES: [&str; 4] = ["pants", "short-pants", "shirt", "tshirt"];

impl Category {
    pub const ALL: [Category; 4] = [Category::Pants, Category::ShortPants, Category::Shirt, Category::Tshirt];

    pub fn named(name: &str) -> Result<Category, GarmentError> {
        CATEGORY_NAMES
            .iter()
            .position(|&n| n == name)
            .map(|i| Category::ALL[i])
            .ok_or_else(|| GarmentError::UnknownCategory { name: name.to_string() })
    }

    pub fn name(self) -> &'static str {
        CATEGORY_NAMES[Category::ALL.iter().position(|&c| c == self).unwrap_or(0)]
    }

    /// The cloth it is made of unless told otherwise (a `mannequin-cloth` material name).
    pub fn default_material(self) -> &'static str {
        match self {
            Category::Pants => "denim",
            Category::ShortPants | Category::Shirt => "cotton",
            Category::Tshirt => "jersey",
        }
    }

    /// Worn on the legs: held up at the waist, and under a top when both are worn.
    pub fn is_lower_body(self) -> bool {
        matches!(self, Category::Pants | Category::ShortPants)
    }

    /// The colour it renders in, linear RGB.
    pub fn colour(self) -> [f32; 3] {
        match self {
            Category::Pants => [0.12, 0.2, 0.42],
            Category::ShortPants => [0.45, 0.38, 0.25],
            Category::Shirt => [0.85, 0.85, 0.8],
            Category::Tshirt => [0.7, 0.15, 0.12],
        }
    }
}
