//! The garments a clothed avatar wears as layers of their own (`mannequin train --garments`),
//! and their reconstruction from the dataset's label maps (NGD, as `garment fit` does it) before
//! the avatar trains over them.

use std::path::Path;

use mannequin_data::layout;
use mannequin_io::fingerprint::Fingerprint;

use super::error::NgdError;
use super::kept::{KEPT, keep, read_kept};
use super::legend::label_legend;
use super::pipeline::{FittedGarment, reconstruct};
use super::settings::NgdSettings;
use crate::category::Category;

/// The garments `spec` names: `auto` (every garment category among the label maps' legend), or a
/// comma-separated list of categories, each optionally after the body part it is worn on
/// (`upper:tshirt,lower:pants`). Each is checked against the dataset's label maps, which the
/// reconstruction fits.
pub fn resolve(spec: &str, data: &Path) -> Result<Vec<Category>, NgdError> {
    let labels = data.join(layout::LABELS);
    if !labels.is_dir() {
        return Err(NgdError::file(
            data,
            format!(
                "--garments reconstructs garments from label maps ({}/label_%04d.png, with subject.json's \"labels\" legend); make them with `mannequin segment --data DATASET`, or train without --garments",
                layout::LABELS
            ),
        ));
    }
    let legend = label_legend(data)?;
    let among = |c: Category| legend.iter().any(|n| n == c.name());
    let garments: Vec<Category> = if spec == "auto" {
        let found: Vec<Category> = legend.iter().filter_map(|n| Category::named(n).ok()).collect();
        if found.is_empty() {
            return Err(NgdError::file(
                data.join("subject.json"),
                format!(
                    "labels: no garment category among {legend:?}; name the garments with --garments upper:tshirt,lower:pants"
                ),
            ));
        }
        found
    } else {
        spec.split(',').map(|item| parse_item(item.trim())).collect::<Result<_, _>>()?
    };
    if let Some(c) = garments.iter().find(|&&c| !among(c)) {
        return Err(NgdError::file(
            data.join("subject.json"),
            format!("labels: no '{}' among {legend:?}, so the label maps do not show that garment", c.name()),
        ));
    }
    if let Some((i, c)) = garments.iter().enumerate().find(|(i, c)| garments[..*i].contains(c)) {
        return Err(NgdError::flag("--garments", format!("{} is named twice (item {})", c.name(), i + 1)));
    }
    Ok(garments)
}

/// `part:category` or `category`, the part (`upper` or `lower`) checked against the category.
pub(crate) fn parse_item(item: &str) -> Result<Category, NgdError> {
    let (part, name) = match item.split_once(':') {
        Some((part, name)) => (Some(part), name),
        None => (None, item),
    };
    let category = Category::named(name).map_err(|e| NgdError::flag("--garments", e.to_string()))?;
    match (part, category.is_lower_body()) {
        (None | Some("lower"), true) | (None | Some("upper"), false) => Ok(category),
        (Some(p @ ("upper" | "lower")), _) => {
            Err(NgdError::flag("--garments", format!("a {name} is not worn on the {p} body")))
        }
        (Some(p), _) => Err(NgdError::flag(
            "--garments",
            format!("unknown body part '{p}' in '{item}' (expected upper or lower)"),
        )),
    }
}

/// Reconstructs each of `garments` with `garment fit`'s defaults but its seed and steps,
/// writing each fit into `out/garments/<category>/`. A garment whose folder keeps a finished
/// reconstruction of the same `data` (by its fingerprint), body, seed and steps is read back
/// instead of fitted again, so a run stopped after its first garments goes on from there.
pub fn reconstruct_all(
    garments: &[Category],
    (data, fingerprint): (&Path, &Fingerprint),
    body: &str,
    (seed, steps): (u64, usize),
    out: &Path,
) -> Result<Vec<FittedGarment>, NgdError> {
    let ngd = NgdSettings { seed, steps, ..NgdSettings::default() };
    garments
        .iter()
        .map(|c| {
            let dir = out.join("garments").join(c.name());
            let record =
                serde_json::json!({ "category": c.name(), "body": body, "seed": seed, "steps": steps, "data": fingerprint })
                    .to_string();
            if let Some(fitted) = read_kept(&dir.join(KEPT), &record, c.name())? {
                tracing::info!("the {} reconstructed earlier is kept in {}: reusing it", c.name(), dir.display());
                return Ok(fitted);
            }
            let fitted = reconstruct(data, c.name(), c.name(), body, &ngd, &dir)?;
            keep(&dir.join(KEPT), &fitted, &record)?;
            Ok(fitted)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn items_name_a_category_and_the_part_it_is_worn_on() {
        assert_eq!(parse_item("upper:tshirt").unwrap(), Category::Tshirt);
        assert_eq!(parse_item("lower:pants").unwrap(), Category::Pants);
        assert_eq!(parse_item("dress").unwrap(), Category::Dress);
        let e = parse_item("lower:tshirt").unwrap_err().to_string();
        assert_eq!(e, "--garments: a tshirt is not worn on the lower body");
        let e = parse_item("legs:pants").unwrap_err().to_string();
        assert!(e.contains("unknown body part 'legs'"), "{e}");
        assert!(parse_item("upper:cape").unwrap_err().to_string().starts_with("--garments: "));
    }
}
