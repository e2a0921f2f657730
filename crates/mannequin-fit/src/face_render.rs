//! A coloured head drawn as a picture a face fit could be given: the rasteriser's vertex colours
//! lit by one directional light and an ambient term. Used to measure the fit on faces whose
//! truth is known.

use glam::{DVec3, Vec3};
use mannequin_data::{Camera, Image};
use mannequin_mesh::normals::vertex_normals;
use mannequin_raster::{Raster, RasterMesh, Shading, rasterize};

/// A head placed in the camera, with its colours and light.
pub struct LitHead<'a> {
    /// Vertices in camera space (x right, y down, z ahead), metres.
    pub points: &'a [DVec3],
    pub faces: &'a [[u32; 3]],
    pub colours: &'a [[f32; 3]],
    /// Toward the light, in camera axes.
    pub light: DVec3,
    /// The share of light that reaches every surface.
    pub ambient: f32,
}

/// Renders `head` through `camera` (the fit's `picture_camera`, whose world axes are the
/// camera's with y and z flipped) over `background`; the raster's colour is lit.
pub fn render_head(head: &LitHead, camera: &Camera, background: [f32; 3]) -> (Image, Raster) {
    let world: Vec<[f32; 3]> = head.points.iter().map(|x| [x.x as f32, -x.y as f32, -x.z as f32]).collect();
    let normals = vertex_normals(&world, head.faces);
    let mesh = RasterMesh {
        positions: &world,
        faces: head.faces,
        normals: &normals,
        shading: Shading::Vertex(head.colours),
    };
    let raster = rasterize(&mesh, camera, background);
    let light = head.light.as_vec3();
    let mut image = raster.color.clone();
    for (pixel, n) in image.pixels.iter_mut().zip(&raster.normals.normals) {
        if *n == [0.0; 3] {
            continue;
        }
        let lit = head.ambient + (1.0 - head.ambient) * Vec3::from(*n).dot(light).max(0.0);
        pixel.iter_mut().for_each(|c| *c = (*c * lit).min(1.0));
    }
    (image, raster)
}
