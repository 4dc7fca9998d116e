//! Textures: reflectance maps over a surface's `(u, v)`, kept as one mip pyramid that
//! serves both the path tracer (filtered colour lookups) and the covariance pass (the
//! texture's local spectrum).
//!
//! A level's colours are the 2×2 box averages of the level below. Every texel of every
//! level also holds five averages of the luminance `A` of that level over the texel's 3×3
//! neighbourhood: `⟨A⟩`, `⟨A²⟩`, `⟨A_u²⟩`, `⟨A_u A_v⟩`, `⟨A_v²⟩` (derivatives per unit of
//! `u` and `v`, by forward differences). A lookup at the level whose texels match a
//! footprint gives the texture's statistics as seen through that footprint, and
//! [`cov_occlusion::Texture::from_moments`] turns them into the spectrum the pass adds: no
//! FFT at render time.
//!
//! Coordinates wrap (the texture repeats); `v = 0` is the image's bottom row, as in OBJ
//! files. Lookups are bilinear within a level and linear between levels.

use std::path::Path;

use glam::{DVec2, DVec3};
use rayon::prelude::*;

/// Largest side of a texture (texels), for images and procedural textures alike: bounds
/// memory (a texture with its pyramid holds 32 bytes a texel, its colour and five moments
/// in f32, times 4/3: about 0.7 GB at 4096²; a scene with one peaked at 0.71 GB resident).
pub const MAX_TEXTURE_SIDE: u32 = 4096;

/// Largest texture image file read (bytes): eight f32 channels at the largest side
/// ([`MAX_TEXTURE_SIDE`]), 512 MiB. The file is hashed into the scene's fingerprint as
/// well as decoded; a PNG padded past its end was read whole.
pub const MAX_TEXTURE_BYTES: u64 = 512 << 20;

/// One level of the pyramid.
#[derive(Clone, Debug)]
struct Level {
    w: usize,
    h: usize,
    rgb: Vec<[f32; 3]>,
    /// `⟨A⟩`, the variance of `A`, `⟨A_u²⟩, ⟨A_u A_v⟩, ⟨A_v²⟩` over the texel's
    /// neighbourhood (the variance is kept rather than `⟨A²⟩`: no cancellation in f32).
    mom: Vec<[f32; 5]>,
}

/// The local averages of a texture's luminance over a footprint (see the module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Moments {
    /// `⟨A⟩`.
    pub mean: f64,
    /// `⟨A²⟩`.
    pub mean_sq: f64,
    /// `[⟨A_u²⟩, ⟨A_u A_v⟩, ⟨A_v²⟩]`, per unit of `u` and `v` squared.
    pub grad: [f64; 3],
}

/// A texture with its pyramid.
#[derive(Clone, Debug)]
pub struct TextureMap {
    levels: Vec<Level>,
    /// How many times the texture repeats over a unit of `u` and of `v`.
    repeat: DVec2,
}

fn lum(c: [f32; 3]) -> f64 {
    crate::material::luminance(DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64))
}

/// A procedural texture's parameter out of its range: which one, by the name a scene
/// file gives it, so that the error can be placed at it, and why.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{why}")]
pub struct BadParameter {
    /// The parameter: `checks`, `count`, `duty`, `cells`, `size` or `repeat`.
    pub name: &'static str,
    /// What is wrong with it, in one line that names it.
    pub why: String,
}

impl BadParameter {
    fn new(name: &'static str, why: String) -> BadParameter {
        BadParameter { name, why }
    }
}

/// Checks a procedural texture's side `size`: 1 to [`MAX_TEXTURE_SIDE`] texels.
fn checked_size(size: u32) -> Result<(), BadParameter> {
    if size == 0 || size > MAX_TEXTURE_SIDE {
        let why = format!("size must be 1 to {MAX_TEXTURE_SIDE} texels, got {size}");
        return Err(BadParameter::new("size", why));
    }
    Ok(())
}

/// Checks that a procedural texture's parameter `what` (a count of features across it)
/// is 1 to its `size` in texels, the size itself first ([`checked_size`]): a count cannot
/// be judged against a size out of range.
fn per_texture(what: &'static str, v: u32, size: u32) -> Result<(), BadParameter> {
    checked_size(size)?;
    if v == 0 || v > size {
        let why = format!("{what} must be 1 to the texture's size ({size}), got {v}");
        return Err(BadParameter::new(what, why));
    }
    Ok(())
}

impl TextureMap {
    /// A texture from linear RGB texels (row 0 at the top, rows of `w`), values clamped to
    /// `[0, 1]` (a reflectance; NaN becomes 0), repeated `repeat` times over a unit of `u`
    /// and `v`.
    ///
    /// # Errors
    /// A side of 0 or above [`MAX_TEXTURE_SIDE`], a texel count that does not match, or a
    /// repeat that is not finite and > 0.
    pub fn from_rgb(w: u32, h: u32, rgb: Vec<[f32; 3]>, repeat: DVec2) -> Result<TextureMap, String> {
        if w == 0 || h == 0 || w > MAX_TEXTURE_SIDE || h > MAX_TEXTURE_SIDE {
            return Err(format!(
                "a texture is {w}x{h} texels; each side must be 1 to {MAX_TEXTURE_SIDE}"
            ));
        }
        if rgb.len() != w as usize * h as usize {
            return Err(format!("{} texels for a {w}x{h} texture", rgb.len()));
        }
        if !(repeat.is_finite() && repeat.min_element() > 0.0) {
            return Err(format!(
                "repeat must be finite and > 0, got ({}, {})",
                repeat.x, repeat.y
            ));
        }
        let (w, h) = (w as usize, h as usize);
        let rgb: Vec<[f32; 3]> = rgb
            .into_iter()
            .map(|c| c.map(|x| if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) }))
            .collect();
        let mut levels = vec![Level::new(w, h, rgb)];
        while let Some(l) = levels.last().filter(|l| l.w > 1 || l.h > 1) {
            levels.push(l.half());
        }
        Ok(TextureMap { levels, repeat })
    }

    /// A checkerboard of `checks` squares along `u` and `v`, colours `a` and `b`,
    /// rasterised on `size` texels per side (the squares' edges are exact to a texel).
    ///
    /// # Errors
    /// A [`BadParameter`]: a `size` of 0 or above [`MAX_TEXTURE_SIDE`], `checks` of 0 or
    /// more than the texels, a `repeat` that is not finite and > 0.
    pub fn checker(
        checks: (u32, u32),
        a: DVec3,
        b: DVec3,
        size: u32,
        repeat: DVec2,
    ) -> Result<TextureMap, BadParameter> {
        checked_size(size)?;
        if checks.0 == 0 || checks.1 == 0 || checks.0 > size || checks.1 > size {
            let why = format!(
                "checks must be 1 to the texture's size ({size}) along each side, got ({}, {})",
                checks.0, checks.1
            );
            return Err(BadParameter::new("checks", why));
        }
        Self::raster(size, repeat, |u, v| {
            let (i, j) = ((u * checks.0 as f64) as u32, (v * checks.1 as f64) as u32);
            if (i + j).is_multiple_of(2) { a } else { b }
        })
    }

    /// `count` stripes along `v` (bands running along `u`): colour `b` over the fraction
    /// `duty` of each period, centred in it, and `a` elsewhere.
    ///
    /// # Errors
    /// A [`BadParameter`]: a `size` of 0 or above [`MAX_TEXTURE_SIDE`], `count` of 0 or
    /// more than the texels, `duty` outside (0, 1), a `repeat` that is not finite and > 0.
    pub fn stripes(
        count: u32,
        duty: f64,
        a: DVec3,
        b: DVec3,
        size: u32,
        repeat: DVec2,
    ) -> Result<TextureMap, BadParameter> {
        per_texture("count", count, size)?;
        if !(duty > 0.0 && duty < 1.0) {
            let why = format!("duty must be in (0, 1), got {}", cov_core::num(duty));
            return Err(BadParameter::new("duty", why));
        }
        Self::raster(size, repeat, |_, v| {
            let f = (v * count as f64).fract();
            if (f - 0.5).abs() < duty / 2.0 { b } else { a }
        })
    }

    /// Smooth value noise: a `cells × cells` periodic lattice of uniform values from
    /// `seed`, interpolated with smoothstep weights, mapped between colours `a` and `b`.
    ///
    /// # Errors
    /// A [`BadParameter`]: a `size` of 0 or above [`MAX_TEXTURE_SIDE`], `cells` of 0 or
    /// more than the texels, a `repeat` that is not finite and > 0.
    pub fn noise(
        cells: u32,
        seed: u64,
        a: DVec3,
        b: DVec3,
        size: u32,
        repeat: DVec2,
    ) -> Result<TextureMap, BadParameter> {
        use rand::{Rng, SeedableRng};
        per_texture("cells", cells, size)?;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let n = cells as usize;
        let lattice: Vec<f64> = (0..n * n).map(|_| rng.random::<f64>()).collect();
        Self::raster(size, repeat, |u, v| {
            let (x, y) = (u * n as f64, v * n as f64);
            let (i, j) = (x.floor() as usize % n, y.floor() as usize % n);
            let s = |t: f64| t * t * (3.0 - 2.0 * t);
            let (fx, fy) = (s(x.fract()), s(y.fract()));
            let l = |i: usize, j: usize| lattice[(j % n) * n + i % n];
            let t = (l(i, j) * (1.0 - fx) + l(i + 1, j) * fx) * (1.0 - fy)
                + (l(i, j + 1) * (1.0 - fx) + l(i + 1, j + 1) * fx) * fy;
            a + (b - a) * t
        })
    }

    /// A texture from a PNG (8 or 16 bit, sRGB-encoded, decoded to linear) or an EXR
    /// (linear; R, G and B channels, or one grey channel `Y`) file.
    ///
    /// # Errors
    /// An unreadable or undecodable file, or an image larger than [`MAX_TEXTURE_SIDE`].
    pub fn load(path: &Path, repeat: DVec2) -> Result<TextureMap, String> {
        let one = |e: &dyn std::fmt::Display| cov_core::one_line(&e.to_string());
        crate::error::regular_file(path)?;
        crate::error::within_length(path, MAX_TEXTURE_BYTES, "texture")?;
        // By content, then by extension; anything but PNG and EXR is named as such.
        let open = || {
            let r = image::ImageReader::open(path)
                .and_then(|r| r.with_guessed_format())
                .map_err(|e| one(&e))?;
            match r.format() {
                Some(image::ImageFormat::Png | image::ImageFormat::OpenExr) => Ok(r),
                _ => Err("not a PNG or EXR image (the formats textures are read from)".to_string()),
            }
        };
        let first = open()?;
        let exr = matches!(first.format(), Some(image::ImageFormat::OpenExr));
        // Where the image library cannot read an EXR (one grey channel `Y`), its header
        // gives the size.
        let exr_size = || {
            let meta = exr::meta::MetaData::read_from_file(path, false).ok()?;
            let size = meta.headers.first()?.layer_size;
            Some((u32::try_from(size.0).ok()?, u32::try_from(size.1).ok()?))
        };
        let (w, h) = match first.into_dimensions() {
            Ok(d) => d,
            // A header whose size exceeds the decoder's own memory limit fails there already.
            Err(image::ImageError::Limits(_)) => {
                return Err(format!(
                    "the image is larger than textures are read, up to {MAX_TEXTURE_SIDE} texels per side"
                ));
            }
            Err(e) if exr => exr_size().ok_or_else(|| match std::fs::metadata(path) {
                Ok(m) if m.len() == 0 => "the file is empty".to_string(),
                _ => format!(
                    "{} (its header cannot be read: the file may be cut short or damaged)",
                    one(&e)
                ),
            })?,
            Err(e) => return Err(format!("{} (the file may be cut short or damaged)", one(&e))),
        };
        if w == 0 || h == 0 || w > MAX_TEXTURE_SIDE || h > MAX_TEXTURE_SIDE {
            return Err(format!(
                "the image is {w}x{h}; texture images are read up to {MAX_TEXTURE_SIDE} texels per side"
            ));
        }
        let reader = open()?;
        let img = match reader.decode() {
            Ok(img) => img.into_rgb32f(),
            // An EXR of one grey channel `Y`, which the image library does not decode.
            Err(e) if exr => {
                let grey = grey_exr(path).ok_or_else(|| match exr_channels(path) {
                    // The channels are there: the data is what the decoder refused (a
                    // file cut short, a damaged block).
                    // One grey channel, which only our own reader reads: the decoder's
                    // words would be about colour channels.
                    Some(c) if has_colour(&c) && !c.iter().any(|n| n == "R") => {
                        "its channel Y cannot be read: the file may be cut short or damaged".to_string()
                    }
                    Some(c) if has_colour(&c) => {
                        format!("{} (the file may be cut short or damaged)", one(&e))
                    }
                    Some(c) => format!(
                        "{} (an EXR texture needs R, G and B channels, or Y; this one has {})",
                        one(&e),
                        if c.is_empty() {
                            "none".to_string()
                        } else {
                            c.join(", ")
                        }
                    ),
                    None => one(&e),
                })?;
                return Self::from_rgb(w, h, grey, repeat);
            }
            Err(e) => return Err(format!("{} (the file may be cut short or damaged)", one(&e))),
        };
        let srgb = |c: f32| {
            if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            }
        };
        let rgb = img
            .pixels()
            .map(|p| if exr { p.0 } else { p.0.map(srgb) })
            .collect();
        Self::from_rgb(w, h, rgb, repeat)
    }

    /// Rasterises `f(u, v)` (u, v in [0, 1), sampled at texel centres) on `size²` texels;
    /// its callers checked `size` ([`checked_size`]).
    ///
    /// # Errors
    /// A `repeat` that is not finite and > 0 (the only check of [`TextureMap::from_rgb`]
    /// that a checked side leaves).
    fn raster(size: u32, repeat: DVec2, f: impl Fn(f64, f64) -> DVec3) -> Result<TextureMap, BadParameter> {
        let n = size as usize;
        let mut rgb = Vec::with_capacity(n * n);
        for row in 0..n {
            let v = 1.0 - (row as f64 + 0.5) / n as f64;
            for col in 0..n {
                let c = f((col as f64 + 0.5) / n as f64, v);
                rgb.push([c.x as f32, c.y as f32, c.z as f32]);
            }
        }
        Self::from_rgb(size, size, rgb, repeat).map_err(|why| BadParameter::new("repeat", why))
    }

    /// Side lengths of level 0 (texels).
    pub fn size(&self) -> (usize, usize) {
        (self.levels[0].w, self.levels[0].h)
    }

    /// How many times the texture repeats over a unit of `u` and `v`.
    pub fn repeat(&self) -> DVec2 {
        self.repeat
    }

    /// The level (fractional) whose texels span `footprint` (in units of the surface's
    /// `u, v`, before the repeat).
    fn level(&self, footprint: f64) -> f64 {
        let (w, h) = self.size();
        let texels = footprint * (self.repeat.x * w as f64).max(self.repeat.y * h as f64);
        if texels > 1.0 {
            texels.log2().min((self.levels.len() - 1) as f64)
        } else {
            0.0
        }
    }

    /// Trilinear interpolation of per-texel values `get` at texture coordinates `st` (the
    /// repeat applied) between the levels around `lev` (fractional, [`TextureMap::level`]).
    fn lookup<const K: usize>(
        &self,
        lev: f64,
        st: DVec2,
        get: impl Fn(&Level, usize) -> [f64; K],
    ) -> [f64; K] {
        // Coordinates past f64 (a huge repeat times a huge uv) average the texture over
        // its every repeat: the mean, the top level's one texel.
        let (lev, st) = if st.is_finite() {
            (lev, st)
        } else {
            ((self.levels.len() - 1) as f64, DVec2::ZERO)
        };
        let l0 = lev.floor() as usize;
        let t = lev - l0 as f64;
        let a = self.levels[l0].bilinear(st, &get);
        if t <= 0.0 || l0 + 1 >= self.levels.len() {
            return a;
        }
        let b = self.levels[l0 + 1].bilinear(st, &get);
        std::array::from_fn(|k| a[k] * (1.0 - t) + b[k] * t)
    }

    /// The colour at `uv`, averaged over a footprint of `footprint` (units of `u, v`).
    pub fn rgb(&self, uv: DVec2, footprint: f64) -> DVec3 {
        let c = self.lookup(self.level(footprint), uv * self.repeat, |l, i| {
            l.rgb[i].map(f64::from)
        });
        DVec3::from_array(c)
    }

    /// The luminance statistics of the texture band-limited at `band` (the finest detail
    /// kept, units of `u, v`: the level whose texels are that wide, interpolated linearly
    /// between the two levels around it as the colour is), each over a 3×3-texel
    /// neighbourhood there, on a grid of at most [`MAX_REGION_GRID`]² points that covers
    /// the parallelogram `uv + a·edges[0] + b·edges[1]`, `a, b ∈ [−½, ½]` (units of `u,
    /// v`; the block's footprint, mapped by the surface's own `(u, v)` map, so that a map
    /// stretched more along `u` than along `v` covers the same area of the surface),
    /// spaced along each edge by the neighbourhoods' width at the nearer level where the
    /// cap allows, with derivatives per unit of the surface's `u` and `v` (the repeat
    /// included).
    ///
    /// A step's derivatives grow as its level's texels shrink, so the nearer level alone
    /// made the prediction jump where the footprint crosses halfway between two levels:
    /// on a frame-filling checker at 3.4 px a period, a disc of a 4× higher prediction in
    /// the middle of the image, and the Σ filter outside it blurred the checks (relMSE
    /// 5.8e-2 against 2.0e-2 to 2.8e-2 interpolated, 16 spp; docs/render-bench.md, "A
    /// texture finer than the pixels").
    pub fn moments(&self, uv: DVec2, band: f64, edges: [DVec2; 2]) -> impl Iterator<Item = Moments> + '_ {
        let get = |l: &Level, i: usize| l.mom[i].map(f64::from);
        let lev = self.level(band);
        // The lookups are spaced by the neighbourhoods of the nearer level: an edge's
        // length in its texels, over three.
        let l = &self.levels[lev.round() as usize];
        let (ru, rv) = (self.repeat.x, self.repeat.y);
        let texels = DVec2::new(ru * l.w as f64, rv * l.h as f64);
        let count = |e: DVec2| {
            let n = ((e * texels).length() / 3.0).ceil();
            // NaN (a degenerate map) and 0 take one lookup.
            if n >= 1.0 {
                (n as usize).min(MAX_REGION_GRID)
            } else {
                1
            }
        };
        let (ka, kb) = (count(edges[0]), count(edges[1]));
        (0..ka * kb).map(move |n| {
            let a = ((n % ka) as f64 + 0.5) / ka as f64 - 0.5;
            let b = ((n / ka) as f64 + 0.5) / kb as f64 - 0.5;
            let at = (uv + edges[0] * a + edges[1] * b) * self.repeat;
            let m = self.lookup(lev, at, get);
            Moments {
                mean: m[0],
                mean_sq: m[0] * m[0] + m[1].max(0.0),
                grad: [m[2] * ru * ru, m[3] * ru * rv, m[4] * rv * rv],
            }
        })
    }
}

/// The channel names of an EXR's first layer, from its header alone; `None` when the
/// header cannot be read.
fn exr_channels(path: &Path) -> Option<Vec<String>> {
    let meta = exr::meta::MetaData::read_from_file(path, false).ok()?;
    let header = meta.headers.first()?;
    Some(header.channels.list.iter().map(|c| c.name.to_string()).collect())
}

/// Whether `channels` hold what a texture reads: R, G and B, or Y.
fn has_colour(channels: &[String]) -> bool {
    let has = |n: &str| channels.iter().any(|c| c == n);
    (has("R") && has("G") && has("B")) || has("Y")
}

/// The texels of an EXR file's first layer as grey colours, where it has a channel `Y`
/// (luminance, as a greyscale EXR stores it); `None` where it has none or cannot be read.
/// Its size was checked from its header.
fn grey_exr(path: &Path) -> Option<Vec<[f32; 3]>> {
    let image = exr::prelude::read_first_flat_layer_from_file(path).ok()?;
    let y = image
        .layer_data
        .channel_data
        .list
        .iter()
        .find(|c| c.name.to_string() == "Y")?;
    Some(y.sample_data.values_as_f32().map(|v| [v; 3]).collect())
}

/// Largest side of the grid of lookups [`TextureMap::moments`] spreads over a region.
pub const MAX_REGION_GRID: usize = 16;

impl Level {
    /// A level from its colours, with its luminance statistics: over each texel's 3×3
    /// neighbourhood (wrapping), the mean and variance of `A`, and the mean products of
    /// the differences between neighbours in it, per unit of `u` (`w` texels) and `v` (`h`
    /// texels, pointing up the rows). Taken at every level from that level's own texels, they describe the
    /// texture as seen through a footprint of one texel there: detail finer than the
    /// footprint is averaged away, as the pixel averages it, and a step acts as a window
    /// of the footprint's size, as a blocker's edge does (cov-occlusion's `BlockerEdge`).
    fn new(w: usize, h: usize, rgb: Vec<[f32; 3]>) -> Level {
        let a: Vec<f64> = rgb.iter().map(|&c| lum(c)).collect();
        let (fw, fh) = (w as f64, h as f64);
        // Each column's left, own and right column (wrapping), found once.
        let cols: Vec<[usize; 3]> = (0..w).map(|x| [(x + w - 1) % w, x, (x + 1) % w]).collect();
        // Rows in parallel, written in place.
        let mut mom = vec![[0f32; 5]; w * h];
        mom.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
            let rows = [(y + h - 1) % h, y, (y + 1) % h];
            for (x, out) in row.iter_mut().enumerate() {
                // The 3×3 neighbourhood, row 0 on top (wrapping).
                let n: [[f64; 3]; 3] =
                    std::array::from_fn(|r| std::array::from_fn(|c| a[rows[r] * w + cols[x][c]]));
                let mean = n.iter().flatten().sum::<f64>() / 9.0;
                let var = n.iter().flatten().map(|v| (v - mean).powi(2)).sum::<f64>() / 9.0;
                // Differences between neighbours inside the neighbourhood only, so that a
                // constant neighbourhood has no gradient (then the variance bounds it):
                // the six horizontal and six vertical pairs, per unit of u and of v (up).
                let mut gu = 0.0;
                let mut gv = 0.0;
                for i in 0..3 {
                    for j in 0..2 {
                        gu += ((n[i][j + 1] - n[i][j]) * fw).powi(2) / 6.0;
                        gv += ((n[j][i] - n[j + 1][i]) * fh).powi(2) / 6.0;
                    }
                }
                // The cross term from each 2×2 sub-square's mean differences, held to
                // |guv| ≤ √(gu gv).
                let mut guv = 0.0;
                for r in 0..2 {
                    for c in 0..2 {
                        let du = (n[r][c + 1] - n[r][c] + n[r + 1][c + 1] - n[r + 1][c]) * 0.5 * fw;
                        let dv = (n[r][c] - n[r + 1][c] + n[r][c + 1] - n[r + 1][c + 1]) * 0.5 * fh;
                        guv += du * dv / 4.0;
                    }
                }
                let lim = (gu * gv).sqrt();
                *out = [mean, var, gu, guv.clamp(-lim, lim), gv].map(|v| v as f32);
            }
        });
        Level { w, h, rgb, mom }
    }

    /// The next level: 2×2 box averages of the colours (an odd last row or column is
    /// averaged with itself).
    fn half(&self) -> Level {
        let (w, h) = ((self.w).div_ceil(2), (self.h).div_ceil(2));
        let mut rgb = Vec::with_capacity(w * h);
        for y in 0..h {
            for x in 0..w {
                let xs = [2 * x, (2 * x + 1).min(self.w - 1)];
                let ys = [2 * y, (2 * y + 1).min(self.h - 1)];
                let mut c = [0f32; 3];
                for &yy in &ys {
                    for &xx in &xs {
                        let i = yy * self.w + xx;
                        c.iter_mut().zip(self.rgb[i]).for_each(|(a, b)| *a += 0.25 * b);
                    }
                }
                rgb.push(c);
            }
        }
        Level::new(w, h, rgb)
    }

    /// Bilinear interpolation at texture coordinates `st` (wrapping).
    fn bilinear<const K: usize>(&self, st: DVec2, get: &impl Fn(&Level, usize) -> [f64; K]) -> [f64; K] {
        let x = (st.x - st.x.floor()) * self.w as f64 - 0.5;
        // v points up; row 0 is the top.
        let y = (1.0 - (st.y - st.y.floor())) * self.h as f64 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        // The texel index, wrapped: no division where it lies in the level already.
        let wrap = |i: f64, n: usize| {
            let i = i as i64;
            if (0..n as i64).contains(&i) {
                i as usize
            } else {
                i.rem_euclid(n as i64) as usize
            }
        };
        let (xa, xb) = (wrap(x0, self.w), wrap(x0 + 1.0, self.w));
        let (ya, yb) = (wrap(y0, self.h), wrap(y0 + 1.0, self.h));
        let (p, q, r, s) = (
            get(self, ya * self.w + xa),
            get(self, ya * self.w + xb),
            get(self, yb * self.w + xa),
            get(self, yb * self.w + xb),
        );
        std::array::from_fn(|k| {
            (p[k] * (1.0 - fx) + q[k] * fx) * (1.0 - fy) + (r[k] * (1.0 - fx) + s[k] * fx) * fy
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rustfft::FftPlanner;
    use rustfft::num_complex::Complex;

    const FOUR_PI_SQ: f64 = 4.0 * std::f64::consts::PI * std::f64::consts::PI;

    /// The amplitude-spectrum second moment along u (cycles per unit u)² of a 1D profile
    /// `a` (n samples over one unit), under a Gaussian window of `std` (units of u)
    /// centred at `c`, minus the window's own (docs/physics.md section 5, in 1D).
    fn fft_moment(a: &[f64], c: f64, std: f64) -> f64 {
        let n = a.len();
        let mut data: Vec<Complex<f64>> = (0..n)
            .map(|i| {
                let mut d = (i as f64 + 0.5) / n as f64 - c;
                d -= d.round();
                Complex::new(a[i] * (-0.5 * d * d / (std * std)).exp(), 0.0)
            })
            .collect();
        FftPlanner::new().plan_fft_forward(n).process(&mut data);
        let (mut m, mut mass) = (0.0, 0.0);
        for (k, z) in data.iter().enumerate() {
            let f = if k < n / 2 { k as f64 } else { k as f64 - n as f64 };
            m += z.norm() * f * f;
            mass += z.norm();
        }
        m / mass - 1.0 / (FOUR_PI_SQ * std * std)
    }

    /// The formula's prediction for the same window: the window-weighted averages of A,
    /// A² and A_u² fed to `Texture::from_moments`.
    fn formula_moment(a: &[f64], c: f64, std: f64) -> f64 {
        let n = a.len();
        let (mut s0, mut s1, mut s2, mut g) = (0.0, 0.0, 0.0, 0.0);
        for i in 0..n {
            let mut d = (i as f64 + 0.5) / n as f64 - c;
            d -= d.round();
            let w = (-0.5 * d * d / (std * std)).exp();
            let du = (a[(i + 1) % n] - a[i]) * n as f64;
            s0 += w;
            s1 += w * a[i];
            s2 += w * a[i] * a[i];
            g += w * du * du;
        }
        let t = cov_occlusion::Texture::from_moments(s1 / s0, s2 / s0, [g / s0, 0.0, 0.0]).expect("valid");
        t.spectrum()[0]
    }

    /// `a` convolved with a periodic Gaussian of `std` (units of u).
    fn blur(a: &[f64], std: f64) -> Vec<f64> {
        let n = a.len();
        let r = (4.0 * std * n as f64) as i64;
        let k: Vec<f64> = (-r..=r)
            .map(|i| (-0.5 * (i as f64 / (std * n as f64)).powi(2)).exp())
            .collect();
        let norm: f64 = k.iter().sum();
        (0..n as i64)
            .map(|i| {
                (-r..=r)
                    .map(|j| k[(j + r) as usize] * a[(i + j).rem_euclid(n as i64) as usize])
                    .sum::<f64>()
                    / norm
            })
            .collect()
    }

    fn profile(n: usize, f: impl Fn(f64) -> f64) -> Vec<f64> {
        (0..n).map(|i| f((i as f64 + 0.5) / n as f64)).collect()
    }

    #[test]
    fn the_formula_is_exact_for_a_sinusoid() {
        // 0.5 + 0.3 cos(2π 40 u): W = 0.3 · 40² / 0.8 = 600 (cycles/u)².
        let a = profile(4096, |u| {
            0.5 + 0.3 * (2.0 * std::f64::consts::PI * 40.0 * u).cos()
        });
        let exact = 0.3 * 1600.0 / 0.8;
        let fft = fft_moment(&a, 0.5, 0.1);
        let formula = formula_moment(&a, 0.5, 0.1);
        assert!((fft - exact).abs() < 1e-2 * exact, "fft {fft} exact {exact}");
        assert!(
            (formula - exact).abs() < 1e-2 * exact,
            "formula {formula} exact {exact}"
        );
    }

    /// Broadband patches: the formula against the FFT of the same windowed patch. The
    /// narrowband model gives broadband variation too little amplitude mass: measured
    /// ratios 0.48 (noise), 0.91 (checker), 0.32 (photograph-like), documented in
    /// docs/physics.md section 3; the bounds hold the model to that.
    #[test]
    fn broadband_patches_against_their_fft() {
        use rand::{Rng, SeedableRng};
        let n = 4096;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        // Smooth noise: 64 lattice values, smoothstep interpolation.
        let lat: Vec<f64> = (0..64).map(|_| rng.random::<f64>()).collect();
        let noise = profile(n, |u| {
            let x = u * 64.0;
            let (i, f) = (x.floor() as usize, x.fract());
            let s = f * f * (3.0 - 2.0 * f);
            0.2 + 0.6 * (lat[i % 64] * (1.0 - s) + lat[(i + 1) % 64] * s)
        });
        // A checker row: 16 squares of 0.2 and 0.8, edges one texel wide.
        let checker = profile(n, |u| {
            if ((u * 16.0) as u32).is_multiple_of(2) {
                0.2
            } else {
                0.8
            }
        });
        // Photograph-like: a few soft blobs and one hard edge over a gradient.
        let photo = profile(n, |u| {
            let blobs: f64 = [(0.3, 0.02, 0.3), (0.45, 0.05, -0.2), (0.62, 0.01, 0.25)]
                .iter()
                .map(|&(c, s, h)| h * (-0.5 * ((u - c) / s).powi(2)).exp())
                .sum();
            0.3 + 0.2 * u + blobs + if u > 0.52 { 0.2 } else { 0.0 }
        });
        for (name, a) in [("noise", &noise), ("checker", &checker), ("photo", &photo)] {
            // Seen through a footprint: blurred at a quarter of the window, as a pyramid
            // level is (without it a step's spectrum has no finite moment).
            let a = &blur(a, 0.02);
            let fft = fft_moment(a, 0.5, 0.08);
            let formula = formula_moment(a, 0.5, 0.08);
            let r = formula / fft;
            println!("{name}: fft {fft:.4e} formula {formula:.4e} ratio {r:.3}");
            assert!((0.25..=2.0).contains(&r), "{name}: fft {fft} formula {formula}");
        }
    }

    fn one(t: &TextureMap, uv: DVec2, band: f64) -> Moments {
        let v: Vec<Moments> = t.moments(uv, band, [DVec2::ZERO; 2]).collect();
        assert_eq!(v.len(), 1);
        v[0]
    }

    #[test]
    fn each_level_sees_the_texture_through_its_footprint() {
        let t =
            TextureMap::checker((4, 4), DVec3::splat(0.2), DVec3::splat(0.8), 64, DVec2::ONE).expect("ok");
        // Inside a square at full resolution: its colour, no gradient.
        let m = one(&t, DVec2::new(0.125, 0.125), 0.0);
        assert_eq!(m.grad, [0.0; 3]);
        assert!(
            (m.mean - 0.2).abs() < 1e-6 && (m.mean_sq - 0.04).abs() < 1e-6,
            "{m:?}"
        );
        assert!((t.rgb(DVec2::new(0.125, 0.125), 0.0) - DVec3::splat(0.2)).length() < 1e-6);
        // Through a footprint of one square (level 4, 4×4 texels): every step of 0.6 over
        // a quarter of u, so A_u² = (0.6 · 4)².
        let m = one(&t, DVec2::new(0.125, 0.125), 0.25);
        let g = (0.6f64 * 4.0).powi(2);
        assert!(
            (m.grad[0] - g).abs() < 1e-3 * g && (m.grad[2] - g).abs() < 1e-3 * g,
            "{m:?}"
        );
        assert!(m.mean_sq - m.mean * m.mean > 0.08, "{m:?}");
        // Through the whole texture (one texel): a constant 0.5, no variation.
        let m = one(&t, DVec2::new(0.3, 0.7), 1e9);
        assert!((m.mean - 0.5).abs() < 1e-6 && m.grad == [0.0; 3], "{m:?}");
        // Band-limited at full resolution, over a region of two squares: lookups on both
        // colours, and on the edge between them.
        let ms: Vec<Moments> = t
            .moments(
                DVec2::new(0.25, 0.125),
                0.0,
                [DVec2::new(0.5, 0.0), DVec2::new(0.0, 0.5)],
            )
            .collect();
        assert!(ms.len() > 1 && ms.len() <= MAX_REGION_GRID * MAX_REGION_GRID);
        assert!(
            ms.iter().any(|m| (m.mean - 0.2).abs() < 1e-6) && ms.iter().any(|m| (m.mean - 0.8).abs() < 1e-6)
        );
        assert!(ms.iter().any(|m| m.grad[0] > 0.0));
        // Repeating twice doubles the derivatives per unit of u.
        let t2 = TextureMap::checker(
            (4, 4),
            DVec3::splat(0.2),
            DVec3::splat(0.8),
            64,
            DVec2::splat(2.0),
        )
        .expect("ok");
        let m2 = one(&t2, DVec2::new(0.0625, 0.0625), 0.125);
        assert!((m2.grad[0] - 4.0 * g).abs() < 1e-3 * g, "{m2:?}");
    }

    /// Between two levels the statistics are interpolated, as the colour is: a footprint
    /// growing by 5% of a level at a time changes them by a fraction of the two levels'
    /// difference, never by the jump from one level to the next (the nearer level alone
    /// jumped from 11.5 to 5.76 halfway between levels 3 and 4 here, and to 0 between 4
    /// and 5), and at a level's own footprint they are that level's.
    #[test]
    fn the_statistics_do_not_jump_between_levels() {
        let t =
            TextureMap::checker((4, 4), DVec3::splat(0.2), DVec3::splat(0.8), 64, DVec2::ONE).expect("ok");
        let uv = DVec2::new(0.3, 0.45);
        // Level `l` has texels of 2^l / 64 of `u`.
        let at = |l: f64| one(&t, uv, l.exp2() / 64.0).grad[0];
        let sweep: Vec<f64> = (0..=40).map(|k| at(3.0 + 0.05 * f64::from(k))).collect();
        let (lo, hi) = (sweep[0].min(sweep[40]), sweep[0].max(sweep[40]));
        assert!(hi - lo > 1.0, "the two levels differ: {sweep:?}");
        for pair in sweep.windows(2) {
            assert!((pair[1] - pair[0]).abs() <= 0.1 * (hi - lo), "{sweep:?}");
        }
        // Level 4 has one texel a square, four along `u`: every difference is a step of 0.6
        // over a quarter of `u`.
        assert!(
            (sweep[20] - (0.6f64 * 4.0).powi(2)).abs() < 1e-3 * sweep[20],
            "{sweep:?}"
        );
        assert!(
            sweep.iter().all(|g| (lo - 1e-9..=hi + 1e-9).contains(g)),
            "{sweep:?}"
        );
    }

    /// A greyscale EXR (one channel `Y`, which the image library does not read) is read
    /// as grey, linear, right way up: its top row is the texture's top (`v` near 1).
    #[test]
    fn a_greyscale_exr_is_read() {
        use exr::prelude::*;
        let dir = std::env::temp_dir().join(format!("covtrace-grey-exr-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let path = dir.join("y.exr");
        // An EXR of 4 × 2 texels and one channel `name`.
        let write = |path: &Path, name: &str, texel: fn(Vec2<usize>) -> f32| {
            let layer = Layer::new(
                (4usize, 2usize),
                LayerAttributes::named(""),
                Encoding::FAST_LOSSLESS,
                SpecificChannels::build()
                    .with_channel(name)
                    .with_pixel_fn(|p: Vec2<usize>| (texel(p),)),
            );
            Image::from_layer(layer).write().to_file(path).expect("write EXR");
        };
        // The top row 0.75, the bottom row 0.25.
        write(&path, "Y", |p| if p.y() == 0 { 0.75 } else { 0.25 });
        let t = TextureMap::load(&path, DVec2::ONE).expect("a Y-only EXR loads");
        assert_eq!(t.size(), (4, 2));
        assert_eq!(t.rgb(DVec2::new(0.375, 0.75), 0.0), DVec3::splat(0.75));
        assert_eq!(t.rgb(DVec2::new(0.375, 0.25), 0.0), DVec3::splat(0.25));
        // An EXR of other channels names them; one cut short is not said to lack channels.
        let depth = dir.join("z.exr");
        write(&depth, "Z", |_| 1.0);
        let e = TextureMap::load(&depth, DVec2::ONE).unwrap_err();
        assert!(
            e.ends_with("(an EXR texture needs R, G and B channels, or Y; this one has Z)"),
            "{e}"
        );
        let bytes = std::fs::read(&path).expect("read EXR");
        let cut = dir.join("cut.exr");
        std::fs::write(&cut, &bytes[..bytes.len() - 8]).expect("write EXR");
        let e = TextureMap::load(&cut, DVec2::ONE).unwrap_err();
        assert_eq!(
            e,
            "its channel Y cannot be read: the file may be cut short or damaged"
        );
        let empty = dir.join("empty.exr");
        std::fs::write(&empty, b"").expect("write EXR");
        let e = TextureMap::load(&empty, DVec2::ONE).unwrap_err();
        assert_eq!(e, "the file is empty");
        let head = dir.join("head.exr");
        std::fs::write(&head, &bytes[..6]).expect("write EXR");
        let e = TextureMap::load(&head, DVec2::ONE).unwrap_err();
        assert!(
            e.ends_with("(its header cannot be read: the file may be cut short or damaged)"),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).expect("clean up");
    }

    #[test]
    fn bad_textures_are_errors() {
        assert!(TextureMap::from_rgb(0, 4, vec![], DVec2::ONE).is_err());
        assert!(TextureMap::from_rgb(2, 2, vec![[0.0; 3]; 3], DVec2::ONE).is_err());
        assert!(TextureMap::from_rgb(1, 1, vec![[0.0; 3]], DVec2::new(0.0, 1.0)).is_err());
        assert!(TextureMap::checker((0, 2), DVec3::ZERO, DVec3::ONE, 8, DVec2::ONE).is_err());
        assert!(TextureMap::stripes(2, 1.0, DVec3::ZERO, DVec3::ONE, 8, DVec2::ONE).is_err());
        assert!(TextureMap::noise(2, 0, DVec3::ZERO, DVec3::ONE, MAX_TEXTURE_SIDE + 1, DVec2::ONE).is_err());
        assert!(TextureMap::load(Path::new("/nonexistent.png"), DVec2::ONE).is_err());
        // A PNG whose header declares 2³¹ − 1 × 1 texels (68 bytes): the decoder's memory
        // limit refuses it before our own size check can, and the message says why.
        let dir = std::env::temp_dir().join(format!("covtrace-texture-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let wide = dir.join("wide.png");
        std::fs::write(
            &wide,
            [
                0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44,
                0x52, 0x7f, 0xff, 0xff, 0xff, 0x00, 0x00, 0x00, 0x01, 0x08, 0x02, 0x00, 0x00, 0x00, 0x2f,
                0x54, 0xa4, 0x8a, 0x00, 0x00, 0x00, 0x0b, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9c, 0x63, 0x60,
                0x80, 0x01, 0x00, 0x00, 0x0a, 0x00, 0x01, 0x7f, 0x80, 0x74, 0x5e, 0x00, 0x00, 0x00, 0x00,
                0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82,
            ],
        )
        .expect("write PNG");
        let e = TextureMap::load(&wide, DVec2::ONE).unwrap_err();
        assert!(e.starts_with("the image is larger than textures are read"), "{e}");
        std::fs::remove_dir_all(&dir).expect("clean up");
        // A file that is no image says so, in its own words.
        let this = Path::new(env!("CARGO_MANIFEST_DIR")).join("Cargo.toml");
        let e = TextureMap::load(&this, DVec2::ONE).unwrap_err();
        assert_eq!(e, "not a PNG or EXR image (the formats textures are read from)");
        // NaN and out-of-range texels are clamped, never passed on.
        let t = TextureMap::from_rgb(1, 1, vec![[f32::NAN, 2.0, -1.0]], DVec2::ONE).expect("ok");
        assert_eq!(t.rgb(DVec2::ZERO, 0.0), DVec3::new(0.0, 1.0, 0.0));
    }
}
