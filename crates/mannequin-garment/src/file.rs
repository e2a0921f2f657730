//! The `.garment` file: a NumPy `.npz` (readable with `numpy.load`) holding the recipe as JSON
//! text and the template's arrays: `positions` (N×3, G^g), `faces` (F×3), `uv` (K×2) and
//! `uv_faces` (F×3), `body_faces` (N, the body face of each row of I^g), `body_bary` (N×3, its
//! barycentric weights) and `offsets` (N×3, D^g).

use std::path::Path;

use mannequin_cloth::{MAX_GARMENT_FACES, MAX_GARMENT_VERTICES, check_garment, check_positions};
use mannequin_io::{NpyArray, Npz, NpzWriter};
use mannequin_mesh::{SurfacePoint, TriMesh, UvLayout, points};

use crate::error::GarmentError;
use crate::garment::{Garment, Recipe};

/// Written into every file, so a reader can refuse one it does not know.
const FORMAT: &str = "mannequin-garment 1";

pub fn write_garment(path: &Path, g: &Garment) -> Result<(), GarmentError> {
    let n = g.vertex_count();
    let flat3 = |p: &[[f32; 3]]| p.iter().flatten().copied().collect::<Vec<f32>>();
    let indices = |f: &[[u32; 3]]| f.iter().flatten().map(|&i| i as i64).collect::<Vec<i64>>();
    let recipe =
        serde_json::to_string(&g.recipe).map_err(|e| GarmentError::invalid("recipe", e.to_string()))?;
    let mut w = NpzWriter::new();
    w.add("format", NpyArray::text(FORMAT));
    w.add("recipe", NpyArray::text(&recipe));
    w.add("positions", NpyArray::f32(vec![n, 3], flat3(&g.mesh.positions)));
    w.add("faces", NpyArray::i64(vec![g.mesh.faces.len(), 3], indices(&g.mesh.faces)));
    if let Some(uv) = &g.mesh.uv {
        let coords: Vec<f32> = uv.coords.iter().flatten().copied().collect();
        w.add("uv", NpyArray::f32(vec![uv.coords.len(), 2], coords));
        w.add("uv_faces", NpyArray::i64(vec![uv.faces.len(), 3], indices(&uv.faces)));
    }
    w.add("body_faces", NpyArray::i64(vec![n], g.binding.iter().map(|s| s.face as i64).collect()));
    let bary: Vec<[f32; 3]> = g.binding.iter().map(|s| s.bary).collect();
    w.add("body_bary", NpyArray::f32(vec![n, 3], flat3(&bary)));
    w.add("offsets", NpyArray::f32(vec![n, 3], flat3(&g.offsets)));
    w.write(path)?;
    Ok(())
}

/// Most array elements a `.garment` holds, checked from its arrays' headers before any is
/// inflated: a template at the simulator's limits has 10 per vertex (position, binding face and
/// weights, offset) and 12 per triangle (corners, UV corners, and at most 3 UVs of 2), and two
/// texts.
const MAX_ELEMENTS: usize = 10 * MAX_GARMENT_VERTICES + 12 * MAX_GARMENT_FACES + 2;

/// Farthest a garment vertex may hang off the body point it is bound to (m): a flared hem
/// stands some 30 cm off the legs; a metre off is no garment worn on this body.
pub const MAX_OFFSET: f32 = 1.0;

/// How far a barycentric weight may stray outside [0, 1], or their sum from 1: float rounding
/// of a closest point, not a point off its face.
const BARY_TOLERANCE: f32 = 1e-3;

/// Reads a `.garment` file, refusing one that `write_garment` would not have written from a
/// template that can be simulated: every refusal names the file and the field.
pub fn read_garment(path: &Path) -> Result<Garment, GarmentError> {
    let npz = Npz::read_within(path, MAX_ELEMENTS)?;
    let file_error = |reason: String| GarmentError::File { path: path.display().to_string(), reason };
    let format = npz.text("format")?;
    if format != FORMAT {
        return Err(file_error(format!("format: {format:?}; expected {FORMAT:?}")));
    }
    let recipe: Recipe = serde_json::from_str(npz.text("recipe")?)
        .map_err(|e| file_error(format!("recipe: {e}; expected the recipe as JSON")))?;
    recipe.validate().map_err(|e| file_error(format!("recipe: {e}")))?;
    let floats = |key: &str, shape: &[Option<usize>]| -> Result<(Vec<usize>, Vec<f32>), GarmentError> {
        let (shape, v) = npz.f64_with_shape(key, shape)?;
        if v.iter().any(|x| !x.is_finite()) {
            return Err(npz.field_error(key, "expected finite numbers").into());
        }
        Ok((shape, v.into_iter().map(|x| x as f32).collect()))
    };
    let (shape, positions) = floats("positions", &[None, Some(3)])?;
    let n = shape[0];
    let triples = |key: &str, count: usize| -> Result<Vec<[u32; 3]>, GarmentError> {
        let (_, v) = npz.f64_with_shape(key, &[None, Some(3)])?;
        if let Some(bad) = v.iter().find(|&&i| i < 0.0 || i >= count as f64 || i.fract() != 0.0) {
            return Err(npz
                .field_error(key, format!("index {bad}; expected whole numbers below {count}"))
                .into());
        }
        Ok(v.chunks_exact(3).map(|t| [t[0] as u32, t[1] as u32, t[2] as u32]).collect())
    };
    let faces = triples("faces", n)?;
    let mut mesh = TriMesh::new(points(&positions), faces);
    check_positions("positions", &mesh.positions)
        .and_then(|()| check_garment(&mesh))
        .map_err(|e| file_error(e.to_string()))?;
    if npz.contains("uv") {
        let (shape, coords) = floats("uv", &[None, Some(2)])?;
        let uv_faces = triples("uv_faces", shape[0])?;
        if uv_faces.len() != mesh.faces.len() {
            return Err(npz
                .field_error(
                    "uv_faces",
                    format!("{} rows; expected one per face ({})", uv_faces.len(), mesh.faces.len()),
                )
                .into());
        }
        mesh.uv = Some(UvLayout {
            coords: coords.chunks_exact(2).map(|c| [c[0], c[1]]).collect(),
            faces: uv_faces,
        });
    }
    let (_, body_faces) = npz.f64_with_shape("body_faces", &[Some(n)])?;
    if let Some(bad) =
        body_faces.iter().find(|&&f| f < 0.0 || f >= recipe.body_faces as f64 || f.fract() != 0.0)
    {
        return Err(npz
            .field_error(
                "body_faces",
                format!("face {bad}; expected whole numbers below {}", recipe.body_faces),
            )
            .into());
    }
    let (_, bary) = floats("body_bary", &[Some(n), Some(3)])?;
    let bary = points(&bary);
    let off_face = |b: &[f32; 3]| {
        b.iter().any(|&w| !(-BARY_TOLERANCE..=1.0 + BARY_TOLERANCE).contains(&w))
            || (b.iter().sum::<f32>() - 1.0).abs() > BARY_TOLERANCE
    };
    if let Some(i) = bary.iter().position(off_face) {
        return Err(npz
            .field_error(
                "body_bary",
                format!("row {i} is {:?}; expected weights in [0, 1] summing to 1", bary[i]),
            )
            .into());
    }
    let (_, offsets) = floats("offsets", &[Some(n), Some(3)])?;
    let offsets = points(&offsets);
    let too_far = |d: &[f32; 3]| d.iter().map(|x| x * x).sum::<f32>() > MAX_OFFSET * MAX_OFFSET;
    if let Some(i) = offsets.iter().position(too_far) {
        return Err(npz
            .field_error(
                "offsets",
                format!("row {i} is {:?}; expected at most {MAX_OFFSET} m long", offsets[i]),
            )
            .into());
    }
    let binding =
        body_faces.iter().zip(bary).map(|(&face, bary)| SurfacePoint { face: face as u32, bary }).collect();
    Ok(Garment { recipe, mesh, binding, offsets })
}
