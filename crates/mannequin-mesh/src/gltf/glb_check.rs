//! Checks that bytes are a glTF 2.0 binary a viewer can load, before anything serves them: the
//! GLB header and chunks, the JSON, and every accessor inside its buffer view and every view
//! inside its buffer. It reads no mesh: it stops a random-bytes `.glb` at the door, with the
//! place it went wrong, rather than in a user's browser.

use std::path::Path;

use serde_json::Value;

use crate::file_error::MeshFileError;

/// Bytes per component of each accessor `componentType`.
fn component_size(component_type: u64) -> Option<u64> {
    match component_type {
        5120 | 5121 => Some(1),
        5122 | 5123 => Some(2),
        5125 | 5126 => Some(4),
        _ => None,
    }
}

/// Components per element of each accessor `type`.
fn components(kind: &str) -> Option<u64> {
    Some(match kind {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        "VEC4" | "MAT2" => 4,
        "MAT3" => 9,
        "MAT4" => 16,
        _ => return None,
    })
}

fn u32_at(bytes: &[u8], at: usize) -> Option<u64> {
    bytes.get(at..at + 4).map(|b| u64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])))
}

/// Refuses `bytes` unless they are a well-formed GLB, naming `path` and where it is wrong.
pub fn check_glb(path: &Path, bytes: &[u8]) -> Result<(), MeshFileError> {
    let bad = |at: &str, expected: String| Err(MeshFileError::format(path, at, expected));
    if bytes.get(..4) != Some(b"glTF") || u32_at(bytes, 4) != Some(2) {
        return bad("header", "the magic 'glTF' and version 2".into());
    }
    if u32_at(bytes, 8) != Some(bytes.len() as u64) {
        return bad("header", format!("a total length equal to the file's {} bytes", bytes.len()));
    }
    let Some(json_len) = u32_at(bytes, 12).map(|n| n as usize) else {
        return bad("header", "a JSON chunk".into());
    };
    if bytes.get(16..20) != Some(b"JSON") || 20 + json_len > bytes.len() {
        return bad("JSON chunk", "a JSON chunk first, within the file".into());
    }
    let json: Value = match serde_json::from_slice(&bytes[20..20 + json_len]) {
        Ok(v) => v,
        Err(e) => return bad("JSON chunk", format!("valid JSON ({e})")),
    };
    let bin_start = 20 + json_len.next_multiple_of(4);
    let bin_len = match u32_at(bytes, bin_start) {
        Some(n) if bytes.get(bin_start + 4..bin_start + 8) == Some(b"BIN\0") => {
            if bin_start as u64 + 8 + n > bytes.len() as u64 {
                return bad("BIN chunk", "its length within the file".into());
            }
            n
        }
        _ => 0,
    };
    if json.pointer("/asset/version").and_then(Value::as_str) != Some("2.0") {
        return bad("asset.version", "\"2.0\"".into());
    }
    let list = |key: &str| json.get(key).and_then(Value::as_array).cloned().unwrap_or_default();
    let num = |v: &Value, key: &str| v.get(key).and_then(Value::as_u64);
    let buffers: Vec<u64> = list("buffers")
        .iter()
        .enumerate()
        .map(|(i, b)| match (num(b, "byteLength"), b.get("uri")) {
            (Some(n), None) if i == 0 && n <= bin_len => Ok(n),
            _ => Err(MeshFileError::format(
                path,
                format!("buffers[{i}]"),
                "the one buffer, in the BIN chunk and no longer than it",
            )),
        })
        .collect::<Result<_, _>>()?;
    let views = list("bufferViews");
    for (i, v) in views.iter().enumerate() {
        let buffer = num(v, "buffer").and_then(|b| buffers.get(b as usize));
        let end = num(v, "byteOffset").unwrap_or(0).checked_add(num(v, "byteLength").unwrap_or(u64::MAX));
        if !matches!((buffer, end), (Some(&len), Some(end)) if end <= len) {
            return bad(&format!("bufferViews[{i}]"), "a range inside its buffer".into());
        }
    }
    for (i, a) in list("accessors").iter().enumerate() {
        let element = num(a, "componentType")
            .and_then(component_size)
            .zip(a.get("type").and_then(Value::as_str).and_then(components))
            .map(|(s, c)| s * c);
        let count = num(a, "count");
        let Some((element, count)) = element.zip(count).filter(|&(_, c)| c > 0) else {
            return bad(&format!("accessors[{i}]"), "a component type, a type and a count ≥ 1".into());
        };
        let Some(view) = num(a, "bufferView") else { continue };
        let fits = views.get(view as usize).is_some_and(|v| {
            let stride = num(v, "byteStride").unwrap_or(element).max(element);
            let need = (count - 1).checked_mul(stride).and_then(|n| n.checked_add(element));
            let need = need.and_then(|n| n.checked_add(num(a, "byteOffset").unwrap_or(0)));
            need.is_some_and(|n| n <= num(v, "byteLength").unwrap_or(0))
        });
        if !fits {
            return bad(&format!("accessors[{i}]"), "its elements inside its buffer view".into());
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gltf::glb::glb;

    /// A glTF of three points, its accessor holding `count` of them.
    fn points(count: u64) -> Vec<u8> {
        let json = serde_json::json!({
            "asset": { "version": "2.0" },
            "buffers": [{ "byteLength": 36 }],
            "bufferViews": [{ "buffer": 0, "byteLength": 36 }],
            "accessors": [{ "bufferView": 0, "componentType": 5126, "type": "VEC3", "count": count }],
        });
        glb(&serde_json::to_vec(&json).unwrap(), &[0u8; 36])
    }

    /// A well-formed GLB passes; random bytes, a cut file, broken JSON and an accessor reaching
    /// past its view are each refused by where they go wrong.
    #[test]
    fn a_well_formed_glb_passes_and_broken_ones_are_named() {
        let path = Path::new("t.glb");
        check_glb(path, &points(3)).unwrap();
        let err = |bytes: &[u8]| check_glb(path, bytes).unwrap_err().to_string();
        assert!(err(&[7u8; 300]).contains("t.glb: header"));
        let good = points(3);
        assert!(err(&good[..good.len() - 4]).contains("total length"));
        let mut broken = good.clone();
        broken[20] = b'!';
        assert!(err(&broken).contains("valid JSON"));
        assert!(err(&points(4)).contains("accessors[0]"));
    }
}
