//! The subject's clothes: garments of the library (`mannequin-garment`), made on the subject's
//! own body at the outfit's sizes and layered inner first, each with a texture of its print.

use crate::error::SynthError;
use glam::{Vec2, Vec3};
use mannequin_body::BodyModel;
use mannequin_garment::{Category, Ease, Garment, make_garment};
use mannequin_mesh::{TriMesh, UvLayout};

use crate::subject::Outfit;

/// Edge length of the garments' triangles (m): the library's default.
const EDGE: f32 = 0.015;
/// How far (m) each layer stands beyond the one under it at rest (as `mannequin dress`).
const LAYER_GAP: f32 = 0.01;

/// Which of the subject's two looks a garment wears.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Piece {
    Top,
    Bottom,
}

/// A garment the subject wears: its name in the outputs, its look, and the layered template.
pub struct Worn {
    pub name: &'static str,
    pub piece: Piece,
    pub garment: Garment,
}

impl Outfit {
    /// The outfit's garments, inner layer first, with their sizes.
    pub fn garments(self) -> &'static [(Category, &'static str, Piece)] {
        match self {
            Outfit::TightShirtTrousers => {
                &[(Category::Pants, "S", Piece::Bottom), (Category::Shirt, "S", Piece::Top)]
            }
            Outfit::LooseShirtTrousers => {
                &[(Category::Pants, "L", Piece::Bottom), (Category::Tshirt, "M", Piece::Top)]
            }
            Outfit::ShirtSkirt => {
                &[(Category::Skirt, "M", Piece::Bottom), (Category::Tshirt, "M", Piece::Top)]
            }
            Outfit::Dress => &[(Category::Dress, "M", Piece::Top)],
        }
    }
}

/// Makes `outfit` on `model` with shape `betas`, each layer clear of those under it.
pub fn dress_subject(model: &BodyModel, betas: &[f32], outfit: Outfit) -> Result<Vec<Worn>, SynthError> {
    let mut worn: Vec<Worn> = Vec::new();
    for &(category, size, piece) in outfit.garments() {
        let fail = |e: mannequin_garment::GarmentError| {
            SynthError::Invalid(format!("making the {}: {e}", category.name()))
        };
        let fit = Ease::size(size).map_err(fail)?;
        let made = make_garment(category, fit, EDGE, category.default_material(), model, "default", betas)
            .map_err(fail)?;
        let inner: Vec<&Garment> = worn.iter().map(|w| &w.garment).collect();
        let garment = made.over(&inner, LAYER_GAP, model).map_err(fail)?;
        worn.push(Worn { name: category.name(), piece, garment });
    }
    Ok(worn)
}

/// A texture layout with every triangle of `mesh` in a square cell of its own, in its own
/// shape: a garment's UVs carried from the body overlap where several layers of cloth hang over
/// one body region (a skirt over the thighs), and a print baked there would be one print's.
/// Cells leave a margin of `margin` (a share of the cell) for the baker's dilation.
pub fn triangle_atlas(mesh: &TriMesh, margin: f32) -> UvLayout {
    let n = mesh.faces.len();
    let per_row = (n as f32).sqrt().ceil().max(1.0) as usize;
    let cell = 1.0 / per_row as f32;
    let usable = cell * (1.0 - 2.0 * margin);
    let mut coords = Vec::with_capacity(3 * n);
    let mut faces = Vec::with_capacity(n);
    for (f, tri) in mesh.faces.iter().enumerate() {
        let [a, b, c] = tri.map(|i| Vec3::from(mesh.positions[i as usize]));
        // The triangle laid flat: a at the origin, b along +u.
        let ab = (b - a).length().max(f32::MIN_POSITIVE);
        let along = (c - a).dot(b - a) / ab;
        let across = (c - a).cross(b - a).length() / ab;
        let flat = [Vec2::ZERO, Vec2::new(ab, 0.0), Vec2::new(along, across)];
        let lo = flat.iter().fold(Vec2::MAX, |m, p| m.min(*p));
        let hi = flat.iter().fold(Vec2::MIN, |m, p| m.max(*p));
        let scale = usable / (hi - lo).max_element().max(f32::MIN_POSITIVE);
        let origin =
            Vec2::new((f % per_row) as f32, (f / per_row) as f32) * cell + Vec2::splat(cell * margin);
        let start = coords.len() as u32;
        coords.extend(flat.map(|p| (origin + (p - lo) * scale).to_array()));
        faces.push([start, start + 1, start + 2]);
    }
    UvLayout { coords, faces }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two triangles of a square: each in its own cell, inside it by the margin, and similar to
    /// itself (side ratios kept).
    #[test]
    fn each_triangle_keeps_its_shape_in_a_cell_of_its_own() {
        let mesh = TriMesh::new(
            vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
            vec![[0, 1, 2], [0, 2, 3]],
        );
        let atlas = triangle_atlas(&mesh, 0.1);
        // Two faces: 2 per row, cells 0.5 wide.
        for (f, tri) in atlas.faces.iter().enumerate() {
            let p = tri.map(|i| Vec2::from(atlas.coords[i as usize]));
            let (x0, y0) = ((f % 2) as f32 * 0.5, (f / 2) as f32 * 0.5);
            for q in p {
                assert!(q.x >= x0 + 0.05 - 1e-6 && q.x <= x0 + 0.45 + 1e-6, "{q:?} in cell {f}");
                assert!(q.y >= y0 + 0.05 - 1e-6 && q.y <= y0 + 0.45 + 1e-6, "{q:?} in cell {f}");
            }
            let corners = mesh.faces[f].map(|i| Vec3::from(mesh.positions[i as usize]));
            let ratio3 = corners[0].distance(corners[1]) / corners[1].distance(corners[2]);
            let ratio2 = p[0].distance(p[1]) / p[1].distance(p[2]);
            assert!((ratio3 - ratio2).abs() < 1e-5, "face {f}: {ratio3} vs {ratio2}");
        }
    }
}
