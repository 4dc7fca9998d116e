//! RON parameters of the curvature operators.

use cov_core::CovError;
use cov_path::{OperatorSpec, Param, Registry};
use serde::Deserialize;

use crate::{Curvature, CurvatureTensor};

/// `Curvature(k: 2.0)` (isotropic) or `Curvature(kx: 2.0, ky: -1.0, angle: 0.3)`.
/// Also the form of the `curvature` field of composite operators: `(k: 2.0)`.
#[derive(Clone, Copy, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CurvatureSpec {
    /// Isotropic curvature (1/m).
    #[serde(default)]
    pub k: Option<f64>,
    /// First principal curvature (1/m).
    #[serde(default)]
    pub kx: Option<f64>,
    /// Second principal curvature (1/m).
    #[serde(default)]
    pub ky: Option<f64>,
    /// Angle of the first principal direction from x (rad).
    #[serde(default)]
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

impl OperatorSpec for CurvatureSpec {
    const NAME: &'static str = Curvature::NAME;
    const SUMMARY: &'static str = "surface curvature in the surface frame, l(x, u + k·x)";
    const PARAMS: &'static [Param] = &[
        Param {
            name: "k",
            unit: "1/m",
            doc: "isotropic curvature (> 0 convex)",
        },
        Param {
            name: "kx",
            unit: "1/m",
            doc: "principal curvature along `angle`",
        },
        Param {
            name: "ky",
            unit: "1/m",
            doc: "principal curvature across it",
        },
        Param {
            name: "angle",
            unit: "rad",
            doc: "principal direction from x",
        },
    ];
    type Op = Curvature;
    fn build(self) -> Result<Curvature, CovError> {
        self.to_curvature()
    }
}

/// `CurvatureTensor(kxx: 1, kxy: 0.2, kyy: -0.5)`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CurvatureTensorSpec {
    /// K_xx (1/m).
    pub kxx: f64,
    /// K_xy (1/m).
    #[serde(default)]
    pub kxy: f64,
    /// K_yy (1/m).
    #[serde(default)]
    pub kyy: f64,
}

impl OperatorSpec for CurvatureTensorSpec {
    const NAME: &'static str = CurvatureTensor::NAME;
    const SUMMARY: &'static str = "surface curvature given by its tensor in the frame";
    const PARAMS: &'static [Param] = &[
        Param {
            name: "kxx",
            unit: "1/m",
            doc: "finite",
        },
        Param {
            name: "kxy",
            unit: "1/m",
            doc: "finite, default 0",
        },
        Param {
            name: "kyy",
            unit: "1/m",
            doc: "finite, default 0",
        },
    ];
    type Op = CurvatureTensor;
    fn build(self) -> Result<CurvatureTensor, CovError> {
        CurvatureTensor::new(self.kxx, self.kxy, self.kyy)
    }
}

/// Registers this crate's operators.
pub fn register(r: &mut Registry) {
    r.register::<CurvatureSpec>().register::<CurvatureTensorSpec>();
}
