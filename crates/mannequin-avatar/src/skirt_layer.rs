//! A skirt layer for subjects whose masks fill the gap between the legs. A body-topology mesh
//! with per-leg skinning cannot span that gap: fitted to a dress it becomes two inflated legs
//! (synthetic dress subject: 26.3 dB, Chamfer 2.5 cm). The layer is a separate garment mesh over
//! the body, as in the thesis's MGN-style garments: a surface of revolution from the waist
//! (the SPINE1 joint's height) to a hem found in the masks, its skinning carried from the body by
//! Gaussian RBFs (NGD §3.5), with each vertex's radius carved to the visual hull of the training
//! masks. The offset field then refines it like the rest of the mesh. Nothing here comes from the
//! synthetic generator, whose own skirts are built and skinned another way.

use glam::{Affine3A, DVec3, Vec3};
use rayon::prelude::*;

use mannequin_body::kinematics::{skinning_transforms, world_transforms};
use mannequin_body::lbs::frame_rotations;
use mannequin_body::smpl_joint::{L_ANKLE, L_HIP, L_KNEE, PELVIS, R_ANKLE, R_HIP, R_KNEE, SPINE1};
use mannequin_body::weight_transfer::{KernelWidth, transfer_weights};
use mannequin_mesh::UvLayout;
use mannequin_mesh::gltf::influences::top_four;
use mannequin_mesh::ring_tube::RingLayout;

use crate::canonical::Canonical;
use crate::error::AvatarError;
use crate::garment_layer::GarmentLayer;
use crate::views::View;

/// The layer's name among the canonical mesh's layers.
const LAYER_NAME: &str = "skirt_layer";
/// Radial step of the carving search (m): about a pixel at 540×540 on a standing subject.
const STEP: f32 = 0.003;
/// How far past the body's own outline the hull is searched (m).
const REACH: f32 = 0.4;
/// A point is inside the hull when at most this fraction of views see it off the mask, which
/// forgives a pixel of mask or pose error at silhouette edges.
const DISAGREE: f32 = 0.02;
/// Views used for carving: every k-th training frame.
const VIEW_STRIDE: usize = 2;
/// A ring still belongs to the skirt when this share of its vertices keep their radius from the
/// ring above; below a hem the gap between the legs opens and the front and back collapse.
const RING_KEEPS: f32 = 0.9;
const KEEP_RATIO: f32 = 0.85;
/// The provisional skirt reaches this far above the ankles while the hem is searched (m), on a
/// grid of this many segments and rings (about 3 cm between rings).
const ANKLE_CLEARANCE: f32 = 0.1;
const PROVISIONAL: (usize, usize) = (64, 28);
/// Edge length of the fitted layer's triangles (m). The body's mean edge (1 cm) rendered the
/// synthetic dress 0.9 dB better but trained a third slower; 1.5 cm already resolves its stripes.
const EDGE: f32 = 0.015;
/// Below the hem, the body's offsets are released over this height (m).
const HEM_MARGIN: f32 = 0.08;
/// Width of the GRBF skinning kernel (m): about a thigh's radius, so a point over the gap
/// between the legs blends both.
const SKIN_SIGMA: f32 = 0.05;
/// Half-width of the strip around a ray in which body points count towards its outline (m).
const OUTLINE_STRIP: f32 = 0.02;
/// The layer's least radius (m), where no body point lies along a ray (over the gap between
/// the legs), so every vertex has a direction to carve along.
const MIN_RADIUS: f32 = 0.05;

/// Whether to add the layer: when the masks show a skirt, or never.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum SkirtMode {
    Auto,
    Off,
}

impl std::str::FromStr for SkirtMode {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        <Self as clap::ValueEnum>::from_str(s, false)
            .map_err(|_| format!("unknown skirt mode '{s}' (expected auto or off)"))
    }
}

/// A tube of rings around the pelvis with its skinning, in the canonical body's rest frame.
pub struct Skirt {
    /// Rest positions, ring-major from the waist down.
    pub positions: Vec<[f32; 3]>,
    pub faces: Vec<[u32; 3]>,
    pub uv: UvLayout,
    /// Skinning weights, V × J row-major, from the body by GRBF.
    pub weights: Vec<f32>,
    /// The four strongest joints of each vertex, for testing points against the masks.
    influences: Vec<([u16; 4], [f32; 4])>,
    pub layout: RingLayout,
}

/// The fitted layer, in the canonical body's rest frame.
pub struct SkirtLayer {
    pub skirt: Skirt,
    /// Heights of the waist and the hem (m).
    pub waist: f32,
    pub hem: f32,
}

/// "a layer of N vertices from the waist to X cm below it", for logs.
impl std::fmt::Display for SkirtLayer {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        let (vertices, length) = (self.skirt.positions.len(), 100.0 * (self.waist - self.hem));
        write!(f, "a layer of {vertices} vertices from the waist to {length:.0} cm below it")
    }
}

/// The horizontal offset of `p` from the skirt's vertical axis through `centre`.
fn horizontal(p: Vec3, centre: Vec3) -> Vec3 {
    Vec3::new(p.x - centre.x, 0.0, p.z - centre.z)
}

/// The training views' skinning transforms, for testing rest-pose points against their masks.
struct Silhouettes<'a> {
    views: Vec<(&'a View, Vec<Affine3A>)>,
}

impl<'a> Silhouettes<'a> {
    fn new(body: &Canonical, views: &'a [View]) -> Self {
        let rest: Vec<Vec3> = body.joints.iter().map(|&j| Vec3::from(j)).collect();
        let views = views
            .iter()
            .step_by(VIEW_STRIDE)
            .map(|v| {
                let world = world_transforms(&body.parents, &frame_rotations(&v.pose), &rest);
                (v, skinning_transforms(&world, &rest))
            })
            .collect();
        Self { views }
    }

    /// Share of views in which the rest-pose point `p`, skinned by `influences`, lands off the
    /// mask.
    fn outside(&self, p: Vec3, (joints, weights): &([u16; 4], [f32; 4])) -> f32 {
        let off = self
            .views
            .iter()
            .filter(|(view, transforms)| {
                let posed: Vec3 = joints
                    .iter()
                    .zip(weights)
                    .map(|(&j, &w)| w * transforms[j as usize].transform_point3(p))
                    .sum();
                let world = (posed + Vec3::from(view.transl)).as_dvec3();
                !on_mask(view, world)
            })
            .count();
        off as f32 / self.views.len().max(1) as f32
    }

    /// The largest radius along the rest-pose ray from `centre` through `vertex` (horizontally)
    /// whose point is inside the hull, searched out to `REACH` past the vertex; `None` when the
    /// whole ray is outside.
    fn carve(&self, centre: Vec3, vertex: Vec3, influences: &([u16; 4], [f32; 4])) -> Option<f32> {
        let d = horizontal(vertex, centre);
        let (r0, dir) = (d.length(), d.normalize_or_zero());
        let steps = ((r0 + REACH) / STEP) as usize;
        (1..=steps).map(|k| k as f32 * STEP).rev().find(|&r| {
            let p = Vec3::new(centre.x, vertex.y, centre.z) + r * dir;
            self.outside(p, influences) <= DISAGREE
        })
    }
}

/// Whether the world point projects onto the view's mask (off the crop is off the mask).
fn on_mask(view: &View, world: DVec3) -> bool {
    let pc = view.camera.world_to_camera(world);
    if pc.z <= view.camera.near {
        return false;
    }
    let [u, v] = view.camera.project(pc);
    let (x, y) = (u.floor() - view.crop.x as f64, v.floor() - view.crop.y as f64);
    if x < 0.0 || y < 0.0 || x >= view.crop.width as f64 || y >= view.crop.height as f64 {
        return false;
    }
    view.mask[y as usize * view.crop.width + x as usize] > 0.5
}

/// Carved radius of every vertex of `skirt` (None where its ray is wholly outside).
fn carve_all(hull: &Silhouettes, skirt: &Skirt, centre: Vec3) -> Vec<Option<f32>> {
    skirt
        .positions
        .par_iter()
        .zip(&skirt.influences)
        .map(|(p, w)| hull.carve(centre, Vec3::from(*p), w))
        .collect()
}

/// Every vertex's carved radius, never inside the body's own outline (its radius as built),
/// which it keeps where it carved nothing.
fn outline_radii(skirt: &Skirt, carved: &[Option<f32>], centre: Vec3) -> Vec<f32> {
    skirt
        .positions
        .iter()
        .zip(carved)
        .map(|(p, c)| {
            let r0 = horizontal(Vec3::from(*p), centre).length();
            c.unwrap_or(r0).max(r0)
        })
        .collect()
}

/// Number of rings, from the waist, that keep their radius (see `RING_KEEPS`).
fn skirt_rings(carved: &[Option<f32>], layout: &RingLayout) -> usize {
    let n = layout.segments[0];
    debug_assert!(layout.segments.iter().all(|&s| s == n), "the provisional grid is uniform");
    let ring = |r: usize| &carved[r * n..(r + 1) * n];
    let kept = |r: usize| {
        let count = if r == 0 {
            ring(0).iter().filter(|c| c.is_some()).count()
        } else {
            ring(r)
                .iter()
                .zip(ring(r - 1))
                .filter(|(c, above)| matches!((c, above), (Some(c), Some(a)) if *c >= KEEP_RATIO * a))
                .count()
        };
        count as f32 >= RING_KEEPS * n as f32
    };
    (0..layout.rings.len()).take_while(|&r| kept(r)).count()
}

/// A layer on `layout` from `waist` down to `hem` around the vertical axis through `centre`, each
/// vertex at the body's outline along its ray (at least `MIN_RADIUS` out), skinned from the body.
fn ring_skirt(body: &Canonical, centre: Vec3, (waist, hem): (f32, f32), layout: &RingLayout) -> Skirt {
    let length = waist - hem;
    let below_waist: Vec<Vec3> =
        body.vertices.iter().map(|&p| Vec3::from(p)).filter(|p| p.y < waist).collect();
    let band = 0.5 * length / layout.rings.len().max(2) as f32 + OUTLINE_STRIP;
    let mut positions = Vec::with_capacity(layout.vertex_count());
    for (&s, &n) in layout.rings.iter().zip(&layout.segments) {
        let y = waist - s * length;
        let near: Vec<Vec3> =
            below_waist.iter().filter(|p| (p.y - y).abs() <= band).map(|&p| horizontal(p, centre)).collect();
        for k in 0..n {
            let (sin, cos) = (std::f32::consts::TAU * k as f32 / n as f32).sin_cos();
            let ray = Vec3::new(cos, 0.0, sin);
            // The farthest body point along the ray, within a strip around it.
            let outline = near
                .iter()
                .filter(|h| h.cross(ray).length() <= OUTLINE_STRIP)
                .map(|h| h.dot(ray))
                .fold(MIN_RADIUS, f32::max);
            positions.push((Vec3::new(centre.x, y, centre.z) + outline * ray).to_array());
        }
    }
    let j = body.num_joints();
    let weights =
        transfer_weights(&body.vertices, &body.weights, j, &positions, KernelWidth::Fixed(SKIN_SIGMA));
    let influences =
        weights.chunks_exact(j).map(|row| top_four(row).unwrap_or(([0; 4], [1.0, 0.0, 0.0, 0.0]))).collect();
    let (faces, uv) = layout.tube();
    Skirt { positions, faces, uv, weights, influences, layout: layout.clone() }
}

/// Rings a triangle's height apart (`EDGE`·√3/2), each with as many vertices as keep `EDGE`
/// between them at its radius, so the layer's triangles are near-equilateral and one size from
/// the narrow waist to the wide hem. With 96 vertices on every ring the hem's edges were 2.5 cm
/// against the body's 1 cm, and a dress's striped texture came out as dots in novel views.
/// `radius(s)` is the mean radius at fraction `s` from waist to hem.
fn even_layout(length: f32, radius: impl Fn(f32) -> f32) -> RingLayout {
    let gaps = (length / (EDGE * 0.75f32.sqrt())).round().max(1.0) as usize;
    let rings: Vec<f32> = (0..=gaps).map(|j| j as f32 / gaps as f32).collect();
    let segments =
        rings.iter().map(|&s| ((std::f32::consts::TAU * radius(s) / EDGE).round() as usize).max(3)).collect();
    RingLayout::new(rings, segments)
}

/// Fits the layer to `views`' masks, or returns `None` when `mode` is off or the masks show the
/// gap between the legs above mid-thigh (trousers or shorts).
pub fn fit_skirt(
    body: &Canonical,
    views: &[View],
    mode: SkirtMode,
) -> Result<Option<SkirtLayer>, AvatarError> {
    if mode == SkirtMode::Off {
        return Ok(None);
    }
    if body.num_joints() != 24 {
        return Err(AvatarError::Invalid(format!(
            "a skirt layer is rigged to SMPL's 24 joints, but the body has {}",
            body.num_joints()
        )));
    }
    let y = |j: usize| body.joints[j][1];
    let (waist, centre) = (y(SPINE1), Vec3::from(body.joints[PELVIS]));
    let ankles = 0.5 * (y(L_ANKLE) + y(R_ANKLE));
    let mid_thigh = 0.5 * (0.5 * (y(L_HIP) + y(R_HIP)) + 0.5 * (y(L_KNEE) + y(R_KNEE)));
    let hull = Silhouettes::new(body, views);

    // A long provisional skirt finds the hem: the last ring that keeps its radius.
    let lowest = ankles + ANKLE_CLEARANCE;
    let coarse = RingLayout::uniform(PROVISIONAL.0, PROVISIONAL.1);
    let provisional = ring_skirt(body, centre, (waist, lowest), &coarse);
    let carved = carve_all(&hull, &provisional, centre);
    let rings = skirt_rings(&carved, &coarse);
    let hem_s = coarse.rings[rings.saturating_sub(1)];
    let hem = waist - hem_s * (waist - lowest);
    if hem >= mid_thigh {
        return Ok(None);
    }

    // The provisional radii, read over the skirt's length, place the final rings.
    let n = coarse.segments[0];
    let profile: Vec<f32> = outline_radii(&provisional, &carved, centre)
        .chunks_exact(n)
        .map(|ring| ring.iter().sum::<f32>() / n as f32)
        .collect();
    let layout = even_layout(waist - hem, |s| {
        let x = (s * hem_s * PROVISIONAL.1 as f32).clamp(0.0, PROVISIONAL.1 as f32);
        let (i, t) = (x.floor() as usize, x.fract());
        let next = profile[(i + 1).min(PROVISIONAL.1)];
        profile[i] * (1.0 - t) + next * t
    });
    let mut skirt = ring_skirt(body, centre, (waist, hem), &layout);
    let carved = carve_all(&hull, &skirt, centre);
    for ((k, p), ring) in skirt.positions.iter_mut().enumerate().zip(layout.ring_of_vertices()) {
        // Smooth along the ring ([1, 2, 1] / 4) over the pixel steps of the carving, and never
        // inside the body's own outline.
        let (n, seg) = (layout.segments[ring], k - layout.vertex(ring, 0));
        let d = horizontal(Vec3::from(*p), centre);
        let r0 = d.length();
        let at = |s: usize| carved[layout.vertex(ring, s)].unwrap_or(r0).max(r0);
        let r = 0.25 * (at(seg + n - 1) + 2.0 * at(seg) + at(seg + 1));
        *p = (Vec3::new(centre.x, p[1], centre.z) + r * d.normalize_or_zero()).to_array();
    }
    Ok(Some(SkirtLayer { skirt, waist, hem }))
}

impl SkirtLayer {
    /// How much of its offset the body's rest point `p` keeps: none under the layer (between
    /// waist and hem, nearer the axis through `centre` than the skirt's nearest vertex), rising
    /// linearly to all of it `HEM_MARGIN` below the hem. Training views see the body just below
    /// the hem only past the hem's edge, and there its offsets fill the hem's edge rather than
    /// fit the legs: ungated, the synthetic dress's inner thighs stretched 9 cm across the gap
    /// between the legs, a curtain that the novel views from above and below showed.
    fn offset_gate(&self, p: Vec3, centre: Vec3) -> f32 {
        if p.y >= self.waist || p.y <= self.hem - HEM_MARGIN {
            return 1.0;
        }
        let layout = &self.skirt.layout;
        let ring = layout.ring_at((self.waist - p.y) / (self.waist - self.hem));
        let d = horizontal(p, centre);
        let s =
            Vec3::from(self.skirt.positions[layout.nearest(ring, d.z.atan2(d.x) / std::f32::consts::TAU)]);
        if d.length() >= horizontal(s, centre).length() {
            1.0
        } else {
            ((self.hem - p.y) / HEM_MARGIN).max(0.0)
        }
    }
}

impl Canonical {
    /// The body with the layer's vertices and faces appended (no pose correctives on them). The
    /// body under the layer gets no offsets, and the legs just below the hem get them gradually
    /// (see [`SkirtLayer::offset_gate`]): no view constrains the body under it, and seen through
    /// the gaps between the layer's Gaussians it would otherwise inflate into the skirt and poke
    /// through (synthetic dress: thighs moved 8 cm on average).
    pub fn with_layer(self, layer: &SkirtLayer) -> Result<Self, AvatarError> {
        let centre = Vec3::from(self.joints[PELVIS]);
        let gate: Vec<f32> =
            self.vertices.iter().map(|p| layer.offset_gate(Vec3::from(*p), centre)).collect();
        let garment = GarmentLayer {
            name: LAYER_NAME.into(),
            positions: layer.skirt.positions.clone(),
            faces: layer.skirt.faces.clone(),
            weights: layer.skirt.weights.clone(),
        };
        self.with_garment(&garment, &gate)
    }
}
