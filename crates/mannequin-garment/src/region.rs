//! The indicator I^g of the thesis (§3.2): the part of the body's rest surface a garment covers,
//! cut out of the body mesh along planes (waist, hems, cuffs) and a sphere about the neck
//! (the neckline), placed by the body's joints so that one recipe fits any body in a T-pose.

use glam::Vec3;
use mannequin_body::smpl_joint::{
    L_KNEE, L_SHOULDER, L_WRIST, NECK, PELVIS, R_SHOULDER, R_WRIST, SPINE1, SPINE3,
};
use mannequin_mesh::TriMesh;
use mannequin_mesh::clip::clip;

use crate::category::Category;
use crate::ease::Ease;

/// Cut vertices closer than this to a cut count as on it (m): no slivers thinner than 1 mm.
const SNAP: f32 = 1e-3;

/// Heights and extents on the rest body that the recipes use.
#[derive(Debug, Clone, Copy)]
pub struct Landmarks {
    pub floor: f32,
    pub hips: f32,
    pub waist: f32,
    pub chest: f32,
    pub neck: Vec3,
    pub left_shoulder: Vec3,
    pub left_wrist: Vec3,
    pub right_shoulder: Vec3,
    pub right_wrist: Vec3,
    pub knee: f32,
}

impl Landmarks {
    pub fn new(vertices: &[[f32; 3]], joints: &[Vec3]) -> Self {
        let floor = vertices.iter().map(|p| p[1]).fold(f32::INFINITY, f32::min);
        Self {
            floor,
            hips: joints[PELVIS].y,
            waist: joints[SPINE1].y,
            chest: joints[SPINE3].y,
            neck: joints[NECK],
            left_shoulder: joints[L_SHOULDER],
            left_wrist: joints[L_WRIST],
            right_shoulder: joints[R_SHOULDER],
            right_wrist: joints[R_WRIST],
            knee: joints[L_KNEE].y,
        }
    }

    /// The lowest cut round the body that stays one loop: below the hip joints, above the
    /// crotch, where a lower cut would go round each thigh. A garment hanging lower leaves the
    /// body here, as a sewn panel.
    pub fn seat(&self) -> f32 {
        self.hips - 0.03
    }

    /// The category's hem height above the soles when the fit does not give one.
    pub fn default_hem_height(&self, category: Category) -> f32 {
        let above_floor = |y: f32| y - self.floor;
        match category {
            // Pants reach the ankle bone; shorts stop a hand above the knee.
            Category::Pants => 0.06,
            Category::ShortPants => above_floor(self.knee) + 0.1,
            // A T-shirt ends above the hip joints, a shirt at the seat.
            Category::Tshirt => above_floor(self.hips) + 0.03,
            Category::Shirt => above_floor(self.seat()),
            // A skirt ends above the knee, a dress and a long coat below it.
            Category::Skirt => above_floor(self.knee) + 0.08,
            Category::Dress => above_floor(self.knee) - 0.1,
            Category::LongCoat => above_floor(self.knee) - 0.15,
        }
    }

    /// The category's sleeve (shoulder 0 … wrist 1) when the fit does not give one.
    pub fn default_sleeve(&self, category: Category) -> f32 {
        match category {
            Category::Tshirt => 0.35,
            Category::Dress => 0.1,
            Category::Shirt | Category::LongCoat => 1.0,
            Category::Pants | Category::ShortPants | Category::Skirt => 0.0,
        }
    }

    /// The hem's rest height.
    pub fn hem(&self, category: Category, fit: &Ease) -> f32 {
        self.floor + fit.hem_height.unwrap_or_else(|| self.default_hem_height(category))
    }

    /// The ease at rest height `y`: the fit's hip, waist and chest values, linear between those
    /// heights and constant beyond them.
    pub fn ease_at(&self, fit: &Ease, y: f32) -> f32 {
        let knots = [(self.hips, fit.ease_hips), (self.waist, fit.ease_waist), (self.chest, fit.ease_chest)];
        if y <= knots[0].0 {
            return knots[0].1;
        }
        for w in knots.windows(2) {
            let ((y0, e0), (y1, e1)) = (w[0], w[1]);
            if y <= y1 {
                return e0 + (e1 - e0) * (y - y0) / (y1 - y0).max(1e-6);
            }
        }
        knots[2].1
    }
}

/// The part of the rest `body` mesh the garment covers (largest connected piece); for a
/// category that hangs free below the seat, the part above it.
pub fn covered_region(body: &TriMesh, marks: &Landmarks, category: Category, fit: &Ease) -> TriMesh {
    let hem = marks.hem(category, fit).max(if category.flare().is_some() { marks.seat() } else { f32::MIN });
    let mut region = body.clone();
    region.uv = None;
    region.colors = None;
    // Keep y ≥ hem.
    region = clip(&region, |p| hem - p.y, SNAP);
    if category.is_lower_body() {
        // Keep y ≤ waist: the arms and hands of a T-pose are far above it.
        return largest_piece(clip(&region, |p| p.y - marks.waist, SNAP));
    }
    let sleeve = fit.sleeve.unwrap_or_else(|| marks.default_sleeve(category));
    // Cuffs: planes across each arm at `sleeve` of the way from shoulder to wrist, beyond which
    // the arm is cut off; sleeve 0 leaves the shoulder's cap.
    for (shoulder, wrist) in
        [(marks.left_shoulder, marks.left_wrist), (marks.right_shoulder, marks.right_wrist)]
    {
        let axis = (wrist - shoulder).normalize_or_zero();
        let cuff = shoulder + (wrist - shoulder) * sleeve.max(0.05);
        region = clip(&region, |p| (p - cuff).dot(axis), SNAP);
    }
    // Neckline: a sphere about a point above the neck joint and forward of it, so the front
    // dips lower than the back, and everything above the neck's top. One cut by the smooth
    // union of the two, so that where they meet at the back the collar is rounded, not a
    // corner that leaves a sliver.
    let centre = marks.neck + Vec3::new(0.0, 0.06, 0.03);
    let top = marks.neck.y + 0.02;
    largest_piece(clip(&region, |p| smooth_max(0.13 - (p - centre).length(), p.y - top, 0.02), SNAP))
}

/// max(a, b) with the corner rounded over about `k`: a hyperbola with the two as asymptotes.
fn smooth_max(a: f32, b: f32, k: f32) -> f32 {
    0.5 * (a + b + ((a - b).powi(2) + k * k).sqrt())
}

/// Half the width of a coat's open front (m).
const HALF_OPENING: f32 = 0.01;

/// `mesh` cut open down the front from neckline to hem. The front is what lies 5 cm or more
/// ahead of the neck joint, which sits near the back of the neck: the collar's back stays whole.
pub fn open_front(mesh: &TriMesh, marks: &Landmarks) -> TriMesh {
    let centre = marks.neck;
    largest_piece(clip(
        mesh,
        |p| if p.z > centre.z + 0.05 { HALF_OPENING - (p.x - centre.x).abs() } else { -1.0 },
        SNAP,
    ))
}

/// The edge-connected piece with the most faces: a cut can leave crumbs (a nipple's tip, a
/// finger's) that are no part of the garment.
fn largest_piece(mesh: TriMesh) -> TriMesh {
    let neighbours = mannequin_mesh::adjacency::face_neighbors(&mesh.faces);
    let mut piece = vec![usize::MAX; mesh.faces.len()];
    let mut sizes = Vec::new();
    for start in 0..mesh.faces.len() {
        if piece[start] != usize::MAX {
            continue;
        }
        let id = sizes.len();
        let mut stack = vec![start];
        piece[start] = id;
        let mut size = 0;
        while let Some(f) = stack.pop() {
            size += 1;
            for g in neighbours[f].iter().flatten() {
                if piece[*g as usize] == usize::MAX {
                    piece[*g as usize] = id;
                    stack.push(*g as usize);
                }
            }
        }
        sizes.push(size);
    }
    let Some(biggest) = (0..sizes.len()).max_by_key(|&i| sizes[i]) else { return mesh };
    let keep: Vec<usize> = (0..mesh.faces.len()).filter(|&f| piece[f] == biggest).collect();
    mesh.submesh(&keep).0
}
