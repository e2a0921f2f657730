//! A random person: body shape, outfit and garment looks, all drawn from one seed.

use serde::Serialize;

use mannequin_io::rng::SplitMix64;

/// The clothing variants, each a few garments of the library (see [`Outfit::garments`]); the
/// skirt and the dress bridge the legs, so the body model alone cannot explain the silhouette.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Outfit {
    TightShirtTrousers,
    LooseShirtTrousers,
    ShirtSkirt,
    Dress,
}

pub const OUTFITS: [Outfit; 4] =
    [Outfit::TightShirtTrousers, Outfit::LooseShirtTrousers, Outfit::ShirtSkirt, Outfit::Dress];

/// A procedural print, evaluated on the rest-pose surface so it continues across UV seams.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Pattern {
    /// Bands of `period` metres across `direction`.
    Stripes { direction: [f32; 3], period: f32 },
    /// A two-colour checkerboard of `cell` metres.
    Checks { cell: f32 },
    /// Jittered dots of `radius` on a grid of `cell`.
    Dots { cell: f32, radius: f32 },
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GarmentLook {
    pub base: [f32; 3],
    pub accent: [f32; 3],
    pub pattern: Pattern,
    /// Rows of text-like glyphs printed on the front.
    pub text_rows: u32,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Subject {
    pub seed: u64,
    pub betas: Vec<f32>,
    pub outfit: Outfit,
    pub skin: [f32; 3],
    pub hair: [f32; 3],
    pub shoes: [f32; 3],
    pub top: GarmentLook,
    pub bottom: GarmentLook,
}

fn colour(rng: &mut SplitMix64, lo: f64, hi: f64) -> [f32; 3] {
    [0; 3].map(|_| rng.range(lo, hi) as f32)
}

fn look(rng: &mut SplitMix64) -> GarmentLook {
    let base = colour(rng, 0.1, 0.8);
    // The accent contrasts with the base in brightness, so the print is visible.
    let accent = base.map(|c| if c > 0.45 { c - 0.35 } else { c + 0.35 });
    let pattern = match rng.below(3) {
        0 => {
            let (a, b) = (rng.range(-0.6, 0.6), rng.range(0.0, std::f64::consts::TAU));
            let direction = [(a.cos() * b.cos()) as f32, a.sin() as f32, (a.cos() * b.sin()) as f32];
            Pattern::Stripes { direction, period: rng.range(0.015, 0.05) as f32 }
        }
        1 => Pattern::Checks { cell: rng.range(0.02, 0.05) as f32 },
        _ => {
            let cell = rng.range(0.02, 0.045) as f32;
            Pattern::Dots { cell, radius: cell * rng.range(0.2, 0.35) as f32 }
        }
    };
    GarmentLook { base, accent, pattern, text_rows: rng.below(3) as u32 }
}

impl Subject {
    /// The subject of `seed`, with `num_betas` shape coefficients (the model's count, at most 10).
    pub fn random(seed: u64, num_betas: usize) -> Self {
        let mut rng = SplitMix64::new(seed ^ 0x5EED_0F5B_1EC7);
        let betas = (0..num_betas).map(|k| (rng.normal() * if k < 2 { 0.8 } else { 0.4 }) as f32).collect();
        let outfit = OUTFITS[rng.below(OUTFITS.len())];
        let tone = rng.range(0.25, 0.85) as f32;
        let skin = [0.35 + 0.6 * tone, 0.25 + 0.5 * tone, 0.18 + 0.42 * tone];
        let hair = colour(&mut rng, 0.03, 0.35);
        let shoes = colour(&mut rng, 0.05, 0.3);
        let top = look(&mut rng);
        let bottom = look(&mut rng);
        Self { seed, betas, outfit, skin, hair, shoes, top, bottom }
    }
}
