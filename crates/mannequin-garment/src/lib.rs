//! Garments (thesis §3.2, MGN): templates cut from the body's surface, carried to any body shape
//! by Eqs. 3.1–3.3, and stored as `.garment` files.

pub mod category;
mod error;
pub mod file;
pub mod fit;
mod garment;
mod layering;
mod make;
pub mod region;
mod transfer;

pub use category::{CATEGORY_NAMES, Category};
pub use error::GarmentError;
pub use fit::{Fit, SIZE_NAMES};
pub use garment::{Garment, Recipe};
pub use make::make_garment;
pub use transfer::Dressed;
