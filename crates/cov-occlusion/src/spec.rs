//! RON parameters of the occlusion operators.

use cov_core::CovError;
use cov_path::{OperatorSpec, Param, Registry};
use serde::Deserialize;

use crate::{BlockerEdge, Texture, ThickOccluder, Window};

/// `Window(std_x: 0.1)` or `Window(std_x: 0.1, std_y: 0.2)`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WindowSpec {
    /// Std along x (m).
    pub std_x: f64,
    /// Std along y (m); defaults to `std_x`.
    #[serde(default)]
    pub std_y: Option<f64>,
}

impl OperatorSpec for WindowSpec {
    const NAME: &'static str = Window::NAME;
    const SUMMARY: &'static str = "Gaussian window across the ray (an occluder's aperture)";
    const PARAMS: &'static [Param] = &[
        Param {
            name: "std_x",
            unit: "m",
            doc: "> 0",
        },
        Param {
            name: "std_y",
            unit: "m",
            doc: "> 0, optional (default std_x)",
        },
    ];
    type Op = Window;
    fn build(self) -> Result<Window, CovError> {
        Window::new(self.std_x, self.std_y.unwrap_or(self.std_x))
    }
}

/// `BlockerEdge(distance: 0.02)`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlockerEdgeSpec {
    /// Distance from the ray to the nearest blocker edge (m).
    pub distance: f64,
}

impl OperatorSpec for BlockerEdgeSpec {
    const NAME: &'static str = BlockerEdge::NAME;
    const SUMMARY: &'static str = "blocker edge near the ray (largest unoccluded disk rule)";
    const PARAMS: &'static [Param] = &[Param {
        name: "distance",
        unit: "m",
        doc: "> 0",
    }];
    type Op = BlockerEdge;
    fn build(self) -> Result<BlockerEdge, CovError> {
        BlockerEdge::new(self.distance)
    }
}

/// `Texture(feature: 0.01)` or `Texture(sxx: 100, sxy: 0, syy: 50)`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TextureSpec {
    /// Size of the texture's features (m): a Gaussian bump of that std.
    #[serde(default)]
    pub feature: Option<f64>,
    /// Spectrum covariance xx ((cycles/m)²).
    #[serde(default)]
    pub sxx: Option<f64>,
    /// Spectrum covariance xy.
    #[serde(default)]
    pub sxy: Option<f64>,
    /// Spectrum covariance yy.
    #[serde(default)]
    pub syy: Option<f64>,
}

impl OperatorSpec for TextureSpec {
    const NAME: &'static str = "Texture";
    const SUMMARY: &'static str = "texture variation as a window on position";
    const PARAMS: &'static [Param] = &[
        Param {
            name: "feature",
            unit: "m",
            doc: "> 0; or give the spectrum below",
        },
        Param {
            name: "sxx",
            unit: "(cycles/m)²",
            doc: "≥ 0",
        },
        Param {
            name: "sxy",
            unit: "(cycles/m)²",
            doc: "|sxy| ≤ √(sxx·syy), default 0",
        },
        Param {
            name: "syy",
            unit: "(cycles/m)²",
            doc: "≥ 0, default sxx",
        },
    ];
    type Op = Texture;
    fn build(self) -> Result<Texture, CovError> {
        match (self.feature, self.sxx) {
            (Some(f), None) if self.sxy.is_none() && self.syy.is_none() => Texture::gaussian_feature(f),
            (None, Some(sxx)) => Texture::new(sxx, self.sxy.unwrap_or(0.0), self.syy.unwrap_or(sxx)),
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
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ThickOccluderSpec {
    /// Depth of the occluder along the ray (m).
    pub depth: f64,
    /// Number of slices.
    pub slices: u32,
    /// Window std of each slice (m).
    pub std: f64,
}

impl OperatorSpec for ThickOccluderSpec {
    const NAME: &'static str = ThickOccluder::NAME;
    const SUMMARY: &'static str = "an occluder with depth, as slices of windows with travel between";
    const PARAMS: &'static [Param] = &[
        Param {
            name: "depth",
            unit: "m",
            doc: "≥ 0",
        },
        Param {
            name: "slices",
            unit: "–",
            doc: "≥ 1",
        },
        Param {
            name: "std",
            unit: "m",
            doc: "> 0",
        },
    ];
    type Op = ThickOccluder;
    fn build(self) -> Result<ThickOccluder, CovError> {
        ThickOccluder::new(self.depth, self.slices, self.std)
    }
}

/// Registers this crate's operators.
pub fn register(r: &mut Registry) {
    r.register::<WindowSpec>()
        .register::<BlockerEdgeSpec>()
        .register::<TextureSpec>()
        .register::<ThickOccluderSpec>();
}
