//! What a render writes: the linear EXR and its tone-mapped PNG, the covariance maps as
//! pictures and JSON, and the colour map they share.

use std::path::Path;

use glam::DVec3;

use crate::RenderError;
use crate::adaptive::{content, filter_std};
use crate::covpass::CovMaps;
use crate::film::{Aovs, Image};

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

/// `v` in single precision, as an EXR stores it: never ±∞ (a value past f32's range is
/// clamped to its largest; scene colours are bounded so that a render does not get there,
/// `scene::MAX_COLOUR`) and never NaN (0).
fn single(v: f64) -> f32 {
    if v.is_nan() {
        0.0
    } else {
        v.clamp(-f64::from(f32::MAX), f64::from(f32::MAX)) as f32
    }
}

/// How covtrace encodes OpenEXR files: exr's fast lossless encoding (run-length
/// encoded tiles of 64×64 px), with the tiles stored in increasing order. exr compresses
/// tiles in parallel; in an unspecified order it stores each as it is done, so the same
/// image gave different files from run to run (the same pixels, other bytes). In
/// increasing order it sorts them first: the same image is the same file, at any thread
/// count (`an_exr_is_the_same_file_every_time`).
pub const EXR_ENCODING: exr::image::Encoding = exr::image::Encoding {
    line_order: exr::meta::attribute::LineOrder::Increasing,
    ..exr::image::Encoding::FAST_LOSSLESS
};

/// Pixel `p` of `img` in single precision ([`single`]).
fn rgb_at(img: &Image, p: exr::math::Vec2<usize>) -> (f32, f32, f32) {
    let v = img.pixels[p.y() * img.width as usize + p.x()];
    (single(v.x), single(v.y), single(v.z))
}

/// Writes `img` as linear OpenEXR (`.exr`, channels `R`, `G`, `B` in 32-bit float,
/// [`EXR_ENCODING`]) and a tone-mapped sRGB PNG beside it.
///
/// # Errors
/// The files cannot be written.
pub fn write_image(img: &Image, exr: &Path, png: &Path) -> Result<(), RenderError> {
    use exr::prelude::*;
    let (w, h) = (img.width as usize, img.height as usize);
    if w == 0 || h == 0 || img.pixels.len() != w * h {
        return Err(RenderError::file(exr, "the image's pixels do not match its size"));
    }
    let layer = Layer::new(
        (w, h),
        LayerAttributes::default(),
        EXR_ENCODING,
        SpecificChannels::rgb(|p| rgb_at(img, p)),
    );
    let mut bytes = std::io::Cursor::new(Vec::new());
    Image::from_layer(layer)
        .write()
        .to_buffered(&mut bytes)
        .map_err(|e| RenderError::file(exr, e))?;
    write_file(exr, bytes.get_ref())?;
    save(tonemap(img), png)
}

/// Writes `img` to `path` in the format its extension names. It is encoded in memory
/// first, so that a write that fails (a full disk) reads as the system's error, not as
/// the encoder's ("Format error decoding OpenExr"), and the partial file is removed.
///
/// # Errors
/// An extension that names no image format; the file cannot be written.
pub fn save(img: impl Into<image::DynamicImage>, path: &Path) -> Result<(), RenderError> {
    let format = image::ImageFormat::from_path(path).map_err(|e| RenderError::file(path, e))?;
    let mut bytes = std::io::Cursor::new(Vec::new());
    img.into()
        .write_to(&mut bytes, format)
        .map_err(|e| RenderError::file(path, e))?;
    write_file(path, bytes.get_ref())
}

/// Writes `bytes` to `path`; if that fails, removes what was written (a regular file).
///
/// # Errors
/// The file cannot be written (the system's reason, after "cannot write").
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<(), RenderError> {
    std::fs::write(path, bytes).map_err(|e| {
        // A partial file is worse than none: a later run would take it for output. Only a
        // regular file is removed (never a device such as /dev/full, nor a link's target).
        if std::fs::symlink_metadata(path).is_ok_and(|m| m.is_file()) {
            let _ = std::fs::remove_file(path);
        }
        RenderError::file(path, format!("cannot write: {e}"))
    })
}

/// Reads a linear RGB image (an EXR written by [`write_image`]).
///
/// # Errors
/// The file cannot be read or decoded.
pub fn read_image(path: &Path) -> Result<Image, RenderError> {
    let img = image::open(path)
        .map_err(|e| RenderError::file(path, e))?
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

/// The share of a density map's pixels below the top of its colour scale
/// ([`write_maps`]): a few blocks of huge predicted density (a tiny bright light, a
/// caustic: 37,440 spp where the median was 7.7) would otherwise squeeze the rest of the
/// map into its darkest colours.
pub const DENSITY_SCALE_QUANTILE: f64 = 0.99;

/// The top of the density map's colour scale: the [`DENSITY_SCALE_QUANTILE`] of the
/// maps' samples per pixel, at least 2 (the scale is logarithmic from 1).
pub fn density_scale_top(maps: &CovMaps) -> f64 {
    let mut spp: Vec<f64> = maps
        .pixels
        .iter()
        .map(|p| p.spp)
        .filter(|s| s.is_finite())
        .collect();
    if spp.is_empty() {
        return 2.0;
    }
    spp.sort_by(f64::total_cmp);
    let k = ((spp.len() - 1) as f64 * DENSITY_SCALE_QUANTILE).round() as usize;
    spp[k.min(spp.len() - 1)].max(2.0)
}

/// Writes the density map (samples per pixel, log scale from 1 to
/// [`density_scale_top`]; denser pixels take the top colour) and the
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
) -> Result<(), RenderError> {
    let hi = density_scale_top(maps).ln();
    let w = maps.width;
    let img = image::RgbImage::from_fn(maps.width, maps.height, |x, y| {
        let p = &maps.pixels[(y * w + x) as usize];
        image::Rgb(colormap((p.spp.max(1.0).ln() / hi).min(1.0)))
    });
    save(img, density)?;
    let stds: Vec<f64> = maps
        .pixels
        .iter()
        .map(|p| filter_std(content(p.sigma, pixel_filter), max_filter))
        .collect();
    let img = image::RgbImage::from_fn(maps.width, maps.height, |x, y| {
        image::Rgb(colormap(stds[(y * w + x) as usize] / max_filter))
    });
    save(img, filter)?;
    let data = serde_json::json!({
        "width": maps.width,
        "height": maps.height,
        "layout": maps.layout,
        "paths_per_block": maps.paths_per_block,
        "block_px": maps.stride,
        "units": { "sigma": "(cycles/px)^2, [xx, xy, yy] per pixel, x along the columns, y down the rows", "spp": "samples per pixel over pixel x lens x time" },
        "sigma": maps.pixels.iter().flat_map(|p| p.sigma).collect::<Vec<f64>>(),
        "spp": maps.pixels.iter().map(|p| p.spp).collect::<Vec<f64>>(),
    });
    let text = serde_json::to_string(&data).map_err(|e| RenderError::file(json, e))?;
    write_file(json, text.as_bytes())
}

/// The per-pixel relative squared error of `img` against `reference` (mean over
/// channels of `(I − R)² / (R² + ε)`), as a heat map: log scale from 1e-4 (dark) to 1
/// (yellow) and above.
///
/// # Errors
/// Images of different sizes.
pub fn error_map(img: &Image, reference: &Image) -> Result<image::RgbImage, RenderError> {
    crate::metrics::same_size(img, reference)?;
    Ok(image::RgbImage::from_fn(img.width, img.height, |x, y| {
        let (a, r) = (img.get(x, y), reference.get(x, y));
        let e = (0..3)
            .map(|k| (a[k] - r[k]).powi(2) / (r[k] * r[k] + crate::metrics::REL_EPS))
            .sum::<f64>()
            / 3.0;
        image::Rgb(colormap((e.max(1e-4).log10() + 4.0) / 4.0))
    }))
}

/// Writes a film's feature images as one multi-layer OpenEXR file (32-bit float): layer
/// `albedo` (R, G, B), layer `normal` (R, G, B: the components x, y, z in [-1, 1], world
/// space) and layer `depth` (Z, m), the guides a denoiser takes.
///
/// # Errors
/// The file cannot be written.
pub fn write_aovs(aovs: &Aovs, path: &Path) -> Result<(), RenderError> {
    use exr::prelude::*;
    let (w, h) = (aovs.albedo.width as usize, aovs.albedo.height as usize);
    let mut bytes = std::io::Cursor::new(Vec::new());
    let layer = |name: &str| (LayerAttributes::named(name), EXR_ENCODING);
    let (na, ea) = layer("albedo");
    let albedo = Layer::new((w, h), na, ea, SpecificChannels::rgb(|p| rgb_at(&aovs.albedo, p)));
    let (nn, en) = layer("normal");
    let normal = Layer::new((w, h), nn, en, SpecificChannels::rgb(|p| rgb_at(&aovs.normal, p)));
    let depth = Layer::new(
        (w, h),
        LayerAttributes::named("depth"),
        EXR_ENCODING,
        SpecificChannels::build()
            .with_channel("Z")
            .with_pixel_fn(|p: Vec2<usize>| (single(aovs.depth[p.y() * w + p.x()]),)),
    );
    Image::empty(ImageAttributes::new(IntegerBounds::from_dimensions((w, h))))
        .with_layer(albedo)
        .with_layer(normal)
        .with_layer(depth)
        .write()
        .to_buffered(&mut bytes)
        .map_err(|e| RenderError::file(path, e))?;
    write_file(path, bytes.get_ref())
}

#[cfg(test)]
mod tests {
    /// What the EXR stores is finite: past f32's range clamped to its largest, NaN as 0.
    #[test]
    fn single_precision_output_is_finite() {
        assert_eq!(super::single(1.5), 1.5);
        assert_eq!(super::single(1e300), f32::MAX);
        assert_eq!(super::single(f64::NEG_INFINITY), -f32::MAX);
        assert_eq!(super::single(f64::NAN), 0.0);
    }

    /// The same image is the same file, byte for byte, however exr's threads finish its
    /// tiles; and it reads back as written.
    #[test]
    fn an_exr_is_the_same_file_every_time() {
        let (w, h) = (300u32, 200u32);
        let img = crate::film::Image {
            width: w,
            height: h,
            pixels: (0..w * h)
                .map(|i| {
                    let t = f64::from(i);
                    glam::DVec3::new((t * 0.37).sin().abs() * 3.0, (t * 0.011).cos().abs(), t / 6e4)
                })
                .collect(),
        };
        let dir = std::env::temp_dir().join(format!("covtrace-exr-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let files: Vec<Vec<u8>> = (0..8)
            .map(|k| {
                let (exr, png) = (dir.join(format!("{k}.exr")), dir.join(format!("{k}.png")));
                super::write_image(&img, &exr, &png).unwrap();
                std::fs::read(&exr).unwrap()
            })
            .collect();
        assert!(files.iter().all(|f| f == &files[0]), "the files differ");
        let back = super::read_image(&dir.join("0.exr")).unwrap();
        assert_eq!((back.width, back.height), (w, h));
        for (a, b) in back.pixels.iter().zip(&img.pixels) {
            assert_eq!(*a, b.as_vec3().as_dvec3());
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A write that fails says so with the system's reason (not an encoder's "decoding"),
    /// leaves no partial regular file, and never removes what is not one.
    #[test]
    fn a_failed_write_says_why_and_leaves_nothing() {
        let img = image::RgbImage::new(4, 4);
        // A path under a regular file cannot be created: nothing is written.
        let dir = std::env::temp_dir().join(format!("covtrace-output-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("f");
        std::fs::write(&file, b"x").unwrap();
        let e = super::save(img, &file.join("a.png")).unwrap_err().to_string();
        assert!(e.contains("cannot write"), "{e}");
        assert_eq!(std::fs::read(&file).unwrap(), b"x");
        // A full device (Linux): the reason is the system's, and the device stays.
        let full = std::path::Path::new("/dev/full");
        if full.exists() {
            let e = super::write_file(full, &[0; 4096]).unwrap_err().to_string();
            assert!(e.contains("cannot write") && e.contains("No space"), "{e}");
            assert!(full.exists());
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
