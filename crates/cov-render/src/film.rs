//! The film: where samples land, and how they become pixels.
//!
//! Each pixel keeps the sums of its own samples, split into the emission of lights seen
//! directly and the light reflected by surfaces ([`crate::trace::radiance_parts`]), and
//! the sample statistics of their luminance. Reconstruction ([`Film::image`]) is then a
//! pass over pixels: emission stays in its pixel (box), and each pixel's reflected sum is
//! splatted into the pixels around it with **its own** normalised Gaussian filter; a
//! pixel's value is its emission mean plus the splatted sums over the splatted sample
//! counts,
//!
//! ```text
//! I_i = E_i / n_i + Σ_j G_j(c_i − c_j) S_j / Σ_j G_j(c_i − c_j) n_j,
//! ```
//!
//! with `c` the pixel centres, `S_j` the reflected sum and `n_j` the count of pixel `j`.
//! A wide filter spreads a pixel thinly; a narrow one ([`MIN_FILTER_STD`]) keeps it in
//! place (a neighbour one pixel away weighs 0.4%): the box estimate. Splatting whole pixels
//! rather than samples costs the footprint once per pixel instead of once per sample and
//! differs only by where inside a pixel the samples fell (under the narrowest filter).
//!
//! Rendering goes tile by tile over rayon and reconstruction band by band; both add their
//! parts in a fixed order, so images do not depend on the thread count.

use std::ops::Range;

use glam::DVec3;
use rayon::prelude::*;

use crate::sampler::{MAX_INDEX, Sampler, SobolSampler};
use crate::trace::{luminance, radiance_parts};
use crate::world::World;

/// Tile side (px): the unit of work of rendering and of the covariance pass.
pub const TILE: u32 = 16;
/// Largest number of samples one pixel takes.
pub const MAX_SPP: u32 = 1 << 16;

/// A linear RGB image.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width (px).
    pub width: u32,
    /// Height (px).
    pub height: u32,
    /// Pixels, row by row from the top.
    pub pixels: Vec<DVec3>,
}

impl Image {
    /// A black image.
    pub fn new(width: u32, height: u32) -> Image {
        Image {
            width,
            height,
            pixels: vec![DVec3::ZERO; width as usize * height as usize],
        }
    }

    /// Pixel `(x, y)`.
    pub fn get(&self, x: u32, y: u32) -> DVec3 {
        self.pixels[y as usize * self.width as usize + x as usize]
    }

    /// A digest of the image's exact values: FNV-1a (64 bits) of its size and of every
    /// pixel's `f64` bits. Two images with one digest are, in practice, the same bits
    /// (`covtrace render` and `covtrace merge` print it; their EXR files, compressed in
    /// parallel, may order their bytes differently).
    pub fn digest(&self) -> u64 {
        use std::hash::Hasher;
        let mut h = fnv::FnvHasher::default();
        h.write_u32(self.width);
        h.write_u32(self.height);
        for p in &self.pixels {
            for v in p.to_array() {
                h.write_u64(v.to_bits());
            }
        }
        h.finish()
    }
}

/// The tiles of a `width × height` image: (x0, y0, x1, y1), row by row.
pub fn tiles(width: u32, height: u32) -> Vec<(u32, u32, u32, u32)> {
    let mut out = Vec::new();
    for y0 in (0..height).step_by(TILE as usize) {
        for x0 in (0..width).step_by(TILE as usize) {
            out.push((x0, y0, (x0 + TILE).min(width), (y0 + TILE).min(height)));
        }
    }
    out
}

/// Number of tiles of the world's image (what [`Progress`] counts to, once per pass).
pub fn tile_count(world: &World) -> usize {
    tiles(world.camera.width, world.camera.height).len()
}

/// Called once per finished tile (to drive a progress bar).
pub type Progress<'a> = Option<&'a (dyn Fn() + Sync)>;

/// Largest filter std the film accepts (px); larger ones are clamped. Bounds the margin
/// a band splats into (3 std).
pub const MAX_FILTER_STD: f64 = 16.0;
/// Smallest filter std (px): a pixel one pixel away weighs `exp(−1/(2·0.3²))` = 0.4% of
/// the pixel itself, so the narrowest filter is the box estimate.
pub const MIN_FILTER_STD: f64 = 0.3;
/// A Gaussian is cut at this many standard deviations (its weight there is 1.1%).
pub const CUTOFF: f64 = 3.0;
/// The reach (px) of the neighbourhood over which [`Film::variance_of_mean`] pools its
/// split estimates: 9×9 pixels, 81 degrees of freedom, so that the pooled ratio's
/// relative standard deviation is about `√(2/81)` = 16% (Gaussian noise); 3×3 pixels
/// would give 47%.
pub const SPLIT_REACH: usize = 4;
/// **Blocks**: the least filter std (px), per pixel of a block's side, at
/// which a square block of pixels that share one filter splats as one source. Such a
/// filter is wide (it was chosen where the image is smooth), and its cost is its area:
/// a block of `b × b` pixels splats the sum of its values once, from its centre, with the
/// filter narrowed by the spread of the block's pixels about it (`(b² − 1)/12` px² on
/// each axis, the variance of `b` evenly spaced offsets), so that the mean splat has
/// the filter's covariance. It costs `1/b²` of the pixels' splats. What differs is the
/// shape: pixel `p`'s samples land around the block's centre instead of around `p`, at
/// most `(b − 1)/√2` px away, and where the block's values vary linearly, the splat of
/// their sum misses the first moment of that variation; both are small against a std of
/// at least `1.5 b` px (3 px for 2×2, 6 px for 4×4). Measured on the bundled scenes in
/// docs/render-bench.md ("Splats of blocks"). A block splats whole only where every pixel
/// has samples and the same filter (the covariance grid gives a block of 4×4 pixels one
/// matched filter; the edges narrow some of them).
const BLOCK_STD: f64 = 1.5;

/// Tiles rendered between two merges into the film (bounds the memory of tile results).
const BATCH: usize = 64;

/// A normalised 2D Gaussian filter in pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gaussian {
    /// Precision (inverse covariance) `xx, xy, yy` (1/px²).
    precision: [f64; 3],
    /// `1 / (2π √det C)`.
    norm: f64,
    /// Larger std (px).
    std_max: f64,
    /// Rows the [`CUTOFF`] ellipse reaches above and below its centre.
    reach_rows: usize,
    /// `exp(−precision_xx)`: the recurrence factor of [`Gaussian::row_weights`].
    decay: f64,
}

impl Gaussian {
    /// The Gaussian of covariance `[xx, xy, yy]` (px²), its eigenvalues clamped to
    /// `[MIN_FILTER_STD², MAX_FILTER_STD²]`. A non-finite input gives the narrowest filter.
    pub fn from_cov(c: [f64; 3]) -> Gaussian {
        let c = if c.iter().all(|v| v.is_finite()) {
            c
        } else {
            [0.0; 3]
        };
        // Eigen-decomposition of the symmetric 2×2.
        let (a, b, d) = (c[0], c[1], c[2]);
        let mean = 0.5 * (a + d);
        let r = (0.25 * (a - d) * (a - d) + b * b).sqrt();
        let (l1, l2) = (mean + r, mean - r);
        // Unit eigenvector of l1.
        let (vx, vy) = if b.abs() > 1e-300 {
            let (x, y) = (l1 - d, b);
            // A plain square root; `hypot` only where the squares overflow (entries
            // beyond about 1e154) or underflow to 0.
            let n = match (x * x + y * y).sqrt() {
                n if n.is_finite() && n > 0.0 => n,
                _ => x.hypot(y),
            };
            (x / n, y / n)
        } else if a >= d {
            (1.0, 0.0)
        } else {
            (0.0, 1.0)
        };
        let lo = MIN_FILTER_STD * MIN_FILTER_STD;
        let hi = MAX_FILTER_STD * MAX_FILTER_STD;
        let (l1, l2) = (l1.clamp(lo, hi), l2.clamp(lo, hi));
        // Precision = V diag(1/l) Vᵀ with V = [[vx, -vy], [vy, vx]].
        let (i1, i2) = (1.0 / l1, 1.0 / l2);
        let pxx = vx * vx * i1 + vy * vy * i2;
        Gaussian {
            precision: [pxx, vx * vy * (i1 - i2), vy * vy * i1 + vx * vx * i2],
            norm: 1.0 / (2.0 * std::f64::consts::PI * (l1 * l2).sqrt()),
            std_max: l1.max(l2).sqrt(),
            // The ellipse's half-height is CUTOFF · σ_y, with σ_y² = C_yy = pxx / det P;
            // one part in 10¹² more, so that rounding never drops a row on the ellipse.
            reach_rows: (CUTOFF * (pxx * l1 * l2).max(0.0).sqrt() * (1.0 + 1e-12)).ceil() as usize,
            decay: (-pxx).exp(),
        }
    }

    /// An isotropic Gaussian of std `s` px (clamped as in [`Gaussian::from_cov`]).
    pub fn isotropic(s: f64) -> Gaussian {
        Gaussian::from_cov([s * s, 0.0, s * s])
    }

    /// The weight it gives a pixel's own samples in that pixel (its value at the origin,
    /// `1 / (2π √det C)`).
    pub fn peak(&self) -> f64 {
        self.norm
    }

    /// The larger std (px).
    pub fn std_max(&self) -> f64 {
        self.std_max
    }

    /// How many cells the filter reaches from its centre, along a row or a column:
    /// `⌈CUTOFF · std_max⌉`.
    pub fn reach(&self) -> usize {
        (CUTOFF * self.std_max).ceil() as usize
    }

    /// How many rows the filter reaches above and below its centre: `⌈CUTOFF · σ_y⌉`, the
    /// half-height of the [`CUTOFF`] ellipse. At most [`Gaussian::reach`], and much less
    /// for a filter drawn out along the rows (as motion blur draws them): the rows a
    /// splat visits.
    pub fn reach_rows(&self) -> usize {
        self.reach_rows
    }

    /// The covariance `[xx, xy, yy]` (px²).
    pub fn cov(&self) -> [f64; 3] {
        let [p, q, r] = self.precision;
        let det = p * r - q * q;
        [r / det, -q / det, p / det]
    }

    /// The weights of the cells at horizontal offset `lo ..= hi` and vertical offset `dy`
    /// that lie inside the [`CUTOFF`] ellipse (a row of an ellipse is one run of cells),
    /// appended to `out`; returns the run's first offset. The centre lies `ox` right of
    /// offset 0 (0 for a pixel's own filter; ½ for a block's, [`BLOCK_STD`]).
    ///
    /// The run is found around the row's minimum `c₀ = ox − q dy / p` (half-width
    /// `√((cut − e(c₀)) / p)`), then corrected cell by cell against the exponent itself, so
    /// that rounding neither adds nor drops a cell that [`Gaussian::weight`] weighs
    /// otherwise. The weights come from the Gaussian's ratio recurrence,
    /// `w(d + 1) / w(d) = exp(−½ (p (2(d − ox) + 1) + 2 q dy))`, a ratio that itself changes by
    /// `exp(−p)` a cell (`p`, `q`: the precision's `xx`, `xy`), run in four interleaved
    /// lanes of four-cell steps so that neighbouring cells do not wait on each other's
    /// product: two `exp` a row, two products a cell.
    fn row_weights(&self, dy: f64, ox: f64, lo: i64, hi: i64, out: &mut Vec<f64>) -> i64 {
        let [p, q, rr] = self.precision;
        let e_at = |dx: i64| {
            let dx = dx as f64 - ox;
            p * dx * dx + 2.0 * q * dx * dy + rr * dy * dy
        };
        let cut = CUTOFF * CUTOFF;
        let c0 = -q * dy / p + ox;
        let half = ((cut - (rr - q * q / p) * dy * dy).max(0.0) / p).sqrt();
        // `as` saturates and truncates towards zero; the corrections below do the rest.
        let mut a = ((c0 - half) as i64).clamp(lo, hi + 1);
        let mut b = ((c0 + half) as i64).clamp(lo - 1, hi);
        while a <= b && e_at(a) > cut {
            a += 1;
        }
        while a > lo && e_at(a - 1) <= cut {
            a -= 1;
        }
        while b >= a && e_at(b) > cut {
            b -= 1;
        }
        while b >= a && b < hi && e_at(b + 1) <= cut {
            b += 1;
        }
        if b < a {
            return a;
        }
        let n = (b - a + 1) as usize;
        // Lane j starts at cell a + j and steps four cells: w(d + 4) / w(d) = ∏ of four
        // one-cell ratios = step(d)⁴ · decay⁶, which changes by decay¹⁶ a step.
        let decay = self.decay;
        let mut w = [0.0; 4];
        w[0] = self.norm * (-0.5 * e_at(a)).exp();
        let step = (-0.5 * (p * ((2 * a + 1) as f64 - 2.0 * ox) + 2.0 * q * dy)).exp();
        let mut st = step;
        for j in 1..4 {
            w[j] = w[j - 1] * st;
            st *= decay;
        }
        let d2 = decay * decay;
        let d4 = d2 * d2;
        let mut ratio = [step * step * step * step * d4 * d2; 4];
        for j in 1..4 {
            ratio[j] = ratio[j - 1] * d4;
        }
        let d16 = d4 * d4 * d4 * d4;
        let start = out.len();
        out.resize(start + n.next_multiple_of(4), 0.0);
        for chunk in out[start..].chunks_exact_mut(4) {
            chunk.copy_from_slice(&w);
            for j in 0..4 {
                w[j] *= ratio[j];
                ratio[j] *= d16;
            }
        }
        out.truncate(start + n);
        a
    }

    /// The filter's weight at offset `(dx, dy)` px (0 beyond [`CUTOFF`] std).
    #[inline]
    pub fn weight(&self, dx: f64, dy: f64) -> f64 {
        let [p, q, r] = self.precision;
        let e = p * dx * dx + 2.0 * q * dx * dy + r * dy * dy;
        if e > CUTOFF * CUTOFF {
            0.0
        } else {
            self.norm * (-0.5 * e).exp()
        }
    }
}

/// How samples are reconstructed into pixels.
#[derive(Clone, Debug, PartialEq)]
pub enum Filter {
    /// Each sample counts in its own pixel only, with weight 1 (the box estimate).
    Box,
    /// One Gaussian for every pixel.
    Fixed(Gaussian),
    /// A Gaussian per pixel (row by row), used for the samples of that pixel.
    PerPixel(Vec<Gaussian>),
}

impl Filter {
    fn at(&self, i: usize) -> Option<&Gaussian> {
        match self {
            Filter::Box => None,
            Filter::Fixed(g) => Some(g),
            Filter::PerPixel(v) => v.get(i),
        }
    }
}

/// Slots of a band's [`Stencils`] (a power of two).
const STENCIL_SLOTS: usize = 1 << 10;
/// Most weights a band's [`Stencils`] keep (8 MB): past it they start afresh.
const STENCIL_WEIGHTS: usize = 1 << 20;

/// The weights of the filters a band splats, each over its whole support, row by row,
/// so that pixels with the same filter compute them once: the pixels of a block of the
/// covariance grid share one, and pixels near an edge take filters narrowed by their
/// distance to it, which repeat along the edge a row apart, where one stencil would be
/// lost to the pixels in between. A filter's stencil is kept in a slot found from its
/// precision's bits (a later filter of the same slot takes it over).
struct Stencils {
    /// Whether the stencils are centred half a cell right of and below their anchor
    /// cell (a block's, [`BLOCK_STD`]) rather than on it.
    shifted: bool,
    /// Per slot: the filter and the range of its rows in `rows`.
    slots: Vec<Option<(Gaussian, Range<usize>)>>,
    /// Per row of each stencil (`dy = −reach ..= reach`, [`Gaussian::reach_rows`]): the
    /// first column offset and the row's range in `weights`.
    rows: Vec<(i64, Range<usize>)>,
    /// The weights, row after row.
    weights: Vec<f64>,
    /// The slot used last.
    last: usize,
}

impl Stencils {
    /// No stencil yet; centred on their cell, or half a cell off (`shifted`).
    fn new(shifted: bool) -> Stencils {
        Stencils {
            shifted,
            slots: vec![None; STENCIL_SLOTS],
            rows: Vec::new(),
            weights: Vec::new(),
            last: 0,
        }
    }

    /// The range in [`Stencils::rows`] of `g`'s stencil (made if it is not kept).
    fn of(&mut self, g: &Gaussian) -> Range<usize> {
        if !matches!(&self.slots[self.last], Some((f, _)) if f == g) {
            // A multiplicative hash of the precision's bits picks the slot.
            let [a, b, c] = g.precision.map(f64::to_bits);
            let mix = (a ^ b.rotate_left(21) ^ c.rotate_left(42)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            self.last = (mix >> (64 - STENCIL_SLOTS.trailing_zeros())) as usize;
            if !matches!(&self.slots[self.last], Some((f, _)) if f == g) {
                if self.weights.len() > STENCIL_WEIGHTS {
                    self.slots.iter_mut().for_each(|s| *s = None);
                    self.rows.clear();
                    self.weights.clear();
                }
                let rows = self.make(g);
                self.slots[self.last] = Some((*g, rows));
            }
        }
        match &self.slots[self.last] {
            Some((_, rows)) => rows.clone(),
            None => 0..0,
        }
    }

    /// Appends `g`'s stencil; returns the range of its rows.
    fn make(&mut self, g: &Gaussian) -> Range<usize> {
        let (ri, rx) = (g.reach_rows() as i64, g.reach() as i64);
        let start = self.rows.len();
        if self.shifted {
            // Centred at (½, ½): rows −ri ..= ri + 1, columns −rx ..= rx + 1.
            for dy in -ri..=ri + 1 {
                let k = self.weights.len();
                let first = g.row_weights(dy as f64 - 0.5, 0.5, -rx, rx + 1, &mut self.weights);
                self.rows.push((first, k..self.weights.len()));
            }
            return start..self.rows.len();
        }
        // Rows 0 ..= ri from the Gaussian; row −dy is row dy reversed (w(−x, −dy) =
        // w(x, dy), and the exponent is the same to the bit, so are its cells).
        self.rows.resize(start + 2 * ri as usize + 1, (0, 0..0));
        let rows = &mut self.rows[start..];
        for dy in 0..=ri {
            let k = self.weights.len();
            let first = g.row_weights(dy as f64, 0.0, -rx, rx, &mut self.weights);
            let n = self.weights.len() - k;
            rows[(ri + dy) as usize] = (first, k..k + n);
            if dy > 0 {
                self.weights.extend_from_within(k..k + n);
                self.weights[k + n..].reverse();
                // The reversed run ends at −first.
                rows[(ri - dy) as usize] = (1 - first - n as i64, k + n..k + 2 * n);
            }
        }
        start..self.rows.len()
    }
}

/// A band of rows' splat buffer: rows `top ..` of the image, `w` columns each.
struct Band<const K: usize> {
    buf: Vec<[f64; K]>,
    top: usize,
    w: usize,
    h: usize,
}

impl<const K: usize> Band<K> {
    /// Adds `v` weighted by the stencil `rows` of `st` anchored at cell `(x, y)` (rows
    /// from `−(len − 1)/2`; columns as each row says), clipped to the image.
    fn add(&mut self, st: &Stencils, rows: Range<usize>, x: i64, y: i64, v: &[f64; K]) {
        let (w, h) = (self.w as i64, self.h as i64);
        let rows = &st.rows[rows];
        let first_dy = -((rows.len() as i64 - 1) / 2);
        for (j, (first, k)) in rows.iter().enumerate() {
            let py = y + first_dy + j as i64;
            if py < 0 || py >= h {
                continue;
            }
            // The row's run, clipped to the image's columns.
            let c0 = (x + first).max(0);
            let skip = (c0 - (x + first)) as usize;
            let wts = &st.weights[(k.start + skip).min(k.end)..k.end];
            let at = (py as usize - self.top) * self.w;
            let row = &mut self.buf[at..at + self.w];
            for (e, &wgt) in row[(c0.min(w)) as usize..].iter_mut().zip(wts) {
                for j in 0..K {
                    e[j] += v[j] * wgt;
                }
            }
        }
    }
}

/// The accumulated samples of an image.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    /// Width (px).
    pub width: u32,
    /// Height (px).
    pub height: u32,
    /// Samples taken in each pixel so far (the next sample's index in its sequence).
    pub count: Vec<u32>,
    /// Sum of the emission each pixel's samples saw directly.
    pub emitted: Vec<DVec3>,
    /// Sum of the reflected radiance each pixel's samples saw.
    pub reflected: Vec<DVec3>,
    /// Sum of the samples' luminance, and of its square.
    pub lum: Vec<[f64; 2]>,
    /// Sum of the luminance of the samples in the pixel's last dyadic block of indices,
    /// `2^⌊log₂(count − 1)⌋ .. count` (all of them below two samples): at a count `n` that
    /// is a power of two, the second half of the pixel's net, whose difference with the
    /// first half measures the error of the mean ([`Film::variance_of_mean`]).
    pub lum_top: Vec<f64>,
    /// Sum of the samples' first-hit albedo ([`crate::trace::Features`]).
    pub albedo: Vec<DVec3>,
    /// Sum of the samples' first-hit shading normal.
    pub normal: Vec<DVec3>,
    /// Sum of the samples' first-hit distance (m).
    pub depth: Vec<f64>,
}

/// A film's feature images (AOVs): per pixel, the mean over its samples of the first
/// hit's albedo, shading normal and distance ([`crate::trace::Features`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Aovs {
    /// Albedo, in [0, 1].
    pub albedo: Image,
    /// Shading normal: the mean of unit vectors (shorter where a pixel sees several
    /// surfaces), each component in [-1, 1].
    pub normal: Image,
    /// Distance (m), row by row.
    pub depth: Vec<f64>,
}

/// What one tile hands to the film, per pixel row by row: the sums of emitted and
/// reflected radiance, the count, the luminance sums, the sums of the features, and the
/// pixel's new [`Film::lum_top`].
type TileOut = Vec<(DVec3, DVec3, u32, [f64; 2], (DVec3, DVec3, f64), f64)>;

/// Sums of `v` (an image of `w` columns, row by row) over the `(2r + 1)²` pixels around
/// each pixel, clipped at the borders: a pass along the rows, then one along the columns.
/// Each window's sum is taken from scratch (`2r + 1` terms a value, in order), not as a
/// running difference, whose rounding would leave a residue where a window holds only
/// zeros. The column pass adds whole rows in that order, so it reads memory row by row,
/// and both passes run a row of output per task.
fn box_sums(v: &[[f64; 2]], w: usize, r: usize) -> Vec<[f64; 2]> {
    let w = w.max(1);
    let h = v.len() / w;
    let mut rows = vec![[0.0; 2]; v.len()];
    rows.par_chunks_mut(w).enumerate().for_each(|(y, out)| {
        let line = &v[y * w..(y + 1) * w];
        for (k, o) in out.iter_mut().enumerate() {
            for q in &line[k.saturating_sub(r)..(k + r + 1).min(w)] {
                o[0] += q[0];
                o[1] += q[1];
            }
        }
    });
    let mut out = vec![[0.0; 2]; v.len()];
    out.par_chunks_mut(w).enumerate().for_each(|(y, out)| {
        for q in y.saturating_sub(r)..(y + r + 1).min(h) {
            for (o, a) in out.iter_mut().zip(&rows[q * w..(q + 1) * w]) {
                o[0] += a[0];
                o[1] += a[1];
            }
        }
    });
    out
}

/// Rows of pixels one reconstruction band splats (bands run in parallel).
const BAND: usize = 16;

impl Film {
    /// An empty film of `width × height` pixels.
    pub fn new(width: u32, height: u32) -> Film {
        let n = width as usize * height as usize;
        Film {
            width,
            height,
            count: vec![0; n],
            emitted: vec![DVec3::ZERO; n],
            reflected: vec![DVec3::ZERO; n],
            lum: vec![[0.0; 2]; n],
            lum_top: vec![0.0; n],
            albedo: vec![DVec3::ZERO; n],
            normal: vec![DVec3::ZERO; n],
            depth: vec![0.0; n],
        }
    }

    /// The feature images: each pixel's means (0 where it has no sample).
    pub fn aovs(&self) -> Aovs {
        let mean = |v: &[DVec3]| -> Vec<DVec3> {
            v.iter()
                .zip(&self.count)
                .map(|(s, &n)| if n == 0 { DVec3::ZERO } else { *s / f64::from(n) })
                .collect()
        };
        let image = |pixels| Image {
            width: self.width,
            height: self.height,
            pixels,
        };
        Aovs {
            albedo: image(mean(&self.albedo)),
            normal: image(mean(&self.normal)),
            depth: self
                .depth
                .iter()
                .zip(&self.count)
                .map(|(s, &n)| if n == 0 { 0.0 } else { s / f64::from(n) })
                .collect(),
        }
    }

    /// The box estimate: each pixel's mean of its own samples (black where it has none).
    pub fn box_image(&self) -> Image {
        let pixels = (0..self.count.len())
            .into_par_iter()
            .map(|i| match self.count[i] {
                0 => DVec3::ZERO,
                n => (self.emitted[i] + self.reflected[i]) / f64::from(n),
            })
            .collect();
        Image {
            width: self.width,
            height: self.height,
            pixels,
        }
    }

    /// The image reconstructed with `filter` (see the module docs); the box estimate for
    /// [`Filter::Box`] and wherever a pixel received no weight.
    pub fn image(&self, filter: &Filter) -> Image {
        if matches!(filter, Filter::Box) {
            return self.box_image();
        }
        let acc = self.splat(filter);
        let mut img = self.box_image();
        for (i, p) in img.pixels.iter_mut().enumerate() {
            let (s, wsum) = acc[i];
            if wsum > 0.0 && self.count[i] > 0 {
                *p = self.emitted[i] / f64::from(self.count[i]) + s / wsum;
            }
        }
        img
    }

    /// Per pixel, the reflected radiance splatted into it with `filter` and the splatted
    /// sample count (the two sums whose ratio [`Film::image`] takes); zero for
    /// [`Filter::Box`] pixels, which splat nothing.
    pub fn splat(&self, filter: &Filter) -> Vec<(DVec3, f64)> {
        Film::colour(self.splat_by(|i| filter.at(i), |i| self.reflected_and_count(i)))
    }

    /// [`Film::splat`] with pixel `i`'s filter `filters[i]` (a candidate of the guard,
    /// splatted without a copy into a [`Filter::PerPixel`]).
    pub fn splat_each(&self, filters: &[Gaussian]) -> Vec<(DVec3, f64)> {
        Film::colour(self.splat_by(|i| filters.get(i), |i| self.reflected_and_count(i)))
    }

    /// Pixel `i`'s reflected sum and count, as [`Film::splat`] splats them.
    fn reflected_and_count(&self, i: usize) -> [f64; 4] {
        let s = self.reflected[i];
        [s.x, s.y, s.z, f64::from(self.count[i])]
    }

    /// Splatted [`Film::reflected_and_count`] as radiance and count.
    fn colour(sums: Vec<[f64; 4]>) -> Vec<(DVec3, f64)> {
        sums.into_iter()
            .map(|v| (DVec3::new(v[0], v[1], v[2]), v[3]))
            .collect()
    }

    /// Per pixel, the sums of `values` of the pixels with samples, each splatted with its
    /// pixel's filter ([`Film::splat`] splats the reflected radiance and the count; the
    /// guard's allocation splats luminance and count alone, at half the cost).
    pub fn splat_values<const K: usize>(
        &self,
        filter: &Filter,
        values: impl Fn(usize) -> [f64; K] + Sync,
    ) -> Vec<[f64; K]> {
        self.splat_by(|i| filter.at(i), values)
    }

    /// [`Film::splat_values`] with pixel `i`'s filter `filters[i]`.
    pub fn splat_values_each<const K: usize>(
        &self,
        filters: &[Gaussian],
        values: impl Fn(usize) -> [f64; K] + Sync,
    ) -> Vec<[f64; K]> {
        self.splat_by(|i| filters.get(i), values)
    }

    /// The splat of `values` with pixel `i`'s filter `at(i)` (none: the pixel splats
    /// nothing).
    fn splat_by<'a, const K: usize>(
        &self,
        at: impl Fn(usize) -> Option<&'a Gaussian> + Sync,
        values: impl Fn(usize) -> [f64; K] + Sync,
    ) -> Vec<[f64; K]> {
        let (w, h) = (self.width as usize, self.height as usize);
        // Each band of rows splats into a buffer with a margin as deep as its filters reach.
        let bands: Vec<(usize, Vec<[f64; K]>)> = (0..h.div_ceil(BAND))
            .into_par_iter()
            .map(|b| {
                let (y0, y1) = (b * BAND, ((b + 1) * BAND).min(h));
                let reach = (y0 * w..y1 * w)
                    .filter_map(&at)
                    .map(Gaussian::reach_rows)
                    .max()
                    .unwrap_or(0);
                let top = y0.saturating_sub(reach);
                let bottom = (y1 + reach).min(h);
                let mut band = Band {
                    buf: vec![[0.0f64; K]; (bottom - top) * w],
                    top,
                    w,
                    h,
                };
                let (mut own, mut shifted) = (Stencils::new(false), Stencils::new(true));
                let mut pixel = |band: &mut Band<K>, x: usize, y: usize| {
                    let i = y * w + x;
                    if let Some(g) = at(i).filter(|_| self.count[i] > 0) {
                        let rows = own.of(g);
                        band.add(&own, rows, x as i64, y as i64, &values(i));
                    }
                };
                // Blocks of 4×4 pixels (a band's rows are a multiple of 4 from its first):
                // whole, as 2×2 quarters, or pixel by pixel ([`BLOCK_STD`]).
                for by in (y0..y1).step_by(4) {
                    for bx in (0..w).step_by(4) {
                        let whole = self.block(&at, &values, bx, by, 4);
                        if let Some((g, v)) = whole {
                            let rows = shifted.of(&g);
                            band.add(&shifted, rows, bx as i64 + 1, by as i64 + 1, &v);
                            continue;
                        }
                        for (qx, qy) in [(bx, by), (bx + 2, by), (bx, by + 2), (bx + 2, by + 2)] {
                            if let Some((g, v)) = self.block(&at, &values, qx, qy, 2) {
                                let rows = shifted.of(&g);
                                band.add(&shifted, rows, qx as i64, qy as i64, &v);
                                continue;
                            }
                            for y in qy..(qy + 2).min(y1) {
                                for x in qx..(qx + 2).min(w) {
                                    pixel(&mut band, x, y);
                                }
                            }
                        }
                    }
                }
                (top, band.buf)
            })
            .collect();
        let mut acc = vec![[0.0; K]; w * h];
        for (top, buf) in bands {
            for (k, v) in buf.into_iter().enumerate() {
                let e = &mut acc[top * w + k];
                for j in 0..K {
                    e[j] += v[j];
                }
            }
        }
        acc
    }

    /// The block of `b × b` pixels at `(x0, y0)` as one source ([`BLOCK_STD`]): its
    /// filter narrowed by the block's spread and the sum of its values; `None` unless the
    /// block lies in the image, every pixel has samples and the same filter, and that
    /// filter's smaller std is at least `BLOCK_STD · b`.
    fn block<'a, const K: usize>(
        &self,
        at: &impl Fn(usize) -> Option<&'a Gaussian>,
        values: &impl Fn(usize) -> [f64; K],
        x0: usize,
        y0: usize,
        b: usize,
    ) -> Option<(Gaussian, [f64; K])> {
        let w = self.width as usize;
        if x0 + b > w || y0 + b > self.height as usize {
            return None;
        }
        let g = *at(y0 * w + x0)?;
        let pixels = (y0..y0 + b).flat_map(|y| (x0..x0 + b).map(move |x| y * w + x));
        if !pixels.clone().all(|i| self.count[i] > 0 && at(i) == Some(&g)) {
            return None;
        }
        let [a, c, d] = g.cov();
        let least = 0.5 * (a + d) - (0.25 * (a - d) * (a - d) + c * c).sqrt();
        let side = BLOCK_STD * b as f64;
        if least.is_nan() || least < side * side {
            return None;
        }
        let spread = ((b * b - 1) as f64) / 12.0;
        let mut v = [0.0; K];
        for i in pixels {
            let vi = values(i);
            for j in 0..K {
                v[j] += vi[j];
            }
        }
        Some((Gaussian::from_cov([a - spread, c, d - spread]), v))
    }

    /// Per pixel, the sample variance of the luminance of its own samples (0 with fewer
    /// than two).
    pub fn variance(&self) -> Vec<f64> {
        self.lum
            .par_iter()
            .zip(&self.count)
            .map(|(&[s, s2], &n)| {
                if n < 2 {
                    return 0.0;
                }
                let nf = f64::from(n);
                let m = s / nf;
                ((s2 - nf * m * m) / (nf - 1.0)).max(0.0)
            })
            .collect()
    }

    /// Per pixel, an estimate of the variance of the mean of its samples' luminance (the
    /// box estimate's error) that sees quasi-Monte Carlo convergence. Pixels with fewer
    /// than two samples get 0, as [`Film::variance`] gives them.
    ///
    /// The sample variance over the count, `s²/n`, is the error of a Monte Carlo mean. A
    /// pixel's samples are a scrambled net, whose mean converges faster where the
    /// integrand is smooth, and there `s²/n` overstates the error several times (on a
    /// directly lit textured floor, 16 samples err 20 times less than 4, not 4 times). At
    /// a count `n` that is a power of two, the net's two halves (indices `0 .. n/2` and
    /// `n/2 .. n`, [`Film::lum_top`]) are nets themselves, and `(m₁ − m₂)²/4` estimates the
    /// full mean's variance: exactly when the halves are independent, from above when
    /// they stratify each other. That split has one degree of freedom per pixel, so the
    /// pixel keeps its own `s²/n` (its shape, with `n − 1` degrees of freedom) scaled by
    /// the ratio `Σ split / Σ s²/n` over the pixels within [`SPLIT_REACH`] that have a
    /// split, at most 1 (a scrambled net is not taken to be worse than Monte Carlo).
    pub fn variance_of_mean(&self) -> Vec<f64> {
        self.variance_of_mean_from(&self.variance())
    }

    /// [`Film::variance_of_mean`] given the film's [`Film::variance`] `var`.
    pub(crate) fn variance_of_mean_from(&self, var: &[f64]) -> Vec<f64> {
        const R: usize = SPLIT_REACH;
        let mc: Vec<f64> = (0..self.count.len())
            .into_par_iter()
            .map(|i| var[i] / f64::from(self.count[i].max(1)))
            .collect();
        // The split estimate where the count is a power of two of at least 2:
        // (m₁ − m₂)²/4 = ((S − T) − T)² / n², `S` the sum and `T` the second half's; and
        // the Monte Carlo estimate of the same pixels.
        let pairs: Vec<[f64; 2]> = (0..self.count.len())
            .into_par_iter()
            .map(|i| {
                let n = self.count[i];
                if n >= 2 && n.is_power_of_two() {
                    let d = (self.lum[i][0] - 2.0 * self.lum_top[i]) / f64::from(n);
                    [d * d, mc[i]]
                } else {
                    [0.0; 2]
                }
            })
            .collect();
        // Their sums over the (2R + 1)² pixels around, a row pass then a column pass.
        let sums = box_sums(&pairs, self.width as usize, R);
        (0..self.count.len())
            .into_par_iter()
            .map(|i| {
                let [a, b] = sums[i];
                // No split around, or no variance to scale: Monte Carlo's estimate.
                let gain = if b > 0.0 { (a / b).min(1.0) } else { 1.0 };
                mc[i] * gain
            })
            .collect()
    }

    /// Takes `counts[i]` more samples in pixel `i`, continuing each pixel's sequence (a
    /// pixel never takes more than [`MAX_SPP`] in all). Each sample's luminance is
    /// clamped to `max_luminance` (colour scaled down; `∞` for an unbiased image).
    pub fn render(
        &mut self,
        world: &World,
        counts: &[u32],
        seed: u64,
        max_luminance: f64,
        progress: Progress<'_>,
    ) {
        self.render_rows(world, counts, seed, max_luminance, 0..self.height, progress);
    }

    /// [`Film::render`] of the tiles whose first row lies in `rows` (a part of a render,
    /// the `parts` module); `progress` is called once per such tile.
    pub fn render_rows(
        &mut self,
        world: &World,
        counts: &[u32],
        seed: u64,
        max_luminance: f64,
        rows: std::ops::Range<u32>,
        progress: Progress<'_>,
    ) {
        let w = self.width;
        let mut tl = tiles(self.width, self.height);
        tl.retain(|t| rows.contains(&t.1));
        for batch in tl.chunks(BATCH) {
            let outs: Vec<TileOut> = batch
                .par_iter()
                .map(|&t| {
                    let out = self.tile(world, counts, seed, max_luminance, t);
                    if let Some(p) = progress {
                        p();
                    }
                    out
                })
                .collect();
            for (&(x0, y0, x1, y1), out) in batch.iter().zip(outs) {
                let coords = (y0..y1).flat_map(|y| (x0..x1).map(move |x| (y * w + x) as usize));
                for (i, (e, r, n, l, aov, top)) in coords.zip(out) {
                    self.lum_top[i] = top;
                    self.albedo[i] += aov.0;
                    self.normal[i] += aov.1;
                    self.depth[i] += aov.2;
                    self.emitted[i] += e;
                    self.reflected[i] += r;
                    self.count[i] += n;
                    self.lum[i][0] += l[0];
                    self.lum[i][1] += l[1];
                }
            }
        }
    }

    /// Renders one tile (its samples come from per-pixel sequences).
    fn tile(
        &self,
        world: &World,
        counts: &[u32],
        seed: u64,
        max_luminance: f64,
        (x0, y0, x1, y1): (u32, u32, u32, u32),
    ) -> TileOut {
        let w = self.width;
        let mut out = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
        for y in y0..y1 {
            for x in x0..x1 {
                let i = (y * w + x) as usize;
                let first = self.count[i].min(MAX_INDEX);
                let n = counts.get(i).copied().unwrap_or(0).min(MAX_INDEX - first);
                let mut sampler = SobolSampler::new(seed, w, x, y);
                let (mut se, mut sr, mut l1, mut l2) = (DVec3::ZERO, DVec3::ZERO, 0.0, 0.0);
                let mut aov = (DVec3::ZERO, DVec3::ZERO, 0.0);
                let mut top = self.lum_top[i];
                for s in first..first + n {
                    // Sample `s` opens the dyadic block `s .. 2s` (and sample 0 its own).
                    if s == 0 || s.is_power_of_two() {
                        top = 0.0;
                    }
                    sampler.start(s);
                    let s = &mut sampler;
                    let (jx, jy, lu, lv, ut) = (s.next(), s.next(), s.next(), s.next(), s.next());
                    let ray = world.camera.ray(x as f64 + jx, y as f64 + jy, (lu, lv), ut);
                    let rs = radiance_parts(world, &ray, s);
                    let f = rs.features;
                    if (f.albedo + f.normal).is_finite() && f.depth.is_finite() {
                        aov.0 += f.albedo;
                        aov.1 += f.normal;
                        aov.2 += f.depth;
                    }
                    let (e, r) = (rs.emitted, rs.reflected);
                    let (e, r) = if (e + r).is_finite() {
                        (e, r)
                    } else {
                        (DVec3::ZERO, DVec3::ZERO)
                    };
                    let yl = luminance(e + r);
                    let (e, r) = if yl > max_luminance {
                        let k = max_luminance / yl;
                        (e * k, r * k)
                    } else {
                        (e, r)
                    };
                    let yl = luminance(e + r);
                    se += e;
                    sr += r;
                    l1 += yl;
                    l2 += yl * yl;
                    top += yl;
                }
                out.push((se, sr, n, [l1, l2], aov, top));
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `box_sums` is the clipped window sum of its definition (to rounding), and a window
    /// of zeros sums to exactly 0 however large the values beside it.
    #[test]
    fn box_sums_are_clipped_window_sums() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        for (w, h, r) in [(13usize, 7usize, 2usize), (5, 11, 4), (1, 9, 4), (9, 1, 1)] {
            let v: Vec<[f64; 2]> = (0..w * h)
                .map(|_| [rng.random_range(0.0..1.0), rng.random_range(-1.0..1.0)])
                .collect();
            let got = box_sums(&v, w, r);
            for y in 0..h {
                for x in 0..w {
                    let mut want = [0.0; 2];
                    for yy in y.saturating_sub(r)..(y + r + 1).min(h) {
                        for xx in x.saturating_sub(r)..(x + r + 1).min(w) {
                            want[0] += v[yy * w + xx][0];
                            want[1] += v[yy * w + xx][1];
                        }
                    }
                    for k in 0..2 {
                        assert!((got[y * w + x][k] - want[k]).abs() <= 1e-12, "({x}, {y}) {k}");
                    }
                }
            }
        }
        // Huge values beside a block of zeros: the zeros' windows stay exactly 0.
        let (w, h) = (20, 3);
        let v: Vec<[f64; 2]> = (0..w * h)
            .map(|i| if i % w < 5 { [1e300, 3e17] } else { [0.0; 2] })
            .collect();
        let got = box_sums(&v, w, 4);
        for y in 0..h {
            for x in 9..w {
                assert_eq!(got[y * w + x], [0.0; 2], "({x}, {y})");
            }
        }
    }

    #[test]
    fn gaussians_are_normalised_and_clamped() {
        for c in [
            [4.0, 1.0, 2.0],
            [1.0, 0.0, 9.0],
            [0.01, 0.0, 0.01],
            [1e9, 0.0, 1.0],
        ] {
            let g = Gaussian::from_cov(c);
            // ∑ over a fine grid ≈ 1.
            let h = 0.05;
            let mut s = 0.0;
            let r = (CUTOFF * g.std_max() / h).ceil() as i64 + 1;
            for i in -r..=r {
                for j in -r..=r {
                    s += g.weight(i as f64 * h, j as f64 * h) * h * h;
                }
            }
            assert!((s - 0.9889).abs() < 0.01, "{c:?}: mass {s}");
            assert!(g.std_max() <= MAX_FILTER_STD + 1e-9 && g.std_max() >= MIN_FILTER_STD - 1e-9);
        }
        let g = Gaussian::from_cov([4.0, 1.0, 2.0]);
        let c = g.cov();
        assert!((c[0] - 4.0).abs() < 1e-9 && (c[1] - 1.0).abs() < 1e-9 && (c[2] - 2.0).abs() < 1e-9);
        assert_eq!(Gaussian::from_cov([f64::NAN, 0.0, 1.0]), Gaussian::isotropic(0.0));
    }

    /// A splat is the sum, over the pixels with samples, of their sums weighted by their
    /// filter at each cell: against that sum taken cell by cell with [`Gaussian::weight`],
    /// on an image of several bands, with filters wider than the image (clipped at every
    /// border), runs of pixels sharing a filter (the stencil reused) and empty pixels.
    /// (The runs lie along rows, so no block of pixels splats as one: that is
    /// `blocks_splat_as_their_pixels_do`.)
    #[test]
    fn splat_is_the_weighted_sum() {
        let (w, h) = (23u32, 37u32);
        let n = (w * h) as usize;
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let mut rnd = move || rng.random::<f64>();
        let mut film = Film::new(w, h);
        for i in 0..n {
            film.count[i] = if rnd() < 0.1 { 0 } else { 1 + (rnd() * 8.0) as u32 };
            film.reflected[i] = DVec3::new(rnd(), rnd(), rnd()) * f64::from(film.count[i]);
        }
        let mut filters = Vec::with_capacity(n);
        while filters.len() < n {
            let s = 0.2 + 20.0 * rnd() * rnd();
            let g = Gaussian::from_cov([s * s, (rnd() - 0.5) * s * s, s * s * (0.2 + rnd())]);
            let run = 1 + (rnd() * 6.0) as usize;
            filters.extend(std::iter::repeat_n(g, run.min(n - filters.len())));
        }
        for filter in [Filter::PerPixel(filters), Filter::Fixed(Gaussian::isotropic(2.5))] {
            let got = film.splat(&filter);
            for p in 0..n {
                let (px, py) = ((p % w as usize) as f64, (p / w as usize) as f64);
                let (mut s, mut c) = (DVec3::ZERO, 0.0);
                for q in (0..n).filter(|&q| film.count[q] > 0) {
                    let g = filter.at(q).expect("a filter");
                    let (qx, qy) = ((q % w as usize) as f64, (q / w as usize) as f64);
                    let wq = g.weight(px - qx, py - qy);
                    s += film.reflected[q] * wq;
                    c += f64::from(film.count[q]) * wq;
                }
                let (gs, gc) = got[p];
                let tol = 1e-12 * (1.0 + c);
                assert!((gc - c).abs() <= tol, "pixel {p}: weight {gc} vs {c}");
                assert!((gs - s).abs().max_element() <= tol, "pixel {p}: {gs} vs {s}");
            }
        }
    }

    /// Wide filters shared by blocks of pixels splat by blocks ([`BLOCK_STD`]): a flat
    /// image stays flat to rounding, whatever the counts, and a smooth one (a 30% sine of
    /// 44 px period and a ramp) is within 3e-3 of the pixel-by-pixel splat, normalised by
    /// the splatted counts as every reconstruction divides (measured: 1.9e-3 at most, at
    /// the borders, where the clipped filter weighs the block's shifted samples unevenly;
    /// 4.7e-4 at most three std inside). The test fails if no block splats as one (the splat would
    /// then equal the exact one to rounding).
    #[test]
    fn blocks_splat_as_their_pixels_do() {
        let (w, h) = (42u32, 38u32);
        let n = (w * h) as usize;
        let field = |x: f64, y: f64| 1.0 + 0.3 * (x / 7.0).sin() + 0.2 * y / f64::from(h);
        let mut film = Film::new(w, h);
        for i in 0..n {
            film.count[i] = 1 + (i * 7 % 5) as u32;
            let (x, y) = ((i % w as usize) as f64, (i / w as usize) as f64);
            film.reflected[i] = DVec3::splat(field(x, y)) * f64::from(film.count[i]);
        }
        let mut flat = film.clone();
        for i in 0..n {
            flat.reflected[i] = DVec3::new(0.5, 0.25, 2.0) * f64::from(flat.count[i]);
        }
        // 7 px: 4×4 blocks; 3.5 px: 2×2 blocks; anisotropic 8 × 4 px: 2×2 blocks.
        for g in [
            Gaussian::isotropic(7.0),
            Gaussian::isotropic(3.5),
            Gaussian::from_cov([64.0, 10.0, 16.0]),
        ] {
            let filter = Filter::Fixed(g);
            let got = film.splat(&filter);
            let (mut worst, mut inexact) = (0.0f64, 0.0f64);
            for p in 0..n {
                let (px, py) = ((p % w as usize) as f64, (p / w as usize) as f64);
                let (mut s, mut c) = (0.0, 0.0);
                for q in 0..n {
                    let (qx, qy) = ((q % w as usize) as f64, (q / w as usize) as f64);
                    let wq = g.weight(px - qx, py - qy);
                    s += film.reflected[q].x * wq;
                    c += f64::from(film.count[q]) * wq;
                }
                let (gs, gc) = got[p];
                let err = (gs.x / gc - s / c).abs() / (s / c);
                worst = worst.max(err);
                inexact = inexact.max((gc - c).abs() / c);
            }
            assert!(worst < 3e-3, "{g:?}: normalised splat off by {worst:e}");
            assert!(inexact > 1e-9, "{g:?}: no block splatted as one");
            for (k, &(v, c)) in flat.splat(&filter).iter().enumerate() {
                let d = (v / c - DVec3::new(0.5, 0.25, 2.0)).abs().max_element();
                assert!(d < 1e-12, "{g:?}: pixel {k} of a flat image reads {}", v / c);
            }
        }
    }

    /// The row weights are the weights `weight` gives, cell by cell, and no others,
    /// whatever the clipping.
    #[test]
    fn row_weights_match_the_weights() {
        for c in [
            [4.0, 1.5, 2.0],
            [9.0, -2.9, 1.0],
            [0.09, 0.0, 0.09],
            [200.0, 0.0, 0.2],
            [256.0, 255.0, 256.0],
        ] {
            let g = Gaussian::from_cov(c);
            let r = g.reach() as i64;
            for (lo, hi) in [(-r, r), (-3, r), (-r, 0), (2, 5), (-r, -r)] {
                for (dy, ox) in (-r..=r).flat_map(|dy| [(dy as f64, 0.0), (dy as f64 - 0.5, 0.5)]) {
                    let mut out = vec![7.0];
                    let first = g.row_weights(dy, ox, lo, hi, &mut out);
                    for dx in lo..=hi {
                        let want = g.weight(dx as f64 - ox, dy);
                        let k = dx - first;
                        let got = if k >= 0 && (k as usize) + 1 < out.len() {
                            out[k as usize + 1]
                        } else {
                            0.0
                        };
                        assert!(
                            (got - want).abs() <= 1e-12 * g.norm,
                            "{c:?} [{lo}, {hi}] dy {dy} ox {ox} dx {dx}: {got} vs {want}"
                        );
                    }
                    assert!(out.len() <= (hi - lo + 2).max(1) as usize && out[0] == 7.0);
                }
                // No cell lies beyond the rows the filter says it reaches.
                let beyond = g.reach_rows() as f64 + 1.0;
                for dy in [beyond, -beyond] {
                    let mut out = Vec::new();
                    g.row_weights(dy, 0.0, -r, r, &mut out);
                    assert!(out.is_empty(), "{c:?}: row {dy} has {} cells", out.len());
                }
            }
        }
    }
}
