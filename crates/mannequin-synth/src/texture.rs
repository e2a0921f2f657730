//! Procedural appearance baked into a UV texture: skin, hair, shoes, and garment prints with
//! high-frequency detail (stripes, checks or dots, text-like glyph rows, a fine weave). Colours
//! are functions of the rest-pose surface point, so prints continue across UV seams.

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use crate::subject::{GarmentLook, Pattern, Subject};
use mannequin_data::image::Image;
use mannequin_io::rng::mix;

/// What a surface point is, for colouring.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Material {
    Skin,
    Hair,
    Shoe,
    Top,
    Bottom,
}

/// Per-vertex data interpolated over the texture: rest position and material weights.
#[derive(Debug, Clone, Copy)]
pub struct SurfacePoint {
    pub position: Vec3,
    /// Membership of top, bottom, hair, shoe (skin is the rest).
    pub layers: [f32; 4],
}

impl SurfacePoint {
    fn material(&self) -> Material {
        let [top, bottom, hair, shoe] = self.layers;
        if top > 0.5 {
            Material::Top
        } else if bottom > 0.5 {
            Material::Bottom
        } else if shoe > 0.5 {
            Material::Shoe
        } else if hair > 0.5 {
            Material::Hair
        } else {
            Material::Skin
        }
    }
}

/// Hermite smoothstep from 0 at `a` to 1 at `b`.
pub fn smoothstep(a: f32, b: f32, x: f32) -> f32 {
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// A hash of integer cell coordinates to [0, 1).
fn cell_hash(x: i32, y: i32, z: i32, salt: u64) -> f32 {
    let h = mix((x as u64).wrapping_mul(0x9E37_79B9)
        ^ (y as u64).wrapping_mul(0x85EB_CA6B) << 1
        ^ (z as u64).wrapping_mul(0xC2B2_AE35) << 2
        ^ salt);
    (h >> 40) as f32 / (1u64 << 24) as f32
}

/// Smooth value noise in [0, 1) with trilinear interpolation.
fn value_noise(p: Vec3, salt: u64) -> f32 {
    let f = p.floor();
    let t = p - f;
    let (x, y, z) = (f.x as i32, f.y as i32, f.z as i32);
    let mut acc = 0.0;
    for c in 0..8 {
        let (dx, dy, dz) = (c & 1, (c >> 1) & 1, (c >> 2) & 1);
        let w = (if dx == 1 { t.x } else { 1.0 - t.x })
            * (if dy == 1 { t.y } else { 1.0 - t.y })
            * (if dz == 1 { t.z } else { 1.0 - t.z });
        acc += w * cell_hash(x + dx, y + dy, z + dz, salt);
    }
    acc
}

fn lerp(a: [f32; 3], b: [f32; 3], t: f32) -> [f32; 3] {
    [0, 1, 2].map(|c| a[c] + (b[c] - a[c]) * t)
}

/// A 5 × 7 glyph drawn from a hash: text-like, not a real alphabet.
fn glyph_on(code: u64, gx: usize, gy: usize) -> bool {
    mix(code.wrapping_add((gy * 5 + gx) as u64)) & 3 != 0 && (gx + gy) % 4 != 3
}

/// Whether a point on the chest falls on a glyph of the subject's text rows. Text is laid out
/// on the front (z > 0) in the (x, y) plane: 8 mm glyph pixels, 6 × 8 px cells.
fn text_ink(p: Vec3, chest: Vec3, rows: u32, seed: u64) -> bool {
    if rows == 0 || p.z < chest.z {
        return false;
    }
    let px = 0.008;
    let (u, v) = ((p.x - chest.x) / px, (chest.y - p.y) / px);
    let (cw, ch) = (6.0, 9.0);
    let half_width = 10.0 * cw;
    if u.abs() >= half_width || v < 0.0 || v >= ch * rows as f32 {
        return false;
    }
    let (col, row) = (((u + half_width) / cw) as usize, (v / ch) as usize);
    let (gx, gy) = (((u + half_width) % cw) as usize, (v % ch) as usize);
    if gx >= 5 || gy >= 7 {
        return false;
    }
    // Word gaps: some cells are blank.
    let code = mix(seed ^ ((row * 64 + col) as u64) << 8);
    !code.is_multiple_of(6) && glyph_on(code, gx, gy)
}

fn garment_colour(look: &GarmentLook, p: Vec3, chest: Vec3, salt: u64) -> [f32; 3] {
    let on = match look.pattern {
        Pattern::Stripes { direction, period } => {
            (Vec3::from(direction).dot(p) / period).rem_euclid(1.0) < 0.5
        }
        Pattern::Checks { cell } => {
            let c = (p / cell).floor();
            (c.x as i32 + c.y as i32 + c.z as i32).rem_euclid(2) == 0
        }
        Pattern::Dots { cell, radius } => {
            let c = (p / cell).floor();
            let jitter = Vec3::new(
                cell_hash(c.x as i32, c.y as i32, c.z as i32, salt),
                cell_hash(c.x as i32, c.y as i32, c.z as i32, salt + 1),
                cell_hash(c.x as i32, c.y as i32, c.z as i32, salt + 2),
            );
            let centre = (c + 0.25 + 0.5 * jitter) * cell;
            centre.distance(p) < radius
        }
    };
    let mut colour = if on { look.accent } else { look.base };
    if text_ink(p, chest, look.text_rows, salt) {
        colour = lerp(look.accent, [1.0 - look.base[0], 1.0 - look.base[1], 1.0 - look.base[2]], 0.5);
    }
    // A fine weave (about 2 mm) and slow dye variation.
    let weave = 0.04 * ((p.x + p.y) * 3100.0).sin() * ((p.x - p.y + p.z) * 2900.0).sin();
    let dye = 0.12 * (value_noise(p * 12.0, salt + 7) - 0.5);
    colour.map(|c| (c * (1.0 + dye) + weave).clamp(0.0, 1.0))
}

/// The colour of a surface point.
pub fn surface_colour(subject: &Subject, s: &SurfacePoint, chest: Vec3) -> [f32; 3] {
    let p = s.position;
    let fine = value_noise(p * 400.0, subject.seed) - 0.5;
    match s.material() {
        Material::Skin => {
            let blotch = value_noise(p * 25.0, subject.seed + 1) - 0.5;
            subject.skin.map(|c| (c * (1.0 + 0.08 * blotch) + 0.03 * fine).clamp(0.0, 1.0))
        }
        Material::Hair => {
            let strands = 0.5 + 0.5 * ((p.x * 900.0 + 40.0 * value_noise(p * 30.0, subject.seed + 2)).sin());
            subject.hair.map(|c| (c * (0.7 + 0.5 * strands)).clamp(0.0, 1.0))
        }
        Material::Shoe => subject.shoes.map(|c| (c + 0.05 * fine).clamp(0.0, 1.0)),
        Material::Top => garment_colour(&subject.top, p, chest, subject.seed ^ 0x70),
        Material::Bottom => garment_colour(&subject.bottom, p, chest, subject.seed ^ 0xB0),
    }
}

/// A textured surface to bake: UV triangles and the per-vertex points they interpolate.
pub struct BakeInput<'a> {
    pub uv: &'a mannequin_mesh::UvLayout,
    pub faces: &'a [[u32; 3]],
    pub points: &'a [SurfacePoint],
}

/// Bakes `surface_colour` into a `width × height` texture (v up), then grows each UV island by
/// a few texels so that bilinear lookups at island borders do not pick up unbaked texels.
pub fn bake(input: &BakeInput, subject: &Subject, chest: Vec3, width: usize, height: usize) -> Image {
    // Which face and barycentrics cover each texel centre.
    let mut cover: Vec<Option<(u32, [f32; 3])>> = vec![None; width * height];
    for (f, t) in input.uv.faces.iter().enumerate() {
        let p = t.map(|i| {
            let c = input.uv.coords[i as usize];
            Vec2::new(c[0] * width as f32, (1.0 - c[1]) * height as f32)
        });
        let area = (p[1] - p[0]).perp_dot(p[2] - p[0]);
        if area == 0.0 {
            continue;
        }
        let lo = p[0].min(p[1]).min(p[2]);
        let hi = p[0].max(p[1]).max(p[2]);
        let (x0, x1) =
            ((lo.x - 0.5).ceil().max(0.0) as usize, ((hi.x - 0.5).floor() as isize).min(width as isize - 1));
        let (y0, y1) =
            ((lo.y - 0.5).ceil().max(0.0) as usize, ((hi.y - 0.5).floor() as isize).min(height as isize - 1));
        for y in y0 as isize..=y1 {
            for x in x0 as isize..=x1 {
                let q = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let b = [
                    (p[2] - p[1]).perp_dot(q - p[1]),
                    (p[0] - p[2]).perp_dot(q - p[2]),
                    (p[1] - p[0]).perp_dot(q - p[0]),
                ]
                .map(|e| e / area);
                if b.iter().all(|&v| v >= 0.0) {
                    cover[y as usize * width + x as usize] = Some((f as u32, b));
                }
            }
        }
    }
    let mut pixels: Vec<[f32; 3]> = cover
        .par_iter()
        .map(|c| match c {
            None => [0.0; 3],
            Some((f, b)) => {
                let corners = input.faces[*f as usize].map(|i| input.points[i as usize]);
                let position = (0..3).map(|k| corners[k].position * b[k]).sum::<Vec3>();
                let layers = [0, 1, 2, 3].map(|l| (0..3).map(|k| corners[k].layers[l] * b[k]).sum::<f32>());
                surface_colour(subject, &SurfacePoint { position, layers }, chest)
            }
        })
        .collect();
    let mut filled: Vec<bool> = cover.iter().map(Option::is_some).collect();
    dilate(&mut pixels, &mut filled, width, height, 4);
    Image { width, height, pixels }
}

/// Fills unfilled texels next to filled ones with their neighbours' mean, `passes` times.
fn dilate(pixels: &mut [[f32; 3]], filled: &mut [bool], width: usize, height: usize, passes: usize) {
    for _ in 0..passes {
        let snapshot: Vec<bool> = filled.to_vec();
        let source = pixels.to_vec();
        for y in 0..height {
            for x in 0..width {
                let i = y * width + x;
                if snapshot[i] {
                    continue;
                }
                let mut acc = [0.0f32; 3];
                let mut n = 0;
                for (dx, dy) in [(-1i32, 0i32), (1, 0), (0, -1), (0, 1)] {
                    let (nx, ny) = (x as i32 + dx, y as i32 + dy);
                    if nx >= 0 && ny >= 0 && (nx as usize) < width && (ny as usize) < height {
                        let j = ny as usize * width + nx as usize;
                        if snapshot[j] {
                            (0..3).for_each(|c| acc[c] += source[j][c]);
                            n += 1;
                        }
                    }
                }
                if n > 0 {
                    pixels[i] = acc.map(|a| a / n as f32);
                    filled[i] = true;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mannequin_mesh::UvLayout;

    #[test]
    fn baking_a_quad_covers_its_uv_square_and_dilates_past_it() {
        let subject = Subject::random(3, 4);
        let uv = UvLayout {
            coords: vec![[0.25, 0.25], [0.75, 0.25], [0.75, 0.75], [0.25, 0.75]],
            faces: vec![[0, 1, 2], [0, 2, 3]],
        };
        let faces = [[0, 1, 2], [0, 2, 3]];
        let skin = |x: f32, y: f32| SurfacePoint { position: Vec3::new(x, y, 0.0), layers: [0.0; 4] };
        let points = [skin(0.0, 0.0), skin(0.1, 0.0), skin(0.1, 0.1), skin(0.0, 0.1)];
        let tex = bake(&BakeInput { uv: &uv, faces: &faces, points: &points }, &subject, Vec3::ZERO, 32, 32);
        // Inside: skin-like (close to the subject's skin tone); far outside: untouched black.
        let inside = tex.at(16, 16);
        for c in 0..3 {
            assert!((inside[c] - subject.skin[c]).abs() < 0.1, "{inside:?} vs {:?}", subject.skin);
        }
        assert_eq!(tex.at(0, 0), [0.0; 3]);
        // Two texels beyond the island's edge (texel 24 is the first outside) are dilated.
        assert_ne!(tex.at(25, 16), [0.0; 3]);
    }
}
