//! The mesh operators against libigl on three meshes (closed regular, closed irregular with obtuse
//! triangles, open with a boundary). Fixture: tools/oracles/mesh_igl.py.

use mannequin_io::Npz;
use mannequin_mesh::adjacency::{edges, face_neighbors, one_rings};
use mannequin_mesh::normals::{face_normals, vertex_normals};
use mannequin_mesh::{MassKind, cotan_laplacian, double_areas, gradient_operator, mass_matrix, vertex_areas};

const MESHES: [&str; 3] = ["ico", "hull", "grid"];

struct Case {
    npz: Npz,
    name: &'static str,
    positions: Vec<[f32; 3]>,
    faces: Vec<[u32; 3]>,
}

impl Case {
    fn load(name: &'static str) -> Case {
        let npz = Npz::read(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/mesh_igl.npz")).unwrap();
        let (_, v) = npz.f64_with_shape(&format!("{name}_v"), &[None, Some(3)]).unwrap();
        let (_, f) = npz.f64_with_shape(&format!("{name}_f"), &[None, Some(3)]).unwrap();
        let positions = v.chunks(3).map(|p| [p[0] as f32, p[1] as f32, p[2] as f32]).collect();
        let faces = f.chunks(3).map(|t| [t[0] as u32, t[1] as u32, t[2] as u32]).collect();
        Case { npz, name, positions, faces }
    }

    fn array(&self, key: &str) -> Vec<f64> {
        self.npz.f64_with_shape(&format!("{}_{key}", self.name), &[None]).unwrap().1
    }

    fn rows3(&self, key: &str) -> Vec<[f64; 3]> {
        let (_, x) = self.npz.f64_with_shape(&format!("{}_{key}", self.name), &[None, Some(3)]).unwrap();
        x.chunks(3).map(|r| [r[0], r[1], r[2]]).collect()
    }

    /// A COO matrix from the fixture as a dense row-major array, with rows renumbered by `row`.
    fn dense(&self, key: &str, rows: usize, cols: usize, row: impl Fn(usize) -> usize) -> Vec<f64> {
        let (i, j, x) = (
            self.array(&format!("{key}_i")),
            self.array(&format!("{key}_j")),
            self.array(&format!("{key}_x")),
        );
        let mut m = vec![0.0; rows * cols];
        for k in 0..x.len() {
            m[row(i[k] as usize) * cols + j[k] as usize] += x[k];
        }
        m
    }
}

fn max_abs_diff(ours: &faer::sparse::SparseColMat<usize, f64>, reference: &[f64]) -> f64 {
    let d = ours.to_dense();
    let cols = d.ncols();
    (0..d.nrows())
        .flat_map(|r| (0..cols).map(move |c| (r, c)))
        .map(|(r, c)| (d[(r, c)] - reference[r * cols + c]).abs())
        .fold(0.0, f64::max)
}

fn scale(reference: &[f64]) -> f64 {
    reference.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

#[test]
fn cotan_laplacian_matches_igl_cotmatrix() {
    for name in MESHES {
        let c = Case::load(name);
        let n = c.positions.len();
        let reference = c.dense("cot", n, n, |r| r);
        let err = max_abs_diff(&cotan_laplacian(&c.positions, &c.faces), &reference);
        assert!(err < 1e-9 * scale(&reference), "{name}: {err}");
    }
}

#[test]
fn mass_matrices_match_igl_massmatrix() {
    for name in MESHES {
        let c = Case::load(name);
        for (kind, key) in [(MassKind::Barycentric, "mass_bary"), (MassKind::Voronoi, "mass_voronoi")] {
            let reference = c.array(key);
            let ours = vertex_areas(&c.positions, &c.faces, kind);
            let err = ours.iter().zip(&reference).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            assert!(err < 1e-12 * scale(&reference).max(1.0), "{name} {kind:?}: {err}");
            let n = ours.len();
            let dense: Vec<f64> =
                (0..n * n).map(|k| if k % (n + 1) == 0 { reference[k / n] } else { 0.0 }).collect();
            assert!(max_abs_diff(&mass_matrix(&c.positions, &c.faces, kind), &dense) < 1e-12);
        }
    }
}

#[test]
fn gradient_operator_matches_igl_grad() {
    for name in MESHES {
        let c = Case::load(name);
        let f = c.faces.len();
        // libigl's row d*F + face is our row 3*face + d.
        let reference = c.dense("grad", 3 * f, c.positions.len(), |r| 3 * (r % f) + r / f);
        let err = max_abs_diff(&gradient_operator(&c.positions, &c.faces), &reference);
        assert!(err < 1e-9 * scale(&reference), "{name}: {err}");
    }
}

#[test]
fn double_areas_and_normals_match_igl() {
    for name in MESHES {
        let c = Case::load(name);
        let reference = c.array("dblarea");
        let ours = double_areas(&c.positions, &c.faces);
        let err = ours.iter().zip(&reference).map(|(a, b)| (a - b).abs() / b).fold(0.0, f64::max);
        assert!(err < 1e-12, "{name} doublearea: relative {err}");
        for (ours, key) in [
            (vertex_normals(&c.positions, &c.faces), "vnormals"),
            (face_normals(&c.positions, &c.faces), "fnormals"),
        ] {
            let reference = c.rows3(key);
            assert_eq!(ours.len(), reference.len());
            let err = ours
                .iter()
                .zip(&reference)
                .flat_map(|(a, b)| (0..3).map(move |d| (a[d] as f64 - b[d]).abs()))
                .fold(0.0, f64::max);
            assert!(err < 1e-5, "{name} {key}: {err}");
        }
    }
}

#[test]
fn adjacency_matches_igl() {
    for name in MESHES {
        let c = Case::load(name);
        let mut reference: Vec<[u32; 2]> = c
            .npz
            .f64_with_shape(&format!("{name}_edges"), &[None, Some(2)])
            .unwrap()
            .1
            .chunks(2)
            .map(|e| [e[0].min(e[1]) as u32, e[0].max(e[1]) as u32])
            .collect();
        reference.sort_unstable();
        let ours = edges(&c.faces);
        assert_eq!(ours, reference, "{name} edges");
        let rings = one_rings(c.positions.len(), &c.faces);
        assert_eq!(rings.iter().map(Vec::len).sum::<usize>(), 2 * ours.len());
        for [a, b] in ours {
            assert!(rings[a as usize].contains(&b) && rings[b as usize].contains(&a));
        }
        let tt = c.rows3("tt");
        let neighbors = face_neighbors(&c.faces);
        for (f, (ours, theirs)) in neighbors.iter().zip(&tt).enumerate() {
            for k in 0..3 {
                let theirs = (theirs[k] >= 0.0).then_some(theirs[k] as u32);
                assert_eq!(ours[k], theirs, "{name} face {f} edge {k}");
            }
        }
        if name == "grid" {
            assert!(neighbors.iter().flatten().any(Option::is_none), "the open grid has boundary edges");
        }
    }
}
