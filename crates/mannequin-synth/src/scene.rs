//! The clothed, textured subject as one skinned mesh (body with clothing offsets, plus a skirt
//! for skirt outfits), posed per frame and rendered with the ground-truth rasterizer.

use glam::{DVec3, Vec3};
use mannequin_body::kinematics::skinning_transforms;
use mannequin_body::{BodyModel, ShapedBody, pose_frames, shape_body};
use mannequin_mesh::normals::vertex_normals;
use mannequin_mesh::{TriMesh, UvLayout};
use rayon::prelude::*;

use crate::clothing::{self, Folds, GarmentSpec, garment_specs, membership, smoothstep};
use crate::skirt::{Skirt, build_skirt, lower_body, skirt_span};
use crate::subject::{Outfit, Subject};
use crate::texture::{BakeInput, SurfacePoint, bake};
use mannequin_body::smpl_joint as joint;
use mannequin_data::Camera;
use mannequin_data::error::DataError;
use mannequin_data::image::{Image, Mask};
use mannequin_data::maps::{DepthMap, NormalMap};
use mannequin_data::mesh_raster::{RasterMesh, Shading, rasterize};
use mannequin_data::rng::SplitMix64;
use mannequin_mesh::ring_tube::RingLayout;

/// Texture sizes: the body's UV atlas and the skirt's strip beside it.
const BODY_TEXTURE: usize = 1024;
const SKIRT_TEXTURE: usize = 1024;

/// Where a camera looks from, relative to the subject's bounding box centre: azimuth about +Y
/// (0 is in front, on +Z), elevation, distance as a multiple of 3.3 m, and roll.
#[derive(Debug, Clone, Copy)]
pub struct ViewSetup {
    pub azimuth: f64,
    pub elevation: f64,
    pub distance: f64,
    pub roll: f64,
}

pub const TRAIN_VIEW: ViewSetup = ViewSetup { azimuth: 0.0, elevation: 0.03, distance: 1.0, roll: 0.0 };
pub const NOVEL_VIEWS: usize = 3;
pub const NOVEL_VIEW_SETUPS: [(&str, ViewSetup); NOVEL_VIEWS] = [
    ("high", ViewSetup { azimuth: 0.4, elevation: 0.6, distance: 1.0, roll: 0.0 }),
    ("low", ViewSetup { azimuth: -0.6, elevation: -0.15, distance: 0.9, roll: 0.0 }),
    ("rolled-close", ViewSetup { azimuth: 2.4, elevation: 0.2, distance: 0.75, roll: 0.25 }),
];

pub struct Scene {
    /// Rest-pose clothed body (with the body model's joints) that LBS poses.
    clothed: ShapedBody,
    skirt_weights: Vec<[(usize, f32); 3]>,
    /// Rest positions of all vertices: body first, then the skirt.
    pub positions: Vec<[f32; 3]>,
    pub faces: Vec<[u32; 3]>,
    pub uv: UvLayout,
    pub texture: Image,
    background: ([f32; 3], [f32; 3]),
}

/// Posed vertices of a sequence, feet on the floor (y = 0), and the translations that put them
/// there (the `transl` of the pose files).
pub struct PosedSequence {
    pub vertices: Vec<Vec<[f32; 3]>>,
    pub transl: Vec<[f32; 3]>,
}

/// One rendered frame at the output resolution.
pub struct Rendered {
    pub color: Image,
    pub mask: Mask,
    pub normals: NormalMap,
    pub depth: DepthMap,
}

impl PosedSequence {
    pub fn len(&self) -> usize {
        self.vertices.len()
    }

    pub fn is_empty(&self) -> bool {
        self.vertices.is_empty()
    }

    /// The ground-truth mesh of frame `i`, world coordinates.
    pub fn mesh(&self, scene: &Scene, i: usize) -> TriMesh {
        TriMesh::new(self.vertices[i].clone(), scene.faces.clone())
    }
}

/// Concatenates two textures side by side.
fn side_by_side(a: &Image, b: &Image) -> Image {
    let (w, h) = (a.width + b.width, a.height.max(b.height));
    let pixels = (0..w * h)
        .map(|p| {
            let (x, y) = (p % w, p / w);
            if x < a.width { a.at(x, y.min(a.height - 1)) } else { b.at(x - a.width, y.min(b.height - 1)) }
        })
        .collect();
    Image { width: w, height: h, pixels }
}

/// UVs squeezed horizontally into `[offset, offset + scale)` of an atlas.
fn remap_uv(uv: &UvLayout, offset: f32, scale: f32, base: u32) -> (Vec<[f32; 2]>, Vec<[u32; 3]>) {
    (
        uv.coords.iter().map(|c| [offset + scale * c[0], c[1]]).collect(),
        uv.faces.iter().map(|f| f.map(|i| i + base)).collect(),
    )
}

impl Scene {
    pub fn new(model: &BodyModel, subject: &Subject) -> Result<Self, DataError> {
        let body_uv = model.uv.as_ref().ok_or_else(|| {
            DataError::Invalid(format!("body model '{}' has no UV layout to paint a texture on", model.name))
        })?;
        let shaped = shape_body(model, &subject.betas)?;
        let rest: Vec<[f32; 3]> = shaped.vertices.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        let normals = vertex_normals(&rest, &model.faces);
        let joints = model.num_joints();
        let weights = model.weights();
        let (top, bottom) = garment_specs(subject.outfit);
        let g_top = membership(weights, joints, &top.coverage);
        let g_bottom = membership(weights, joints, &bottom.coverage);
        let mut rng = SplitMix64::new(subject.seed ^ 0xF01D5);
        let (folds_top, folds_bottom) = (Folds::new(&mut rng, 6), Folds::new(&mut rng, 6));
        let garments: [(&GarmentSpec, &[f32], &Folds); 2] =
            [(&top, &g_top, &folds_top), (&bottom, &g_bottom, &folds_bottom)];
        let clothed_rest = clothing::clothe(&rest, &normals, &garments);

        // Hair on the top and back of the head, shoes on the feet.
        let head = shaped.joints[joint::HEAD];
        let points: Vec<SurfacePoint> = (0..rest.len())
            .map(|v| {
                let w = &weights[v * joints..(v + 1) * joints];
                let p = Vec3::from(rest[v]);
                let on_head = w.get(joint::HEAD).copied().unwrap_or(0.0);
                let scalp = smoothstep(0.02, 0.06, p.y - head.y)
                    .max(smoothstep(0.0, 0.04, head.z - p.z) * smoothstep(-0.06, 0.0, p.y - head.y));
                let feet: f32 = [joint::L_ANKLE, joint::R_ANKLE, joint::L_FOOT, joint::R_FOOT]
                    .iter()
                    .map(|&j| w.get(j).copied().unwrap_or(0.0))
                    .sum();
                SurfacePoint { position: p, layers: [g_top[v], g_bottom[v], on_head * scalp, feet] }
            })
            .collect();

        let skirt = skirt_span(subject.outfit, &shaped.joints).map(|(waist, hem)| {
            let inside = lower_body(&clothed_rest, weights, joints);
            build_skirt(
                &inside,
                shaped.joints[joint::PELVIS],
                (waist, hem),
                (0.012, 0.35),
                &RingLayout::uniform(64, 28),
            )
        });

        let body_texture = bake(
            &BakeInput { uv: body_uv, faces: &model.faces, points: &points },
            subject,
            head - Vec3::new(0.0, 0.25, 0.0),
            BODY_TEXTURE,
            BODY_TEXTURE,
        );
        let mut positions = clothed_rest.clone();
        let mut faces = model.faces.clone();
        let (texture, uv) = match &skirt {
            None => (body_texture, body_uv.clone()),
            Some(s) => Self::add_skirt(s, subject, body_uv, body_texture, head, &mut positions, &mut faces),
        };
        let mut bg = SplitMix64::new(subject.seed ^ 0xBAC6);
        let grey = bg.range(0.35, 0.8) as f32;
        let tint = [0; 3].map(|_| (grey + bg.range(-0.08, 0.08) as f32).clamp(0.0, 1.0));
        let flat: Vec<f32> = clothed_rest.iter().flatten().copied().collect();
        Ok(Self {
            clothed: ShapedBody { vertices: flat, joints: shaped.joints },
            skirt_weights: skirt.map(|s| s.weights).unwrap_or_default(),
            positions,
            faces,
            uv,
            texture,
            background: (tint, tint.map(|c| c * 0.75)),
        })
    }

    /// Appends the skirt's vertices and faces and returns the atlas (body | skirt) and its UVs.
    fn add_skirt(
        s: &Skirt,
        subject: &Subject,
        body_uv: &UvLayout,
        body_texture: Image,
        head: Vec3,
        positions: &mut Vec<[f32; 3]>,
        faces: &mut Vec<[u32; 3]>,
    ) -> (Image, UvLayout) {
        let layers =
            if subject.outfit == Outfit::Dress { [1.0, 0.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0, 0.0] };
        let points: Vec<SurfacePoint> =
            s.positions.iter().map(|p| SurfacePoint { position: Vec3::from(*p), layers }).collect();
        let chest = head - Vec3::new(0.0, 0.25, 0.0);
        let skirt_texture = bake(
            &BakeInput { uv: &s.uv, faces: &s.faces, points: &points },
            subject,
            chest,
            SKIRT_TEXTURE,
            BODY_TEXTURE,
        );
        let atlas = side_by_side(&body_texture, &skirt_texture);
        let body_share = BODY_TEXTURE as f32 / (BODY_TEXTURE + SKIRT_TEXTURE) as f32;
        let (mut coords, mut uv_faces) = remap_uv(body_uv, 0.0, body_share, 0);
        let (c2, f2) = remap_uv(&s.uv, body_share, 1.0 - body_share, coords.len() as u32);
        coords.extend(c2);
        uv_faces.extend(f2);
        let base = positions.len() as u32;
        positions.extend_from_slice(&s.positions);
        faces.extend(s.faces.iter().map(|f| f.map(|i| i + base)));
        (atlas, UvLayout { coords, faces: uv_faces })
    }

    /// Poses every frame of `poses` (F × 72) and lifts each so the lowest vertex touches y = 0.
    pub fn pose(&self, model: &BodyModel, poses: &[f32]) -> Result<PosedSequence, DataError> {
        let frames = poses.len() / 72;
        let posed = pose_frames(model, &self.clothed, poses, &vec![0.0; 3 * frames])?;
        let joints = model.num_joints();
        let (vertices, transl): (Vec<Vec<[f32; 3]>>, Vec<[f32; 3]>) = (0..frames)
            .into_par_iter()
            .map(|f| {
                let mut v: Vec<[f32; 3]> =
                    posed.frame_vertices(f).chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
                let skinning = skinning_transforms(
                    &posed.transforms[f * joints..(f + 1) * joints],
                    &self.clothed.joints,
                );
                let body = v.len();
                for (k, w) in self.skirt_weights.iter().enumerate() {
                    let p = glam::Vec3A::from(self.positions[body + k]);
                    let q: glam::Vec3A = w.iter().map(|&(j, wj)| skinning[j].transform_point3a(p) * wj).sum();
                    v.push(q.to_array());
                }
                let lift = -v.iter().map(|p| p[1]).fold(f32::INFINITY, f32::min);
                v.iter_mut().for_each(|p| p[1] += lift);
                (v, [0.0, lift, 0.0])
            })
            .unzip();
        Ok(PosedSequence { vertices, transl })
    }

    /// A camera of `setup` that frames every frame of `seqs` with a margin.
    pub fn framing_camera(&self, seqs: &[&PosedSequence], setup: ViewSetup, size: usize) -> Camera {
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for p in seqs.iter().flat_map(|s| s.vertices.iter().flatten()) {
            let p = DVec3::from(p.map(f64::from));
            lo = lo.min(p);
            hi = hi.max(p);
        }
        let centre = (lo + hi) * 0.5;
        let extent = hi - lo;
        let d = 3.3 * setup.distance;
        let dir = DVec3::new(
            setup.azimuth.sin() * setup.elevation.cos(),
            setup.elevation.sin(),
            setup.azimuth.cos() * setup.elevation.cos(),
        );
        let eye = centre + dir * d;
        let forward = -dir;
        let right = forward.cross(DVec3::Y).normalize();
        let up = DVec3::Y * setup.roll.cos() + right * setup.roll.sin();
        // Fit the box's largest extent, seen from the nearest depth, with 12 % margin.
        let half = 0.56 * extent.x.max(extent.y).max(extent.z);
        let fov = 2.0 * (half / (d - 0.5 * extent.x.max(extent.z))).atan();
        Camera::look_at(eye.to_array(), centre.to_array(), (up.normalize()).to_array(), fov, size, size)
    }

    /// Renders a posed mesh: textured colour on the backdrop, mask, normals and depth, at
    /// `supersample` times the camera's resolution and box-filtered down to it.
    pub fn render(&self, mesh: &TriMesh, camera: &Camera, supersample: usize) -> Rendered {
        let s = supersample as f64;
        let mut big = camera.clone();
        big.width *= supersample;
        big.height *= supersample;
        for row in &mut big.intrinsic[..2] {
            row.iter_mut().for_each(|v| *v *= s);
        }
        let normals = vertex_normals(&mesh.positions, &mesh.faces);
        let shading = Shading::Texture { uv: &self.uv, texture: &self.texture };
        let mut r = rasterize(
            &RasterMesh { positions: &mesh.positions, faces: &mesh.faces, normals: &normals, shading },
            &big,
            [0.0; 3],
        );
        let (top, bottom) = self.background;
        for (i, p) in r.color.pixels.iter_mut().enumerate() {
            if !r.mask.values[i] {
                let t = (i / big.width) as f32 / big.height as f32;
                *p = [0, 1, 2].map(|c| top[c] + (bottom[c] - top[c]) * t);
            }
        }
        let mask = r.mask.downscale(supersample);
        let mut normals = r.normals.downscale(supersample);
        let mut depth = r.depth.downscale(supersample);
        // Keep the geometry maps exactly on the mask.
        for (i, &m) in mask.values.iter().enumerate() {
            if !m {
                normals.normals[i] = [0.0; 3];
                depth.depth[i] = 0.0;
            }
        }
        Rendered { color: r.color.downscale(supersample), mask, normals, depth }
    }
}
