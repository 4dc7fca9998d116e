//! RON parameters of the occlusion operators.

use cov_core::CovError;
use cov_core::{OperatorSpec, Registrar};

use crate::{BlockerEdge, Texture, ThickOccluder, Window};

/// `Window(std_x: 0.1)` or `Window(std_x: 0.1, std_y: 0.2)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "Gaussian window across the ray (an occluder's aperture)")]
pub struct WindowSpec {
    /// Std along x, > 0.
    #[param(unit = "m")]
    pub std_x: f64,
    /// Std along y, > 0 (`std_x` when left out).
    #[param(unit = "m", default)]
    pub std_y: Option<f64>,
}

impl TryFrom<WindowSpec> for Window {
    type Error = CovError;
    fn try_from(spec: WindowSpec) -> Result<Window, CovError> {
        Window::new(spec.std_x, spec.std_y.unwrap_or(spec.std_x))
    }
}

/// `BlockerEdge(distance: 0.02)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "blocker edge near the ray (largest unoccluded disk rule)")]
pub struct BlockerEdgeSpec {
    /// Distance from the ray to the nearest blocker edge, > 0.
    #[param(unit = "m")]
    pub distance: f64,
}

impl TryFrom<BlockerEdgeSpec> for BlockerEdge {
    type Error = CovError;
    fn try_from(spec: BlockerEdgeSpec) -> Result<BlockerEdge, CovError> {
        BlockerEdge::new(spec.distance)
    }
}

/// `Texture(feature: 0.01)` or `Texture(sxx: 100, sxy: 0, syy: 50)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "texture variation as a window on position")]
pub struct TextureSpec {
    /// Size of the texture's features (a Gaussian bump of that std), > 0; or give the spectrum `sxx`, `sxy`, `syy`.
    #[param(unit = "m", default)]
    pub feature: Option<f64>,
    /// Spectrum covariance xx, ≥ 0.
    #[param(unit = "(cycles/m)²", default)]
    pub sxx: Option<f64>,
    /// Spectrum covariance xy, `|sxy| ≤ √(sxx·syy)` (0 when left out).
    #[param(unit = "(cycles/m)²", default)]
    pub sxy: Option<f64>,
    /// Spectrum covariance yy, ≥ 0 (`sxx` when left out).
    #[param(unit = "(cycles/m)²", default)]
    pub syy: Option<f64>,
}

impl TryFrom<TextureSpec> for Texture {
    type Error = CovError;
    fn try_from(spec: TextureSpec) -> Result<Texture, CovError> {
        match (spec.feature, spec.sxx) {
            (Some(f), None) if spec.sxy.is_none() && spec.syy.is_none() => Texture::gaussian_feature(f),
            (None, Some(sxx)) => Texture::new(sxx, spec.sxy.unwrap_or(0.0), spec.syy.unwrap_or(sxx)),
            _ => Err(CovError::OutOfRange {
                operator: "Texture".into(),
                parameter: "feature / sxx".into(),
                value: f64::NAN,
                expected: "give either `feature` or the spectrum `sxx` (with optional `sxy`, `syy`)".into(),
            }),
        }
    }
}

/// `ThickOccluder(depth: 0.3, slices: 4, std: 0.05)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "an occluder with depth, as slices of windows with travel between")]
pub struct ThickOccluderSpec {
    /// Depth of the occluder along the ray, ≥ 0.
    #[param(unit = "m")]
    pub depth: f64,
    /// Number of slices, 1 to 10000.
    pub slices: u32,
    /// Window std of each slice, > 0.
    #[param(unit = "m")]
    pub std: f64,
}

impl TryFrom<ThickOccluderSpec> for ThickOccluder {
    type Error = CovError;
    fn try_from(spec: ThickOccluderSpec) -> Result<ThickOccluder, CovError> {
        ThickOccluder::new(spec.depth, spec.slices, spec.std)
    }
}

/// Registers this crate's operators.
pub fn register<R: Registrar>(r: &mut R) {
    r.add::<WindowSpec>()
        .add::<BlockerEdgeSpec>()
        .add::<TextureSpec>()
        .add::<ThickOccluderSpec>();
}
