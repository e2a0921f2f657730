//! The avatar: canonical mesh + hash-grid offsets (Tavatar Eq. 4), posed by LBS (Eq. 1),
//! carrying Gaussians bound to the posed mesh, rendered as colour and camera-space normals in
//! one splatting pass.

use std::path::Path;

use burn::tensor::{Device, Tensor};
use mannequin_body::{Rig, skin_tensors};
use mannequin_io::limits::FLOAT32;
use mannequin_io::{NpyArray, Npz, NpzWriter, write_atomic};
use mannequin_splat::{Camera, ColorTensor, RenderOptions, RotationTensor, sh, splat_render};

use crate::antialias;
use crate::camera_rotation::rotation_transposed;
use crate::canonical::Canonical;
use crate::config::{AvatarConfig, Method};
use crate::error::AvatarError;
use crate::field::Field;
use crate::fused_binding::{self, BindConfig};
use crate::fused_skinning::SkinRig;
use crate::host_ops;
use crate::ihuman;
use crate::mesh_gaussians::{Faces, GaussianGeometry, MeshIndex, face_gaussians, vertex_gaussians};
use crate::params::{Param, tensor_from};
use crate::render_features::{FeaturesConfig, render_features};
use crate::sh_colour::{ColourConfig, colour_convention, sh_colour, sh_colour_tensors};
use mannequin_io::rng::SplitMix64;

/// Background of the colour channels: white, as the peers train and evaluate.
pub const WHITE: [f64; 3] = [1.0; 3];

/// Learning rate of Tavatar's SH colours. Tavatar trains everything at 1e-3; with one view per
/// iteration a Gaussian is updated in about half the iterations, and Adam moves a coefficient at
/// most ~lr per update, so 1e-3 cannot reach saturated colours (DC ≈ ±1.8) within 2,000
/// iterations. 3DGS uses 2.5e-3 for its colour DC with 30,000 iterations; 1e-2 here.
pub const COLOUR_LR: f64 = 1e-2;

/// File names inside a model directory.
pub const CONFIG_FILE: &str = "avatar.json";
pub const PARAMS_FILE: &str = "avatar.npz";
/// The member of `avatar.npz` that holds the configuration.
const CONFIG_MEMBER: &str = "config";

/// The learned parts that are not fields, by index into `Avatar::params`.
#[derive(Clone, Debug, Default)]
struct Slots {
    /// Tavatar: SH colour, the DC term [G, 3] and the higher bands [G, 3((d+1)² − 1)],
    /// basis-major.
    sh_dc: Option<usize>,
    sh_rest: Option<usize>,
    /// Tavatar w/o FG: log in-plane scales of vertex Gaussians [V, 2].
    vertex_log_scales: Option<usize>,
    /// iHuman: log in-plane scales (s2, s3) [F, 2], in-plane rotation (x, y) [F, 2], joints [J, 3].
    face_log_scales: Option<usize>,
    face_rotation: Option<usize>,
    joints: Option<usize>,
}

pub struct Avatar {
    pub config: AvatarConfig,
    pub canonical: Canonical,
    pub params: Vec<Param>,
    device: Device,
    index: MeshIndex,
    vertices: Tensor<2>,
    weights: Tensor<2>,
    posedirs: Option<Tensor<2>>,
    /// The rig in the fused skinning's layout, on devices that run it.
    skin_rig: Option<SkinRig>,
    /// The canonical mesh's offset gate [V, 1], where any vertex is gated.
    offset_gate: Option<Tensor<2>>,
    rest_joints: Tensor<2>,
    offsets: Field,
    /// iHuman's colour encoder over canonical face centroids.
    colour_field: Option<Field>,
    slots: Slots,
    /// Opacity 1 for every Gaussian, made once: a fill each render is a GPU launch.
    full_opacity: Tensor<1>,
}

/// A posed avatar: its mesh and Gaussians, still differentiable.
#[derive(Clone, Debug)]
pub struct Posed {
    /// Personalised canonical vertices V_s [V, 3] (Eq. 4).
    pub personalised: Tensor<2>,
    /// Posed vertices V_p [V, 3].
    pub vertices: Tensor<2>,
    pub gaussians: GaussianGeometry,
}

/// Rendered maps as the renderer stacks them, [8, H, W]: colour over white, camera-space
/// normals over zero, alpha and expected depth. The fused image loss reads them in place; the
/// accessors slice them (lazily on the CPU, copies on a GPU where a plane is not aligned).
#[derive(Clone, Debug)]
pub struct Rendered {
    pub planes: Tensor<3>,
}

/// Where alpha is in [`Rendered::planes`]: after the three colour and three normal planes.
pub const ALPHA_PLANE: usize = 6;

impl Rendered {
    fn plane(&self, k: usize) -> Tensor<2> {
        let [_, h, w] = self.planes.dims();
        self.planes.clone().narrow(0, k, 1).reshape([h, w])
    }

    /// Colour and normals [6, H, W] (the losses read both at once).
    pub fn image(&self) -> Tensor<3> {
        self.planes.clone().narrow(0, 0, ALPHA_PLANE)
    }

    /// Colour over white [3, H, W].
    pub fn rgb(&self) -> Tensor<3> {
        self.planes.clone().narrow(0, 0, 3)
    }

    /// Camera-space normals over zero [3, H, W].
    pub fn normals(&self) -> Tensor<3> {
        self.planes.clone().narrow(0, 3, 3)
    }

    /// Accumulated opacity [H, W].
    pub fn alpha(&self) -> Tensor<2> {
        self.plane(ALPHA_PLANE)
    }

    /// Expected camera-space depth [H, W].
    pub fn depth(&self) -> Tensor<2> {
        self.plane(ALPHA_PLANE + 1)
    }
}

fn flat(v: &[[f32; 3]]) -> Vec<f32> {
    v.iter().flatten().copied().collect()
}

impl Avatar {
    /// A fresh avatar on `device` (an autodiff device for training) with seeded initialisation.
    pub fn new(config: AvatarConfig, canonical: Canonical, device: &Device) -> Result<Self, AvatarError> {
        config.validate().map_err(AvatarError::Invalid)?;
        let (v, f) = (canonical.num_vertices(), canonical.faces.len());
        let index = MeshIndex::new(v, &canonical.faces, device);
        let vertices = tensor_from(flat(&canonical.vertices), v, 3, device);
        // Learned in-plane scales start where the analytic ones are on the canonical mesh.
        let log_in_plane = |g: GaussianGeometry| g.scales.narrow(1, 0, 2).clamp_min(1e-5).log().detach();
        let mut rng = SplitMix64::new(config.seed);
        let mut params = Vec::new();
        let offsets =
            Field::new("offsets", &config, &canonical.vertices, 3, 1e-3, &mut rng, device, &mut params)?;
        let mut slots = Slots::default();
        let mut colour_field = None;
        match config.method {
            Method::Tavatar => {
                let g = usize::from(config.face_gaussians) * f + usize::from(config.vertex_gaussians) * v;
                params.push(Param::new("sh_dc", tensor_from(vec![0.0; g * 3], g, 3, device), COLOUR_LR));
                slots.sh_dc = Some(params.len() - 1);
                let k = 3 * (sh::basis_len(config.sh_degree) - 1);
                if k > 0 {
                    // 3DGS's rates: the view-dependent bands learn 20× slower than the DC term, so
                    // colour is explained view-independently first and novel views stay sane.
                    let lr = COLOUR_LR / 20.0;
                    params.push(Param::new("sh_rest", tensor_from(vec![0.0; g * k], g, k, device), lr));
                    slots.sh_rest = Some(params.len() - 1);
                }
                if !config.face_gaussians {
                    let faces = Faces::of(&vertices, &index);
                    let init = log_in_plane(vertex_gaussians(&vertices, &faces, &index));
                    params.push(Param::new("vertex_log_scales", init, 1e-3));
                    slots.vertex_log_scales = Some(params.len() - 1);
                }
            }
            Method::Ihuman => {
                let centroids = ihuman::face_centroids(&canonical);
                colour_field =
                    Some(Field::new("colour", &config, &centroids, 3, 5e-4, &mut rng, device, &mut params)?);
                let init = log_in_plane(face_gaussians(&Faces::of(&vertices, &index)));
                params.push(Param::new("face_log_scales", init, 5e-3));
                slots.face_log_scales = Some(params.len() - 1);
                let identity: Vec<f32> = (0..f).flat_map(|_| [1.0, 0.0]).collect();
                params.push(Param::new("face_rotation", tensor_from(identity, f, 2, device), 5e-3));
                slots.face_rotation = Some(params.len() - 1);
                let j = canonical.num_joints();
                params.push(Param::new("joints", tensor_from(flat(&canonical.joints), j, 3, device), 5e-4));
                slots.joints = Some(params.len() - 1);
            }
        }
        let j = canonical.num_joints();
        let posedirs = (!canonical.posedirs.is_empty()).then(|| {
            tensor_from(canonical.posedirs.clone(), canonical.posedirs.len() / (3 * v), 3 * v, device)
        });
        let offset_gate = canonical
            .offset_gate
            .iter()
            .any(|&g| g != 1.0)
            .then(|| tensor_from(canonical.offset_gate.clone(), v, 1, device));
        let skin_rig = host_ops::on_cube(device)
            .then(|| SkinRig::new(&canonical.weights, v, posedirs.as_ref(), &canonical.parents, device))
            .transpose()?;
        let gaussians = match config.method {
            Method::Tavatar => {
                usize::from(config.face_gaussians) * canonical.faces.len()
                    + usize::from(config.vertex_gaussians) * v
            }
            Method::Ihuman => canonical.faces.len(),
        };
        Ok(Self {
            full_opacity: Tensor::<1>::ones([gaussians], device),
            skin_rig,
            index,
            vertices,
            offset_gate,
            weights: tensor_from(canonical.weights.clone(), v, j, device),
            rest_joints: tensor_from(flat(&canonical.joints), j, 3, device),
            posedirs,
            offsets,
            colour_field,
            slots,
            params,
            device: device.clone(),
            config,
            canonical,
        })
    }

    pub fn device(&self) -> &Device {
        &self.device
    }

    pub fn mesh_index(&self) -> &MeshIndex {
        &self.index
    }

    pub fn num_gaussians(&self) -> usize {
        self.full_opacity.dims()[0]
    }

    fn param(&self, slot: Option<usize>) -> Option<Tensor<2>> {
        slot.map(|i| self.params[i].value.clone())
    }

    /// The offset field E_s(V_c) [V, 3] (Eq. 4), gated where a garment layer hides the body.
    pub fn offsets(&self) -> Result<Tensor<2>, AvatarError> {
        let offsets = self.offsets.forward(&self.params)?;
        Ok(match &self.offset_gate {
            Some(gate) => offsets * gate.clone(),
            None => offsets,
        })
    }

    /// V_s = V_c + E_s(V_c) (Eq. 4).
    pub fn personalised(&self, offsets: Tensor<2>) -> Tensor<2> {
        self.vertices.clone() + offsets
    }

    /// LBS of personalised vertices (Eq. 1): `pose` is the body's axis-angle vector (3J),
    /// `transl` the root translation.
    pub fn skin(
        &self,
        personalised: Tensor<2>,
        pose: &[f32],
        transl: [f32; 3],
    ) -> Result<Tensor<2>, AvatarError> {
        let j = self.canonical.num_joints();
        if pose.len() != 3 * j {
            return Err(AvatarError::Invalid(format!(
                "pose has {} values, the body has {j} joints ({})",
                pose.len(),
                3 * j
            )));
        }
        if let Some(i) = pose.iter().chain(&transl).position(|x| !x.is_finite()) {
            return Err(AvatarError::Invalid(format!("pose value {i} is not finite")));
        }
        let pose = tensor_from(pose.to_vec(), 1, 3 * j, &self.device);
        Ok(self.skin_tensor(personalised, pose, tensor_from(transl.to_vec(), 1, 3, &self.device)))
    }

    /// [`Avatar::skin`] with the pose [1, 3J] and translation [1, 3] as tensors, so that
    /// gradients reach them (pose refinement).
    pub fn skin_tensor(&self, personalised: Tensor<2>, pose: Tensor<2>, transl: Tensor<2>) -> Tensor<2> {
        let (v, j) = (self.canonical.num_vertices(), self.canonical.num_joints());
        let joints = self.param(self.slots.joints).unwrap_or_else(|| self.rest_joints.clone());
        if let Some(rig) = &self.skin_rig {
            return rig.skin(personalised, joints, pose, transl);
        }
        let rig = Rig {
            weights: &self.weights,
            posedirs: self.posedirs.as_ref(),
            parents: &self.canonical.parents,
        };
        let posed =
            skin_tensors(&rig, personalised.reshape([1, v, 3]), joints.reshape([1, j, 3]), pose, transl);
        posed.vertices.reshape([v, 3])
    }

    /// Poses the avatar and binds its Gaussians.
    pub fn pose(&self, pose: &[f32], transl: [f32; 3]) -> Result<Posed, AvatarError> {
        let personalised = self.personalised(self.offsets()?);
        let vertices = self.skin(personalised.clone(), pose, transl)?;
        let gaussians = self.bind(&vertices);
        Ok(Posed { personalised, vertices, gaussians })
    }

    /// Posed vertices on the host, for cameras, exports and metrics.
    pub fn pose_mesh(&self, pose: &[f32], transl: [f32; 3]) -> Result<Vec<[f32; 3]>, AvatarError> {
        Ok(crate::params::host_rows(self.skin(self.personalised(self.offsets()?), pose, transl)?))
    }

    /// Gaussians on posed vertices, by the configured binding.
    pub fn bind(&self, vertices: &Tensor<2>) -> GaussianGeometry {
        match self.config.method {
            Method::Tavatar => {
                let mut g = if host_ops::supported(&self.device) {
                    let config = BindConfig {
                        mesh: self.index.mesh.clone(),
                        face_gaussians: self.config.face_gaussians,
                        vertex_gaussians: self.config.vertex_gaussians,
                    };
                    fused_binding::bind(vertices.clone(), &config)
                } else {
                    let faces = Faces::of(vertices, &self.index);
                    let vertex =
                        self.config.vertex_gaussians.then(|| vertex_gaussians(vertices, &faces, &self.index));
                    let face = self.config.face_gaussians.then(|| face_gaussians(&faces));
                    match (face, vertex) {
                        (Some(f), Some(v)) => GaussianGeometry::cat(f, v),
                        (Some(f), None) => f,
                        (None, Some(v)) => v,
                        (None, None) => unreachable!("rejected in Avatar::new"),
                    }
                };
                if let Some(ls) = self.param(self.slots.vertex_log_scales) {
                    // Tavatar §5.3 "w/o FG": only vertex Gaussians, whose scales become learnable.
                    let eps = g.scales.clone().narrow(1, 2, 1);
                    g.scales = Tensor::cat(vec![ls.exp(), eps], 1);
                }
                g
            }
            Method::Ihuman => ihuman::centroid_gaussians(
                vertices,
                &self.index,
                self.param(self.slots.face_rotation).expect("iHuman has rotations"),
                self.param(self.slots.face_log_scales).expect("iHuman has scales"),
            ),
        }
    }

    /// Replaces Tavatar's DC colour coefficients [G · 3]; iHuman's colour field is left alone.
    pub fn set_sh_dc(&mut self, values: Vec<f32>) -> Result<(), AvatarError> {
        let Some(i) = self.slots.sh_dc else { return Ok(()) };
        let g = self.num_gaussians();
        if values.len() != 3 * g {
            return Err(AvatarError::Invalid(format!("{} DC values for {g} Gaussians", values.len())));
        }
        self.params[i].value = crate::params::trainable(tensor_from(values, g, 3, &self.device));
        Ok(())
    }

    /// Tavatar's SH coefficients [G, 3(d+1)²], basis-major (DC first); `None` for iHuman.
    pub fn sh_coefficients(&self) -> Option<Tensor<2>> {
        let dc = self.param(self.slots.sh_dc)?;
        Some(match self.param(self.slots.sh_rest) {
            Some(rest) => Tensor::cat(vec![dc, rest], 1),
            None => dc,
        })
    }

    /// Per-Gaussian RGB [G, 3] seen from `eye` (view-dependent through the SH).
    pub fn colours(&self, gaussians: &GaussianGeometry, eye: [f64; 3]) -> Result<Tensor<2>, AvatarError> {
        match self.config.method {
            Method::Tavatar => {
                let coeffs = self.sh_coefficients().expect("Tavatar has SH");
                let config = ColourConfig { eye: eye.map(|x| x as f32), degree: self.config.sh_degree };
                let means = gaussians.means.clone();
                if host_ops::supported(&self.device) {
                    Ok(sh_colour(means, coeffs, &config))
                } else {
                    Ok(sh_colour_tensors(means, coeffs, &config)?)
                }
            }
            Method::Ihuman => {
                let rgb =
                    self.colour_field.as_ref().expect("iHuman has a colour field").forward(&self.params)?;
                Ok(colour_convention(rgb))
            }
        }
    }

    /// Per-Gaussian colour seen from `camera` and camera-space normal, [G, 6]: one fused op on a
    /// GPU for Tavatar, where the composition costs launches.
    fn features(&self, g: &GaussianGeometry, camera: &Camera) -> Result<Tensor<2>, AvatarError> {
        if self.config.method == Method::Tavatar && host_ops::on_cube(&self.device) {
            let e = &camera.extrinsic;
            let config = FeaturesConfig {
                colour: ColourConfig {
                    eye: camera.centre().map(|x| x as f32),
                    degree: self.config.sh_degree,
                },
                rotation: std::array::from_fn(|k| e[k / 3][k % 3] as f32),
            };
            let coeffs = self.sh_coefficients().expect("Tavatar has SH");
            return Ok(render_features(g.means.clone(), coeffs, g.normals.clone(), &config));
        }
        let rgb = self.colours(g, camera.centre())?;
        let normals_cam = g.normals.clone().matmul(rotation_transposed(camera, &self.device));
        Ok(Tensor::cat(vec![rgb, normals_cam], 1))
    }

    /// Renders colour over white and camera-space normals over zero in one pass of six channels.
    pub fn render(&self, posed: &Posed, camera: &Camera) -> Result<Rendered, AvatarError> {
        let g = &posed.gaussians;
        let n = g.len();
        let features = self.features(g, camera)?;
        let options = RenderOptions {
            background: vec![WHITE[0], WHITE[1], WHITE[2], 0.0, 0.0, 0.0],
            dilation: self.config.dilation,
            ..RenderOptions::default()
        };
        let opacities = if self.config.antialiased {
            antialias::compensation(g, camera, self.config.dilation)
        } else {
            if n != self.num_gaussians() {
                return Err(AvatarError::Invalid(format!(
                    "render: {n} posed Gaussians for an avatar of {}",
                    self.num_gaussians()
                )));
            }
            self.full_opacity.clone()
        };
        let out = splat_render(
            g.means.clone(),
            RotationTensor::Matrices(g.frames.clone()),
            g.scales.clone(),
            opacities,
            ColorTensor::Features(features),
            camera,
            &options,
        )?;
        Ok(Rendered { planes: out.planes })
    }

    /// Writes the model directory `dir`. `avatar.npz` holds everything [`Avatar::load`] reads,
    /// the configuration included (as JSON text), so one atomic rename replaces the whole model
    /// and a crash never pairs a new configuration with old parameters. `avatar.json` is a
    /// copy for people, written after it; a crash between the two leaves only that copy stale.
    pub fn save(&self, dir: &Path) -> Result<(), AvatarError> {
        std::fs::create_dir_all(dir).map_err(|e| AvatarError::file(dir, e.to_string()))?;
        let json = serde_json::to_string_pretty(&self.config).expect("config serialises");
        let mut w = NpzWriter::new();
        w.add(CONFIG_MEMBER, NpyArray::text(&json));
        self.canonical.write(&mut w);
        for p in &self.params {
            p.save(&mut w, "param/");
        }
        w.write(dir.join(PARAMS_FILE))?;
        let path = dir.join(CONFIG_FILE);
        write_atomic(&path, json.as_bytes()).map_err(|e| AvatarError::file(&path, e.to_string()))?;
        Ok(())
    }

    /// Loads a model directory written by [`Avatar::save`] onto `device`. Directories saved
    /// before `avatar.npz` held the configuration are read from `avatar.json`.
    pub fn load(dir: &Path, device: &Device) -> Result<Self, AvatarError> {
        let npz_path = dir.join(PARAMS_FILE);
        if !npz_path.exists() {
            return Err(AvatarError::file(
                &npz_path,
                "missing (is this a model directory written by `mannequin train`?)",
            ));
        }
        let npz = Npz::read(&npz_path)?;
        let config: AvatarConfig = if npz.contains(CONFIG_MEMBER) {
            serde_json::from_str(npz.text(CONFIG_MEMBER)?)
                .map_err(|e| npz.field_error(CONFIG_MEMBER, e.to_string()))?
        } else {
            let path = dir.join(CONFIG_FILE);
            let text = std::fs::read_to_string(&path).map_err(|e| AvatarError::file(&path, e.to_string()))?;
            serde_json::from_str(&text).map_err(|e| AvatarError::file(&path, e.to_string()))?
        };
        config.validate().map_err(|e| npz.field_error(CONFIG_MEMBER, e))?;
        let canonical = Canonical::read(&npz)?;
        let mut avatar = Self::new(config, canonical, device)?;
        avatar.load_params(&npz, "param/")?;
        Ok(avatar)
    }

    /// Replaces every parameter with `{prefix}{name}` from `npz`.
    pub fn load_params(&mut self, npz: &Npz, prefix: &str) -> Result<(), AvatarError> {
        for p in &mut self.params {
            p.load(npz, prefix, FLOAT32)?;
        }
        Ok(())
    }
}
