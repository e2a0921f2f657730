//! Inference: render an avatar at a pose through a camera into host images (colour over white,
//! normal map, mask, depth) and its posed mesh, and write whole test sets in the dataset layout
//! (each garment layer's mesh too, as a synthetic subject's ground truth has them) so
//! `mannequin_data::evaluation` can score them.

use std::path::Path;

use mannequin_data::{Dataset, DatasetWriter, DepthMap, Frame, Image, Mask, NormalMap, Split};
use mannequin_mesh::TriMesh;

use crate::avatar::Avatar;
use crate::error::AvatarError;
use crate::params::{host, host_rows};
use crate::views::frame_camera;

/// A pixel belongs to the avatar where its alpha reaches this.
const FOREGROUND_ALPHA: f32 = 0.5;

pub struct Prediction {
    pub image: Image,
    pub mask: Mask,
    pub normals: NormalMap,
    pub depth: DepthMap,
    /// The posed personalised mesh, world coordinates.
    pub mesh: TriMesh,
}

/// Renders `avatar` at `pose`/`transl` through `camera`.
pub fn predict(
    avatar: &Avatar,
    camera: &mannequin_splat::Camera,
    pose: &[f32],
    transl: [f32; 3],
) -> Result<Prediction, AvatarError> {
    let posed = avatar.pose(pose, transl)?;
    let r = avatar.render(&posed, camera)?;
    let (w, h) = (camera.width, camera.height);
    let n = w * h;
    let rgb = host(r.rgb());
    let nrm = host(r.normals());
    let alpha = host(r.alpha());
    let depth = host(r.depth());
    let fg: Vec<bool> = alpha.iter().map(|&a| a >= FOREGROUND_ALPHA).collect();
    let image =
        Image { width: w, height: h, pixels: (0..n).map(|p| [rgb[p], rgb[n + p], rgb[2 * n + p]]).collect() };
    let normals = (0..n)
        .map(|p| {
            let v = [nrm[p], nrm[n + p], nrm[2 * n + p]];
            let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if fg[p] && len > 0.0 { v.map(|c| c / len) } else { [0.0; 3] }
        })
        .collect();
    // The renderer's depth is Σ wᵢ zᵢ; over alpha it is the expected depth of the surface.
    let depth = (0..n).map(|p| if fg[p] { depth[p] / alpha[p] } else { 0.0 }).collect();
    let positions = host_rows(posed.vertices);
    Ok(Prediction {
        image,
        mask: Mask { width: w, height: h, values: fg },
        normals: NormalMap { width: w, height: h, normals },
        depth: DepthMap { width: w, height: h, depth },
        mesh: TriMesh::new(positions, avatar.canonical.faces.clone()),
    })
}

/// Renders every frame of `split` of `dataset` at the split's poses into `out` (images, masks,
/// normals, depth, meshes, in the dataset layout), calling `on_frame` after each.
pub fn predict_split(
    avatar: &Avatar,
    dataset: &Dataset,
    split: &Split,
    out: &Path,
    on_frame: &dyn Fn(),
) -> Result<(), AvatarError> {
    let writer = DatasetWriter::new(out);
    let garments: Vec<_> = avatar
        .canonical
        .garment_names()
        .iter()
        .filter_map(|name| Some((name, avatar.canonical.layer_part(name)?)))
        .collect();
    for (i, &frame) in split.frames.iter().enumerate() {
        let camera = frame_camera(dataset, frame);
        let p = predict(avatar, &camera, &split.poses.pose72(i), split.poses.transl[i])?;
        writer.write_frame(&Frame {
            index: frame,
            image: p.image,
            mask: p.mask,
            normals: Some(p.normals),
            depth: Some(p.depth),
        })?;
        writer.write_mesh(frame, &p.mesh)?;
        for (name, part) in &garments {
            writer.write_garment_mesh(frame, name, &part.mesh(&p.mesh))?;
        }
        on_frame();
    }
    Ok(())
}
