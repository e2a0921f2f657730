//! Loads SMPL, SMPL-H and SMPL-X model files with the arrays `v_template, shapedirs, posedirs,
//! J_regressor, weights, kintree_table, f`, float32 or float64 alike: `.npz` archives, and the
//! released `.pkl` files (NumPy arrays, SciPy sparse matrices and chumpy objects, read by
//! `mannequin_io::pickle_arrays` without Python).

use std::collections::BTreeMap;
use std::path::Path;

use mannequin_io::{IoError, NpyData, Npz};
use mannequin_mesh::UvLayout;

use crate::error::BodyError;
use crate::model::{BodyModel, BodyModelParts};

/// Shape-space size of SMPL-X: components past this index are expressions.
const SMPLX_SHAPE_SPACE: usize = 300;

/// Keys the forward pass reads; every other array is kept in `extras`.
const CORE_KEYS: &[&str] = &[
    "v_template",
    "f",
    "shapedirs",
    "posedirs",
    "J_regressor",
    "weights",
    "kintree_table",
    "vt",
    "ft",
    "joint_names",
    "shape_names",
    "gender",
];

/// Reorders an `(V, 3, K)` array into component-major `[K][3V]`.
fn component_major(values: &[f64], v: usize, k: usize) -> Vec<f32> {
    if k == 0 {
        // No components (a model without a shape space): nothing to reorder.
        return Vec::new();
    }
    let mut out = vec![0.0f32; k * 3 * v];
    for (row, chunk) in values.chunks_exact(k).enumerate() {
        for (c, &x) in chunk.iter().enumerate() {
            out[c * 3 * v + row] = x as f32;
        }
    }
    out
}

fn strings(npz: &Npz, key: &str) -> Vec<String> {
    match npz.get(key).map(|a| &a.data) {
        Some(NpyData::Str(s)) => s.clone(),
        _ => Vec::new(),
    }
}

fn index_triples(npz: &Npz, key: &str, bound: usize) -> Result<Vec<[u32; 3]>, BodyError> {
    let a = npz.require(key)?;
    if a.shape.len() != 2 || a.shape[1] != 3 {
        return Err(npz.field_error(key, format!("expected shape (*, 3), found {:?}", a.shape)).into());
    }
    let ints = a
        .to_i64()
        .ok_or_else(|| npz.field_error(key, format!("expected integers, found {}", a.dtype_name())))?;
    if let Some(&bad) = ints.iter().find(|&&i| i < 0 || i as usize >= bound) {
        return Err(npz.field_error(key, format!("index {bad} is outside 0..{bound}")).into());
    }
    Ok(ints.chunks_exact(3).map(|t| [t[0] as u32, t[1] as u32, t[2] as u32]).collect())
}

/// Parents from `kintree_table` row 0; the root's parent is -1 or 2³²−1 in the wild.
fn parents(npz: &Npz) -> Result<Vec<Option<usize>>, BodyError> {
    let key = "kintree_table";
    let a = npz.require(key)?;
    if a.shape.len() != 2 || a.shape[0] != 2 {
        return Err(npz.field_error(key, format!("expected shape (2, J), found {:?}", a.shape)).into());
    }
    let j = a.shape[1];
    if j == 0 {
        return Err(npz.field_error(key, "expected at least one joint, found shape (2, 0)").into());
    }
    let ints = a.to_i64().ok_or_else(|| npz.field_error(key, "expected integers"))?;
    let ids = &ints[j..];
    if ids.iter().enumerate().any(|(k, &id)| id != k as i64) {
        return Err(npz.field_error(key, "row 1 must list the joints in order 0..J").into());
    }
    Ok(ints[..j].iter().map(|&p| if p < 0 || p >= j as i64 { None } else { Some(p as usize) }).collect())
}

/// Reads a SMPL-family model from the arrays of a model file; their `path` names it in errors.
pub fn parse_model(npz: &Npz, num_betas: Option<usize>) -> Result<BodyModel, BodyError> {
    let path = npz.path.clone();
    let (_, vt) = npz.f64_with_shape("v_template", &[None, Some(3)])?;
    let v = vt.len() / 3;
    let v_template: Vec<[f32; 3]> =
        vt.chunks_exact(3).map(|p| [p[0] as f32, p[1] as f32, p[2] as f32]).collect();
    let faces = index_triples(npz, "f", v)?;
    let parents = parents(npz)?;
    let j = parents.len();

    let (sd_shape, sd) = npz.f64_with_shape("shapedirs", &[Some(v), Some(3), None])?;
    let stored = sd_shape[2];
    let family_is_x = j == 55;
    let (file_betas, num_expression) = if family_is_x && stored > SMPLX_SHAPE_SPACE {
        (SMPLX_SHAPE_SPACE, stored - SMPLX_SHAPE_SPACE)
    } else {
        (stored, 0)
    };
    let shapedirs = component_major(&sd, v, stored);
    let posedirs = match npz.get("posedirs") {
        Some(a) if a.shape.len() == 3 && a.shape[2] == 0 => Vec::new(),
        _ => {
            let (_, pd) = npz.f64_with_shape("posedirs", &[Some(v), Some(3), Some(9 * (j - 1))])?;
            component_major(&pd, v, 9 * (j - 1))
        }
    };
    let (_, jr) = npz.f64_with_shape("J_regressor", &[Some(j), Some(v)])?;
    let (_, w) = npz.f64_with_shape("weights", &[Some(v), Some(j)])?;

    let uv = match (npz.get("vt"), npz.get("ft")) {
        (Some(_), Some(_)) => {
            let (_, coords) = npz.f64_with_shape("vt", &[None, Some(2)])?;
            let coords: Vec<[f32; 2]> = coords.chunks_exact(2).map(|c| [c[0] as f32, c[1] as f32]).collect();
            let uv_faces = index_triples(npz, "ft", coords.len())?;
            Some(UvLayout { coords, faces: uv_faces })
        }
        _ => None,
    };
    let gender = strings(npz, "gender").into_iter().next().unwrap_or_else(|| "neutral".into());
    let extras: BTreeMap<_, _> = npz
        .keys()
        .filter(|k| !CORE_KEYS.contains(k))
        .map(|k| (k.to_string(), npz.get(k).expect("listed key").clone()))
        .collect();
    let name = path.display().to_string();
    BodyModel::new(BodyModelParts {
        name,
        gender,
        v_template,
        faces,
        uv,
        shapedirs,
        num_betas: file_betas,
        num_expression,
        posedirs,
        j_regressor: jr.iter().map(|&x| x as f32).collect(),
        parents,
        weights: w.iter().map(|&x| x as f32).collect(),
        joint_names: strings(npz, "joint_names"),
        shape_names: strings(npz, "shape_names"),
        extras,
    })
    .and_then(|m| match num_betas {
        Some(n) => m.with_num_betas(n),
        None => Ok(m),
    })
}

/// Loads a SMPL-family `.npz` or `.pkl` model, keeping `num_betas` shape components (all when
/// `None`). A zip archive is read as `.npz`; a pickle is known by its protocol marker (0x80,
/// protocols 2–5) or, for protocols 0–1 that have none, by the `.pkl` extension.
pub fn load_model(path: &Path, num_betas: Option<usize>) -> Result<BodyModel, BodyError> {
    let bytes = std::fs::read(path).map_err(|source| IoError::Io { path: path.to_path_buf(), source })?;
    let pickled = !bytes.starts_with(b"PK")
        && (bytes.first() == Some(&0x80) || path.extension().is_some_and(|e| e == "pkl"));
    let arrays = if pickled {
        Npz::from_pickle(path.to_path_buf(), &bytes)?
    } else {
        Npz::from_bytes(path.to_path_buf(), &bytes)?
    };
    parse_model(&arrays, num_betas)
}
