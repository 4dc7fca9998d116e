//! RON parameters of the media operators.

use cov_core::CovError;
use cov_core::{OperatorSpec, Registrar};

use crate::{Absorption, Fit, Phase, Scatter, Segment};

fn hessian(op: &str, h: &[f64]) -> Result<[f64; 3], CovError> {
    match h {
        [a] => Ok([*a, 0.0, 0.0]),
        [a, b, c] => Ok([*a, *b, *c]),
        _ => Err(CovError::Shape {
            what: format!("{op}: hessian"),
            expected: "[hxx] or [hxx, hxy, hyy]".into(),
            got: format!("{} numbers", h.len()),
        }),
    }
}

/// `Absorption(length: 2.0, hessian: [0.5])`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "absorption across a heterogeneous segment (a window)")]
pub struct AbsorptionSpec {
    /// Length of the segment, ≥ 0.
    #[param(unit = "m")]
    pub length: f64,
    /// Hessian of σ_t across the ray: `[hxx]` or `[hxx, hxy, hyy]`.
    #[param(unit = "1/m³")]
    pub hessian: Vec<f64>,
}

impl TryFrom<AbsorptionSpec> for Absorption {
    type Error = CovError;
    fn try_from(spec: AbsorptionSpec) -> Result<Absorption, CovError> {
        Absorption::new(spec.length, hessian(Absorption::NAME, &spec.hessian)?)
    }
}

/// `Segment(length: 2.0, hessian: [0.5])`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "a volumetric segment: absorption then travel")]
pub struct SegmentSpec {
    /// Length of the segment, ≥ 0.
    #[param(unit = "m")]
    pub length: f64,
    /// Hessian of σ_t across the ray: `[hxx]` or `[hxx, hxy, hyy]`.
    #[param(unit = "1/m³")]
    pub hessian: Vec<f64>,
}

impl TryFrom<SegmentSpec> for Segment {
    type Error = CovError;
    fn try_from(spec: SegmentSpec) -> Result<Segment, CovError> {
        Segment::new(spec.length, hessian(Segment::NAME, &spec.hessian)?)
    }
}

/// `Scatter(angle: 0.3, phase: HenyeyGreenstein(g: 0.7), fit: Curvature, azimuth: 0.0)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "scattering at a point: frame alignment and the phase function lobe")]
pub struct ScatterSpec {
    /// Scattering angle, in [0, π].
    #[param(unit = "rad")]
    pub angle: f64,
    /// Phase function: `HenyeyGreenstein(g)` or `Tabulated(angles, values)`.
    pub phase: Phase,
    /// How the phase lobe is fitted: `Moment` (default) or `Curvature`.
    #[param(default)]
    pub fit: Option<Fit>,
    /// Frame rotation into the scattering plane (3D).
    #[param(unit = "rad", default)]
    pub azimuth: Option<f64>,
}

impl TryFrom<ScatterSpec> for Scatter {
    type Error = CovError;
    fn try_from(spec: ScatterSpec) -> Result<Scatter, CovError> {
        Scatter::new(
            spec.angle,
            spec.phase,
            spec.fit.unwrap_or_default(),
            spec.azimuth.unwrap_or(0.0),
        )
    }
}

/// Registers this crate's operators.
pub fn register<R: Registrar>(r: &mut R) {
    r.add::<AbsorptionSpec>()
        .add::<SegmentSpec>()
        .add::<ScatterSpec>();
}
