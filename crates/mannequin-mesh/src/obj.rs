//! Wavefront OBJ, the interchange format of MakeHuman, Blender and most garment datasets.
//!
//! Reading keeps positions, optional `v x y z r g b` colours, texture coordinates and named groups;
//! normals (`vn`) are ignored because Mannequin recomputes them from the geometry. Polygons are
//! fan-triangulated and negative (relative) indices are resolved, as the OBJ specification allows.

use std::fmt::Write as _;
use std::ops::Range;
use std::path::Path;

use crate::{MeshFileError, TriMesh, UvLayout};

/// An OBJ file's triangle mesh and its named groups (`g name`).
#[derive(Debug, Clone, PartialEq)]
pub struct Obj {
    pub mesh: TriMesh,
    /// Runs of consecutive triangles under one `g` statement; a name may appear in several runs.
    pub groups: Vec<ObjGroup>,
}

/// A run of triangles (indices into `Obj::mesh.faces`) that the file put under one group name.
#[derive(Debug, Clone, PartialEq)]
pub struct ObjGroup {
    pub name: String,
    pub faces: Range<usize>,
}

/// Reads an OBJ file's triangle mesh, ignoring its groups.
pub fn read_obj(path: impl AsRef<Path>) -> Result<TriMesh, MeshFileError> {
    Ok(Obj::read(path)?.mesh)
}

impl Obj {
    pub fn read(path: impl AsRef<Path>) -> Result<Obj, MeshFileError> {
        let path = path.as_ref();
        let bytes = std::fs::read(path).map_err(|e| MeshFileError::io(path, e))?;
        Obj::parse(path, &bytes)
    }

    /// Parses OBJ text held in memory (for instance a member of a zip archive); `path` only names
    /// the source in error messages.
    pub fn parse(path: &Path, bytes: &[u8]) -> Result<Obj, MeshFileError> {
        let mut parser = Parser::default();
        for (i, line) in String::from_utf8_lossy(bytes).lines().enumerate() {
            parser
                .line(line)
                .map_err(|expected| MeshFileError::format(path, format!("line {}", i + 1), expected))?;
        }
        let obj = parser.finish();
        obj.mesh.validate().map_err(|e| MeshFileError::invalid(path, e))?;
        Ok(obj)
    }

    /// The faces of every run named `name` as a compact mesh, or `None` if no face carries that name.
    pub fn group(&self, name: &str) -> Option<TriMesh> {
        let faces: Vec<usize> =
            self.groups.iter().filter(|g| g.name == name).flat_map(|g| g.faces.clone()).collect();
        (!faces.is_empty()).then(|| self.mesh.submesh(&faces).0)
    }
}

#[derive(Default)]
struct Parser {
    positions: Vec<[f32; 3]>,
    colors: Vec<[f32; 3]>,
    uv_coords: Vec<[f32; 2]>,
    faces: Vec<[u32; 3]>,
    uv_faces: Vec<[u32; 3]>,
    /// Whether vertices carry colours, fixed by the first `v` line.
    vertex_colors: Option<bool>,
    /// Whether faces carry texture indices, fixed by the first `f` line.
    face_uvs: Option<bool>,
    groups: Vec<ObjGroup>,
}

impl Parser {
    /// Consumes one line; the error says what was expected there.
    fn line(&mut self, line: &str) -> Result<(), String> {
        let line = line.split('#').next().unwrap_or("").trim();
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => self.vertex(words),
            Some("vt") => {
                let n = numbers(words, "vt u [v [w]]")?;
                match n[..] {
                    [u] => self.uv_coords.push([u, 0.0]),
                    [u, v] | [u, v, _] => self.uv_coords.push([u, v]),
                    _ => return Err(format!("vt u [v [w]] (1 to 3 numbers, found {})", n.len())),
                }
                Ok(())
            }
            Some("f") => self.face(words),
            Some("g") => {
                let start = self.faces.len();
                self.close_group();
                let name = line[1..].trim().to_string();
                self.groups.push(ObjGroup { name, faces: start..start });
                Ok(())
            }
            // vn, o, s, usemtl, mtllib, l, p and blank lines carry nothing a TriMesh keeps.
            _ => Ok(()),
        }
    }

    fn vertex<'a>(&mut self, words: impl Iterator<Item = &'a str>) -> Result<(), String> {
        let n = numbers(words, "v x y z [r g b]")?;
        let (p, color) = match n[..] {
            [x, y, z] | [x, y, z, _] => ([x, y, z], None),
            [x, y, z, r, g, b] => ([x, y, z], Some([r, g, b])),
            _ => return Err(format!("v x y z [w] or v x y z r g b (found {} numbers)", n.len())),
        };
        let has_color = *self.vertex_colors.get_or_insert(color.is_some());
        match (has_color, color) {
            (true, Some(c)) => self.colors.push(c),
            (false, None) => {}
            _ => return Err("every vertex to have a colour or none to (the first vertex decides)".into()),
        }
        self.positions.push(p);
        Ok(())
    }

    fn face<'a>(&mut self, words: impl Iterator<Item = &'a str>) -> Result<(), String> {
        let corners = words.map(|w| self.corner(w)).collect::<Result<Vec<(u32, Option<u32>)>, String>>()?;
        if corners.len() < 3 {
            return Err(format!("a face with at least 3 corners (found {})", corners.len()));
        }
        let has_uv = corners[0].1.is_some();
        if corners.iter().any(|c| c.1.is_some() != has_uv) || *self.face_uvs.get_or_insert(has_uv) != has_uv {
            return Err(
                "every face corner to have a texture index or none to (the first face decides)".into()
            );
        }
        for k in 1..corners.len() - 1 {
            let tri = [corners[0], corners[k], corners[k + 1]];
            self.faces.push(tri.map(|c| c.0));
            if has_uv {
                self.uv_faces.push(tri.map(|c| c.1.unwrap_or(0)));
            }
        }
        Ok(())
    }

    /// One `v`, `v/vt`, `v//vn` or `v/vt/vn` corner, resolved to 0-based indices.
    fn corner(&self, word: &str) -> Result<(u32, Option<u32>), String> {
        let mut parts = word.split('/');
        let v = resolve(parts.next().unwrap_or(""), self.positions.len(), "vertex")?;
        let vt = match parts.next() {
            Some(t) if !t.is_empty() => Some(resolve(t, self.uv_coords.len(), "texture coordinate")?),
            _ => None,
        };
        Ok((v, vt))
    }

    fn close_group(&mut self) {
        if let Some(g) = self.groups.last_mut() {
            g.faces.end = self.faces.len();
        }
    }

    fn finish(mut self) -> Obj {
        self.close_group();
        let mut mesh = TriMesh::new(self.positions, self.faces);
        if self.face_uvs == Some(true) {
            mesh.uv = Some(UvLayout { coords: self.uv_coords, faces: self.uv_faces });
        }
        if self.vertex_colors == Some(true) {
            mesh.colors = Some(self.colors);
        }
        self.groups.retain(|g| !g.faces.is_empty());
        Obj { mesh, groups: self.groups }
    }
}

/// Parses finite numbers; `form` describes the statement for the error message.
fn numbers<'a>(words: impl Iterator<Item = &'a str>, form: &str) -> Result<Vec<f32>, String> {
    words
        .map(|w| match w.parse::<f32>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => Err(format!("{form} with finite numbers, found '{w}'")),
        })
        .collect()
}

/// A 1-based (or negative, counted back from the last defined) OBJ index as a 0-based index.
fn resolve(word: &str, defined: usize, what: &str) -> Result<u32, String> {
    let i: i64 = word.parse().map_err(|_| format!("a {what} index, found '{word}'"))?;
    let zero_based = if i > 0 { i - 1 } else { defined as i64 + i };
    if i == 0 || zero_based < 0 || zero_based >= defined as i64 {
        return Err(format!(
            "a {what} index between 1 and {defined} or between -{defined} and -1, found {i}"
        ));
    }
    Ok(zero_based as u32)
}

/// Writes positions (with colours as `v x y z r g b` when present), UVs and faces, atomically.
pub fn write_obj(path: impl AsRef<Path>, mesh: &TriMesh) -> Result<(), MeshFileError> {
    let path = path.as_ref();
    mesh.validate().map_err(|e| MeshFileError::invalid(path, e))?;
    let mut text = String::with_capacity(40 * (mesh.positions.len() + mesh.faces.len()));
    text.push_str("# Mannequin\n");
    for (i, p) in mesh.positions.iter().enumerate() {
        let _ = write!(text, "v {} {} {}", p[0], p[1], p[2]);
        if let Some(c) = &mesh.colors {
            let _ = write!(text, " {} {} {}", c[i][0], c[i][1], c[i][2]);
        }
        text.push('\n');
    }
    if let Some(uv) = &mesh.uv {
        for t in &uv.coords {
            let _ = writeln!(text, "vt {} {}", t[0], t[1]);
        }
    }
    for (f, tri) in mesh.faces.iter().enumerate() {
        text.push('f');
        for (k, v) in tri.iter().enumerate() {
            let _ = write!(text, " {}", v + 1);
            if let Some(uv) = &mesh.uv {
                let _ = write!(text, "/{}", uv.faces[f][k] + 1);
            }
        }
        text.push('\n');
    }
    mannequin_io::write_atomic_with(path, |w| w.write_all(text.as_bytes()))
        .map_err(|e| MeshFileError::io(path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Obj, MeshFileError> {
        Obj::parse(Path::new("test.obj"), text.as_bytes())
    }

    fn error(text: &str) -> String {
        parse(text).unwrap_err().to_string()
    }

    #[test]
    fn quads_fan_triangulate_and_indices_can_be_negative() {
        let obj = parse("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf -4 -3 -2 -1\n").unwrap();
        assert_eq!(obj.mesh.faces, vec![[0, 1, 2], [0, 2, 3]]);
        assert!(obj.mesh.uv.is_none() && obj.mesh.colors.is_none());
    }

    #[test]
    fn corner_forms_with_normals_and_texture_coordinates() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n\
                    f 1/3/1 2/2/1 3/1/1\nf 3//1 2//1 1//1\n";
        // Mixing faces with and without texture indices is rejected, at the line that mixes them.
        assert!(error(text).contains("line 9"), "{}", error(text));
        let obj = parse(&text.replace("f 3//1 2//1 1//1\n", "f 3/1 2/2 1/3\n")).unwrap();
        let uv = obj.mesh.uv.unwrap();
        assert_eq!(uv.faces, vec![[2, 1, 0], [0, 1, 2]]);
        assert_eq!(uv.coords[2], [0.0, 1.0]);
        let obj = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n").unwrap();
        assert_eq!(obj.mesh.faces, vec![[0, 1, 2]]);
    }

    #[test]
    fn groups_select_submeshes() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\nv 6 5 5\nv 5 6 5\n\
                    g body\nf 1 2 3\ng helper\nf 4 5 6\ng body\nf 3 2 1\n";
        let obj = parse(text).unwrap();
        assert_eq!(
            obj.groups.iter().map(|g| (g.name.as_str(), g.faces.clone())).collect::<Vec<_>>(),
            [("body", 0..1), ("helper", 1..2), ("body", 2..3)]
        );
        let helper = obj.group("helper").unwrap();
        assert_eq!(helper.positions, vec![[5.0, 5.0, 5.0], [6.0, 5.0, 5.0], [5.0, 6.0, 5.0]]);
        assert_eq!(helper.faces, vec![[0, 1, 2]]);
        assert_eq!(obj.group("body").unwrap().faces, vec![[0, 1, 2], [2, 1, 0]]);
        assert!(obj.group("hat").is_none());
    }

    #[test]
    fn errors_name_file_line_and_expectation() {
        let e = error("v 0 0 0\nv 1 0 0\nf 1 2 3\n");
        assert!(e.starts_with("test.obj: line 3:") && e.contains("between 1 and 2"), "{e}");
        assert!(error("v 0 0\n").contains("line 1: v x y z"));
        assert!(error("v 0 0 x\n").contains("found 'x'"));
        assert!(error("v 0 0 nan\n").contains("finite"));
        assert!(error("v 0 0 0\nv 1 0 0\nf 1 2\n").contains("at least 3 corners"));
        assert!(error("v 0 0 0\nf 0 1 1\n").contains("found 0"));
        assert!(error("v 0 0 0 1 1 1\nv 0 0 0\n").contains("line 2: every vertex to have a colour"));
        let missing = read_obj("/nonexistent/mannequin.obj").unwrap_err().to_string();
        assert!(missing.starts_with("/nonexistent/mannequin.obj: "), "{missing}");
    }

    #[test]
    fn write_then_read_round_trips_exactly() {
        let mut mesh = TriMesh::new(
            vec![[0.1, -2.5e-7, 3.0], [1.0 / 3.0, 0.0, 0.0], [0.0, 1.0, 0.0], [7.0, 8.0, 9.0]],
            vec![[0, 1, 2], [0, 2, 3]],
        );
        mesh.uv =
            Some(UvLayout { coords: vec![[0.0, 0.5], [0.25, 1.0 / 7.0]], faces: vec![[0, 1, 1], [1, 0, 0]] });
        mesh.colors = Some(vec![[0.1, 0.2, 0.3], [1.0, 0.0, 0.5], [0.0; 3], [1.0; 3]]);
        let dir = std::env::temp_dir().join(format!("mq-obj-{}", std::process::id()));
        let path = dir.join("mesh.obj");
        write_obj(&path, &mesh).unwrap();
        assert_eq!(read_obj(&path).unwrap(), mesh);
        mesh.uv = None;
        mesh.colors = None;
        write_obj(&path, &mesh).unwrap();
        assert_eq!(read_obj(&path).unwrap(), mesh);
        mesh.faces[1][2] = 4;
        assert!(write_obj(&path, &mesh).unwrap_err().to_string().contains("vertex 4"));
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn non_finite_numbers_are_not_written() {
        let dir = std::env::temp_dir().join(format!("mq-obj-nan-{}", std::process::id()));
        let path = dir.join("nan.obj");
        let base = || {
            let mut m = TriMesh::new(vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], vec![[0, 1, 2]]);
            m.colors = Some(vec![[0.5; 3]; 3]);
            m.uv = Some(UvLayout { coords: vec![[0.0, 0.0]; 3], faces: vec![[0, 1, 2]] });
            m
        };
        type Spoil = fn(&mut TriMesh);
        let spoil: [(&str, Spoil); 3] = [
            ("vertex 1 is not finite", |m| m.positions[1][2] = f32::INFINITY),
            ("the colour of vertex 2 is not finite", |m| m.colors.as_mut().unwrap()[2][0] = f32::NAN),
            ("UV coordinate 0 is not finite", |m| m.uv.as_mut().unwrap().coords[0][1] = f32::NAN),
        ];
        for (expected, f) in spoil {
            let mut m = base();
            f(&mut m);
            let e = write_obj(&path, &m).unwrap_err().to_string();
            assert_eq!(e, format!("{}: {expected}", path.display()));
            assert!(!path.exists());
        }
        let _ = std::fs::remove_dir_all(dir);
    }
}
