//! Tile binning on the device, with the CPU binning's rule and order (`tiles.rs`): each 16×16
//! tile lists the Gaussians that can reach one of its pixels, front to back, ties by index.
//!
//! The steps (as gsplat and 3DGS do it):
//! 1. a depth key per Gaussian (`u32::MAX` for those not listed), sorted stably with the
//!    Gaussian indices as values: the depth order, ties by index;
//! 2. in that order, each Gaussian counts the tiles it reaches; an exclusive prefix sum places
//!    its entries (the total is the one word read back, to size the lists);
//! 3. each Gaussian writes `(tile, Gaussian)` for its tiles, still in depth order;
//! 4. a stable sort by tile keeps the depth order within each tile;
//! 5. each tile finds where its run starts by a binary search.
//!
//! The tile rectangle is computed exactly as the CPU's `f64` arithmetic (see [`span`]). The
//! ellipse test that drops tiles a faint or elongated splat cannot reach is evaluated in `f32`
//! here and in `f64` on the CPU; a tile whose nearest pixel sits within rounding of the alpha
//! level could in principle be listed on one side only. That changes no pixel: the level carries
//! a 1% slack in alpha, so the pixels of such a tile are skipped by the compositor either way.

// `!(σ > level)` keeps the CPU's answer for NaN (listed); kernels have no `partial_cmp`.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use burn::backend::ops::FloatTensorOps;
use burn::backend::wgpu::{CubeBackend, CubeTensor};
use burn_cubecl::cubecl;
use cubecl::prelude::*;

use super::SplatConfig;
use super::device_buffers::{buffer, read, u32_of, units_dim, units_grid, upload};
use super::radix_sort::sort_pairs;
use super::scan::exclusive_scan;
use crate::composite::field;
use crate::tiles::CULL_SLACK;

/// The image and the alpha level, as the binning kernels read them.
#[derive(CubeLaunch, CubeType, Clone, Copy)]
pub(crate) struct Grid {
    pub width: u32,
    pub height: u32,
    pub tiles_x: u32,
    pub tiles_y: u32,
    /// `CULL_SLACK − ln(threshold)`: a Gaussian of opacity `o` reaches the threshold only where
    /// `σ ≤ ln(o) + level_offset`.
    pub level_offset: f32,
}

/// Tiles `[lo, hi)` along one axis.
#[derive(CubeType, Clone, Copy)]
struct Span {
    lo: u32,
    hi: u32,
}

/// The tiles that the box `m ± r` meets along one axis: `floor((m − r)/16)` to
/// `ceil((m + r)/16)`, clamped to `[0, tiles]`, equal to the CPU's `f64` result.
///
/// `r` is a whole number, so `floor((m − r)/16) = floor((floor(m) − r)/16)`, and the difference
/// of two whole `f32`s is exact below 2²⁴; above it, both sides clamp to the same end (for images
/// under 2²⁴ pixels across). The CPU holds radii as `u32`, saturating at `2³² − 1`; that case is
/// `(floor(m) − 2³²) + 1`, again exact where it matters.
#[cube]
fn span(m: f32, r: f32, tiles: u32) -> Span {
    let big = r >= 4_294_967_296.0f32;
    let r = select(big, 4_294_967_296.0f32, r);
    let one = select(big, 1.0f32, 0.0f32);
    let lo = f32::floor((f32::floor(m) - r + one) / 16.0f32);
    let hi = -f32::floor((f32::floor(-m) - r + one) / 16.0f32);
    let top = f32::cast_from(tiles);
    Span {
        lo: u32::cast_from(f32::min(f32::max(lo, 0.0f32), top)),
        hi: u32::cast_from(f32::min(f32::max(hi, 0.0f32), top)),
    }
}

/// `σ(d) = ½(a dx² + c dy²) + b dx dy`, in the CPU's order of operations.
#[cube]
fn sigma(a: f32, b: f32, c: f32, dx: f32, dy: f32) -> f32 {
    0.5f32 * (a * dx * dx + c * dy * dy) + b * dx * dy
}

/// The minimum of σ over `[x0, x1] × [y0, y1]`, as `tiles::min_sigma_on_rect`.
#[cube]
#[allow(clippy::too_many_arguments)]
fn min_sigma_on_rect(a: f32, b: f32, c: f32, x0: f32, x1: f32, y0: f32, y1: f32) -> f32 {
    let mut least = 0.0f32;
    if !(x0 <= 0.0f32 && 0.0f32 <= x1 && y0 <= 0.0f32 && 0.0f32 <= y1) {
        let row0 = sigma(a, b, c, f32::min(f32::max(-b * y0 / a, x0), x1), y0);
        let row1 = sigma(a, b, c, f32::min(f32::max(-b * y1 / a, x0), x1), y1);
        let col0 = sigma(a, b, c, x0, f32::min(f32::max(-b * x0 / c, y0), y1));
        let col1 = sigma(a, b, c, x1, f32::min(f32::max(-b * x1 / c, y0), y1));
        least = f32::min(f32::min(row0, row1), f32::min(col0, col1));
    }
    least
}

/// What the tile loop needs of one Gaussian.
#[derive(CubeType, Clone, Copy)]
struct Footprint {
    x: Span,
    y: Span,
    mx: f32,
    my: f32,
    a: f32,
    b: f32,
    c: f32,
    level: f32,
    /// Whether to test tiles against the ellipse (an alpha threshold, and more than one tile).
    test: bool,
}

#[cube]
fn footprint(
    rows: &[f32],
    radii: &[f32],
    g: u32,
    grid: &Grid,
    #[comptime] stride: usize,
    #[comptime] cull: bool,
) -> Footprint {
    let row = g as usize * stride;
    let mx = rows[row + field::MX];
    let my = rows[row + field::MY];
    let x = span(mx, radii[2 * g as usize], grid.tiles_x);
    let y = span(my, radii[2 * g as usize + 1], grid.tiles_y);
    // A single tile needs no test: the extent box already put the Gaussian there.
    let mut test = false;
    if cull {
        test = x.hi - x.lo > 1 || y.hi - y.lo > 1;
    }
    Footprint {
        x,
        y,
        mx,
        my,
        a: rows[row + field::A],
        b: rows[row + field::B],
        c: rows[row + field::C],
        level: f32::ln(rows[row + field::OPACITY]) + grid.level_offset,
        test,
    }
}

/// Whether some pixel centre of tile `(tx, ty)` can reach the alpha threshold, as
/// `tiles::Footprint::for_each_tile`.
#[cube]
fn reaches(f: &Footprint, tx: u32, ty: u32, grid: &Grid) -> bool {
    let mut inside = true;
    if f.test {
        let x0 = f32::cast_from(tx * 16) + 0.5f32 - f.mx;
        let x1 = f32::cast_from(min((tx + 1) * 16, grid.width)) - 0.5f32 - f.mx;
        let y0 = f32::cast_from(ty * 16) + 0.5f32 - f.my;
        let y1 = f32::cast_from(min((ty + 1) * 16, grid.height)) - 0.5f32 - f.my;
        inside = !(min_sigma_on_rect(f.a, f.b, f.c, x0, x1, y0, y1) > f.level);
    }
    inside
}

/// Each Gaussian's depth key and index: the key is the depth's bit pattern (depths are positive,
/// so the patterns sort as the values), or `u32::MAX` for Gaussians that are not listed (culled,
/// or opacity under the threshold).
#[cube(launch)]
fn depth_keys(
    rows: &[f32],
    radii: &[f32],
    keys: &mut [u32],
    ids: &mut [u32],
    n: u32,
    min_opacity: f32,
    #[comptime] stride: usize,
) {
    let i = ABSOLUTE_POS;
    if i >= n as usize {
        terminate!();
    }
    let row = i * stride;
    let listed = radii[2 * i] > 0.0f32 && rows[row + field::OPACITY] >= min_opacity;
    keys[i] = select(listed, u32::reinterpret(rows[row + field::DEPTH]), u32::MAX);
    ids[i] = i as u32;
}

/// How many tiles the Gaussian of depth rank `r` reaches.
#[cube(launch)]
#[allow(clippy::too_many_arguments)]
fn count_tiles(
    rows: &[f32],
    radii: &[f32],
    keys: &[u32],
    order: &[u32],
    counts: &mut [u32],
    n: u32,
    grid: Grid,
    #[comptime] stride: usize,
    #[comptime] cull: bool,
) {
    let r = ABSOLUTE_POS;
    // The word past the last count is zero, so that the scan leaves the total there.
    if r == n as usize {
        counts[r] = 0u32;
    }
    if r >= n as usize {
        terminate!();
    }
    let mut count = 0u32;
    if keys[r] != u32::MAX {
        let f = footprint(rows, radii, order[r], &grid, stride, cull);
        for ty in f.y.lo..f.y.hi {
            for tx in f.x.lo..f.x.hi {
                if reaches(&f, tx, ty, &grid) {
                    count += 1;
                }
            }
        }
    }
    counts[r] = count;
}

/// The `(tile, Gaussian)` entries of depth rank `r`, from `starts[r]` on.
#[cube(launch)]
#[allow(clippy::too_many_arguments)]
fn write_entries(
    rows: &[f32],
    radii: &[f32],
    keys: &[u32],
    order: &[u32],
    starts: &[u32],
    tiles: &mut [u32],
    gaussians: &mut [u32],
    n: u32,
    grid: Grid,
    #[comptime] stride: usize,
    #[comptime] cull: bool,
) {
    let r = ABSOLUTE_POS;
    if r >= n as usize || keys[r] == u32::MAX {
        terminate!();
    }
    let g = order[r];
    let f = footprint(rows, radii, g, &grid, stride, cull);
    let mut at = starts[r] as usize;
    for ty in f.y.lo..f.y.hi {
        for tx in f.x.lo..f.x.hi {
            if reaches(&f, tx, ty, &grid) {
                tiles[at] = ty * grid.tiles_x + tx;
                gaussians[at] = g;
                at += 1;
            }
        }
    }
}

/// `offsets[t]`: the number of entries of tiles before `t` (a binary search of the sorted
/// tiles).
#[cube(launch)]
fn tile_offsets(tiles: &[u32], offsets: &mut [u32], len: u32, n_tiles: u32) {
    let t = ABSOLUTE_POS as u32;
    if t > n_tiles {
        terminate!();
    }
    let mut lo = 0u32;
    let mut hi = len;
    loop {
        if lo >= hi {
            break;
        }
        let mid = (lo + hi) / 2;
        if tiles[mid as usize] < t {
            lo = mid + 1;
        } else {
            hi = mid;
        }
    }
    offsets[t as usize] = lo;
}

/// The tile lists, as `u32` words on the device.
pub(super) struct DeviceTiles {
    /// `offsets[t]..offsets[t + 1]` indexes `ids` for tile `t`; `n_tiles + 1` words.
    pub offsets: CubeTensor,
    /// Gaussian indices, tile after tile, each tile front to back; `None` when empty.
    pub ids: Option<CubeTensor>,
    pub n_ids: usize,
}

/// The smallest `f32` at or above `threshold`, so that `o ≥ it` in `f32` is `o ≥ threshold` in
/// `f64`, as the CPU compares.
fn min_opacity(threshold: f64) -> f32 {
    let t = threshold as f32;
    if (t as f64) < threshold { t.next_up() } else { t }
}

/// Bins the `n` Gaussians that `project_forward` wrote to `rows` (`stride` words each) and
/// `radii`.
pub(super) fn bin(
    rows: &CubeTensor,
    radii: &CubeTensor,
    n: usize,
    stride: usize,
    config: &SplatConfig,
) -> DeviceTiles {
    let (w, h) = (config.camera.width, config.camera.height);
    let (tiles_x, tiles_y) = config.camera.tiles();
    let n_tiles = tiles_x * tiles_y;
    let threshold = config.options.alpha_threshold;
    let grid = || {
        GridLaunch::new(
            u32_of(w),
            u32_of(h),
            u32_of(tiles_x),
            u32_of(tiles_y),
            (CULL_SLACK - threshold.ln()) as f32,
        )
    };
    let cull = threshold > 0.0;
    let client = rows.client.clone();
    let (mut keys, mut order) = (buffer(n.max(1), rows), buffer(n.max(1), rows));
    // `count_tiles` writes every word of it (one per Gaussian, then the zero past them).
    let counts = if n > 0 { buffer(n + 1, rows) } else { upload(vec![0.0], rows) };
    if n > 0 {
        depth_keys::launch(
            &client,
            units_grid(n),
            units_dim(),
            rows.clone().into_buffer_arg(),
            radii.clone().into_buffer_arg(),
            keys.clone().into_buffer_arg(),
            order.clone().into_buffer_arg(),
            u32_of(n),
            min_opacity(threshold),
            stride,
        );
        (keys, order) = sort_pairs(keys, order, n, u32::BITS);
        count_tiles::launch(
            &client,
            units_grid(n + 1),
            units_dim(),
            rows.clone().into_buffer_arg(),
            radii.clone().into_buffer_arg(),
            keys.clone().into_buffer_arg(),
            order.clone().into_buffer_arg(),
            counts.clone().into_buffer_arg(),
            u32_of(n),
            grid(),
            stride,
            cull,
        );
        exclusive_scan(&counts, n + 1);
    }
    let total = read(CubeBackend::float_slice(counts.clone(), &[(n..n + 1).into()]));
    let n_ids = total[0].to_bits() as usize;
    let (mut tiles, mut ids) = (buffer(n_ids.max(1), rows), buffer(n_ids.max(1), rows));
    if n_ids > 0 {
        write_entries::launch(
            &client,
            units_grid(n),
            units_dim(),
            rows.clone().into_buffer_arg(),
            radii.clone().into_buffer_arg(),
            keys.into_buffer_arg(),
            order.into_buffer_arg(),
            counts.into_buffer_arg(),
            tiles.clone().into_buffer_arg(),
            ids.clone().into_buffer_arg(),
            u32_of(n),
            grid(),
            stride,
            cull,
        );
        let bits = u32::BITS - u32_of(n_tiles.max(2) - 1).leading_zeros();
        (tiles, ids) = sort_pairs(tiles, ids, n_ids, bits);
    }
    let offsets = buffer(n_tiles + 1, rows);
    tile_offsets::launch(
        &client,
        units_grid(n_tiles + 1),
        units_dim(),
        tiles.into_buffer_arg(),
        offsets.clone().into_buffer_arg(),
        u32_of(n_ids),
        u32_of(n_tiles),
    );
    DeviceTiles { offsets, ids: (n_ids > 0).then_some(ids), n_ids }
}

#[cfg(test)]
mod tests {
    use super::super::cube::project;
    use super::super::device_buffers::read;
    use super::super::device_buffers::testing::{device, floats, read_words};
    use super::*;
    use crate::project::Projection;
    use crate::{Camera, RenderOptions, tiles};

    /// A seeded generator (PCG-style LCG), so the scenes are fixed.
    struct Lcg(u64);

    impl Lcg {
        fn uniform(&mut self, lo: f64, hi: f64) -> f32 {
            self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (lo + (hi - lo) * ((self.0 >> 11) as f64 / (1u64 << 53) as f64)) as f32
        }
        fn quat(&mut self) -> [f32; 4] {
            [0; 4].map(|_| self.uniform(-1.0, 1.0))
        }
    }

    /// Gaussians with quaternions and three feature channels.
    #[derive(Default)]
    struct Cloud {
        means: Vec<f32>,
        quats: Vec<f32>,
        scales: Vec<f32>,
        opacities: Vec<f32>,
        features: Vec<f32>,
    }

    impl Cloud {
        fn push(&mut self, mean: [f32; 3], quat: [f32; 4], scale: [f32; 3], opacity: f32) {
            self.means.extend(mean);
            self.quats.extend(quat);
            self.scales.extend(scale);
            self.opacities.push(opacity);
            self.features.extend([0.2, 0.5, 0.8]);
        }
        fn len(&self) -> usize {
            self.opacities.len()
        }
        /// Appends a copy of Gaussian `i` (the same depth: a tie that the index must break).
        fn duplicate(&mut self, i: usize) {
            let mean = std::array::from_fn(|k| self.means[3 * i + k]);
            let quat = std::array::from_fn(|k| self.quats[4 * i + k]);
            let scale = std::array::from_fn(|k| self.scales[3 * i + k]);
            self.push(mean, quat, scale, self.opacities[i]);
        }
    }

    /// The CPU binning (`tiles::bin`) of the device's projection, as per-tile Gaussian indices.
    fn cpu_lists(rows: &[f32], radii: &[f32], stride: usize, config: &SplatConfig) -> (Vec<u32>, Vec<u32>) {
        let n = radii.len() / 2;
        let at = |i: usize, f: usize| rows[i * stride + f];
        let projection = Projection {
            means2d: (0..n).flat_map(|i| [at(i, field::MX), at(i, field::MY)]).collect(),
            conics: (0..n).flat_map(|i| [at(i, field::A), at(i, field::B), at(i, field::C)]).collect(),
            depths: (0..n).map(|i| at(i, field::DEPTH)).collect(),
            radii: radii.iter().map(|&r| r.min(u32::MAX as f32) as u32).collect(),
            colors: Vec::new(),
            skipped: 0,
        };
        let opacities: Vec<f32> = (0..n).map(|i| at(i, field::OPACITY)).collect();
        let (w, h) = (config.camera.width, config.camera.height);
        let t = tiles::bin(&projection, &opacities, config.options.alpha_threshold, w, h);
        let ids = t.ids.iter().map(|&r| t.order[r as usize]).collect();
        (t.offsets.iter().map(|&o| o as u32).collect(), ids)
    }

    /// What a scene's lists look like, for checking that the scene tests what it claims to.
    struct Stats {
        entries: usize,
        longest_list: usize,
        /// How many tiles list each Gaussian.
        tiles_of: Vec<usize>,
        skipped: f32,
    }

    /// Bins `cloud` on the device and on the CPU (from the same projection) and requires the
    /// same lists, tile by tile, in the same order.
    fn same_lists(name: &str, cloud: &Cloud, camera: Camera, options: RenderOptions) -> Stats {
        let config = SplatConfig {
            camera,
            options,
            matrices: false,
            sh_degree: None,
            color_len: 3,
            header: Default::default(),
        };
        let d = device();
        let n = cloud.len();
        let inputs = [
            floats(&cloud.means, vec![n, 3], &d),
            floats(&cloud.quats, vec![n, 4], &d),
            floats(&cloud.scales, vec![n, 3], &d),
            floats(&cloud.opacities, vec![n, 1], &d),
            floats(&cloud.features, vec![n, 3], &d),
        ];
        let p = project(inputs, &config);
        let (want_offsets, want_ids) =
            cpu_lists(&read(p.rows.clone()), &read(p.radii.clone()), p.stride, &config);
        let got = bin(&p.rows, &p.radii, n, p.stride, &config);
        let offsets = read_words(got.offsets, want_offsets.len());
        let ids = got.ids.map(|t| read_words(t, got.n_ids)).unwrap_or_default();
        let list = |o: &[u32], ids: &[u32], t: usize| ids[o[t] as usize..o[t + 1] as usize].to_vec();
        for t in 0..want_offsets.len() - 1 {
            assert_eq!(list(&offsets, &ids, t), list(&want_offsets, &want_ids, t), "{name}: tile {t}");
        }
        assert_eq!(ids.len(), want_ids.len(), "{name}: entries");
        let mut tiles_of = vec![0; n];
        for &g in &ids {
            tiles_of[g as usize] += 1;
        }
        Stats {
            entries: ids.len(),
            longest_list: offsets.windows(2).map(|w| (w[1] - w[0]) as usize).max().unwrap_or(0),
            tiles_of,
            skipped: read(p.skipped)[0],
        }
    }

    fn camera(width: usize, height: usize) -> Camera {
        Camera::look_at([0.3, -0.2, 3.0], [0.0; 3], [0.0, 1.0, 0.0], 0.9, width, height)
    }

    /// Random sizes, shapes and opacities, including opacities on either side of the threshold.
    #[test]
    fn a_random_cloud_bins_as_on_the_cpu() {
        let mut rng = Lcg(3);
        let mut cloud = Cloud::default();
        for _ in 0..400 {
            let mean = [rng.uniform(-1.0, 1.0), rng.uniform(-0.8, 0.8), rng.uniform(-1.0, 1.0)];
            let scale = [0; 3].map(|_| rng.uniform(0.005, 0.2));
            cloud.push(mean, rng.quat(), scale, rng.uniform(0.0, 1.0));
        }
        let t = (1.0f64 / 255.0) as f32;
        for (i, o) in [t.next_down(), t, t.next_up(), 0.0].into_iter().enumerate() {
            cloud.push([0.1 * i as f32, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0], [0.1; 3], o);
        }
        let s = same_lists("random cloud", &cloud, camera(160, 120), RenderOptions::default());
        assert!(s.entries > 2000 && s.longest_list > 50, "{} entries", s.entries);
        let listed = s.tiles_of[400..].iter().map(|&k| k > 0).collect::<Vec<_>>();
        let want = [t.next_down(), t, t.next_up(), 0.0].map(|o| o as f64 >= 1.0 / 255.0);
        assert_eq!(listed, want, "opacities at the threshold");
        assert!(!want[0] && want[2], "the opacities straddle the threshold");
    }

    /// Thin splats on a sphere, many to a tile, with exact copies (equal depths).
    #[test]
    fn a_dense_shell_with_equal_depths_bins_as_on_the_cpu() {
        let mut rng = Lcg(5);
        let mut cloud = Cloud::default();
        for _ in 0..3000 {
            let (u, v) = (rng.uniform(0.0, std::f64::consts::TAU), rng.uniform(-1.0, 1.0).acos());
            let mean = [0.7 * v.sin() * u.cos(), 0.7 * v.cos(), 0.7 * v.sin() * u.sin()];
            cloud.push(mean, rng.quat(), [rng.uniform(0.01, 0.04), rng.uniform(0.01, 0.04), 0.001], 0.9);
        }
        for i in (0..3000).step_by(30) {
            cloud.duplicate(i);
        }
        let s = same_lists("dense shell", &cloud, camera(200, 160), RenderOptions::default());
        assert!(s.longest_list > 200, "longest list {}", s.longest_list);
    }

    /// Gaussians behind the camera, across the near plane and with NaN or infinite parameters are
    /// left out (the non-finite ones counted), the rest binned as on the CPU.
    #[test]
    fn gaussians_behind_the_camera_or_not_finite_are_left_out() {
        let mut rng = Lcg(7);
        let mut cloud = Cloud::default();
        for i in 0..300 {
            // The camera sits at z ≈ 3 looking down −z: half of them behind it, some around it.
            let z = match i % 3 {
                0 => rng.uniform(3.2, 6.0),
                1 => rng.uniform(2.9, 3.1),
                _ => rng.uniform(-1.0, 1.0),
            };
            let mean = [rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), z];
            cloud.push(mean, rng.quat(), [0; 3].map(|_| rng.uniform(0.02, 0.3)), rng.uniform(0.2, 1.0));
        }
        cloud.means[0] = f32::NAN;
        cloud.scales[5] = f32::INFINITY;
        cloud.opacities[9] = f32::NEG_INFINITY;
        cloud.features[3 * 12 + 2] = f32::NAN;
        let s = same_lists("behind the camera", &cloud, camera(128, 96), RenderOptions::default());
        assert_eq!(s.skipped, 4.0);
        assert_eq!(s.tiles_of.iter().step_by(3).filter(|&&k| k > 0).count(), 0, "behind the camera");
        assert!(s.entries > 200, "{} entries", s.entries);
    }

    /// Splats near the camera that cover most of the image, long thin ones that the ellipse
    /// test trims, and some centred off screen.
    #[test]
    fn huge_splats_bin_as_on_the_cpu() {
        let mut rng = Lcg(9);
        let mut cloud = Cloud::default();
        for i in 0..80 {
            let mean = [rng.uniform(-2.5, 2.5), rng.uniform(-2.0, 2.0), rng.uniform(-1.0, 2.5)];
            let scale = if i % 2 == 0 {
                [0; 3].map(|_| rng.uniform(0.3, 3.0))
            } else {
                [rng.uniform(1.0, 4.0), 0.01, 0.01]
            };
            cloud.push(mean, rng.quat(), scale, rng.uniform(0.02, 1.0));
        }
        let s = same_lists("huge splats", &cloud, camera(256, 192), RenderOptions::default());
        let all = 16 * 12;
        assert!(s.tiles_of.iter().filter(|&&k| k == all).count() > 5, "{:?}", s.tiles_of);
        assert!(s.tiles_of.iter().filter(|&&k| k > 0 && k < all / 4).count() > 5, "{:?}", s.tiles_of);
    }

    /// Without an alpha threshold a Gaussian has no extent: every visible one is in every tile.
    #[test]
    fn without_a_threshold_every_tile_lists_every_visible_gaussian() {
        let mut rng = Lcg(11);
        let mut cloud = Cloud::default();
        for _ in 0..40 {
            let mean = [rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)];
            cloud.push(mean, rng.quat(), [0.05; 3], rng.uniform(0.0, 1.0));
        }
        let options = RenderOptions::default().without_cutoffs();
        let s = same_lists("no threshold", &cloud, camera(80, 48), options);
        assert!(s.tiles_of.iter().all(|&k| k == 0 || k == 15), "{:?}", s.tiles_of);
        assert!(s.tiles_of.iter().filter(|&&k| k == 15).count() > 30);
    }
}
