//! The CPU renderer: projection, binning, per-tile compositing, and the backward pass that
//! replays it. Tiles run in parallel (rayon); each worker reuses its scratch, so there is no
//! allocation per pixel or per tile.

use rayon::prelude::*;

use crate::camera::{Camera, CameraParams};
use crate::composite::{Packed, Rule, TILE_PIXELS, TileOut, TileRect, composite_tile, field};
use crate::composite_vjp::{Replay, SCREEN_GRADS, TileGrads, composite_tile_vjp};
use crate::gaussians::{GaussianGrads, Gaussians};
use crate::planes::TilePlanes;
use crate::project::{DILATION, GradRow, ScreenGrad, project, project_vjp};
use crate::real::Real;
use crate::tiles::{Tiles, bin};
use crate::{SplatError, TILE, sh};

/// Alpha below which expected depth is not divided further (as gsplat's `clamp_min(1e-10)`).
const MIN_ALPHA_FOR_DEPTH: f64 = 1e-10;

/// How pixels are composed. The defaults are the 3DGS rules.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderOptions {
    /// Background, one value per channel; empty means zeros.
    pub background: Vec<f64>,
    /// A Gaussian is skipped at a pixel where its alpha is below this (1/255).
    pub alpha_threshold: f64,
    /// Alpha is capped here (0.99).
    pub max_alpha: f64,
    /// A pixel stops before the Gaussian that would bring its transmittance to this or below (1e-4).
    pub min_transmittance: f64,
    /// Also return how many Gaussians each pixel composited.
    pub count_contributors: bool,
    /// Variance (px²) added to every screen-space covariance: the low-pass filter that keeps
    /// sub-pixel Gaussians from falling between pixel centres ([`DILATION`], 0.3, as 3DGS).
    /// It also widens every silhouette by about `sqrt(2 ln 2 · dilation)` px at alpha ½.
    pub dilation: f64,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            background: Vec::new(),
            alpha_threshold: 1.0 / 255.0,
            max_alpha: 0.99,
            min_transmittance: 1e-4,
            count_contributors: false,
            dilation: DILATION,
        }
    }
}

impl RenderOptions {
    /// The same rule without the hard cutoffs (no alpha threshold, no early stop, so no screen
    /// extent either): the image is then a smooth function of every parameter, which is what
    /// finite-difference checks need. Alpha is still capped.
    pub fn without_cutoffs(mut self) -> Self {
        self.alpha_threshold = 0.0;
        self.min_transmittance = 0.0;
        self
    }

    fn validate(&self, channels: usize) -> Result<(), SplatError> {
        let err = |m: String| Err(SplatError::Options(m));
        if !self.background.is_empty() && self.background.len() != channels {
            return err(format!("background has {} values for {channels} channels", self.background.len()));
        }
        if self.background.iter().any(|v| !v.is_finite()) {
            return err(format!("background {:?} is not finite", self.background));
        }
        if !(0.0..1.0).contains(&self.alpha_threshold) {
            return err(format!("alpha_threshold {} is outside [0, 1)", self.alpha_threshold));
        }
        if !(self.max_alpha > 0.0 && self.max_alpha < 1.0) {
            return err(format!("max_alpha {} is outside (0, 1)", self.max_alpha));
        }
        if !(0.0..1.0).contains(&self.min_transmittance) {
            return err(format!("min_transmittance {} is outside [0, 1)", self.min_transmittance));
        }
        if !(self.dilation.is_finite() && self.dilation >= 0.0) {
            return err(format!("dilation {} px² is not a finite variance >= 0", self.dilation));
        }
        Ok(())
    }

    fn rule<T: Real>(&self) -> Rule<T> {
        Rule {
            threshold: T::from_f64(self.alpha_threshold),
            max_alpha: T::from_f64(self.max_alpha),
            min_transmittance: T::from_f64(self.min_transmittance),
        }
    }

    fn background_of<T: Real>(&self, channels: usize) -> Vec<T> {
        (0..channels).map(|c| T::from_f64(self.background.get(c).copied().unwrap_or(0.0))).collect()
    }
}

/// What [`render`] produces. Images are planar, row-major, with pixel `(x, y)` at `y * width + x`.
#[derive(Clone, Debug)]
pub struct RenderOutput<T> {
    pub width: usize,
    pub height: usize,
    pub channels: usize,
    /// `C × H × W` composited colour or features, background included.
    pub image: Vec<T>,
    /// `H × W` accumulated opacity `1 − T_N`.
    pub alpha: Vec<T>,
    /// `H × W` expected depth `Σ wᵢ zᵢ / alpha` (camera z), 0 where nothing was drawn.
    pub depth: Vec<T>,
    /// `H × W` number of Gaussians composited per pixel, if asked for.
    pub count: Option<Vec<u32>>,
    /// Gaussians skipped because a parameter was NaN or infinite.
    pub skipped: usize,
    pub(crate) saved: Saved<T>,
}

/// What [`backward`] needs from the forward pass besides the images.
#[derive(Clone, Debug)]
pub(crate) struct Saved<T> {
    pub prep: Prepared<T>,
    /// `H × W` length of the pixel's tile list that compositing consumed; the backward pass
    /// replays exactly that much.
    pub last: Vec<u32>,
}

/// Gradients of a scalar loss with respect to the outputs of [`render`]; `None` means zero.
#[derive(Clone, Copy, Debug, Default)]
pub struct OutputGrads<'a, T> {
    pub image: Option<&'a [T]>,
    pub alpha: Option<&'a [T]>,
    pub depth: Option<&'a [T]>,
}

/// What both passes derive from the inputs before compositing; [`render`] keeps it in its output
/// so that [`backward`] does not redo it.
#[derive(Clone, Debug)]
pub(crate) struct Prepared<T> {
    pub packed: Packed<T>,
    pub tiles: Tiles,
}

/// Checks the camera, options and array shapes, and with `values` also each Gaussian's domain.
/// The tensor path skips the per-value check (it would cost a device read-back); there a
/// Gaussian outside its domain is rendered by the same formulas, never panicking.
pub(crate) fn validate<T: Real>(
    g: &Gaussians<T>,
    camera: &Camera,
    opts: &RenderOptions,
    values: bool,
) -> Result<(), SplatError> {
    camera.validate()?;
    g.validate_shapes()?;
    if values {
        g.validate_values()?;
    }
    opts.validate(g.channels())
}

pub(crate) fn prepare<T: Real>(
    g: &Gaussians<T>,
    camera: &Camera,
    opts: &RenderOptions,
    values: bool,
) -> Result<(Prepared<T>, usize), SplatError> {
    validate(g, camera, opts, values)?;
    let projection = project(g, &CameraParams::new(camera), opts.alpha_threshold, opts.dilation);
    let tiles = bin(&projection, g.opacities, opts.alpha_threshold, camera.width, camera.height);
    let packed = Packed::new(&projection, g.opacities, g.channels(), opts.alpha_threshold, &tiles.order);
    Ok((Prepared { packed, tiles }, projection.skipped))
}

/// Screen-space projection alone (means, conics, depths, radii, colours), for inspection and for
/// checks against other implementations.
pub fn project_gaussians<T: Real>(
    g: &Gaussians<T>,
    camera: &Camera,
    opts: &RenderOptions,
) -> Result<crate::Projection<T>, SplatError> {
    validate(g, camera, opts, true)?;
    Ok(project(g, &CameraParams::new(camera), opts.alpha_threshold, opts.dilation))
}

/// Renders the Gaussians through the camera.
pub fn render<T: Real>(
    g: &Gaussians<T>,
    camera: &Camera,
    opts: &RenderOptions,
) -> Result<RenderOutput<T>, SplatError> {
    render_checked(g, camera, opts, true)
}

/// [`render`], checking per-Gaussian domains only if `values`.
pub(crate) fn render_checked<T: Real>(
    g: &Gaussians<T>,
    camera: &Camera,
    opts: &RenderOptions,
    values: bool,
) -> Result<RenderOutput<T>, SplatError> {
    let (prep, skipped) = prepare(g, camera, opts, values)?;
    let (w, h, ch) = (camera.width, camera.height, g.channels());
    let tiles = &prep.tiles;
    let rule = opts.rule::<T>();
    let npx = w * h;
    let mut image = vec![T::ZERO; ch * npx];
    let mut transmittance = vec![T::ONE; npx];
    let mut depth = vec![T::ZERO; npx];
    let mut last = vec![0u32; npx];
    let mut count = vec![0u32; if opts.count_contributors { npx } else { 0 }];
    {
        let planes = (
            TilePlanes::new(&mut image, w, h),
            TilePlanes::new(&mut transmittance, w, h),
            TilePlanes::new(&mut depth, w, h),
            TilePlanes::new(&mut last, w, h),
            TilePlanes::new(&mut count, w, h),
        );
        (0..tiles.tiles_x * tiles.tiles_y).into_par_iter().for_each_init(
            || TileOut::new(ch),
            |out, tile| {
                let rect = TileRect::new(tiles, tile, w, h);
                composite_tile(rect, tiles.list(tile), &prep.packed, &rule, out);
                // SAFETY: every tile index is visited once, and tiles are disjoint.
                unsafe {
                    for c in 0..ch {
                        planes.0.write(&rect, c, &out.color[c * TILE_PIXELS..(c + 1) * TILE_PIXELS]);
                    }
                    planes.1.write(&rect, 0, &out.transmittance);
                    planes.2.write(&rect, 0, &out.depth);
                    planes.3.write(&rect, 0, &out.last);
                    if opts.count_contributors {
                        planes.4.write(&rect, 0, &out.count);
                    }
                }
            },
        );
    }
    let bg = opts.background_of::<T>(ch);
    image.par_chunks_mut(npx).zip(bg.par_iter()).for_each(|(plane, &b)| {
        for (v, &t) in plane.iter_mut().zip(&transmittance) {
            *v += t * b;
        }
    });
    let alpha: Vec<T> = transmittance.par_iter().map(|&t| T::ONE - t).collect();
    let min_a = T::from_f64(MIN_ALPHA_FOR_DEPTH);
    depth.par_iter_mut().zip(&alpha).for_each(|(d, &a)| *d = *d / a.max(min_a));
    let count = opts.count_contributors.then_some(count);
    Ok(RenderOutput {
        width: w,
        height: h,
        channels: ch,
        image,
        alpha,
        depth,
        count,
        skipped,
        saved: Saved { prep, last },
    })
}

/// Gradients of a loss with respect to every input, given the loss's gradients with respect to
/// the outputs `out` of [`render`]. The inputs must be the ones `out` was rendered from: the
/// projection and tile lists are taken from `out` rather than recomputed.
pub fn backward<T: Real>(
    g: &Gaussians<T>,
    camera: &Camera,
    opts: &RenderOptions,
    out: &RenderOutput<T>,
    grads: &OutputGrads<T>,
) -> Result<GaussianGrads<T>, SplatError> {
    backward_checked(g, camera, opts, out, grads, true)
}

/// [`backward`], checking per-Gaussian domains only if `values`.
pub(crate) fn backward_checked<T: Real>(
    g: &Gaussians<T>,
    camera: &Camera,
    opts: &RenderOptions,
    out: &RenderOutput<T>,
    grads: &OutputGrads<T>,
    values: bool,
) -> Result<GaussianGrads<T>, SplatError> {
    validate(g, camera, opts, values)?;
    let prep = &out.saved.prep;
    let (w, h, ch) = (camera.width, camera.height, g.channels());
    let npx = w * h;
    if prep.tiles.order.iter().any(|&i| i as usize >= g.len()) || prep.packed.stride != field::COLOR + ch {
        return Err(SplatError::Options(
            "backward: the forward output was rendered from other Gaussians".into(),
        ));
    }
    let check = |field: &'static str, len: usize, per: usize| {
        if len == per * npx {
            Ok(())
        } else {
            Err(SplatError::Shape { field, expected: per * npx, found: len })
        }
    };
    check("forward image", out.image.len(), ch)?;
    check("forward alpha", out.alpha.len(), 1)?;
    check("forward depth", out.depth.len(), 1)?;
    check("forward contributor ends", out.saved.last.len(), 1)?;
    if let Some(d) = grads.image {
        check("image gradient", d.len(), ch)?;
    }
    if let Some(d) = grads.alpha {
        check("alpha gradient", d.len(), 1)?;
    }
    if let Some(d) = grads.depth {
        check("depth gradient", d.len(), 1)?;
    }
    // Expected depth E = D / max(A, ε): pass its gradient on to D and A.
    let min_a = T::from_f64(MIN_ALPHA_FOR_DEPTH);
    let mut d_acc = vec![T::ZERO; npx];
    let mut d_alpha = grads.alpha.map_or_else(|| vec![T::ZERO; npx], <[T]>::to_vec);
    let mut depth_acc = vec![T::ZERO; npx];
    if let Some(gd) = grads.depth {
        (d_acc.par_iter_mut(), d_alpha.par_iter_mut(), depth_acc.par_iter_mut())
            .into_par_iter()
            .enumerate()
            .for_each(|(i, (da, dal, dacc))| {
                let (a, e) = (out.alpha[i], out.depth[i]);
                let am = a.max(min_a);
                *dacc = e * am;
                *da = gd[i] / am;
                if a > min_a {
                    *dal -= gd[i] * e / am;
                }
            });
    } else {
        depth_acc.par_iter_mut().enumerate().for_each(|(i, d)| *d = out.depth[i] * out.alpha[i].max(min_a));
    }

    let tiles = &prep.tiles;
    let stride = SCREEN_GRADS + ch;
    let rule = opts.rule::<T>();
    // Each (tile, Gaussian) entry of the tile lists gets its own row, so tiles write disjoint
    // memory in parallel; the rows are then summed per Gaussian in tile order, which makes the
    // gradient bit-identical whichever thread ran which tile.
    let mut entries = vec![T::ZERO; tiles.ids.len() * stride];
    let mut rows: Vec<(usize, &mut [T])> = Vec::with_capacity(tiles.tiles_x * tiles.tiles_y);
    let mut rest = entries.as_mut_slice();
    for tile in 0..tiles.tiles_x * tiles.tiles_y {
        let (head, tail) = rest.split_at_mut(tiles.list(tile).len() * stride);
        rows.push((tile, head));
        rest = tail;
    }
    rows.into_par_iter().for_each_init(
        || (TileGrads::new(ch), Replay::new(ch)),
        |(px, replay), (tile, rows)| {
            let list = tiles.list(tile);
            if list.is_empty() {
                return;
            }
            let rect = TileRect::new(tiles, tile, w, h);
            px.last.fill(0);
            for r in 0..rect.h {
                for c in 0..rect.w {
                    let (y, x, p) = (rect.y0 + r, rect.x0 + c, r * TILE + c);
                    let i = y * w + x;
                    px.last[p] = out.saved.last[i];
                    px.transmittance[p] = T::ONE - out.alpha[i];
                    px.d_alpha[p] = d_alpha[i];
                    px.d_depth[p] = d_acc[i];
                    px.depth[p] = depth_acc[i];
                    for k in 0..ch {
                        px.color[k * TILE_PIXELS + p] = out.image[k * npx + i];
                        px.d_color[k * TILE_PIXELS + p] = grads.image.map_or(T::ZERO, |d| d[k * npx + i]);
                    }
                }
            }
            composite_tile_vjp(rect, list, &prep.packed, &rule, px, replay, rows);
        },
    );
    Ok(screen_vjp(g, camera, opts.dilation, tiles, &entries, ch))
}

/// Each rank's entries in the tile lists, in tile order: entry indices grouped by rank
/// (`entries[start[r]..start[r + 1]]`), by a counting sort.
fn entries_by_rank(ids: &[u32], ranks: usize) -> (Vec<usize>, Vec<u32>) {
    let mut start = vec![0usize; ranks + 1];
    for &r in ids {
        start[r as usize + 1] += 1;
    }
    for r in 0..ranks {
        start[r + 1] += start[r];
    }
    let mut next = start.clone();
    let mut entries = vec![0u32; ids.len()];
    for (e, &r) in ids.iter().enumerate() {
        entries[next[r as usize]] = e as u32;
        next[r as usize] += 1;
    }
    (start, entries)
}

/// Chains screen-space gradients back to every Gaussian's parameters. `rows` hold
/// `SCREEN_GRADS + channels` values per entry of the tile lists; each Gaussian sums its own
/// entries in tile order.
pub(crate) fn screen_vjp<T: Real>(
    g: &Gaussians<T>,
    camera: &Camera,
    dilation: f64,
    tiles: &Tiles,
    rows: &[T],
    channels: usize,
) -> GaussianGrads<T> {
    let n = g.len();
    let stride = SCREEN_GRADS + channels;
    let (start, by_rank) = entries_by_rank(&tiles.ids, tiles.order.len());
    let mut rank = vec![u32::MAX; n];
    for (r, &i) in tiles.order.iter().enumerate() {
        rank[i as usize] = r as u32;
    }
    let (cam, dil) = (CameraParams::new(camera), T::from_f64(dilation));
    let mut out_grads = GaussianGrads::zeros_like(g);
    let (rot_n, col_n) = (out_grads.rotations.len() / n.max(1), out_grads.colors.len() / n.max(1));
    let GaussianGrads { means, rotations, scales, opacities, colors } = &mut out_grads;
    means
        .par_chunks_mut(3)
        .zip(rotations.par_chunks_mut(rot_n.max(1)))
        .zip(scales.par_chunks_mut(3))
        .zip(opacities.par_chunks_mut(1))
        .zip(colors.par_chunks_mut(col_n.max(1)))
        .enumerate()
        .for_each_init(
            || (vec![T::ZERO; stride], vec![T::ZERO; sh::basis_len(sh::MAX_DEGREE)]),
            |(sum, basis), (i, ((((m, r), s), o), c))| {
                let at = rank[i] as usize;
                if at == u32::MAX as usize {
                    return;
                }
                sum.fill(T::ZERO);
                for &e in &by_rank[start[at]..start[at + 1]] {
                    let row = &rows[e as usize * stride..(e as usize + 1) * stride];
                    sum.iter_mut().zip(row).for_each(|(s, &v)| *s += v);
                }
                // Gaussians that reached no pixel have zero gradient.
                if sum.iter().all(|&v| v == T::ZERO) {
                    return;
                }
                let sg =
                    ScreenGrad { mean2d: [sum[0], sum[1]], conic: [sum[2], sum[3], sum[4]], depth: sum[6] };
                let row = GradRow { means: m, rotations: r, scales: s, opacity: o, colors: c };
                project_vjp(g, &cam, dil, i, &sg, &sum[SCREEN_GRADS..], sum[5], basis, row);
            },
        );
    out_grads
}
