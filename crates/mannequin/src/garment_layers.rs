//! `mannequin train --garments`: which garments a clothed avatar wears as layers of their own,
//! and their reconstruction from the dataset's label maps (NGD, as `garment fit` does it) before
//! the avatar trains over them.

use std::path::Path;

use anyhow::{Context, Result, bail};
use mannequin_avatar::garment_layer::GarmentLayer;
use mannequin_data::layout;
use mannequin_io::fingerprint::Fingerprint;
use mannequin_garment::Category;
use mannequin_io::{NpyArray, Npz, NpzWriter};

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

/// Where a finished reconstruction is kept beside its fit, with the record of what made it.
const KEPT: &str = "layer.npz";

/// Reconstructs each of `garments` with `garment fit`'s defaults but its seed and steps,
/// writing each fit into `out/garments/<category>/`, and returns them as avatar layers. A
/// garment whose folder keeps a finished reconstruction of the same `data` (by its
/// fingerprint), body, seed and steps is read back instead of fitted again, so a run stopped
/// after its first garments goes on from there.
pub fn reconstruct_all(
    garments: &[Category],
    (data, fingerprint): (&Path, &Fingerprint),
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
            let record =
                serde_json::json!({ "category": c.name(), "body": body, "seed": seed, "steps": steps, "data": fingerprint })
                    .to_string();
            if let Some(layer) = read_kept(&dir.join(KEPT), &record, c.name())? {
                tracing::info!("the {} reconstructed earlier is kept in {}: reusing it", c.name(), dir.display());
                return Ok(layer);
            }
            let fitted = reconstruct(data, c.name(), c.name(), body, &ngd, &dir)?;
            let layer = GarmentLayer {
                name: fitted.category,
                positions: fitted.positions,
                faces: fitted.faces,
                weights: fitted.weights,
            };
            keep(&dir.join(KEPT), &layer, &record)?;
            Ok(layer)
        })
        .collect()
}

fn keep(path: &Path, layer: &GarmentLayer, record: &str) -> Result<()> {
    let mut w = NpzWriter::new();
    w.add("record", NpyArray::text(record));
    let v = layer.positions.len();
    w.add("positions", NpyArray::f32(vec![v, 3], layer.positions.iter().flatten().copied().collect()));
    let faces = layer.faces.iter().flatten().map(|&i| i64::from(i)).collect();
    w.add("faces", NpyArray::i64(vec![layer.faces.len(), 3], faces));
    w.add("weights", NpyArray::f32(vec![v, layer.weights.len() / v.max(1)], layer.weights.clone()));
    w.write(path).with_context(|| format!("writing {}", path.display()))
}

/// The layer kept at `path` if it was made as `record` says; `None` if there is none or it was
/// made another way.
fn read_kept(path: &Path, record: &str, name: &str) -> Result<Option<GarmentLayer>> {
    if !path.exists() {
        return Ok(None);
    }
    let npz = Npz::read(path)?;
    if npz.text("record")? != record {
        return Ok(None);
    }
    let (_, positions) = npz.f64_with_shape("positions", &[None, Some(3)])?;
    let v = positions.len() / 3;
    let (_, faces) = npz.f64_with_shape("faces", &[None, Some(3)])?;
    let (_, weights) = npz.f64_with_shape("weights", &[Some(v), None])?;
    if let Some(f) = faces.iter().position(|&i| i < 0.0 || i as usize >= v) {
        bail!("{}: faces: face {} indexes past the {v} vertices", path.display(), f / 3);
    }
    Ok(Some(GarmentLayer {
        name: name.to_string(),
        positions: positions.chunks_exact(3).map(|p| [p[0] as f32, p[1] as f32, p[2] as f32]).collect(),
        faces: faces.chunks_exact(3).map(|f| [f[0] as u32, f[1] as u32, f[2] as u32]).collect(),
        weights: weights.into_iter().map(|w| w as f32).collect(),
    }))
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
