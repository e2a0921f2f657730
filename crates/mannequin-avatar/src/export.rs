//! Exports of a trained avatar: its Gaussians at a pose as a 3DGS scene in the INRIA layout (so
//! any splat viewer shows it), per-vertex colour baked from the Gaussians' view-independent (DC)
//! colour, and the personalised mesh skinned for glTF.

use mannequin_mesh::TriMesh;
use mannequin_mesh::gltf::influences::top_four;
use mannequin_mesh::gltf::{Skeleton, SkinnedLayer, SkinnedMesh};
use mannequin_splat::{SplatScene, sh};

use crate::avatar::{Avatar, Posed};
use crate::canonical::BODY;
use crate::config::Method;
use crate::error::AvatarError;
use crate::mesh_gaussians::GaussianGeometry;
use crate::params::{host, host_rows};

/// Y₀₀ = 1 / (2√π): 3DGS shows a DC coefficient `dc` as the colour 0.5 + C0·dc.
pub const SH_C0: f64 = 0.282_094_791_773_878_1;

/// The avatar renders every Gaussian fully opaque; `SplatScene::write_ply` stores 1 as the finite
/// logit of 1 − 1e-7 (≈ 16.1), which viewers show as opaque.
const OPACITY: f32 = 1.0;

/// Colour of a vertex that no Gaussian covers (one in no face): DC zero.
const UNCOVERED: [f32; 3] = [0.5; 3];

/// Unit quaternion (w, x, y, z) with w ≥ 0 of a Gaussian frame `m`, row-major, whose columns are
/// (t1, t2, n). A left-handed frame has t2 negated first: a quaternion holds only proper
/// rotations, and negating an axis leaves the covariance F S² Fᵀ unchanged. A degenerate frame
/// (zero or non-finite) gives the identity.
pub fn frame_quaternion(m: [[f64; 3]; 3]) -> [f64; 4] {
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    let mut m = m;
    if det < 0.0 {
        for row in &mut m {
            row[1] = -row[1];
        }
    }
    // Shepperd's method: divide by the largest of 4w², 4x², 4y², 4z², never by a small one.
    let trace = m[0][0] + m[1][1] + m[2][2];
    let q = if trace >= m[0][0].max(m[1][1]).max(m[2][2]) {
        let s = 2.0 * (1.0 + trace).sqrt();
        [0.25 * s, (m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s]
    } else if m[0][0] >= m[1][1] && m[0][0] >= m[2][2] {
        let s = 2.0 * (1.0 + m[0][0] - m[1][1] - m[2][2]).sqrt();
        [(m[2][1] - m[1][2]) / s, 0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s]
    } else if m[1][1] >= m[2][2] {
        let s = 2.0 * (1.0 + m[1][1] - m[0][0] - m[2][2]).sqrt();
        [(m[0][2] - m[2][0]) / s, (m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s]
    } else {
        let s = 2.0 * (1.0 + m[2][2] - m[0][0] - m[1][1]).sqrt();
        [(m[1][0] - m[0][1]) / s, (m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s]
    };
    let norm = q.iter().map(|c| c * c).sum::<f64>().sqrt();
    if !(norm.is_finite() && norm > 0.0) {
        return [1.0, 0.0, 0.0, 0.0];
    }
    let sign = if q[0] < 0.0 { -1.0 } else { 1.0 };
    q.map(|c| sign * c / norm)
}

/// Per-Gaussian SH coefficients `[G, (d+1)², 3]`, basis-major as `SplatScene::sh`, and the
/// degree d: Tavatar's learned SH as they are; iHuman's view-independent RGB as a DC term
/// (rgb − 0.5) / C0, which a viewer shows as that RGB.
pub fn sh_coefficients(
    avatar: &Avatar,
    gaussians: &GaussianGeometry,
) -> Result<(usize, Vec<f32>), AvatarError> {
    match avatar.config.method {
        Method::Tavatar => {
            let degree = avatar.config.sh_degree;
            let coeffs: Vec<f32> = avatar
                .sh_coefficients()
                .ok_or_else(|| AvatarError::Invalid("the Tavatar avatar has no SH coefficients".into()))?
                .into_data()
                .iter::<f32>()
                .collect();
            let expected = gaussians.len() * 3 * sh::basis_len(degree);
            if coeffs.len() != expected {
                return Err(AvatarError::Invalid(format!(
                    "{} SH values, expected {expected} ({} Gaussians, degree {degree})",
                    coeffs.len(),
                    gaussians.len()
                )));
            }
            Ok((degree, coeffs))
        }
        Method::Ihuman => {
            // The colour field is view-independent: the eye is not used.
            let rgb = avatar.colours(gaussians, [0.0; 3])?;
            Ok((0, rgb.into_data().iter::<f32>().map(|c| ((f64::from(c) - 0.5) / SH_C0) as f32).collect()))
        }
    }
}

/// The avatar's Gaussians `gaussians` (at any pose) as a 3DGS scene: frames become quaternions,
/// every opacity is 1, colours are [`sh_coefficients`].
pub fn gaussian_scene(avatar: &Avatar, gaussians: &GaussianGeometry) -> Result<SplatScene, AvatarError> {
    let (sh_degree, sh) = sh_coefficients(avatar, gaussians)?;
    let frames = host(gaussians.frames.clone());
    let quaternions = frames
        .chunks_exact(9)
        .flat_map(|f| {
            let m = [0, 1, 2].map(|i| [0, 1, 2].map(|k| f64::from(f[3 * i + k])));
            frame_quaternion(m).map(|c| c as f32)
        })
        .collect();
    Ok(SplatScene {
        means: host(gaussians.means.clone()),
        quaternions,
        scales: host(gaussians.scales.clone()),
        opacities: vec![OPACITY; gaussians.len()],
        sh_degree,
        sh,
    })
}

/// View-independent colour per Gaussian from its SH (`[G, (d+1)², 3]`): 0.5 + C0·dc, in [0, 1].
pub fn dc_colours(sh_degree: usize, sh: &[f32]) -> Vec<[f32; 3]> {
    sh.chunks_exact(3 * sh::basis_len(sh_degree))
        .map(|c| [0, 1, 2].map(|k| (0.5 + SH_C0 * f64::from(c[k])).clamp(0.0, 1.0) as f32))
        .collect()
}

/// Which Gaussians an avatar carries, in their order: one per face (if any), then one per vertex
/// (if any).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Binding {
    pub per_face: bool,
    pub per_vertex: bool,
}

impl Binding {
    pub fn of(avatar: &Avatar) -> Self {
        match avatar.config.method {
            Method::Tavatar => {
                Self { per_face: avatar.config.face_gaussians, per_vertex: avatar.config.vertex_gaussians }
            }
            Method::Ihuman => Self { per_face: true, per_vertex: false },
        }
    }
}

/// Four joint indices and their weights.
pub type Influences = ([u16; 4], [f32; 4]);

/// The linear-blend skinning of each of the avatar's Gaussians, in their order ([`Binding`]):
/// a face Gaussian takes the mean of its face's three vertex weight rows (it sits at the
/// centroid, which the face's vertices carry), a vertex Gaussian its vertex's row; each keeps
/// its four largest weights, renormalised, as glTF's JOINTS_0/WEIGHTS_0 do. A viewer moving the
/// canonical Gaussians by these weights approximates the binding: exact for rigid parts, and off
/// where a triangle bends across a joint.
pub fn gaussian_skinning(avatar: &Avatar) -> Result<Vec<Influences>, AvatarError> {
    let c = &avatar.canonical;
    let (v, j) = (c.num_vertices(), c.num_joints());
    if c.weights.len() != v * j {
        return Err(AvatarError::Invalid(format!(
            "{} skinning weights for {v} vertices × {j} joints",
            c.weights.len()
        )));
    }
    let row = |i: u32| &c.weights[i as usize * j..(i as usize + 1) * j];
    let binding = Binding::of(avatar);
    let faces = c.faces.iter().filter(|_| binding.per_face).map(|f| {
        let mean: Vec<f32> = (0..j).map(|k| f.iter().map(|&i| row(i)[k]).sum::<f32>() / 3.0).collect();
        top_four(&mean)
    });
    let vertices = (0..v as u32).filter(|_| binding.per_vertex).map(|i| top_four(row(i)));
    faces
        .chain(vertices)
        .enumerate()
        .map(|(g, w)| {
            w.ok_or_else(|| AvatarError::Invalid(format!("Gaussian {g} has no positive skinning weight")))
        })
        .collect()
}

/// The avatar's Gaussians at the canonical pose (`canonical`, posed with zero rotations) with
/// their [`gaussian_skinning`] as the extra float vertex properties `joint_0..3` (joint indices)
/// and `weight_0..3` that animated-splat viewers read (docs/viewer.md), as `.ply` bytes.
pub fn skinned_gaussians_ply(avatar: &Avatar, canonical: &Posed) -> Result<Vec<u8>, AvatarError> {
    let scene = gaussian_scene(avatar, &canonical.gaussians)?;
    let skin = gaussian_skinning(avatar)?;
    let columns: Vec<(String, Vec<f32>)> = (0..4)
        .map(|k| (format!("joint_{k}"), skin.iter().map(|(j, _)| f32::from(j[k])).collect()))
        .chain((0..4).map(|k| (format!("weight_{k}"), skin.iter().map(|(_, w)| w[k]).collect())))
        .collect();
    let extra: Vec<(&str, &[f32])> = columns.iter().map(|(n, v)| (n.as_str(), v.as_slice())).collect();
    Ok(scene.ply_bytes(&extra)?)
}

/// Running sums over a vertex's faces: Σ A·rgb, Σ A, Σ rgb and their count.
#[derive(Clone, Copy, Default)]
struct FaceSums {
    weighted: [f64; 3],
    area: f64,
    plain: [f64; 3],
    count: usize,
}

/// Per-vertex colour of the mesh (`vertices`, `faces`) from per-Gaussian colours `rgb` laid out by
/// `binding`: a vertex takes its own vertex Gaussian's colour where it has one, else the
/// area-weighted mean over its faces' Gaussians (a plain mean where all those faces are
/// degenerate), else grey.
pub fn bake_vertex_colours(
    vertices: &[[f32; 3]],
    faces: &[[u32; 3]],
    binding: Binding,
    rgb: &[[f32; 3]],
) -> Result<Vec<[f32; 3]>, AvatarError> {
    let (v, f) = (vertices.len(), faces.len());
    let expected = usize::from(binding.per_face) * f + usize::from(binding.per_vertex) * v;
    if rgb.len() != expected {
        return Err(AvatarError::Invalid(format!(
            "{} Gaussian colours for {f} faces and {v} vertices ({binding:?}): expected {expected}",
            rgb.len()
        )));
    }
    if let Some(i) = faces.iter().flatten().find(|&&i| i as usize >= v) {
        return Err(AvatarError::Invalid(format!("a face indexes vertex {i} of {v}")));
    }
    if binding.per_vertex {
        let start = usize::from(binding.per_face) * f;
        return Ok(rgb[start..].to_vec());
    }
    if !binding.per_face {
        return Ok(vec![UNCOVERED; v]);
    }
    let mut sums = vec![FaceSums::default(); v];
    for (face, colour) in faces.iter().zip(rgb) {
        let [a, b, c] = face.map(|i| vertices[i as usize].map(f64::from));
        let (e1, e2) = ([0, 1, 2].map(|k| b[k] - a[k]), [0, 1, 2].map(|k| c[k] - a[k]));
        let cross =
            [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
        let area = 0.5 * cross.iter().map(|x| x * x).sum::<f64>().sqrt();
        let area = if area.is_finite() { area } else { 0.0 };
        for &i in face {
            let acc = &mut sums[i as usize];
            for (k, &c) in colour.iter().enumerate() {
                acc.weighted[k] += area * f64::from(c);
                acc.plain[k] += f64::from(c);
            }
            acc.area += area;
            acc.count += 1;
        }
    }
    Ok(sums
        .iter()
        .map(|s| match (s.area > 0.0, s.count) {
            (_, 0) => UNCOVERED,
            (true, _) => s.weighted.map(|x| (x / s.area) as f32),
            (false, n) => s.plain.map(|x| (x / n as f64) as f32),
        })
        .collect())
}

/// Per-vertex DC colour of the avatar, with faces weighted by their area on the personalised
/// canonical mesh V_s (pose-independent).
pub fn vertex_colours(avatar: &Avatar, posed: &Posed) -> Result<Vec<[f32; 3]>, AvatarError> {
    let (degree, sh) = sh_coefficients(avatar, &posed.gaussians)?;
    let personalised = host_rows(posed.personalised.clone());
    bake_vertex_colours(&personalised, &avatar.canonical.faces, Binding::of(avatar), &dc_colours(degree, &sh))
}

/// The personalised canonical mesh V_s as a glTF bind pose, coloured by [`vertex_colours`], with
/// the avatar's skeleton (iHuman's learned joints where it has them) and canonical weights. Pose
/// correctives are not carried (glTF skinning is plain LBS); joints are named `joint_{k}`, as
/// the canonical body stores no names.
pub fn skinned_mesh(avatar: &Avatar, posed: &Posed) -> Result<SkinnedMesh, AvatarError> {
    let mut mesh = TriMesh::new(host_rows(posed.personalised.clone()), avatar.canonical.faces.clone());
    mesh.colors = Some(vertex_colours(avatar, posed)?);
    let bind_joints = match avatar.params.iter().find(|p| p.name == "joints") {
        Some(p) => host_rows(p.value.clone()),
        None => avatar.canonical.joints.clone(),
    };
    let j = avatar.canonical.num_joints();
    Ok(SkinnedMesh {
        mesh,
        skeleton: Skeleton {
            names: (0..j).map(|k| format!("joint_{k}")).collect(),
            parents: avatar.canonical.parents.clone(),
            bind_joints,
        },
        weights: avatar.canonical.weights.clone(),
    })
}

/// [`skinned_mesh`] taken apart: the body, and each garment layer as a mesh of its own skinned
/// by the body's skeleton.
pub fn skinned_layers(
    avatar: &Avatar,
    posed: &Posed,
) -> Result<(SkinnedMesh, Vec<SkinnedLayer>), AvatarError> {
    let whole = skinned_mesh(avatar, posed)?;
    let canonical = &avatar.canonical;
    let j = canonical.num_joints();
    let part = |name: &str| -> (TriMesh, Vec<f32>) {
        let part = canonical.layer_part(name).expect("a layer the canonical mesh names");
        (part.mesh(&whole.mesh), part.rows(&whole.weights, j))
    };
    let layers = canonical
        .garment_names()
        .iter()
        .map(|name| {
            let (mesh, weights) = part(name);
            SkinnedLayer { name: name.clone(), mesh, weights }
        })
        .collect();
    let (mesh, weights) = part(BODY);
    Ok((SkinnedMesh { mesh, weights, skeleton: whole.skeleton }, layers))
}

#[cfg(test)]
mod tests {
    use burn::tensor::Device;
    use mannequin_splat::{Camera, Colors, Gaussians, RenderOptions, Rotations, render};

    use super::*;
    use crate::canonical::Canonical;
    use crate::config::AvatarConfig;
    use crate::params::tensor_from;

    /// 1 / (2√π), written independently of [`SH_C0`].
    fn y00() -> f64 {
        0.5 / std::f64::consts::PI.sqrt()
    }

    /// R = cos θ I + sin θ [u]× + (1 − cos θ) u uᵀ, row-major.
    fn rodrigues(u: [f64; 3], theta: f64) -> [[f64; 3]; 3] {
        let (c, s) = (theta.cos(), theta.sin());
        let skew = [[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]];
        std::array::from_fn(|i| {
            std::array::from_fn(|k| {
                f64::from(u8::from(i == k)) * c + s * skew[i][k] + (1.0 - c) * u[i] * u[k]
            })
        })
    }

    /// The rotation of a unit quaternion (w, x, y, z), row-major.
    fn quat_matrix([w, x, y, z]: [f64; 4]) -> [[f64; 3]; 3] {
        [
            [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)],
            [2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x)],
            [2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y)],
        ]
    }

    fn unit(v: [f64; 3]) -> [f64; 3] {
        let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        v.map(|x| x / n)
    }

    #[test]
    fn quaternion_is_half_angle_of_axis_angle() {
        // Angles cover every branch of Shepperd's method (trace > 0 and each dominant diagonal).
        let axes = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 2.0, -0.5], [-0.3, 0.1, 0.9]];
        for u in axes.map(unit) {
            for theta in [0.0, 0.3, 1.5, 2.5, 3.1, std::f64::consts::PI - 1e-9] {
                let m = rodrigues(u, theta);
                let expected = [
                    (theta / 2.0).cos(),
                    u[0] * (theta / 2.0).sin(),
                    u[1] * (theta / 2.0).sin(),
                    u[2] * (theta / 2.0).sin(),
                ];
                let q = frame_quaternion(m);
                for k in 0..4 {
                    assert!((q[k] - expected[k]).abs() < 1e-7, "u {u:?} θ {theta}: {q:?} vs {expected:?}");
                }
                // A left-handed frame (t2 negated) is the same Gaussian and the same quaternion.
                let mut flipped = m;
                flipped.iter_mut().for_each(|row| row[1] = -row[1]);
                let qf = frame_quaternion(flipped);
                assert!(q.iter().zip(qf).all(|(a, b)| (a - b).abs() < 1e-7), "{q:?} vs {qf:?}");
            }
        }
        assert_eq!(frame_quaternion([[0.0; 3]; 3]), [1.0, 0.0, 0.0, 0.0]);
    }

    fn tetrahedron() -> Canonical {
        Canonical {
            vertices: vec![[0.0, 0.0, 0.0], [0.4, 0.0, 0.0], [0.0, 0.3, 0.0], [0.0, 0.0, 0.5]],
            faces: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
            weights: vec![1.0; 4],
            joints: vec![[0.1, 0.1, 0.1]],
            parents: vec![None],
            posedirs: Vec::new(),
            offset_gate: vec![1.0; 4],
            layer: vec![0; 4],
            layer_names: vec![crate::canonical::BODY.into()],
        }
    }

    fn small(method: Method) -> AvatarConfig {
        let mut config = AvatarConfig::new(method, 3);
        config.hash_levels = 2;
        config.hash_log2_table = 8;
        config.hidden = 8;
        config
    }

    /// A tetrahedron avatar whose DC terms are `per_face` on face Gaussians and `per_vertex` on
    /// vertex Gaussians, with the higher bands set to a nonzero filler.
    fn tavatar(config: AvatarConfig, per_face: [f32; 3], per_vertex: [f32; 3]) -> Avatar {
        let device = Device::flex();
        let mut avatar = Avatar::new(config.clone(), tetrahedron(), &device).unwrap();
        let mut dc: Vec<f32> = Vec::new();
        if config.face_gaussians {
            dc.extend((0..4).flat_map(|_| per_face));
        }
        if config.vertex_gaussians {
            dc.extend((0..4).flat_map(|_| per_vertex));
        }
        avatar.set_sh_dc(dc).unwrap();
        if let Some(rest) = avatar.params.iter_mut().find(|p| p.name == "sh_rest") {
            let [g, k] = rest.value.dims();
            rest.value =
                tensor_from((0..g * k).map(|i| 0.1 * (i % 13) as f32 - 0.6).collect(), g, k, &device);
        }
        avatar
    }

    fn assert_colour(got: &[[f32; 3]], expected: [f64; 3]) {
        for (v, c) in got.iter().enumerate() {
            for k in 0..3 {
                assert!((f64::from(c[k]) - expected[k]).abs() < 1e-6, "vertex {v}: {c:?} vs {expected:?}");
            }
        }
    }

    #[test]
    fn baked_colour_of_uniform_face_gaussians_is_their_colour() {
        let mut config = small(Method::Tavatar);
        config.vertex_gaussians = false;
        config.sh_degree = 0;
        let dc = [0.8f32, -0.4, 1.2];
        let avatar = tavatar(config, dc, [0.0; 3]);
        let posed = avatar.pose(&[0.0; 3], [0.0; 3]).unwrap();
        let baked = vertex_colours(&avatar, &posed).unwrap();
        assert_eq!(baked.len(), 4);
        assert_colour(&baked, dc.map(|d| 0.5 + y00() * f64::from(d)));
        // The renderer's own colour path (degree 0: view-independent) agrees.
        let rendered = host_rows(avatar.colours(&posed.gaussians, [0.0, 0.0, 5.0]).unwrap());
        assert_colour(&baked, rendered[0].map(f64::from));
    }

    #[test]
    fn vertex_gaussians_take_precedence_over_faces() {
        let (face, vertex) = ([1.5f32, 1.5, 1.5], [-0.6f32, 0.2, 0.9]);
        let avatar = tavatar(small(Method::Tavatar), face, vertex);
        let posed = avatar.pose(&[0.0; 3], [0.0; 3]).unwrap();
        assert_colour(&vertex_colours(&avatar, &posed).unwrap(), vertex.map(|d| 0.5 + y00() * f64::from(d)));
    }

    #[test]
    fn face_colours_are_area_weighted() {
        // Two triangles sharing the edge 1–2: areas 0.5 and 1.5.
        let vertices = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [2.0, 2.0, 0.0]];
        let faces = [[0, 1, 2], [1, 3, 2]];
        let rgb = [[1.0, 0.0, 0.2], [0.0, 1.0, 0.6]];
        let binding = Binding { per_face: true, per_vertex: false };
        let baked = bake_vertex_colours(&vertices, &faces, binding, &rgb).unwrap();
        let shared = [0.25, 0.75, 0.5];
        let expected = [[1.0, 0.0, 0.2], shared, shared, [0.0, 1.0, 0.6]];
        for (got, want) in baked.iter().zip(expected) {
            assert!(
                got.iter().zip(want).all(|(a, b)| (f64::from(*a) - b).abs() < 1e-6),
                "{got:?} vs {want:?}"
            );
        }
        // A wrong count is an error, not a panic.
        assert!(bake_vertex_colours(&vertices, &faces, binding, &rgb[..1]).is_err());
    }

    /// Rotates the single joint so frames are not axis-aligned.
    const POSE: [f32; 3] = [0.4, -1.1, 0.7];

    #[test]
    fn scene_reproduces_posed_gaussians() {
        let avatar = tavatar(small(Method::Tavatar), [0.3, -0.2, 0.5], [0.1, 0.4, -0.3]);
        assert_eq!(avatar.config.sh_degree, 2);
        let posed = avatar.pose(&POSE, [0.2, -0.1, 0.3]).unwrap();
        let scene = gaussian_scene(&avatar, &posed.gaussians).unwrap();
        assert_eq!(scene.len(), avatar.num_gaussians());
        let means: Vec<f32> = posed.gaussians.means.clone().into_data().iter::<f32>().collect();
        assert_eq!(scene.means, means);
        let frames: Vec<f32> = posed.gaussians.frames.clone().into_data().iter::<f32>().collect();
        for (g, q) in scene.quaternions.chunks_exact(4).enumerate() {
            let m = quat_matrix([q[0], q[1], q[2], q[3]].map(f64::from));
            for i in 0..3 {
                for k in 0..3 {
                    let f = f64::from(frames[9 * g + 3 * i + k]);
                    assert!((m[i][k] - f).abs() < 1e-5, "Gaussian {g} entry ({i}, {k}): {} vs {f}", m[i][k]);
                }
            }
        }
        // Basis-major: each Gaussian's DC triple, then its higher bands as the test set them.
        let (face_dc, vertex_dc) = ([0.3, -0.2, 0.5], [0.1, 0.4, -0.3]);
        let rest_len = 3 * (sh::basis_len(scene.sh_degree) - 1);
        let sh: Vec<f32> = (0..8)
            .flat_map(|g| {
                let dc: [f32; 3] = if g < 4 { face_dc } else { vertex_dc };
                let rest = (g * rest_len..(g + 1) * rest_len).map(|i| 0.1 * (i % 13) as f32 - 0.6);
                dc.into_iter().chain(rest)
            })
            .collect();
        assert_eq!(scene.sh, sh);

        // Through a file: INRIA stores log scales and a logit opacity.
        let path = std::env::temp_dir().join(format!("mq-export-{}.ply", std::process::id()));
        scene.write_ply(&path).unwrap();
        let back = SplatScene::read_ply(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert_eq!(back.len(), scene.len());
        assert!(back.opacities.iter().all(|&o| o > 0.9999), "{:?}", back.opacities);
        for (a, b) in back.scales.iter().zip(&scene.scales) {
            assert!((a / b - 1.0).abs() < 1e-5, "{a} vs {b}");
        }

        // The renderer draws the quaternion scene as it draws the frames themselves.
        let camera = Camera::look_at([0.3, 0.5, 1.6], [0.1, 0.1, 0.2], [0.0, 1.0, 0.0], 0.9, 40, 32);
        let opacities = vec![1.0f32; scene.len()];
        let colors = Colors::Sh { degree: scene.sh_degree, coeffs: &scene.sh };
        let with = |rotations| Gaussians {
            means: &scene.means,
            rotations,
            scales: &scene.scales,
            opacities: &opacities,
            colors,
        };
        let a = render(&with(Rotations::Quaternions(&scene.quaternions)), &camera, &RenderOptions::default())
            .unwrap();
        let b = render(&with(Rotations::Matrices(&frames)), &camera, &RenderOptions::default()).unwrap();
        assert!(a.alpha.iter().any(|&x| x > 0.5), "the tetrahedron is in view");
        let worst = a.image.iter().zip(&b.image).map(|(x, y)| (x - y).abs()).fold(0.0f32, f32::max);
        assert!(worst < 1e-3, "images differ by {worst}");
    }

    #[test]
    fn ihuman_rgb_becomes_dc_that_shows_as_that_rgb() {
        let avatar = Avatar::new(small(Method::Ihuman), tetrahedron(), &Device::flex()).unwrap();
        let posed = avatar.pose(&POSE, [0.0; 3]).unwrap();
        let scene = gaussian_scene(&avatar, &posed.gaussians).unwrap();
        assert_eq!((scene.sh_degree, scene.len()), (0, 4));
        let rgb = host_rows(avatar.colours(&posed.gaussians, [0.0; 3]).unwrap());
        for (g, dc) in scene.sh.chunks_exact(3).enumerate() {
            for k in 0..3 {
                let shown = 0.5 + y00() * f64::from(dc[k]);
                assert!((shown - f64::from(rgb[g][k])).abs() < 1e-6, "Gaussian {g}: {shown} vs {:?}", rgb[g]);
            }
        }
        let skinned = skinned_mesh(&avatar, &posed).unwrap();
        assert_eq!(skinned.mesh.colors.as_ref().map(Vec::len), Some(4));
        assert_eq!(skinned.skeleton.bind_joints.len(), 1);
    }
}
