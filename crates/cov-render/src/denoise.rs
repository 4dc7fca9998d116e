//! Denoising with Intel Open Image Denoise (OIDN), the denoiser users of a renderer already
//! have: the baseline covariance tracing is measured against, and a partner it feeds.
//!
//! OIDN's ray-tracing filter takes the noisy HDR image and, optionally, the feature images
//! of the first hit (albedo and normal, [`crate::film::Aovs`]), averaged over each pixel's
//! samples like the image. It is linked only with the cargo feature `oidn` (off by
//! default): build with `--features oidn` and `OIDN_DIR` set to an OIDN 2.x installation
//! (for example the libraries of the `pyoidn` wheel, see `docs/oidn.md`). Without the
//! feature, [`oidn`] returns an error that says so.

use crate::RenderError;
use crate::film::{Aovs, Image};

/// Which denoiser runs after reconstruction.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Denoise {
    /// None: the method's own reconstruction.
    #[default]
    None,
    /// OIDN with the albedo and normal guides.
    Oidn,
    /// OIDN on the colour alone.
    OidnColor,
}

impl Denoise {
    /// Every denoiser, `None` first.
    pub const ALL: [Denoise; 3] = [Denoise::None, Denoise::Oidn, Denoise::OidnColor];

    /// Its name on the command line (`""` for none).
    pub fn name(self) -> &'static str {
        match self {
            Denoise::None => "",
            Denoise::Oidn => "oidn",
            Denoise::OidnColor => "oidn-color",
        }
    }

    /// The denoiser of a name (`None` for an unknown one).
    pub fn from_name(s: &str) -> Option<Denoise> {
        Denoise::ALL.into_iter().find(|d| d.name() == s)
    }
}

/// Whether this build links OIDN (the cargo feature `oidn`).
pub const AVAILABLE: bool = cfg!(feature = "oidn");

/// `img` as OIDN's interleaved `f32` RGB; non-finite values as 0.
fn rgb_f32(img: &Image) -> Vec<f32> {
    img.pixels
        .iter()
        .flat_map(|p| [p.x, p.y, p.z])
        .map(|v| if v.is_finite() { v as f32 } else { 0.0 })
        .collect()
}

/// Denoises `image` with OIDN's ray-tracing filter (HDR, high quality), guided by the
/// albedo and normal of `guides` when given.
///
/// # Errors
/// This build has no OIDN (the feature `oidn` is off), OIDN cannot create a CPU device,
/// or it reports an error while filtering.
pub fn oidn(image: &Image, guides: Option<&Aovs>) -> Result<Image, RenderError> {
    let color = rgb_f32(image);
    let aux = guides.map(|g| {
        let albedo: Vec<f32> = rgb_f32(&g.albedo)
            .into_iter()
            .map(|v| v.clamp(0.0, 1.0))
            .collect();
        let normal: Vec<f32> = rgb_f32(&g.normal)
            .into_iter()
            .map(|v| v.clamp(-1.0, 1.0))
            .collect();
        (albedo, normal)
    });
    let out = run(&color, aux.as_ref(), image.width as usize, image.height as usize)?;
    let pixels = out
        .chunks_exact(3)
        .map(|c| glam::DVec3::new(f64::from(c[0]), f64::from(c[1]), f64::from(c[2])))
        .map(|p| {
            if p.is_finite() {
                p.max(glam::DVec3::ZERO)
            } else {
                glam::DVec3::ZERO
            }
        })
        .collect();
    Ok(Image {
        width: image.width,
        height: image.height,
        pixels,
    })
}

#[cfg(feature = "oidn")]
fn run(
    color: &[f32],
    aux: Option<&(Vec<f32>, Vec<f32>)>,
    w: usize,
    h: usize,
) -> Result<Vec<f32>, RenderError> {
    let fail = |e: oidn::Error| RenderError::Denoiser(format!("Open Image Denoise: {e:?}"));
    let device = oidn::Device::cpu().map_err(fail)?;
    let mut filter = oidn::RayTracing::try_new(&device).map_err(fail)?;
    filter.hdr(true).image_dimensions(w, h);
    if let Some((albedo, normal)) = aux {
        filter.albedo_normal(albedo, normal);
    }
    let mut output = vec![0.0f32; color.len()];
    filter.filter(color, &mut output).map_err(fail)?;
    device.get_error().map_err(fail)?;
    Ok(output)
}

#[cfg(not(feature = "oidn"))]
fn run(_: &[f32], _: Option<&(Vec<f32>, Vec<f32>)>, _: usize, _: usize) -> Result<Vec<f32>, RenderError> {
    Err(RenderError::Denoiser(
        "this covtrace was built without Open Image Denoise: rebuild with `--features oidn` and OIDN_DIR set (docs/oidn.md)"
            .into(),
    ))
}
