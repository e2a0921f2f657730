//! The `.garment` reader refuses what `write_garment` would never have written from a template
//! that can be simulated (issue 42: a garment of one vertex, a duplicate or degenerate face, the
//! material "vibranium" and a negative edge length were accepted), naming the file and field.

use std::path::{Path, PathBuf};

use mannequin_body::{BodyModel, shape_body};
use mannequin_garment::file::{read_garment, write_garment};
use mannequin_garment::{Category, Ease, Garment, Recipe};
use mannequin_io::{NpyArray, NpyData, Npz, NpzWriter};
use mannequin_mesh::{ClosestPoint, TriMesh};

/// A 2 cm square of two triangles, 2 cm in front of the light body's first vertex, bound to it.
fn square_garment() -> Garment {
    let model = BodyModel::default_body_lod1();
    let shaped = shape_body(&model, &[]).unwrap();
    let rest: Vec<[f32; 3]> = shaped.vertices.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    let p = rest[0];
    let corner = |dx: f32, dy: f32| [p[0] + dx, p[1] + dy, p[2] + 0.02];
    let mesh = TriMesh::new(
        vec![corner(0.0, 0.0), corner(0.02, 0.0), corner(0.02, 0.02), corner(0.0, 0.02)],
        vec![[0, 1, 2], [0, 2, 3]],
    );
    let recipe = Recipe {
        category: Category::Tshirt,
        fit: Ease::size("M").unwrap(),
        edge_length: 0.015,
        material: mannequin_cloth::Material::COTTON,
        body: "default-lod1".into(),
        betas: vec![],
        body_vertices: model.num_vertices(),
        body_faces: model.faces.len(),
    };
    Garment::bind(recipe, mesh, &ClosestPoint::new(&rest, &model.faces, 0.05))
}

/// `good` written again as `name` with `key` replaced by `array`.
fn with(dir: &Path, good: &Path, name: &str, key: &str, array: NpyArray) -> PathBuf {
    let npz = Npz::read(good).unwrap();
    let mut w = NpzWriter::new();
    for k in npz.keys().filter(|&k| k != key) {
        w.add(k, npz.get(k).unwrap().clone());
    }
    w.add(key, array);
    let path = dir.join(name);
    w.write(&path).unwrap();
    path
}

#[test]
fn a_garment_that_cannot_be_worn_is_refused_naming_file_and_field() {
    let dir = std::env::temp_dir().join(format!("mq-garment-file-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let good = dir.join("good.garment");
    let garment = square_garment();
    write_garment(&good, &garment).unwrap();
    assert_eq!(read_garment(&good).unwrap(), garment);

    let recipe = |edit: &dyn Fn(&mut serde_json::Value)| {
        let mut r = serde_json::to_value(&garment.recipe).unwrap();
        edit(&mut r);
        NpyArray::text(&r.to_string())
    };
    let points =
        |rows: &[[f32; 3]]| NpyArray::f32(vec![rows.len(), 3], rows.iter().flatten().copied().collect());
    let faces =
        |rows: &[[i64; 3]]| NpyArray::i64(vec![rows.len(), 3], rows.iter().flatten().copied().collect());
    let cases = [
        (
            "vibranium",
            "recipe",
            recipe(&|r| r["material"] = "vibranium".into()),
            "recipe: material: unknown name \"vibranium\"; the materials are cotton, denim, silk, jersey, leather",
        ),
        (
            "short_edges",
            "recipe",
            recipe(&|r| r["edge_length"] = (-0.01).into()),
            "recipe: edge_length: -0.01 m",
        ),
        (
            "one_vertex",
            "positions",
            points(&[[0.0; 3]]),
            "field 'faces': index 1; expected whole numbers below 1",
        ),
        (
            "duplicate",
            "faces",
            faces(&[[0, 1, 2], [0, 1, 2]]),
            "faces: faces[0] and faces[1] are the same triangle",
        ),
        ("degenerate", "faces", faces(&[[0, 1, 1], [0, 2, 3]]), "faces[0] is degenerate (zero area)"),
        (
            "flipped",
            "faces",
            faces(&[[0, 1, 2], [0, 3, 2]]),
            "faces: faces 0 and 1 both run edge 2–0 the same way",
        ),
        ("loose", "faces", faces(&[[0, 1, 2]]), "positions: vertex 3 is in no triangle"),
        ("no_faces", "faces", faces(&[]), "faces: the garment has no triangles"),
        (
            "far",
            "offsets",
            points(&[[0.0, 0.0, 5.0]; 4]),
            "field 'offsets': row 0 is [0.0, 0.0, 5.0]; expected at most 1 m",
        ),
        (
            "off_face",
            "body_bary",
            points(&[[2.0, -1.0, 0.0]; 4]),
            "field 'body_bary': row 0 is [2.0, -1.0, 0.0]",
        ),
        // A header alone claiming 3 million vertices: refused before anything is inflated.
        (
            "huge_header",
            "positions",
            NpyArray { shape: vec![3_000_000, 3], data: NpyData::F32(vec![]) },
            "field 'positions': shape [3000000, 3] brings the archive to",
        ),
    ];
    for (name, key, array, message) in cases {
        let path = with(&dir, &good, &format!("{name}.garment"), key, array);
        let e = read_garment(&path).unwrap_err().to_string();
        assert!(e.starts_with(&path.display().to_string()) && e.contains(message), "{name}: {e}");
    }
    std::fs::remove_dir_all(dir).ok();
}
