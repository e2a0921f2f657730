//! Polygon File Format (`.ply`) for triangle meshes: ASCII and binary (little or big endian)
//! reading, binary little-endian writing.
//!
//! Reads the `vertex` element's `x y z`, optional `nx ny nz` and `red green blue` (integer
//! colours are scaled from their type's range to [0, 1]), and the `face` element's
//! `vertex_indices` (or `vertex_index`) list; polygons are split into triangle fans. Every other
//! element and property is skipped, so files from trimesh, MeshLab or Blender load as they are.

use std::path::Path;

use mannequin_io::ply_header::{Element, Property, Scalar};
use mannequin_io::{PlyHeader, PlyValueError, PlyValues};

use crate::{MeshFileError, TriMesh};

/// A mesh read from PLY, with the per-vertex normals the file carried, if any.
#[derive(Debug, Clone, PartialEq)]
pub struct PlyMesh {
    pub mesh: TriMesh,
    pub normals: Option<Vec<[f32; 3]>>,
}

/// The value that an integer colour channel of type `ty` takes at full intensity.
fn colour_max(ty: Scalar) -> f64 {
    match ty {
        Scalar::U8 | Scalar::I8 => 255.0,
        Scalar::U16 | Scalar::I16 => 65535.0,
        Scalar::I32 | Scalar::U32 => u32::MAX as f64,
        Scalar::F32 | Scalar::F64 => 1.0,
    }
}

/// Where in the file something is wrong, and what was expected there.
struct Problem {
    at: String,
    expected: String,
}

fn bad(at: impl Into<String>, expected: impl Into<String>) -> Problem {
    Problem { at: at.into(), expected: expected.into() }
}

/// What a body value (or an element's count) should have been, in this reader's "expected"
/// phrasing.
fn expected_value(e: PlyValueError) -> String {
    match e {
        PlyValueError::End => "more data (the file ends early)".into(),
        PlyValueError::NotANumber => "a number".into(),
        PlyValueError::CountTooLarge { .. } => e.to_string(),
    }
}

/// Where each property we use sits in a vertex record.
#[derive(Default)]
struct VertexSlots {
    position: [Option<usize>; 3],
    normal: [Option<usize>; 3],
    color: [Option<(usize, Scalar)>; 3],
}

fn vertex_slots(element: &Element) -> Result<VertexSlots, Problem> {
    let mut s = VertexSlots::default();
    for (i, p) in element.properties.iter().enumerate() {
        let Property::Scalar { name, ty } = p else { continue };
        match name.as_str() {
            "x" => s.position[0] = Some(i),
            "y" => s.position[1] = Some(i),
            "z" => s.position[2] = Some(i),
            "nx" => s.normal[0] = Some(i),
            "ny" => s.normal[1] = Some(i),
            "nz" => s.normal[2] = Some(i),
            "red" | "r" => s.color[0] = Some((i, *ty)),
            "green" | "g" => s.color[1] = Some((i, *ty)),
            "blue" | "b" => s.color[2] = Some((i, *ty)),
            _ => {}
        }
    }
    if s.position.iter().any(Option::is_none) {
        return Err(bad("header, element vertex", "properties x, y and z"));
    }
    Ok(s)
}

fn parse_body(header: &PlyHeader, bytes: &[u8]) -> Result<PlyMesh, Problem> {
    let mut body = PlyValues::new(bytes, header);
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut colors = Vec::new();
    let mut faces = Vec::new();
    let mut has_normals = false;
    let mut has_colors = false;
    let mut record = Vec::new();
    for element in &header.elements {
        // The header's count is untrusted: past this check the file holds that many records.
        body.check_count(element)
            .map_err(|e| bad(format!("header, element {}", element.name), e.to_string()))?;
        let slots = if element.name == "vertex" { Some(vertex_slots(element)?) } else { None };
        if let Some(s) = &slots {
            has_normals = s.normal.iter().all(Option::is_some);
            has_colors = s.color.iter().all(Option::is_some);
            positions.reserve(element.count);
        }
        let face_list = (element.name == "face")
            .then(|| {
                element.properties.iter().position(|p| {
                    matches!(p, Property::List { .. })
                        && matches!(p.name(), "vertex_indices" | "vertex_index")
                })
            })
            .flatten();
        if element.name == "face" && face_list.is_none() {
            return Err(bad("header, element face", "a 'vertex_indices' list property"));
        }
        for row in 0..element.count {
            record.clear();
            for (pi, p) in element.properties.iter().enumerate() {
                let at = || format!("element {} {row}, property {}", element.name, p.name());
                match p {
                    Property::Scalar { ty, .. } => {
                        record.push(body.next(*ty).map_err(|e| bad(at(), expected_value(e)))?)
                    }
                    Property::List { count, item, .. } => {
                        let n = body.next(*count).map_err(|e| bad(at(), expected_value(e)))?;
                        if n < 0.0 || n.fract() != 0.0 {
                            return Err(bad(at(), "a whole list length"));
                        }
                        let mut items = Vec::with_capacity((n as usize).min(64));
                        for _ in 0..n as usize {
                            items.push(body.next(*item).map_err(|e| bad(at(), expected_value(e)))?);
                        }
                        if Some(pi) == face_list {
                            push_fan(&items, &at(), &mut faces)?;
                        }
                        record.push(f64::NAN);
                    }
                }
            }
            if let Some(s) = &slots {
                let get = |slot: [Option<usize>; 3]| slot.map(|i| record[i.unwrap_or(0)] as f32);
                positions.push(get(s.position));
                if has_normals {
                    normals.push(get(s.normal));
                }
                if has_colors {
                    colors.push(s.color.map(|c| {
                        let (i, ty) = c.unwrap_or((0, Scalar::F32));
                        (record[i] / colour_max(ty)) as f32
                    }));
                }
            }
        }
    }
    let mut mesh = TriMesh::new(positions, faces);
    mesh.colors = has_colors.then_some(colors);
    Ok(PlyMesh { mesh, normals: has_normals.then_some(normals) })
}

/// Splits a polygon into the triangle fan (v0, vi, vi+1).
fn push_fan(items: &[f64], at: &str, faces: &mut Vec<[u32; 3]>) -> Result<(), Problem> {
    if items.len() < 3 {
        return Err(bad(at, format!("at least 3 corners, found {}", items.len())));
    }
    let idx = |x: f64| {
        (x >= 0.0 && x.fract() == 0.0 && x <= u32::MAX as f64)
            .then_some(x as u32)
            .ok_or_else(|| bad(at, format!("a vertex index, found {x}")))
    };
    for k in 1..items.len() - 1 {
        faces.push([idx(items[0])?, idx(items[k])?, idx(items[k + 1])?]);
    }
    Ok(())
}

/// Parses PLY bytes; `path` is used only in error messages.
pub fn parse(path: &Path, bytes: &[u8]) -> Result<PlyMesh, MeshFileError> {
    let header = PlyHeader::parse(bytes).map_err(|e| MeshFileError::format(path, "header", e.to_string()))?;
    let ply = parse_body(&header, bytes).map_err(|p| MeshFileError::format(path, p.at, p.expected))?;
    ply.mesh.validate().map_err(|e| MeshFileError::invalid(path, e))?;
    Ok(ply)
}

pub fn read(path: impl AsRef<Path>) -> Result<PlyMesh, MeshFileError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| MeshFileError::io(path, e))?;
    parse(path, &bytes)
}

/// Binary little-endian PLY: float positions, optional float normals, optional uchar colours,
/// and faces as `uchar` count + `int` indices (the layout trimesh and MeshLab write).
pub fn to_bytes(mesh: &TriMesh, normals: Option<&[[f32; 3]]>) -> Vec<u8> {
    let mut header = String::from("ply\nformat binary_little_endian 1.0\ncomment written by Mannequin\n");
    header += &format!("element vertex {}\n", mesh.positions.len());
    header += "property float x\nproperty float y\nproperty float z\n";
    if normals.is_some() {
        header += "property float nx\nproperty float ny\nproperty float nz\n";
    }
    if mesh.colors.is_some() {
        header += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    }
    header +=
        &format!("element face {}\nproperty list uchar int vertex_indices\nend_header\n", mesh.faces.len());
    let per_vertex = 12 + normals.map_or(0, |_| 12) + mesh.colors.as_ref().map_or(0, |_| 3);
    let mut out =
        Vec::with_capacity(header.len() + per_vertex * mesh.positions.len() + 13 * mesh.faces.len());
    out.extend_from_slice(header.as_bytes());
    for (i, p) in mesh.positions.iter().enumerate() {
        p.iter().for_each(|c| out.extend_from_slice(&c.to_le_bytes()));
        if let Some(n) = normals {
            n[i].iter().for_each(|c| out.extend_from_slice(&c.to_le_bytes()));
        }
        if let Some(colors) = &mesh.colors {
            out.extend(colors[i].map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8));
        }
    }
    for f in &mesh.faces {
        out.push(3);
        f.iter().for_each(|&i| out.extend_from_slice(&(i as i32).to_le_bytes()));
    }
    out
}

/// Writes a binary PLY atomically. `normals`, when given, must have one entry per vertex.
pub fn write(
    path: impl AsRef<Path>,
    mesh: &TriMesh,
    normals: Option<&[[f32; 3]]>,
) -> Result<(), MeshFileError> {
    let path = path.as_ref();
    mesh.validate().map_err(|e| MeshFileError::invalid(path, e))?;
    if let Some(n) = normals.filter(|n| n.len() != mesh.positions.len()) {
        let expected = format!("one normal per vertex ({}), given {}", mesh.positions.len(), n.len());
        return Err(MeshFileError::format(path, "normals", expected));
    }
    if let Some(v) = normals.and_then(|n| n.iter().position(|n| n.iter().any(|c| !c.is_finite()))) {
        return Err(MeshFileError::format(path, format!("normal of vertex {v}"), "a finite normal"));
    }
    let bytes = to_bytes(mesh, normals);
    mannequin_io::write_atomic(path, &bytes).map_err(|e| MeshFileError::io(path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> TriMesh {
        let mut m = TriMesh::new(
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.5], [0.0, 1.0, -0.25]],
            vec![[0, 1, 2], [0, 2, 3]],
        );
        m.colors = Some(vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]]);
        m
    }

    #[test]
    fn binary_round_trip_keeps_everything() {
        let m = quad();
        let n = vec![[0.0, 0.0, 1.0]; 4];
        let back = parse(Path::new("q.ply"), &to_bytes(&m, Some(&n))).unwrap();
        assert_eq!(back.mesh, m);
        assert_eq!(back.normals.unwrap(), n);
    }

    /// A hand-written ASCII file with a quad face, an extra property and an extra element.
    #[test]
    fn ascii_polygons_become_fans_and_unknown_fields_are_skipped() {
        let text = "ply\nformat ascii 1.0\ncomment hand made\nelement vertex 4\nproperty double x\n\
                    property double y\nproperty double z\nproperty float quality\n\
                    element face 1\nproperty list uchar uint vertex_indices\nproperty uchar flags\n\
                    element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n\
                    0 0 0 9\n1 0 0 9\n1 1 0 9\n0 1 0 9\n4 0 1 2 3 7\n0 1\n";
        let m = parse(Path::new("a.ply"), text.as_bytes()).unwrap();
        assert_eq!(m.mesh.positions[2], [1.0, 1.0, 0.0]);
        assert_eq!(m.mesh.faces, vec![[0, 1, 2], [0, 2, 3]]);
        assert!(m.normals.is_none() && m.mesh.colors.is_none());
    }

    #[test]
    fn big_endian_is_read() {
        let mut b =
            b"ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                      property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                .to_vec();
        for v in [0.0f32, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 3.0, 0.0] {
            b.extend_from_slice(&v.to_be_bytes());
        }
        b.push(3);
        for i in [0i32, 1, 2] {
            b.extend_from_slice(&i.to_be_bytes());
        }
        let m = parse(Path::new("be.ply"), &b).unwrap();
        assert_eq!(m.mesh.positions[1], [2.0, 0.0, 0.0]);
        assert_eq!(m.mesh.positions[2], [0.0, 3.0, 0.0]);
        assert_eq!(m.mesh.faces, vec![[0, 1, 2]]);
    }

    #[test]
    fn truncated_and_bad_files_name_the_file() {
        let bytes = to_bytes(&quad(), None);
        let err = parse(Path::new("cut.ply"), &bytes[..bytes.len() - 3]).unwrap_err().to_string();
        assert!(err.starts_with("cut.ply: ") && err.contains("ends early"), "{err}");
        let mut bad = quad();
        bad.faces[1][2] = 9;
        let err = parse(Path::new("idx.ply"), &to_bytes(&bad, None)).unwrap_err().to_string();
        assert!(err.contains("idx.ply") && err.contains("vertex 9"), "{err}");
        let err = parse(Path::new("x.ply"), b"plx\n").unwrap_err().to_string();
        assert!(err.contains("magic"), "{err}");
    }

    #[test]
    fn non_finite_numbers_are_not_written() {
        let dir = std::env::temp_dir().join(format!("mq-ply-nan-{}", std::process::id()));
        let path = dir.join("nan.ply");
        let mut m = quad();
        m.colors.as_mut().unwrap()[3][1] = f32::NAN;
        let e = write(&path, &m, None).unwrap_err().to_string();
        assert_eq!(e, format!("{}: the colour of vertex 3 is not finite", path.display()));
        let mut n = vec![[0.0, 0.0, 1.0]; 4];
        n[2][0] = f32::NEG_INFINITY;
        let e = write(&path, &quad(), Some(&n)).unwrap_err().to_string();
        assert_eq!(e, format!("{}: normal of vertex 2: a finite normal", path.display()));
        assert!(!path.exists());
        let _ = std::fs::remove_dir_all(dir);
    }

    /// An element of no properties takes no bytes a record, so its count is checked against the
    /// file like every other: a huge one is refused at once rather than looped over.
    #[test]
    fn counts_the_file_cannot_hold_are_refused() {
        let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                    property float z\nelement junk 18446744073709551615\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
        let err = parse(Path::new("junk.ply"), text.as_bytes()).unwrap_err().to_string();
        assert!(err.starts_with("junk.ply: header, element junk: ") && err.contains("at most 1"), "{err}");
        let many = text.replace("vertex 3", "vertex 99999999999");
        let err = parse(Path::new("v.ply"), many.as_bytes()).unwrap_err().to_string();
        assert!(err.contains("element vertex") && err.contains("found 99999999999"), "{err}");
    }
}
