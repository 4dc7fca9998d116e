//! RON parameters of the occlusion operators.

use cov_core::{Build, Checked, CovError, OperatorSpec, Registrar};

use crate::{BlockerEdge, Texture, ThickOccluder, Window, window_var};

/// `Window(std_x: 0.1)` or `Window(std_x: 0.1, std_y: 0.2)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "Gaussian window across the ray (an occluder's aperture)")]
pub struct WindowSpec {
    /// Std along x.
    #[param(unit = "m", positive)]
    pub std_x: f64,
    /// Std along y (`std_x` when left out).
    #[param(unit = "m", default, positive)]
    pub std_y: Option<f64>,
}

impl Build for WindowSpec {
    type Op = Window;
    #[inline]
    fn make(spec: Checked<Self>) -> Result<Window, CovError> {
        Ok(Window {
            wx: window_var(&WindowSpec::STD_X, spec.std_x)?,
            wy: match spec.std_y {
                Some(s) => window_var(&WindowSpec::STD_Y, s)?,
                None => window_var(&WindowSpec::STD_X, spec.std_x)?,
            },
        })
    }
}

/// `BlockerEdge(distance: 0.02)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "blocker edge near the ray (largest unoccluded disk rule)")]
pub struct BlockerEdgeSpec {
    /// Distance from the ray to the nearest blocker edge.
    #[param(unit = "m", positive)]
    pub distance: f64,
}

impl Build for BlockerEdgeSpec {
    type Op = BlockerEdge;
    fn make(spec: Checked<Self>) -> Result<BlockerEdge, CovError> {
        let w = window_var(&BlockerEdgeSpec::DISTANCE, spec.distance)?;
        Ok(BlockerEdge {
            window: Window { wx: w, wy: w },
            distance: spec.distance,
        })
    }
}

/// `Texture(feature: 0.01)` or `Texture(sxx: 100, sxy: 0, syy: 50)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "texture variation as a window on position")]
pub struct TextureSpec {
    /// Size of the texture's features (a Gaussian bump of that std); or give the spectrum `sxx`, `sxy`, `syy`.
    #[param(unit = "m", default, positive)]
    pub feature: Option<f64>,
    /// Spectrum covariance xx.
    #[param(unit = "(cycles/m)²", default, non_negative)]
    pub sxx: Option<f64>,
    /// Spectrum covariance xy, `|sxy| ≤ √(sxx·syy)` (0 when left out).
    #[param(unit = "(cycles/m)²", default)]
    pub sxy: Option<f64>,
    /// Spectrum covariance yy (`sxx` when left out).
    #[param(unit = "(cycles/m)²", default, non_negative)]
    pub syy: Option<f64>,
}

impl Build for TextureSpec {
    type Op = Texture;
    #[inline]
    fn make(spec: Checked<Self>) -> Result<Texture, CovError> {
        let (sxx, sxy, syy) = match (spec.feature, spec.sxx) {
            (Some(f), None) if spec.sxy.is_none() && spec.syy.is_none() => {
                let w = window_var(&TextureSpec::FEATURE, f)?;
                (w, 0.0, w)
            }
            (None, Some(sxx)) => (sxx, spec.sxy.unwrap_or(0.0), spec.syy.unwrap_or(sxx)),
            (f, _) => {
                let [feature, sxx, sxy, syy] = [
                    &TextureSpec::FEATURE,
                    &TextureSpec::SXX,
                    &TextureSpec::SXY,
                    &TextureSpec::SYY,
                ];
                let forms = format!(
                    "give either `{}` or the spectrum `{}` (with optional `{}`, `{}`)",
                    feature.name, sxx.name, sxy.name, syy.name
                );
                // Neither form, or `feature` with a part of the spectrum: said of that part.
                return Err(
                    match (
                        f,
                        [(sxx, spec.sxx), (sxy, spec.sxy), (syy, spec.syy)]
                            .into_iter()
                            .find(|(_, v)| v.is_some()),
                    ) {
                        (Some(_), Some((part, _))) => {
                            part.choice(format!("not with `{}`; {forms}", feature.name))
                        }
                        _ => feature.choice(format!("missing; {forms}")),
                    },
                );
            }
        };
        // PSD, with a relative tolerance for rounding in the caller's products.
        if sxy * sxy > sxx * syy * (1.0 + 1e-12) {
            return Err(TextureSpec::SXY.error(
                sxy,
                format!("|sxy| must be ≤ √(sxx·syy) = {}", (sxx * syy).sqrt()),
            ));
        }
        Ok(Texture { s: [sxx, sxy, syy] })
    }
}

/// `ThickOccluder(depth: 0.3, slices: 4, std: 0.05)`.
#[derive(Debug, OperatorSpec)]
#[operator(
    summary = "an occluder with depth: `slices` times a window then a travel of depth/slices (its travels add up to `depth`; add none of your own across it)"
)]
pub struct ThickOccluderSpec {
    /// Depth of the occluder along the ray.
    #[param(unit = "m", non_negative)]
    pub depth: f64,
    /// Number of slices, each a window and a travel. (At most 10⁴. The operator applies
    /// them in closed form, at the same cost for any number.)
    #[param(ge = 1, le = 10_000)]
    pub slices: u32,
    /// Window std of each slice.
    #[param(unit = "m", positive)]
    pub std: f64,
}

impl Build for ThickOccluderSpec {
    type Op = ThickOccluder;
    fn make(spec: Checked<Self>) -> Result<ThickOccluder, CovError> {
        let w = window_var(&ThickOccluderSpec::STD, spec.std)?;
        Ok(ThickOccluder {
            window: Window { wx: w, wy: w },
            depth: spec.depth,
            slices: spec.slices,
        })
    }
}

/// Registers this crate's operators.
pub fn register<R: Registrar>(r: &mut R) {
    r.add::<WindowSpec>()
        .add::<BlockerEdgeSpec>()
        .add::<TextureSpec>()
        .add::<ThickOccluderSpec>();
}
