//! Camera files: JSON in the OpenCV convention (x right, y down, z forward, pixel centres at
//! +0.5), as `mannequin splat render` and `mannequin animate --camera` read them:
//!
//! ```json
//! {
//!   "width": 540, "height": 540,
//!   "K": [[500, 0, 270], [0, 500, 270], [0, 0, 1]],
//!   "extrinsic": [[1, 0, 0, 0], [0, -1, 0, 1], [0, 0, -1, 2.5], [0, 0, 0, 1]],
//!   "near": 0.01, "far": 100,
//!   "background": [1, 1, 1]
//! }
//! ```
//!
//! `K` is the 3×3 intrinsic matrix in pixels and `extrinsic` the 4×4 world→camera transform,
//! both row-major. `near` (default 0.01), `far` (default 1e10) and `background` (RGB in
//! `[0, 1]`, default black) are optional.

use std::path::Path;

use serde_json::Value;

use crate::{Camera, SplatError};

/// Parses a camera file's bytes into a validated camera and its background colour; `path` only
/// names the file in errors, which also name the field and say what was expected.
pub fn parse_camera_json(path: &Path, bytes: &[u8]) -> Result<(Camera, Vec<f64>), SplatError> {
    let err = |reason: String| SplatError::CameraFile { path: path.to_path_buf(), reason };
    let v: Value = serde_json::from_slice(bytes).map_err(|e| err(format!("not valid JSON: {e}")))?;
    let field = |k: &str| v.get(k).ok_or_else(|| err(format!("missing field '{k}'")));
    let number = |k: &str, x: &Value| {
        x.as_f64().ok_or_else(|| err(format!("field '{k}' must hold numbers, found {x}")))
    };
    let size = |k: &str| -> Result<usize, SplatError> {
        let x = field(k)?;
        x.as_u64()
            .and_then(|n| usize::try_from(n).ok())
            .ok_or_else(|| err(format!("'{k}' must be a whole number, found {x}")))
    };
    let matrix = |k: &str, rows: usize, cols: usize| -> Result<Vec<f64>, SplatError> {
        let bad = || err(format!("'{k}' must be a {rows}×{cols} array of rows"));
        let rs = field(k)?.as_array().filter(|rs| rs.len() == rows).ok_or_else(bad)?;
        let mut out = Vec::with_capacity(rows * cols);
        for r in rs {
            for x in r.as_array().filter(|r| r.len() == cols).ok_or_else(bad)? {
                out.push(number(k, x)?);
            }
        }
        Ok(out)
    };
    let optional = |k: &str, default: f64| v.get(k).map_or(Ok(default), |x| number(k, x));
    let (k, e) = (matrix("K", 3, 3)?, matrix("extrinsic", 4, 4)?);
    let camera = Camera {
        width: size("width")?,
        height: size("height")?,
        intrinsic: std::array::from_fn(|i| std::array::from_fn(|j| k[3 * i + j])),
        extrinsic: std::array::from_fn(|i| std::array::from_fn(|j| e[4 * i + j])),
        near: optional("near", 0.01)?,
        far: optional("far", 1e10)?,
    };
    let background = match v.get("background") {
        None => vec![0.0; 3],
        Some(b) => {
            let b = b.as_array().ok_or_else(|| err("'background' must be [r, g, b]".into()))?;
            if b.len() != 3 {
                return Err(err(format!("'background' must have 3 values, found {}", b.len())));
            }
            b.iter().map(|x| number("background", x)).collect::<Result<_, _>>()?
        }
    };
    camera.validate().map_err(|e| err(e.to_string()))?;
    Ok((camera, background))
}

#[cfg(test)]
mod tests {
    use super::*;

    const CAMERA: &str = r#"{"width": 32, "height": 24, "K": [[30, 0, 16], [0, 30, 12], [0, 0, 1]],
        "extrinsic": [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 2], [0, 0, 0, 1]], "background": [0, 0, 1]}"#;

    fn parse(text: &str) -> Result<(Camera, Vec<f64>), SplatError> {
        parse_camera_json(Path::new("cam.json"), text.as_bytes())
    }

    #[test]
    fn camera_json_is_read_and_bad_fields_are_named() {
        let (cam, bg) = parse(CAMERA).unwrap();
        assert_eq!((cam.width, cam.height, cam.near, cam.far), (32, 24, 0.01, 1e10));
        assert_eq!(cam.extrinsic[2][3], 2.0);
        assert_eq!(bg, vec![0.0, 0.0, 1.0]);
        let msg = |text: String| parse(&text).unwrap_err().to_string();
        let short_k =
            msg(CAMERA.replace("[[30, 0, 16], [0, 30, 12], [0, 0, 1]]", "[[30, 0, 16], [0, 30, 12]]"));
        assert!(short_k.starts_with("cam.json: ") && short_k.contains("'K' must be a 3×3"), "{short_k}");
        let empty = msg(CAMERA.replace("\"width\": 32", "\"width\": 0"));
        assert!(empty.starts_with("cam.json: ") && empty.contains("empty"), "{empty}");
        let missing = msg(CAMERA.replace("\"height\"", "\"h\""));
        assert!(missing.contains("missing field 'height'"), "{missing}");
        let text = msg(CAMERA.replace("[0, 0, 1]}", "[0, 0, \"blue\"]}"));
        assert!(text.contains("'background' must hold numbers"), "{text}");
        assert!(msg("{\"width\": ".into()).contains("not valid JSON"));
    }
}
