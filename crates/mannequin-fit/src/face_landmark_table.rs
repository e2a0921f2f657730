//! Where MediaPipe's 468 face-mesh landmarks sit on the default body's head: a triangle of the
//! default body and barycentric weights per landmark, from registering MediaPipe's canonical
//! face mesh to the head once (`tools/default_body/face_landmarks.py`, `data/NOTICE.md`). On the
//! canonical face, the registered points lie within 2.5 mm (median) and 12.8 mm (the forehead's
//! top) of the head's surface. A face fit compares these surface points, moved by the face
//! model, with the detected landmarks.

use mannequin_io::Npz;

use crate::error::FitError;

static TABLE: &[u8] = include_bytes!("../data/face_landmarks.npz");

/// Each landmark's triangle and barycentrics on the default body.
#[derive(Debug, Clone)]
pub struct FaceLandmarkTable {
    pub triangles: Vec<usize>,
    pub barycentrics: Vec<[f32; 3]>,
}

impl FaceLandmarkTable {
    pub fn default_head() -> Self {
        let npz = Npz::from_bytes("<embedded face_landmarks.npz>".into(), TABLE)
            .expect("the embedded face landmark table is a valid npz");
        let triangles = npz.require("triangles").ok().and_then(|a| a.to_i64()).expect("triangles");
        let (_, bary) =
            npz.f64_with_shape("barycentrics", &[Some(triangles.len()), Some(3)]).expect("barycentrics");
        Self {
            triangles: triangles.into_iter().map(|t| t as usize).collect(),
            barycentrics: bary.chunks_exact(3).map(|b| [b[0] as f32, b[1] as f32, b[2] as f32]).collect(),
        }
    }

    /// The landmarks' points on a mesh with the default body's triangles (posed or not).
    pub fn positions(&self, vertices: &[[f32; 3]], faces: &[[u32; 3]]) -> Result<Vec<[f32; 3]>, FitError> {
        self.triangles
            .iter()
            .zip(&self.barycentrics)
            .map(|(&t, b)| {
                let corners = faces
                    .get(t)
                    .and_then(|f| f.iter().map(|&v| vertices.get(v as usize)).collect::<Option<Vec<_>>>())
                    .ok_or_else(|| {
                        FitError::input("body", "the face landmark table is made for the default body's mesh")
                    })?;
                Ok(std::array::from_fn(|c| (0..3).map(|k| b[k] * corners[k][c]).sum()))
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use glam::{DMat4, DVec4};
    use mannequin_body::BodyModel;

    use super::*;

    /// The fraction of the inter-ocular distance by which the best affine camera (3D → 2D)
    /// misses `detected` with `points`: median over the landmarks.
    fn affine_miss(points: &[[f32; 3]], detected: &[f32]) -> f64 {
        let rows: Vec<DVec4> =
            points.iter().map(|p| DVec4::new(p[0] as f64, p[1] as f64, p[2] as f64, 1.0)).collect();
        let ata = rows
            .iter()
            .fold(DMat4::ZERO, |m, r| m + DMat4::from_cols(*r * r.x, *r * r.y, *r * r.z, *r * r.w));
        let q = |i: usize, c: usize| detected[3 * i + c] as f64;
        let solve = |c: usize| {
            ata.inverse() * rows.iter().enumerate().fold(DVec4::ZERO, |s, (i, r)| s + *r * q(i, c))
        };
        let (mu, mv) = (solve(0), solve(1));
        let mut miss: Vec<f64> =
            rows.iter().enumerate().map(|(i, r)| (r.dot(mu) - q(i, 0)).hypot(r.dot(mv) - q(i, 1))).collect();
        miss.sort_by(f64::total_cmp);
        // Landmarks 33 and 263: the outer eye corners.
        let iod = (q(33, 0) - q(263, 0)).hypot(q(33, 1) - q(263, 1));
        miss[miss.len() / 2] / iod
    }

    /// The default head's landmark points explain MediaPipe's face mesh on real photos up to an
    /// affine camera (a generic head, not a fit of the face, so not exactly); the same points in
    /// a scrambled order do not.
    #[test]
    fn the_default_head_explains_the_face_mesh_on_real_photos() {
        let body = BodyModel::default_body();
        let table = FaceLandmarkTable::default_head();
        let points = table.positions(&body.v_template, &body.faces).unwrap();
        for (picture, bound) in [("astronaut", 0.05), ("camera", 0.09)] {
            let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join(format!("tests/data/face_pipeline_{picture}.npz"));
            let detected = Npz::read(path).unwrap().require("landmarks_px").unwrap().to_f32().unwrap();
            let miss = affine_miss(&points, &detected);
            let mut scrambled = points.clone();
            scrambled.rotate_left(100);
            let scrambled_miss = affine_miss(&scrambled, &detected);
            println!(
                "{picture}: median miss {miss:.3} of the eyes' distance (scrambled {scrambled_miss:.3})"
            );
            assert!(miss < bound, "{picture}: {miss}");
            assert!(scrambled_miss > 0.2, "{picture}: scrambled {scrambled_miss}");
        }
    }

    #[test]
    fn another_mesh_is_refused() {
        let lod1 = BodyModel::default_body_lod1();
        assert!(FaceLandmarkTable::default_head().positions(&lod1.v_template, &lod1.faces).is_err());
    }
}
