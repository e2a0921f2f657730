//! Attachments: garment particles bound to a point of the body surface (a waistband on the hips),
//! placed there kinematically at every substep, so they follow the skinned body exactly.

use glam::Vec3;

use crate::body::Body;
use crate::error::ClothError;
use mannequin_mesh::barycentric::{at_barycentric, closest_barycentric, plane_barycentric};

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Attachment {
    pub particle: u32,
    /// A body triangle.
    pub triangle: u32,
    /// Barycentric coordinates on that triangle's plane (they may stray outside [0, 1] a little,
    /// for a point beside the triangle).
    pub barycentric: [f32; 3],
    /// Metres along the triangle's unit normal.
    pub offset: f32,
}

impl Attachment {
    /// Binds `particle`, now at `point`, to the nearest triangle of the body (`body_positions`,
    /// `body_faces`): the foot of the perpendicular from `point` to that triangle's plane and the
    /// height above it, so [`Attachment`] reproduces `point` exactly on this body. Faces with an
    /// index out of range are skipped; with no usable face the attachment names triangle u32::MAX,
    /// which [`crate::Simulator::new`] refuses.
    pub fn bind(
        body_positions: &[[f32; 3]],
        body_faces: &[[u32; 3]],
        particle: u32,
        point: [f32; 3],
    ) -> Attachment {
        let p = Vec3::from(point);
        let corners = |tri: &[u32; 3]| -> Option<[Vec3; 3]> {
            let get = |i: u32| body_positions.get(i as usize).map(|&q| Vec3::from(q));
            Some([get(tri[0])?, get(tri[1])?, get(tri[2])?])
        };
        let nearest = body_faces
            .iter()
            .enumerate()
            .filter_map(|(f, tri)| {
                let [a, b, c] = corners(tri)?;
                let d = (at_barycentric(closest_barycentric(p, a, b, c), a, b, c) - p).length_squared();
                Some((f, [a, b, c], d))
            })
            .min_by(|x, y| x.2.total_cmp(&y.2));
        let Some((triangle, [a, b, c], _)) = nearest else {
            return Attachment { particle, triangle: u32::MAX, barycentric: [1.0, 0.0, 0.0], offset: 0.0 };
        };
        let n = (b - a).cross(c - a).normalize_or_zero();
        let offset = (p - a).dot(n);
        Attachment {
            particle,
            triangle: triangle as u32,
            barycentric: plane_barycentric(p - offset * n, a, b, c),
            offset,
        }
    }

    /// Where the particle goes when the body's vertices are at `body` and its faces' unit normals
    /// are `normals`.
    pub(crate) fn target(&self, body: &[Vec3], faces: &[[u32; 3]], normals: &[Vec3]) -> Vec3 {
        let [a, b, c] = faces[self.triangle as usize].map(|i| body[i as usize]);
        at_barycentric(self.barycentric, a, b, c) + self.offset * normals[self.triangle as usize]
    }
}

/// Refuses attachments naming particles or triangles that do not exist, or non-finite numbers.
pub(crate) fn check_attachments(
    attachments: &[Attachment],
    particles: usize,
    body: Option<&Body>,
) -> Result<(), ClothError> {
    let Some(body) = body else {
        return match attachments.is_empty() {
            true => Ok(()),
            false => Err(ClothError::invalid("attachments", "attachments need a body to attach to")),
        };
    };
    for (k, a) in attachments.iter().enumerate() {
        if a.particle as usize >= particles {
            let reason = format!("{} is out of range: the garment has {particles} vertices", a.particle);
            return Err(ClothError::invalid(format!("attachments[{k}].particle"), reason));
        }
        if a.triangle as usize >= body.faces.len() {
            let reason =
                format!("{} is out of range: the body has {} triangles", a.triangle, body.faces.len());
            return Err(ClothError::invalid(format!("attachments[{k}].triangle"), reason));
        }
        if !(a.barycentric.iter().all(|x| x.is_finite()) && a.offset.is_finite()) {
            return Err(ClothError::invalid(
                format!("attachments[{k}]"),
                "barycentric and offset must be finite",
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn binding_reproduces_the_point() {
        let body = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [5.0, 5.0, 5.0],
            [6.0, 5.0, 5.0],
            [5.0, 6.0, 5.0],
        ];
        let faces = [[3, 4, 5], [0, 1, 2]];
        let point = [0.3, 0.2, 0.05];
        let a = Attachment::bind(&body, &faces, 7, point);
        assert_eq!((a.particle, a.triangle), (7, 1));
        assert!((a.offset - 0.05).abs() < 1e-6);
        let positions: Vec<Vec3> = body.iter().map(|&p| Vec3::from(p)).collect();
        let normals = [Vec3::Z, Vec3::Z];
        assert!((a.target(&positions, &faces, &normals) - Vec3::from(point)).length() < 1e-6);
    }

    #[test]
    fn a_body_without_usable_faces_binds_nothing() {
        let a = Attachment::bind(&[[0.0; 3]], &[[0, 1, 2]], 0, [0.0; 3]);
        assert_eq!(a.triangle, u32::MAX);
    }
}
