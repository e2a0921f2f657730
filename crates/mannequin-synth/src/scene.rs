//! The clothed, textured subject: the body (skin, hair, shoes) and the library's garments as
//! separate meshes, posed per frame (the garments by the cloth simulator) and rendered with the
//! ground-truth rasterizer, with a label map and a hand mask beside each image.

use glam::{DVec3, Vec3};
use mannequin_body::{BodyModel, Motion, Settling, ShapedBody, pose_frames, shape_body};
use mannequin_cloth::Settings;
use mannequin_garment::{Dressed, GarmentError, WearProgress, Wearer, wear};
use mannequin_mesh::normals::vertex_normals;
use mannequin_mesh::{TriMesh, UvLayout, points};

use crate::error::SynthError;
use crate::step::Step;
use crate::subject::Subject;
use crate::texture::{BakeInput, SurfacePoint, bake, smoothstep};
use crate::wardrobe::{Piece, Worn, dress_subject, triangle_atlas};
use mannequin_body::smpl_joint as joint;
use mannequin_data::Camera;
use mannequin_data::image::{Image, Mask};
use mannequin_data::labels::LabelMap;
use mannequin_data::maps::{DepthMap, NormalMap};
use mannequin_garment::segmentation::BODY_LABELS;
use mannequin_io::rng::SplitMix64;
use mannequin_raster::{NO_FACE, RasterMesh, Shading, rasterize};

/// Texture size of the body's UV atlas and of each garment's triangle atlas beside it (square,
/// all one size, so the atlas's rows line up).
const TEXTURE: usize = 2048;
/// Share of each garment triangle's atlas cell left round it for the baker's dilation.
const ATLAS_MARGIN: f32 = 0.12;

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
    /// The subject's body at rest, unclothed.
    shaped: ShapedBody,
    body_faces: Vec<[u32; 3]>,
    betas: Vec<f32>,
    /// The garments, inner layer first.
    pub worn: Vec<Worn>,
    /// Rest positions of all vertices: the body's, then each garment's.
    pub positions: Vec<[f32; 3]>,
    pub faces: Vec<[u32; 3]>,
    pub uv: UvLayout,
    pub texture: Image,
    /// Per face, its label (an index into [`Scene::legend`]) and whether it is a hand's.
    face_labels: Vec<u8>,
    hand_faces: Vec<bool>,
    background: ([f32; 3], [f32; 3]),
}

/// Posed vertices of a sequence (the body's, then each garment's), feet on the floor (y = 0),
/// and the translations that put them there (the `transl` of the pose files).
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
    pub labels: LabelMap,
    pub hands: Mask,
}

impl PosedSequence {
    pub fn len(&self) -> usize {
        self.vertices.len()
    }

    pub fn is_empty(&self) -> bool {
        self.vertices.is_empty()
    }

    /// The frames at `picks`.
    pub fn select(&self, picks: &[usize]) -> Self {
        Self {
            vertices: picks.iter().map(|&i| self.vertices[i].clone()).collect(),
            transl: picks.iter().map(|&i| self.transl[i]).collect(),
        }
    }

    /// The ground-truth mesh of frame `i`, world coordinates: body and garments in one.
    pub fn mesh(&self, scene: &Scene, i: usize) -> TriMesh {
        TriMesh::new(self.vertices[i].clone(), scene.faces.clone())
    }

    /// Each garment's ground-truth mesh at frame `i`, with its name.
    pub fn garment_meshes(&self, scene: &Scene, i: usize) -> Vec<(&'static str, TriMesh)> {
        let mut start = scene.shaped.vertices.len() / 3;
        scene
            .worn
            .iter()
            .map(|w| {
                let n = w.garment.vertex_count();
                let positions = self.vertices[i][start..start + n].to_vec();
                start += n;
                (w.name, TriMesh::new(positions, w.garment.mesh.faces.clone()))
            })
            .collect()
    }
}

/// Textures side by side, each squeezed into its share of the atlas's width.
fn side_by_side(textures: &[&Image]) -> Image {
    let (w, h) =
        (textures.iter().map(|t| t.width).sum(), textures.iter().map(|t| t.height).max().unwrap_or(1));
    let mut pixels = Vec::with_capacity(w * h);
    for y in 0..h {
        for t in textures {
            pixels.extend((0..t.width).map(|x| t.at(x, y.min(t.height - 1))));
        }
    }
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
    pub fn new(model: &BodyModel, subject: &Subject) -> Result<Self, SynthError> {
        let body_uv = model.uv.as_ref().ok_or_else(|| {
            SynthError::Invalid(format!("body model '{}' has no UV layout to paint a texture on", model.name))
        })?;
        let shaped = shape_body(model, &subject.betas)?;
        let rest: Vec<[f32; 3]> = points(&shaped.vertices);
        let joints = model.num_joints();
        let weights = model.weights();

        // Hair on the top and back of the head, shoes on the feet; hands for the hand masks.
        let head = shaped.joints[joint::HEAD];
        let strongest = |v: usize| {
            let w = &weights[v * joints..(v + 1) * joints];
            (0..joints).max_by(|&a, &b| w[a].total_cmp(&w[b])).unwrap_or(0)
        };
        let body_points: Vec<SurfacePoint> = (0..rest.len())
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
                SurfacePoint { position: p, layers: [0.0, 0.0, on_head * scalp, feet] }
            })
            .collect();
        let chest = head - Vec3::new(0.0, 0.25, 0.0);
        let body_texture = bake(
            &BakeInput { uv: body_uv, faces: &model.faces, points: &body_points },
            subject,
            chest,
            TEXTURE,
            TEXTURE,
        );
        let mut face_labels: Vec<u8> = model
            .faces
            .iter()
            .map(|tri| {
                let mean =
                    |l: usize| tri.iter().map(|&v| body_points[v as usize].layers[l]).sum::<f32>() / 3.0;
                if mean(3) > 0.5 {
                    3
                } else if mean(2) > 0.5 {
                    2
                } else {
                    1
                }
            })
            .collect();
        let hands = [joint::L_WRIST, joint::R_WRIST, joint::L_HAND, joint::R_HAND];
        let mut hand_faces: Vec<bool> = model
            .faces
            .iter()
            .map(|tri| tri.iter().filter(|&&v| hands.contains(&strongest(v as usize))).count() >= 2)
            .collect();

        let worn = dress_subject(model, &subject.betas, subject.outfit)?;
        let mut positions = rest;
        let mut faces = model.faces.clone();
        let mut textures = vec![body_texture];
        let mut layouts = vec![body_uv.clone()];
        for (k, w) in worn.iter().enumerate() {
            let layers = match w.piece {
                Piece::Top => [1.0, 0.0, 0.0, 0.0],
                Piece::Bottom => [0.0, 1.0, 0.0, 0.0],
            };
            let mesh = &w.garment.mesh;
            let points: Vec<SurfacePoint> =
                mesh.positions.iter().map(|p| SurfacePoint { position: Vec3::from(*p), layers }).collect();
            let atlas = triangle_atlas(mesh, ATLAS_MARGIN);
            let input = BakeInput { uv: &atlas, faces: &mesh.faces, points: &points };
            textures.push(bake(&input, subject, chest, TEXTURE, TEXTURE));
            layouts.push(atlas);
            let base = positions.len() as u32;
            positions.extend_from_slice(&mesh.positions);
            faces.extend(mesh.faces.iter().map(|t| t.map(|i| i + base)));
            face_labels.extend(std::iter::repeat_n((BODY_LABELS.len() + k) as u8, mesh.faces.len()));
            hand_faces.extend(std::iter::repeat_n(false, mesh.faces.len()));
        }
        let total: usize = textures.iter().map(|t| t.width).sum();
        let (mut coords, mut uv_faces, mut offset) = (Vec::new(), Vec::new(), 0.0);
        for (t, layout) in textures.iter().zip(&layouts) {
            let share = t.width as f32 / total as f32;
            let (c, f) = remap_uv(layout, offset, share, coords.len() as u32);
            coords.extend(c);
            uv_faces.extend(f);
            offset += share;
        }
        let texture = side_by_side(&textures.iter().collect::<Vec<_>>());
        let mut bg = SplitMix64::new(subject.seed ^ 0xBAC6);
        let grey = bg.range(0.35, 0.8) as f32;
        let tint = [0; 3].map(|_| (grey + bg.range(-0.08, 0.08) as f32).clamp(0.0, 1.0));
        Ok(Self {
            shaped,
            body_faces: model.faces.clone(),
            betas: subject.betas.clone(),
            worn,
            positions,
            faces,
            uv: UvLayout { coords, faces: uv_faces },
            texture,
            face_labels,
            hand_faces,
            background: (tint, tint.map(|c| c * 0.75)),
        })
    }

    /// The label names, by index: background, skin, hair, shoes, then each garment.
    pub fn legend(&self) -> Vec<&'static str> {
        BODY_LABELS.iter().copied().chain(self.worn.iter().map(|w| w.name)).collect()
    }

    /// Poses every frame of `poses` (F × 72, played at `fps`), each lifted so the body's lowest
    /// vertex touches y = 0, and plays the garments through it with the cloth simulator, from
    /// rest, after settling into the first frame. The simulator sees `subframes` poses per frame,
    /// blended between the frames: its body moves linearly between the poses it is given, which
    /// for a swinging limb far apart cuts the corner through the cloth. `self_collision` turns
    /// the cloth–cloth contacts on; each garment's simulated frames are reported to `on_step`.
    pub fn pose(
        &self,
        model: &BodyModel,
        (poses, fps, subframes): (&[f32], f32, usize),
        self_collision: bool,
        on_step: &(dyn Fn(Step) + Sync),
    ) -> Result<PosedSequence, SynthError> {
        let frames = poses.len() / 72;
        let dense: Vec<f32> = (0..frames)
            .flat_map(|f| {
                let (a, b) = (&poses[72 * f..72 * f + 72], &poses[72 * (f + 1).min(frames - 1)..][..72]);
                let steps = if f + 1 < frames { subframes } else { 1 };
                (0..steps).flat_map(move |s| {
                    let t = s as f32 / subframes as f32;
                    (0..72).map(move |i| a[i] + (b[i] - a[i]) * t)
                })
            })
            .collect();
        let played = self.play(model, &dense, fps * subframes as f32, self_collision, on_step)?;
        Ok(played.select(&(0..frames).map(|f| f * subframes).collect::<Vec<_>>()))
    }

    fn play(
        &self,
        model: &BodyModel,
        poses: &[f32],
        fps: f32,
        self_collision: bool,
        on_step: &(dyn Fn(Step) + Sync),
    ) -> Result<PosedSequence, SynthError> {
        let frames = poses.len() / 72;
        let still = pose_frames(model, &self.shaped, poses, &vec![0.0; 3 * frames])?;
        let lift: Vec<f32> = (0..frames)
            .map(|f| -still.frame_vertices(f).chunks_exact(3).map(|p| p[1]).fold(f32::INFINITY, f32::min))
            .collect();
        // The cloth plays the lifts relative to the first frame's (settling starts from rest at
        // the origin, and a body jumping a metre up while it settles would leave it behind);
        // the first frame's lift moves everything afterwards.
        let motion = Motion {
            source: "synthetic".into(),
            poses: poses.to_vec(),
            joints: 24,
            trans: lift.iter().flat_map(|&y| [0.0, y - lift[0], 0.0]).collect(),
            betas: self.betas.clone(),
            fps,
            gender: None,
        };
        let schedule = Settling::new(model, &motion, mannequin_cloth::SETTLE_SECONDS)?;
        // Each garment's first frame is its rest shape.
        on_step(Step::Planned(self.worn.len() * (schedule.len() - 1)));
        let body_frames = schedule.body_frames(model, &self.shaped)?;
        let fail = |e: GarmentError| SynthError::Invalid(format!("dressing the subject: {e}"));
        let dressed: Vec<Dressed> = self
            .worn
            .iter()
            .map(|w| Dressed::new(&w.garment, model, &self.betas))
            .collect::<Result<_, _>>()
            .map_err(fail)?;
        let named: Vec<(&str, &Dressed)> = self.worn.iter().zip(&dressed).map(|(w, d)| (w.name, d)).collect();
        let wearer = Wearer { faces: &self.body_faces, frames: &body_frames, schedule: &schedule, fps };
        let settings =
            Settings { substeps: Settings::substeps_at(fps), self_collision, ..Settings::default() };
        let layers = wear::<GarmentError>(&named, &wearer, settings, WearProgress::default(), &mut |step| {
            (0..step.stepped).for_each(|_| on_step(Step::Simulated));
            Ok(())
        })
        .map_err(fail)?;
        let vertices = (schedule.settle..schedule.len())
            .map(|k| {
                let mut all = body_frames[k].clone();
                for layer in &layers {
                    all.extend_from_slice(&layer.frames[k]);
                }
                all.iter_mut().for_each(|p| p[1] += lift[0]);
                all
            })
            .collect();
        Ok(PosedSequence { vertices, transl: lift.iter().map(|&y| [0.0, y, 0.0]).collect() })
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
        let (labels, hands) = self.labels(&r.face_id, big.width, big.height, supersample);
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
        Rendered { color: r.color.downscale(supersample), mask, normals, depth, labels, hands }
    }

    /// The label map and hand mask at 1/`factor` of the rendered `face_id` image: each pixel
    /// takes the label most of its samples show (the lower index on a tie), and is a hand's
    /// when most of its samples are.
    fn labels(&self, face_id: &[u32], width: usize, height: usize, factor: usize) -> (LabelMap, Mask) {
        let (w, h) = (width / factor, height / factor);
        let mut labels = Vec::with_capacity(w * h);
        let mut hands = Vec::with_capacity(w * h);
        for y in 0..h {
            for x in 0..w {
                let mut votes = [0usize; 256];
                let mut hand = 0;
                for sy in 0..factor {
                    for sx in 0..factor {
                        let f = face_id[(y * factor + sy) * width + x * factor + sx];
                        if f == NO_FACE {
                            votes[0] += 1;
                        } else {
                            votes[self.face_labels[f as usize] as usize] += 1;
                            hand += usize::from(self.hand_faces[f as usize]);
                        }
                    }
                }
                let best = (0..256).max_by(|&a, &b| votes[a].cmp(&votes[b]).then(b.cmp(&a))).unwrap_or(0);
                labels.push(best as u8);
                hands.push(2 * hand > factor * factor);
            }
        }
        (LabelMap { width: w, height: h, labels }, Mask { width: w, height: h, values: hands })
    }
}
