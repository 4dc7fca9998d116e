//! RON parameters of the curvature operators.

use cov_core::CovError;
use cov_core::{OperatorSpec, Registrar};
use serde::Deserialize;

use crate::{Curvature, CurvatureTensor};

/// `Curvature(k: 2.0)` (isotropic) or `Curvature(kx: 2.0, ky: -1.0, angle: 0.3)`.
/// Also the form of the `curvature` field of composite operators: `(k: 2.0)`.
#[derive(Clone, Copy, Debug, Default, Deserialize, OperatorSpec)]
#[serde(deny_unknown_fields, rename = "Curvature")]
#[operator(summary = "surface curvature in the surface frame, l(x, u + k·x)")]
pub struct CurvatureSpec {
    /// Isotropic curvature (> 0 convex).
    #[serde(default)]
    #[param(unit = "1/m", default)]
    pub k: Option<f64>,
    /// First principal curvature, along `angle`.
    #[serde(default)]
    #[param(unit = "1/m", default)]
    pub kx: Option<f64>,
    /// Second principal curvature, across `angle`.
    #[serde(default)]
    #[param(unit = "1/m", default)]
    pub ky: Option<f64>,
    /// Angle of the first principal direction from x.
    #[serde(default)]
    #[param(unit = "rad", default)]
    pub angle: Option<f64>,
}

impl CurvatureSpec {
    /// The curvature this describes (flat when empty).
    ///
    /// # Errors
    /// Both `k` and `kx`/`ky` given, or invalid values.
    pub fn to_curvature(self) -> Result<Curvature, CovError> {
        match (self.k, self.kx, self.ky) {
            (Some(k), None, None) if self.angle.is_none() => Curvature::isotropic(k),
            (None, kx, ky) => {
                Curvature::anisotropic(kx.unwrap_or(0.0), ky.unwrap_or(0.0), self.angle.unwrap_or(0.0))
            }
            _ => Err(CovError::OutOfRange {
                operator: Curvature::NAME.into(),
                parameter: "k / kx, ky, angle".into(),
                value: f64::NAN,
                expected: "give either `k` alone or the principal form `kx`, `ky`, `angle`".into(),
            }),
        }
    }
}

impl TryFrom<CurvatureSpec> for Curvature {
    type Error = CovError;
    fn try_from(spec: CurvatureSpec) -> Result<Curvature, CovError> {
        spec.to_curvature()
    }
}

/// `CurvatureTensor(kxx: 1, kxy: 0.2, kyy: -0.5)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "surface curvature given by its tensor in the frame")]
pub struct CurvatureTensorSpec {
    /// `K_xx`, finite.
    #[param(unit = "1/m")]
    pub kxx: f64,
    /// `K_xy`, finite.
    #[param(unit = "1/m", default)]
    pub kxy: f64,
    /// `K_yy`, finite.
    #[param(unit = "1/m", default)]
    pub kyy: f64,
}

impl TryFrom<CurvatureTensorSpec> for CurvatureTensor {
    type Error = CovError;
    fn try_from(spec: CurvatureTensorSpec) -> Result<CurvatureTensor, CovError> {
        CurvatureTensor::new(spec.kxx, spec.kxy, spec.kyy)
    }
}

/// Registers this crate's operators.
pub fn register<R: Registrar>(r: &mut R) {
    r.add::<CurvatureSpec>().add::<CurvatureTensorSpec>();
}
