//! Image error against a reference: what render-bench and the tests measure.

use crate::RenderError;
use crate::film::Image;

/// The `relMSE` denominator's offset: `(I − R)² / (R² + ε)` per channel. It keeps black
/// pixels of the reference from dominating the mean; 0.01 is the convention of the
/// adaptive-sampling literature for images of mean luminance near 1 (it is not tuned on a
/// scene).
pub const REL_EPS: f64 = 0.01;

pub(crate) fn same_size(img: &Image, reference: &Image) -> Result<(), RenderError> {
    if (img.width, img.height) == (reference.width, reference.height) {
        return Ok(());
    }
    Err(RenderError::Size {
        what: "an image against its reference",
        a_w: img.width,
        a_h: img.height,
        b_w: reference.width,
        b_h: reference.height,
    })
}

/// An image's errors against a reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metrics {
    /// Root mean square error over pixels and channels.
    pub rmse: f64,
    /// Mean of `(I − R)² / (R² + ε)` over pixels and channels ([`REL_EPS`]).
    pub relmse: f64,
}

/// The errors of `img` against `reference` (same size).
///
/// # Errors
/// Images of different sizes.
pub fn measure(img: &Image, reference: &Image) -> Result<Metrics, RenderError> {
    same_size(img, reference)?;
    let (mut se, mut rel) = (0.0, 0.0);
    for (a, r) in img.pixels.iter().zip(&reference.pixels) {
        for k in 0..3 {
            let d = a[k] - r[k];
            se += d * d;
            rel += d * d / (r[k] * r[k] + REL_EPS);
        }
    }
    let n = (3 * img.pixels.len()).max(1) as f64;
    Ok(Metrics {
        rmse: (se / n).sqrt(),
        relmse: rel / n,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_are_zero_on_the_reference_and_scale_as_expected() {
        let r = Image {
            width: 2,
            height: 1,
            pixels: vec![glam::DVec3::splat(1.0), glam::DVec3::splat(0.0)],
        };
        assert_eq!(
            measure(&r, &r).unwrap(),
            Metrics {
                rmse: 0.0,
                relmse: 0.0
            }
        );
        let mut a = r.clone();
        a.pixels[1] = glam::DVec3::splat(0.1);
        let e = measure(&a, &r).unwrap();
        assert!((e.rmse - (0.01f64 * 3.0 / 6.0).sqrt()).abs() < 1e-12);
        assert!((e.relmse - 0.5).abs() < 1e-12, "{}", e.relmse);
    }
}
