//! Rendering an image and its covariance maps, tile by tile over rayon.
//!
//! Each tile draws its random numbers from its own generator, seeded from the scene seed
//! and the tile's index, and tiles are assembled in order: an image does not depend on the
//! number of threads.

use std::path::Path;
use std::time::Instant;

use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use crate::covpass::{CovCamera, PixelCov, trace_path};
use crate::film::Film;
use crate::world::World;

/// Tile side (px).
pub const TILE: u32 = 16;
/// Largest number of samples per pixel a render takes.
pub const MAX_SPP: u32 = 1 << 16;
/// Largest number of covariance paths per pixel.
pub const MAX_COV_PATHS: u32 = 256;

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
}

/// The tiles of a `width × height` image: (x0, y0, x1, y1).
pub(crate) fn tiles(width: u32, height: u32) -> Vec<(u32, u32, u32, u32)> {
    let mut out = Vec::new();
    for y0 in (0..height).step_by(TILE as usize) {
        for x0 in (0..width).step_by(TILE as usize) {
            out.push((x0, y0, (x0 + TILE).min(width), (y0 + TILE).min(height)));
        }
    }
    out
}

/// The image of per-tile results, each tile's values row by row, in tile order.
fn assemble<T: Clone>(
    w: u32,
    h: u32,
    tiles: &[(u32, u32, u32, u32)],
    results: Vec<Vec<T>>,
    fill: T,
) -> Vec<T> {
    let mut out = vec![fill; w as usize * h as usize];
    for (&(x0, y0, x1, y1), tile) in tiles.iter().zip(results) {
        let coords = (y0..y1).flat_map(|y| (x0..x1).map(move |x| (y * w + x) as usize));
        for (i, v) in coords.zip(tile) {
            out[i] = v;
        }
    }
    out
}

/// The generator of tile `index` for `stream` (0: image samples, 1: covariance paths).
fn tile_rng(seed: u64, stream: u64, index: usize) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ (stream << 56));
    rng.set_stream(index as u64);
    rng
}

/// Renders `spp` samples per pixel with a box pixel filter, over pixel × lens × time from
/// each pixel's Owen-scrambled Sobol sequence ([`crate::sampler`]).
pub fn render(world: &World, spp: u32, seed: u64) -> Image {
    let spp = spp.clamp(1, MAX_SPP);
    let per_pixel = vec![spp; world.camera.width as usize * world.camera.height as usize];
    render_adaptive(world, &per_pixel, seed, None).0
}

/// Called once per finished tile (to drive a progress bar).
pub type Progress<'a> = Option<&'a (dyn Fn() + Sync)>;

/// Number of tiles of the world's image (what [`Progress`] counts to, once per pass).
pub fn tile_count(world: &World) -> usize {
    tiles(world.camera.width, world.camera.height).len()
}

/// Renders `counts[i]` samples in pixel `i` (at least 1, at most [`MAX_SPP`] each) with a
/// box pixel filter; also returns the per-pixel sample variance of the luminance (for
/// variance-driven sampling).
pub fn render_adaptive(
    world: &World,
    counts: &[u32],
    seed: u64,
    progress: Progress<'_>,
) -> (Image, Vec<f64>) {
    render_clamped(world, counts, seed, f64::INFINITY, progress)
}

/// [`render_adaptive`] with every sample's luminance clamped to `max_luminance` (colour
/// scaled down). Biased: for measuring the spectrum of a reference without its rare
/// caustic fireflies (`covtrace render-check`), never for an image.
pub fn render_clamped(
    world: &World,
    counts: &[u32],
    seed: u64,
    max_luminance: f64,
    progress: Progress<'_>,
) -> (Image, Vec<f64>) {
    let (w, h) = (world.camera.width, world.camera.height);
    let counts: Vec<u32> = (0..w as usize * h as usize)
        .map(|i| counts.get(i).copied().unwrap_or(1).clamp(1, MAX_SPP))
        .collect();
    let mut film = Film::new(w, h);
    film.render(world, &counts, seed, max_luminance, progress);
    (film.box_image(), film.variance())
}

/// The covariance maps of an image: per pixel, the predicted image-space Σ and samples
/// per pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct CovMaps {
    /// Width (px).
    pub width: u32,
    /// Height (px).
    pub height: u32,
    /// Per pixel.
    pub pixels: Vec<PixelCov>,
    /// Covariance paths traced per block of the grid.
    pub paths_per_block: u32,
    /// Side of the grid's blocks (px; 1: a prediction per pixel).
    pub stride: u32,
    /// Layout the paths were traced in.
    pub layout: usize,
}

/// Traces `paths` covariance paths per pixel (jittered over the pixel and the shutter).
///
/// # Errors
/// An operator that rejects what the scene gives it (a chain that overflows, say), with
/// the pixel it happened at.
pub fn covariance_maps(world: &World, paths: u32, seed: u64) -> Result<CovMaps, String> {
    covariance_maps_with(world, paths, seed, None)
}

/// [`covariance_maps`] reporting each finished tile to `progress`.
///
/// # Errors
/// As [`covariance_maps`].
pub fn covariance_maps_with(
    world: &World,
    paths: u32,
    seed: u64,
    progress: Progress<'_>,
) -> Result<CovMaps, String> {
    covariance_maps_strided(world, paths, 1, seed, progress)
}

/// Strides of the covariance grid [`covariance_maps_strided`] accepts (they divide a tile).
pub const STRIDES: [u32; 5] = [1, 2, 4, 8, 16];

/// Traces `paths` covariance paths per block of `stride × stride` pixels (jittered over
/// the block and the shutter); every pixel of a block gets the block's prediction. A
/// coarser grid costs `stride²` times less; a block that holds an edge predicts for all
/// its pixels the detail that its paths saw (radiance-weighted), so edges widen to the
/// block, which narrows filters and raises densities near them (conservative).
///
/// # Errors
/// A stride not in [`STRIDES`]; an operator that rejects what the scene gives it, with the
/// pixel it happened at.
pub fn covariance_maps_strided(
    world: &World,
    paths: u32,
    stride: u32,
    seed: u64,
    progress: Progress<'_>,
) -> Result<CovMaps, String> {
    if !STRIDES.contains(&stride) {
        return Err(format!(
            "the covariance grid's stride must be one of {STRIDES:?}, got {stride}"
        ));
    }
    let paths = paths.clamp(1, MAX_COV_PATHS);
    let cc = CovCamera::new(world).map_err(|e| e.to_string())?;
    let (w, h) = (world.camera.width, world.camera.height);
    let tl = tiles(w, h);
    let results: Result<Vec<Vec<PixelCov>>, String> = tl
        .par_iter()
        .enumerate()
        .map(|(index, &(x0, y0, x1, y1))| {
            let mut rng = tile_rng(seed, 1, index);
            let mut out = vec![PixelCov::default(); ((x1 - x0) * (y1 - y0)) as usize];
            for by in (y0..y1).step_by(stride as usize) {
                for bx in (x0..x1).step_by(stride as usize) {
                    let (sx, sy) = ((x1 - bx).min(stride), (y1 - by).min(stride));
                    let acc = block_cov(world, &cc, (bx, by), (sx, sy), paths, &mut rng)?;
                    for y in by..by + sy {
                        for x in bx..bx + sx {
                            out[((y - y0) * (x1 - x0) + (x - x0)) as usize] = acc;
                        }
                    }
                }
            }
            if let Some(p) = progress {
                p();
            }
            Ok(out)
        })
        .collect();
    Ok(CovMaps {
        width: w,
        height: h,
        pixels: assemble(w, h, &tl, results?, PixelCov::default()),
        paths_per_block: paths,
        stride,
        layout: cc.layout(),
    })
}

/// The radiance-weighted mean prediction of `paths` paths through the block of `size`
/// pixels at `at`.
fn block_cov(
    world: &World,
    cc: &CovCamera,
    (x, y): (u32, u32),
    (sx, sy): (u32, u32),
    paths: u32,
    rng: &mut ChaCha8Rng,
) -> Result<PixelCov, String> {
    let mut acc = PixelCov::default();
    let (mut plain, mut n_plain, mut plain_spp) = ([0.0; 3], 0.0, 0.0);
    for _ in 0..paths {
        let (jx, jy, ut) = (
            rng.random::<f64>() * f64::from(sx),
            rng.random::<f64>() * f64::from(sy),
            rng.random::<f64>(),
        );
        let (px, py) = (f64::from(x) + jx, f64::from(y) + jy);
        let r = trace_path(world, cc, px, py, ut, rng)
            .map_err(|e| format!("covariance path at pixel ({}, {}): {e}", px.floor(), py.floor()))?;
        let Some((d, wgt)) = r else { continue };
        let s = [d.image_cov_px[0][0], d.image_cov_px[0][1], d.image_cov_px[1][1]];
        if !(s.iter().all(|v| v.is_finite()) && d.samples_per_pixel.is_finite()) {
            continue;
        }
        for k in 0..3 {
            acc.sigma[k] += wgt * s[k];
            plain[k] += s[k];
        }
        acc.spp += wgt * d.samples_per_pixel;
        acc.weight += wgt;
        plain_spp += d.samples_per_pixel;
        n_plain += 1.0;
    }
    if acc.weight > 0.0 {
        for k in 0..3 {
            acc.sigma[k] /= acc.weight;
        }
        acc.spp /= acc.weight;
    } else if n_plain > 0.0 {
        // No path carried light: the geometry's content, unweighted.
        acc.sigma = plain.map(|v| v / n_plain);
        acc.spp = plain_spp / n_plain;
    }
    Ok(acc)
}

/// Runs `f`, returning its result and the seconds it took.
pub fn timed<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let t = Instant::now();
    let r = f();
    (r, t.elapsed().as_secs_f64())
}

/// sRGB encoding of a linear value in `[0, 1]`.
fn srgb(c: f64) -> u8 {
    let c = if c.is_finite() { c.clamp(0.0, 1.0) } else { 0.0 };
    let s = if c <= 0.0031308 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0 + 0.5) as u8
}

/// The tone-mapped sRGB picture of `img` (Reinhard on luminance, which keeps hues;
/// exposure 1).
pub fn tonemap(img: &Image) -> image::RgbImage {
    image::RgbImage::from_fn(img.width, img.height, |x, y| {
        let p = img.get(x, y);
        let l = crate::trace::luminance(p).max(0.0);
        let s = if l > 0.0 { 1.0 / (1.0 + l) } else { 1.0 };
        image::Rgb([srgb(p.x * s), srgb(p.y * s), srgb(p.z * s)])
    })
}

/// Writes `img` as linear OpenEXR (`.exr`) and a tone-mapped sRGB PNG beside it.
///
/// # Errors
/// The files cannot be written.
pub fn write_image(img: &Image, exr: &Path, png: &Path) -> Result<(), String> {
    let raw: Vec<f32> = img
        .pixels
        .iter()
        .flat_map(|p| [p.x as f32, p.y as f32, p.z as f32])
        .collect();
    let hdr = image::Rgb32FImage::from_raw(img.width, img.height, raw).ok_or("image size")?;
    hdr.save(exr).map_err(|e| format!("{}: {e}", exr.display()))?;
    tonemap(img)
        .save(png)
        .map_err(|e| format!("{}: {e}", png.display()))
}

/// Reads a linear RGB image (an EXR written by [`write_image`]).
///
/// # Errors
/// The file cannot be read or decoded.
pub fn read_image(path: &Path) -> Result<Image, String> {
    let img = image::open(path)
        .map_err(|e| format!("{}: {e}", path.display()))?
        .into_rgb32f();
    Ok(Image {
        width: img.width(),
        height: img.height(),
        pixels: img
            .pixels()
            .map(|p| DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])))
            .collect(),
    })
}

/// A perceptually ordered colour map (dark blue → yellow) for `t` in `[0, 1]`.
pub fn colormap(t: f64) -> [u8; 3] {
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 };
    // A few stops of viridis.
    const STOPS: [[f64; 3]; 5] = [
        [68.0, 1.0, 84.0],
        [59.0, 82.0, 139.0],
        [33.0, 145.0, 140.0],
        [94.0, 201.0, 98.0],
        [253.0, 231.0, 37.0],
    ];
    let x = t * (STOPS.len() - 1) as f64;
    let i = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - i as f64;
    let c = |k: usize| (STOPS[i][k] * (1.0 - f) + STOPS[i + 1][k] * f).round() as u8;
    [c(0), c(1), c(2)]
}

/// Writes the density map (samples per pixel, log scale from 1 to the largest) and the
/// filter map (reconstruction filter std of the content, [`content`], 0 to `max_filter`
/// px) as PNGs, and the maps as JSON.
///
/// # Errors
/// The files cannot be written.
pub fn write_maps(
    maps: &CovMaps,
    pixel_filter: f64,
    max_filter: f64,
    density: &Path,
    filter: &Path,
    json: &Path,
) -> Result<(), String> {
    let hi = maps
        .pixels
        .iter()
        .map(|p| p.spp)
        .fold(1.0f64, f64::max)
        .ln()
        .max(1e-9);
    let w = maps.width;
    let img = image::RgbImage::from_fn(maps.width, maps.height, |x, y| {
        let p = &maps.pixels[(y * w + x) as usize];
        image::Rgb(colormap(p.spp.max(1.0).ln() / hi))
    });
    img.save(density)
        .map_err(|e| format!("{}: {e}", density.display()))?;
    let stds: Vec<f64> = maps
        .pixels
        .iter()
        .map(|p| filter_std(content(p.sigma, pixel_filter), max_filter))
        .collect();
    let img = image::RgbImage::from_fn(maps.width, maps.height, |x, y| {
        image::Rgb(colormap(stds[(y * w + x) as usize] / max_filter))
    });
    img.save(filter)
        .map_err(|e| format!("{}: {e}", filter.display()))?;
    let data = serde_json::json!({
        "width": maps.width,
        "height": maps.height,
        "layout": maps.layout,
        "paths_per_block": maps.paths_per_block,
        "block_px": maps.stride,
        "units": { "sigma": "(cycles/px)^2, [xx, xy, yy] per pixel", "spp": "samples per pixel over pixel x lens x time" },
        "sigma": maps.pixels.iter().flat_map(|p| p.sigma).collect::<Vec<f64>>(),
        "spp": maps.pixels.iter().map(|p| p.spp).collect::<Vec<f64>>(),
    });
    std::fs::write(json, serde_json::to_string(&data).map_err(|e| e.to_string())?)
        .map_err(|e| format!("{}: {e}", json.display()))
}

/// The image's own content: the sensor's image-space Σ `[xx, xy, yy]` less the pixel
/// filter's window (`1/(4π² f²)` per axis for a filter of std `f` px, which the sensor adds
/// because it describes the integrand a pixel's samples see), clamped to PSD. Reconstruction
/// filters are made from this: the sensor's Σ would never allow a filter wider than the
/// pixel filter itself.
pub fn content(s: [f64; 3], pixel_filter: f64) -> [f64; 3] {
    let w = 1.0 / (cov_core::FOUR_PI_SQ * pixel_filter * pixel_filter);
    let (a, b, c) = ((s[0] - w).max(0.0), s[1], (s[2] - w).max(0.0));
    let lim = (a * c).sqrt();
    [a, b.clamp(-lim, lim), c]
}

/// The reconstruction filter of an image-space Σ `[xx, xy, yy]` (cycles/px)²: the
/// sensor's rule (`CovBlock::reconstruction_filter`: the Gaussian whose spectrum matches,
/// clamped at `max_filter` px where Σ is small or singular). `None` for a Σ the rule
/// rejects (not finite).
pub fn image_filter(s: [f64; 3], max_filter: f64) -> Option<cov_core::Filter> {
    let mut c = cov_core::Cov::<2>::zeros();
    c.set(0, 0, s[0]);
    c.set(0, 1, s[1]);
    c.set(1, 1, s[2]);
    c.block().reconstruction_filter(&[max_filter; 2]).ok()
}

/// The reconstruction filter's larger std (px) for an image-space Σ ([`image_filter`]).
pub fn filter_std(s: [f64; 3], max_filter: f64) -> f64 {
    image_filter(s, max_filter).map_or(max_filter, |f| {
        f.extents.iter().fold(0.0, |m: f64, v| m.max(*v)).min(max_filter)
    })
}
