//! RON parameters of the curvature operators.

use cov_core::{Build, Checked, CovError, OperatorSpec, Registrar};
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
        self.build()
    }
}

impl Build for CurvatureSpec {
    type Op = Curvature;
    #[inline]
    fn make(spec: Checked<Self>) -> Result<Curvature, CovError> {
        match (spec.k, spec.kx, spec.ky) {
            (Some(k), None, None) if spec.angle.is_none() => Curvature::checked(k, k, 0.0),
            (None, kx, ky) => {
                Curvature::checked(kx.unwrap_or(0.0), ky.unwrap_or(0.0), spec.angle.unwrap_or(0.0))
            }
            _ => {
                let [k, kx, ky, angle] = [&Self::K, &Self::KX, &Self::KY, &Self::ANGLE];
                // `k` is given with one of the principal form: said of that one.
                let given = [(kx, spec.kx), (ky, spec.ky), (angle, spec.angle)];
                let other = given.iter().find(|(_, v)| v.is_some()).map_or(kx, |(p, _)| *p);
                Err(other.choice(format!(
                    "not with `{}`; give either `{}` alone or the principal form `{}`, `{}`, `{}`",
                    k.name, k.name, kx.name, ky.name, angle.name
                )))
            }
        }
    }
}

/// `CurvatureTensor(kxx: 1, kxy: 0.2, kyy: -0.5)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "surface curvature given by its tensor in the frame")]
pub struct CurvatureTensorSpec {
    /// `K_xx`.
    #[param(unit = "1/m")]
    pub kxx: f64,
    /// `K_xy`.
    #[param(unit = "1/m", default)]
    pub kxy: f64,
    /// `K_yy`.
    #[param(unit = "1/m", default)]
    pub kyy: f64,
}

impl Build for CurvatureTensorSpec {
    type Op = CurvatureTensor;
    #[inline]
    fn make(spec: Checked<Self>) -> Result<CurvatureTensor, CovError> {
        Ok(CurvatureTensor {
            k: [spec.kxx, spec.kxy, spec.kyy],
        })
    }
}

/// Registers this crate's operators.
pub fn register<R: Registrar>(r: &mut R) {
    r.add::<CurvatureSpec>().add::<CurvatureTensorSpec>();
}
