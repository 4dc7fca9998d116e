//! RON parameters of the media operators.

use cov_core::{Build, Checked, CovError, OperatorSpec, Param, Registrar};

use crate::{Absorption, Fit, Phase, Scatter, Segment, psd_part};

/// `[hxx]` or `[hxx, hxy, hyy]` as `[hxx, hxy, hyy]`; `p` is the parameter.
fn hessian(p: &Param, h: &[f64]) -> Result<[f64; 3], CovError> {
    match h {
        [a] => Ok([*a, 0.0, 0.0]),
        [a, b, c] => Ok([*a, *b, *c]),
        _ => Err(p.wrong_length(h.len(), "[hxx] or [hxx, hxy, hyy]")),
    }
}

/// The absorption of a segment of checked `length` with the Hessian `h`, the parameter `p`.
fn absorption(length: f64, p: &Param, h: &[f64]) -> Result<Absorption, CovError> {
    Ok(Absorption {
        length,
        h: psd_part(hessian(p, h)?),
    })
}

/// `Absorption(length: 2.0, hessian: [0.5])`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "absorption across a heterogeneous segment (a window)")]
pub struct AbsorptionSpec {
    /// Length of the segment.
    #[param(unit = "m", non_negative)]
    pub length: f64,
    /// Hessian of σ_t across the ray: `[hxx]` or `[hxx, hxy, hyy]`.
    #[param(unit = "1/m³")]
    pub hessian: Vec<f64>,
}

impl Build for AbsorptionSpec {
    type Op = Absorption;
    fn make(spec: Checked<Self>) -> Result<Absorption, CovError> {
        absorption(spec.length, &Self::HESSIAN, &spec.hessian)
    }
}

/// `Segment(length: 2.0, hessian: [0.5])`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "a volumetric segment: absorption then travel")]
pub struct SegmentSpec {
    /// Length of the segment.
    #[param(unit = "m", non_negative)]
    pub length: f64,
    /// Hessian of σ_t across the ray: `[hxx]` or `[hxx, hxy, hyy]`.
    #[param(unit = "1/m³")]
    pub hessian: Vec<f64>,
}

impl Build for SegmentSpec {
    type Op = Segment;
    fn make(spec: Checked<Self>) -> Result<Segment, CovError> {
        Ok(Segment {
            absorption: absorption(spec.length, &Self::HESSIAN, &spec.hessian)?,
        })
    }
}

/// `Scatter(angle: 0.3, phase: HenyeyGreenstein(g: 0.7), fit: Curvature, azimuth: 0.0)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "scattering at a point: frame alignment and the phase function lobe")]
pub struct ScatterSpec {
    /// Scattering angle.
    #[param(unit = "rad", ge = 0, le = std::f64::consts::PI)]
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

impl Build for ScatterSpec {
    type Op = Scatter;
    fn make(spec: Checked<Self>) -> Result<Scatter, CovError> {
        let spec = spec.into_inner();
        Scatter::checked(
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
