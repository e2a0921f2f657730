//! Garments (thesis §3.2, MGN): templates cut from the body's surface (and, below the seat,
//! sewn from flat panels and draped), carried to any body shape by Eqs. 3.1–3.3, and stored as
//! `.garment` files.

pub mod category;
mod collider;
mod drape;
mod dress_error;
pub mod dressing;
pub mod ease;
mod ease_relief;
mod error;
pub mod file;
mod garment;
mod garment_cache;
mod layered_scene;
mod layering;
mod make;
pub mod ngd;
mod panel;
pub mod region;
pub mod segmentation;
mod sewing;
mod transfer;
mod wear;

pub use category::{CATEGORY_NAMES, Category};
pub use dress_error::DressError;
pub use dressing::{DressJob, DressSettings, Dressing, Wardrobe, dress};
pub use ease::{Ease, SIZE_NAMES};
pub use error::GarmentError;
pub use garment::{Garment, Recipe};
pub use garment_cache::{load_or_make, read_for_body};
pub use layered_scene::write_layered_scene;
pub use make::{TEMPLATE_REVISION, make_garment};
pub use transfer::Dressed;
pub use wear::{LayerProgress, WearProgress, WearStep, Wearer, WornLayer, wear};
