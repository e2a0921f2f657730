//! The dressed body rendered as lit meshes through the ground-truth rasteriser: each mesh drawn
//! on its own, the nearest surface kept per pixel, and a head-on light shading it.

use std::path::Path;

use anyhow::{Context, Result};
use glam::Vec3;
use mannequin_data::image::Image;
use mannequin_mesh::normals::vertex_normals;
use mannequin_raster::{RasterMesh, Shading, rasterize};
use mannequin_splat::Camera;
use rayon::prelude::*;

use mannequin_io::progress::bar;
use mannequin_io::write_video;
use mannequin_splat::clip_camera;

/// Skin's colour, linear RGB.
const SKIN: [f32; 3] = [0.8, 0.6, 0.5];
const BACKGROUND: [f32; 3] = [1.0, 1.0, 1.0];
/// A light from above-left of the camera, in camera space (OpenCV: y down, z forward).
const LIGHT: [f32; 3] = [-0.3, -0.5, -1.0];
const AMBIENT: f32 = 0.3;

/// The topology and colour of what is drawn.
pub struct Scene<'a> {
    pub body_faces: &'a [[u32; 3]],
    pub garments: &'a [(&'a [[u32; 3]], [f32; 3])],
}

/// One frame: every mesh rasterised, the nearest kept per pixel, shaded by its normal.
pub fn render_frame(scene: &Scene, body: &[[f32; 3]], garments: &[&[[f32; 3]]], camera: &Camera) -> Image {
    let light = Vec3::from(LIGHT).normalize();
    let meshes = std::iter::once((body, scene.body_faces, SKIN))
        .chain(garments.iter().zip(scene.garments).map(|(p, (f, c))| (*p, *f, *c)));
    let (w, h) = (camera.width, camera.height);
    let mut depth = vec![f32::INFINITY; w * h];
    let mut pixels = vec![BACKGROUND; w * h];
    for (positions, faces, colour) in meshes {
        let normals = vertex_normals(positions, faces);
        let mesh = RasterMesh { positions, faces, normals: &normals, shading: Shading::Flat(colour) };
        let raster = rasterize(&mesh, camera, BACKGROUND);
        for i in 0..w * h {
            let z = raster.depth.depth[i];
            if raster.mask.values[i] && z < depth[i] {
                depth[i] = z;
                let n = Vec3::from(raster.normals.normals[i]);
                // Back faces seen through an open hem face away: light them as their front.
                let lit = AMBIENT + (1.0 - AMBIENT) * n.dot(light).abs();
                pixels[i] = raster.color.pixels[i].map(|c| c * lit);
            }
        }
    }
    Image { width: w, height: h, pixels }
}

/// Renders every frame to `dir/frames/frame_%04d.png` (and `dir/frames.mp4` with ffmpeg), through
/// `camera` or a front view that frames the whole clip.
pub fn render(
    scene: &Scene,
    body: &[&[[f32; 3]]],
    garments: &[Vec<&[[f32; 3]]>],
    camera: Option<&Camera>,
    dir: &Path,
    fps: f32,
) -> Result<()> {
    let camera = match camera {
        Some(camera) => camera.clone(),
        None => {
            let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
            for p in
                body.iter().flat_map(|b| b.iter()).chain(garments.iter().flatten().flat_map(|g| g.iter()))
            {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
            clip_camera(lo, hi)
        }
    };
    let folder = dir.join("frames");
    std::fs::create_dir_all(&folder).with_context(|| format!("creating {}", folder.display()))?;
    let progress = bar(body.len() as u64, "rendering");
    // Frames in parallel: encoding a PNG is serial work as long as rasterising one.
    (0..body.len()).into_par_iter().try_for_each(|f| -> Result<()> {
        let path = folder.join(format!("frame_{f:04}.png"));
        render_frame(scene, body[f], &garments[f], &camera)
            .write_png(&path)
            .with_context(|| format!("writing {}", path.display()))?;
        progress.inc(1);
        Ok(())
    })?;
    progress.finish_and_clear();
    Ok(write_video(&folder, &dir.join("frames.mp4"), body.len(), fps)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use mannequin_body::{BodyModel, named_pose, pose_frames, shape_body};

    /// Pixel centres covered by any projected triangle, by a projection and point-in-triangle
    /// test of its own (OpenCV pinhole from the camera's matrices, edge functions).
    /// A mesh's positions and triangles.
    type Posed<'a> = (&'a [[f32; 3]], &'a [[u32; 3]]);

    fn projected_union(meshes: &[Posed], camera: &Camera) -> Vec<bool> {
        let (k, e) = (camera.intrinsic, camera.extrinsic);
        let project = |p: [f32; 3]| {
            let c: Vec<f64> =
                (0..3).map(|r| (0..3).map(|j| e[r][j] * p[j] as f64).sum::<f64>() + e[r][3]).collect();
            [k[0][0] * c[0] / c[2] + k[0][2], k[1][1] * c[1] / c[2] + k[1][2]]
        };
        let mut covered = vec![false; camera.width * camera.height];
        for (positions, faces) in meshes {
            let screen: Vec<[f64; 2]> = positions.iter().map(|&p| project(p)).collect();
            for t in *faces {
                let [a, b, c] = t.map(|i| screen[i as usize]);
                let edge = |p: [f64; 2], q: [f64; 2], x: [f64; 2]| {
                    (q[0] - p[0]) * (x[1] - p[1]) - (q[1] - p[1]) * (x[0] - p[0])
                };
                let (x0, x1) = (
                    a[0].min(b[0]).min(c[0]).floor().max(0.0) as usize,
                    a[0].max(b[0]).max(c[0]).ceil() as usize,
                );
                let (y0, y1) = (
                    a[1].min(b[1]).min(c[1]).floor().max(0.0) as usize,
                    a[1].max(b[1]).max(c[1]).ceil() as usize,
                );
                for y in y0..y1.min(camera.height) {
                    for x in x0..x1.min(camera.width) {
                        let centre = [x as f64 + 0.5, y as f64 + 0.5];
                        let w = [edge(a, b, centre), edge(b, c, centre), edge(c, a, centre)];
                        if w.iter().all(|&v| v >= 0.0) || w.iter().all(|&v| v <= 0.0) {
                            covered[y * camera.width + x] = true;
                        }
                    }
                }
            }
        }
        covered
    }

    /// A body in a squat with a T-shirt-like band cut from it (the body's own triangles above the
    /// hips, 2 cm out): the rendered frame's non-background pixels are the union of the
    /// projected triangles, but for pixels whose centre lies on a shared edge (under 0.5 %).
    #[test]
    fn a_dressed_frame_covers_the_union_of_its_projected_meshes() {
        let model = BodyModel::default_body_lod1();
        let shaped = shape_body(&model, &[]).unwrap();
        let pose = named_pose("squat").unwrap();
        let posed = pose_frames(&model, &shaped, &pose, &[0.0, 0.0, 0.0]).unwrap();
        let body: Vec<[f32; 3]> =
            posed.frame_vertices(0).chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
        let faces = model.template_mesh().faces;
        let normals = vertex_normals(&body, &faces);
        let band: Vec<[u32; 3]> =
            faces.iter().copied().filter(|t| t.iter().all(|&v| body[v as usize][1] > -0.2)).collect();
        let shirt: Vec<[f32; 3]> =
            body.iter().zip(&normals).map(|(p, n)| [0, 1, 2].map(|k| p[k] + 0.02 * n[k])).collect();
        let garments = [(band.as_slice(), [0.7, 0.1, 0.1])];
        let scene = Scene { body_faces: &faces, garments: &garments };
        let camera = clip_camera([-0.9, -1.2, -0.4], [0.9, 0.6, 0.4]);
        let image = render_frame(&scene, &body, &[&shirt], &camera);
        let rendered: Vec<bool> = image.pixels.iter().map(|&p| p != BACKGROUND).collect();
        let expected = projected_union(&[(&body, &faces), (&shirt, &band)], &camera);
        let differ = rendered.iter().zip(&expected).filter(|(a, b)| a != b).count();
        let covered = expected.iter().filter(|&&c| c).count();
        assert!(covered > 10_000, "the body covers {covered} pixels");
        assert!(differ * 200 < covered, "{differ} pixels differ of {covered}");
        // The shirt is in front of the body where both are: red dominates the chest.
        let chest = camera.width * camera.height / 3 + camera.width / 2;
        assert!(image.pixels[chest][0] > 2.0 * image.pixels[chest][1], "{:?}", image.pixels[chest]);
    }
}
