//! One frame as the segmentation sees it: the image, the person's mask, and the fitted body
//! drawn through the frame's camera, so that every pixel of the person knows which body face it
//! shows or, off the body (a skirt between the legs, hair past the head), from which body pixel
//! it takes its prior: the nearest one inside the mask, walking through the mask.

use std::collections::VecDeque;

use mannequin_body::{BodyModel, ShapedBody, pose_frames};
use mannequin_data::image::{Image, Mask};
use mannequin_data::{Camera, Dataset};
use mannequin_mesh::normals::vertex_normals;
use mannequin_raster::hard::{NO_FACE, RasterMesh, Shading, rasterize};

use crate::ngd::NgdError;

/// A pixel of the person no body pixel reaches through the mask.
pub const NO_SOURCE: u32 = u32::MAX;

pub struct FrameView {
    pub width: usize,
    pub height: usize,
    pub image: Image,
    pub mask: Mask,
    /// Per pixel, the body face drawn there, [`NO_FACE`] off the body.
    pub face: Vec<u32>,
    /// Per pixel, its barycentrics in `face`.
    pub barycentrics: Vec<[f32; 3]>,
    /// Per pixel of the person, the body pixel its prior comes from (itself on the body);
    /// [`NO_SOURCE`] off the person or out of the body's reach.
    pub source: Vec<u32>,
}

/// A frame's body pose: 72 axis-angle values and the translation.
pub struct FramePose<'a> {
    pub pose: &'a [f32],
    pub transl: [f32; 3],
}

impl FrameView {
    pub fn new(
        dataset: &Dataset,
        frame: usize,
        model: &BodyModel,
        shaped: &ShapedBody,
        pose: &FramePose,
    ) -> Result<Self, NgdError> {
        let data = dataset.frame(frame)?;
        let camera: &Camera = dataset.camera(frame);
        let posed = pose_frames(model, shaped, pose.pose, &pose.transl)?;
        let positions: Vec<[f32; 3]> =
            posed.frame_vertices(0).chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
        let normals = vertex_normals(&positions, &model.faces);
        let mesh = RasterMesh {
            positions: &positions,
            faces: &model.faces,
            normals: &normals,
            shading: Shading::Flat([0.0; 3]),
        };
        let raster = rasterize(&mesh, camera, [0.0; 3]);
        let (width, height) = (data.image.width, data.image.height);
        let mut face = raster.face_id;
        for (f, &inside) in face.iter_mut().zip(&data.mask.values) {
            if !inside {
                *f = NO_FACE;
            }
        }
        let source = nearest_body_pixel(&face, &data.mask.values, width, height);
        Ok(Self {
            width,
            height,
            image: data.image,
            mask: data.mask,
            face,
            barycentrics: raster.barycentrics,
            source,
        })
    }
}

/// For every pixel of the person, the body pixel nearest to it through the person's mask (a
/// breadth-first walk from all body pixels at once, in 4-neighbour steps).
fn nearest_body_pixel(face: &[u32], mask: &[bool], width: usize, height: usize) -> Vec<u32> {
    let mut source = vec![NO_SOURCE; face.len()];
    let mut queue = VecDeque::new();
    for (i, &f) in face.iter().enumerate() {
        if f != NO_FACE {
            source[i] = i as u32;
            queue.push_back(i);
        }
    }
    while let Some(i) = queue.pop_front() {
        for n in neighbours(i, width, height).into_iter().flatten() {
            if mask[n] && source[n] == NO_SOURCE {
                source[n] = source[i];
                queue.push_back(n);
            }
        }
    }
    source
}

/// The pixel's 4 neighbours on a `width` × `height` grid, `None` past the border.
pub fn neighbours(i: usize, width: usize, height: usize) -> [Option<usize>; 4] {
    let (x, y) = (i % width, i / width);
    [
        (x > 0).then(|| i - 1),
        (x + 1 < width).then(|| i + 1),
        (y > 0).then(|| i - width),
        (y + 1 < height).then(|| i + width),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixels_off_the_body_take_the_nearest_body_pixel_through_the_mask() {
        // A 5×1 strip: body at 0 and 4, mask everywhere but pixel 3 (a gap), so pixel 2 reaches
        // only the body pixel at 0.
        let face = [7, NO_FACE, NO_FACE, NO_FACE, 9];
        let mask = [true, true, true, false, true];
        assert_eq!(nearest_body_pixel(&face, &mask, 5, 1), vec![0, 0, 0, NO_SOURCE, 4]);
    }
}
