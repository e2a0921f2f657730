//! Garments by name or file: a `.garment` file is read and checked against the body; a category
//! name is made at a size on the body and cached, keyed by everything that made it, so the
//! next run (`dress`, `garment fit`) skips the minutes of making it.

use std::path::{Path, PathBuf};
use std::time::Instant;

use mannequin_body::BodyModel;
use mannequin_cloth::SimulateError;
use mannequin_cloth::run_checkpoint::file_hash;

use crate::category::{CATEGORY_NAMES, Category};
use crate::dress_error::DressError;
use crate::ease::Ease;
use crate::file::{read_garment, write_garment};
use crate::garment::Garment;
use crate::make::{TEMPLATE_REVISION, make_garment};

/// Edge length (m) of the templates made by category name.
const EDGE_LENGTH: f32 = 0.015;

/// A `.garment` file, or a category name made at `size` on this body and cached under
/// `$XDG_CACHE_HOME/mannequin/garments` (or `~/.cache/...`), keyed by everything that made it;
/// with the name the garment goes by in outputs.
pub fn load_or_make(
    spec: &str,
    model: &BodyModel,
    body: &str,
    size: &str,
) -> Result<(String, Garment), DressError> {
    let Ok(category) = Category::named(spec) else {
        let path = Path::new(spec);
        if !path.exists() {
            return Err(SimulateError::invalid(
                "--garments",
                format!("{spec:?} is neither a .garment file nor a category ({})", CATEGORY_NAMES.join(", ")),
            )
            .into());
        }
        let garment = read_for_body(path, model)?;
        let name = path.file_stem().map_or_else(|| "garment".into(), |s| s.to_string_lossy().into_owned());
        return Ok((name, garment));
    };
    let body_key = if Path::new(body).exists() { file_hash(Path::new(body))? } else { body.to_string() };
    let key =
        format!("{}-{size}-{body_key}-v{}-r{TEMPLATE_REVISION}", category.name(), env!("CARGO_PKG_VERSION"));
    let cache = cache_dir().map(|d| d.join("garments").join(format!("{key}.garment")));
    if let Some(path) = &cache
        && path.exists()
        && let Ok(garment) = read_garment(path)
    {
        tracing::info!("{}: from the cache, {}", category.name(), path.display());
        return Ok((category.name().to_string(), garment));
    }
    let start = Instant::now();
    let garment = make_garment(
        category,
        Ease::size(size)?,
        EDGE_LENGTH,
        category.default_material(),
        model,
        body,
        &[],
    )?;
    tracing::info!("{}: made in {:.1} s", category.name(), start.elapsed().as_secs_f64());
    if let Some(path) = &cache {
        let written = path.parent().map_or(Ok(()), std::fs::create_dir_all).map_err(|e| e.to_string());
        if let Err(e) = written.and_then(|()| write_garment(path, &garment).map_err(|e| e.to_string())) {
            tracing::warn!("not cached: {}: {e}", path.display());
        }
    }
    Ok((category.name().to_string(), garment))
}

/// The `.garment` file at `path`, checked against the body `model` it is to be worn on.
pub fn read_for_body(path: &Path, model: &BodyModel) -> Result<Garment, DressError> {
    let garment = read_garment(path)?;
    garment.check_body(model).map_err(|e| DressError::from(e).of(path.display().to_string()))?;
    Ok(garment)
}

/// `$XDG_CACHE_HOME/mannequin`, or `~/.cache/mannequin`.
fn cache_dir() -> Option<PathBuf> {
    std::env::var_os("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
        .map(|d| d.join("mannequin"))
}
