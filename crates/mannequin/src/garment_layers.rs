//! `mannequin train --garments`: which garments a clothed avatar wears as layers of their own,
//! and their reconstruction from the dataset's label maps (NGD, as `garment fit` does it) before
//! the avatar trains over them.

use std::path::Path;

use anyhow::{Result, bail};
use mannequin_avatar::garment_layer::GarmentLayer;
use mannequin_data::layout;
use mannequin_garment::Category;

use crate::garment_fit::{NgdArgs, label_legend, reconstruct};

/// The garments `spec` names: `auto` (every garment category among the label maps' legend), or a
/// comma-separated list of categories, each optionally after the body part it is worn on
/// (`upper:tshirt,lower:pants`). Each is checked against the dataset's label maps, which the
/// reconstruction fits.
pub fn resolve(spec: &str, data: &Path) -> Result<Vec<Category>> {
    let labels = data.join(layout::LABELS);
    if !labels.is_dir() {
        bail!(
            "{}: --garments reconstructs garments from label maps ({}/label_%04d.png, with subject.json's \"labels\" legend); add them, or train without --garments",
            data.display(),
            layout::LABELS
        );
    }
    let legend = label_legend(data)?;
    let among = |c: Category| legend.iter().any(|n| n == c.name());
    let garments: Vec<Category> = if spec == "auto" {
        let found: Vec<Category> = legend.iter().filter_map(|n| Category::named(n).ok()).collect();
        if found.is_empty() {
            bail!(
                "{}: labels: no garment category among {legend:?}; name the garments with --garments upper:tshirt,lower:pants",
                data.join("subject.json").display()
            );
        }
        found
    } else {
        spec.split(',').map(|item| parse_item(item.trim())).collect::<Result<_>>()?
    };
    if let Some(c) = garments.iter().find(|&&c| !among(c)) {
        bail!(
            "{}: labels: no '{}' among {legend:?}, so the label maps do not show that garment",
            data.join("subject.json").display(),
            c.name()
        );
    }
    if let Some((i, c)) = garments.iter().enumerate().find(|(i, c)| garments[..*i].contains(c)) {
        bail!("--garments: {} is named twice (item {})", c.name(), i + 1);
    }
    Ok(garments)
}

/// `part:category` or `category`, the part (`upper` or `lower`) checked against the category.
fn parse_item(item: &str) -> Result<Category> {
    let (part, name) = match item.split_once(':') {
        Some((part, name)) => (Some(part), name),
        None => (None, item),
    };
    let category = Category::named(name).map_err(|e| anyhow::anyhow!("--garments: {e}"))?;
    match (part, category.is_lower_body()) {
        (None | Some("lower"), true) | (None | Some("upper"), false) => Ok(category),
        (Some(p @ ("upper" | "lower")), _) => bail!("--garments: a {name} is not worn on the {p} body"),
        (Some(p), _) => bail!("--garments: unknown body part '{p}' in '{item}' (expected upper or lower)"),
    }
}

/// Reconstructs each of `garments` with `garment fit`'s defaults but its seed and steps,
/// writing each fit into `out/garments/<category>/`, and returns them as avatar layers.
pub fn reconstruct_all(
    garments: &[Category],
    data: &Path,
    body: &str,
    (seed, steps): (u64, usize),
    out: &Path,
) -> Result<Vec<GarmentLayer>> {
    let mut ngd = NgdArgs::defaults(seed);
    ngd.iters = steps;
    garments
        .iter()
        .map(|c| {
            let dir = out.join("garments").join(c.name());
            let fitted = reconstruct(data, c.name(), c.name(), body, &ngd, &dir)?;
            Ok(GarmentLayer {
                name: fitted.category,
                positions: fitted.positions,
                faces: fitted.faces,
                weights: fitted.weights,
            })
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
